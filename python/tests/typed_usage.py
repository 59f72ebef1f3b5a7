"""Checked by `mypy --strict` in .ci/run (not run by pytest): the package's stubs and annotations are real.

Each `# type: ignore[...]` marks a call the types must refuse; with --strict (warn_unused_ignores), an ignore
that nothing needed fails the check, so stubs that had gone `Any` would fail here."""
import pathlib
from typing import Any, Dict, List

import numpy as np
import numpy.typing as npt
import pandas as pd

import glossmeter
from glossmeter import (
    CompareReport,
    ConvergenceReport,
    FitReport,
    LobeHint,
    ProfileReport,
    Reading,
    Sheet,
    SweepPoint,
)


def grey(wi: npt.NDArray[np.float64], wo: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    return np.full(len(wi), 0.1)


def usage() -> None:
    readings: List[Reading] = glossmeter.measure(pathlib.Path("fixtures/recipes/black-glass.json"))
    value = readings[0]["value"]
    if value is not None:
        print(value + 1.0)
    print(readings[0]["geometry"].upper(), readings[0]["evaluations"] + 1, readings[0].get("note"))
    frame: pd.DataFrame = glossmeter.measure({"model": "lambert", "albedo": 0.5}, as_frame=True)
    arrays: Dict[str, npt.NDArray[Any]] = glossmeter.measure("{}", ["astm-d523-60"], 1e-6, False, as_arrays=True)
    hint: LobeHint = {"slope": 0.05, "tail": "gaussian"}
    brdf: List[Reading] = glossmeter.measure_brdf(grey, geometries="astm-d523-60", lobes=[0.1, hint], delta=0.04)
    print(frame.shape, arrays["value"].mean(), brdf[0]["converged"])
    ids: List[str] = glossmeter.DEFAULT_GEOMETRIES
    spec: Dict[str, Any] = glossmeter.geometry(ids[0])
    text: str = glossmeter.describe_geometry(spec) + glossmeter.describe({"model": "lambert", "albedo": 0.5})
    print(text, glossmeter.schema()["title"], len(glossmeter.standards()), glossmeter.__version__)

    sheet: Sheet = glossmeter.read_sheet("fixtures/sheets/black-glass-check.csv", header_row=3, ignore_columns="x")
    print(sheet["rows"][0]["value"] + 1.0, sheet["sheet"]["layout"], sheet["workbook_sheet"])
    report: CompareReport = glossmeter.compare(pathlib.Path("r.json"), b"sample,60\nx,1\n", tolerance={"gloss": 2})
    print(report["summary"]["outside"] + 1, report["comparisons"][0]["verdict"], report.get("baseline"))
    points: List[SweepPoint] = glossmeter.sweep("r.json", ["/roughness=0.1..0.2:3"], shard=(1, 2), timing=False)
    rows: pd.DataFrame = glossmeter.read_sheet(b"sample,60\nx,1\n", as_frame=True)
    grid: pd.DataFrame = glossmeter.sweep("r.json", "/roughness=0.1..0.2:3", as_frame=True)
    print(rows.shape, grid.shape, glossmeter.sweep_rows(points)[0]["index"])
    for p in points:
        for r in p.get("readings") or []:
            print(p["index"], p["parameters"]["/roughness"], r["value"])
    fitted: FitReport = glossmeter.fit("r.json", {"astm-d523-60/gloss": (60.0, 0.2)}, free={"/roughness": (0.01, 0.5)})
    fitted_to_sheet: FitReport = glossmeter.fit("r.json", free=["/ior=1.3..1.8"], sheet="s.xlsx", sample="a")
    print(fitted["parameters"][0]["value"], fitted["recipe"], fitted_to_sheet["chi2"])
    prof: ProfileReport = glossmeter.profile("r.json", "rspec-20", max_total_evals=10_000)
    conv: ConvergenceReport = glossmeter.convergence({"model": "lambert", "albedo": 0.5}, tolerances=[1e-3])
    print(prof["rows"][0]["angle_deg"], conv["rows"][0]["rtol"], glossmeter.schema("sheet")["title"])
    verdicts: pd.DataFrame = glossmeter.compare("r.json", "s.csv", tolerance=2.0, as_frame=True)
    params: pd.DataFrame = glossmeter.fit("r.json", free=["/ior=1.3..1.8"], sheet="s.csv", as_frame=True)
    pixels: pd.DataFrame = glossmeter.profile("r.json", as_frame=True)
    budgeted: List[Reading] = glossmeter.measure("r.json", max_evals=1000, max_seconds=5.0, illuminant="A")
    print(verdicts.shape, params.shape, pixels.shape, budgeted[0]["value"])
    held: glossmeter.HeightMap = glossmeter.height_map(np.zeros((8, 8)), 1.0, unit="nm")
    from_map: List[Reading] = glossmeter.measure({"model": "topography", "file": held, "ior": 1.5})
    stats: Dict[str, Any] = glossmeter.topography(held)
    print(held.shape[0] + 1, held.dx_um + held.dy_um, held.label.upper(), from_map[0]["value"], stats["map"])

    # What the types refuse (each ignore is needed, or mypy --strict fails on an unused one):
    glossmeter.measure(42)  # type: ignore[call-overload]
    topo: Dict[str, Any] = glossmeter.topography(np.zeros((4, 4)), dx_um=0.5, unit="nm", levelling="plane")
    topo = glossmeter.topography(pathlib.Path("fixtures/topography/gaussian.sur"))
    glossmeter.topography(np.zeros((4, 4)), dx_um="0.5")  # type: ignore[arg-type]
    glossmeter.topography(np.zeros((4, 4)), dx_um=0.5, unit="inch")  # type: ignore[arg-type]
    print(topo)
    glossmeter.measure("r.json", rtol="x")  # type: ignore[call-overload]
    glossmeter.measure_brdf(42)  # type: ignore[call-overload]
    bad_hint: LobeHint = {"slope": 0.05, "tail": "fat"}  # type: ignore[typeddict-item]
    wrong: List[Reading] = glossmeter.measure("r.json", as_frame=True)  # type: ignore[assignment]
    not_a_str: int = glossmeter.describe("r.json")  # type: ignore[assignment]
    glossmeter.read_sheet(42)  # type: ignore[call-overload]
    glossmeter.sweep("r.json", vary=5)  # type: ignore[call-overload]
    glossmeter.fit("r.json", ["astm-d523-60/gloss=60"])  # type: ignore[call-overload]
    not_a_report: CompareReport = glossmeter.compare("r.json", "s.csv", as_frame=True)  # type: ignore[assignment]
    not_points: Sheet = glossmeter.sweep("r.json", "/roughness=0.1..0.2:3")  # type: ignore[assignment]
    not_a_frame: Sheet = glossmeter.read_sheet("s.csv", as_frame=True)  # type: ignore[assignment]
    bad_field = glossmeter.profile("r.json")["pixel"]  # type: ignore[typeddict-item]
    print(bad_hint, wrong, not_a_str, not_points, not_a_frame, bad_field, not_a_report)
