"""The actions besides measure (docs/python.md §Actions): each returns what the command line prints with
`--format json` for the same input (the shipped fixtures), a bad keyword raises ValueError (or TypeError for a
wrong type) naming the keyword, and sweep and fit stop on Ctrl-C."""
import _thread
import csv
import json
import subprocess
import threading
import time

import pytest

import glossmeter
from conftest import RECIPES, ROOT, cli_binary

SHEETS = ROOT / "fixtures" / "sheets"
GLASS = RECIPES / "glass-n1.5.json"
BLACK = RECIPES / "black-glass.json"
ROUGH = RECIPES / "rough-dielectric-ggx-vcavity.json"


def cli_json(*args, lines=False):
    """The command line's JSON document for `args` (its exit status is the verdict's: not checked here)."""
    exe = cli_binary()
    if exe is None:
        pytest.skip("the release CLI is not built (cargo build --release); .ci/run builds it first")
    p = subprocess.run([exe, *map(str, args)], capture_output=True, text=True)
    assert p.returncode in (0, 1), p.stderr
    if lines:
        return [json.loads(line) for line in p.stdout.splitlines()]
    return json.loads(p.stdout)


# ---- read_sheet ---------------------------------------------------------------------------------------------

def test_read_sheet_reads_every_value_of_a_text_sheet_as_the_file_has_it():
    path = SHEETS / "black-glass-check.csv"
    doc = glossmeter.read_sheet(path)
    with open(path, newline="") as f:
        expected = [r for r in csv.DictReader(line for line in f if not line.startswith("#"))]
    assert [(r["sample"], r["geometry"], r["reading"], r["value"], r["uncertainty"]) for r in doc["rows"]] == [
        (e["sample"], e["geometry"], e["quantity"], float(e["value"]), float(e["uncertainty"])) for e in expected
    ]
    assert doc["sheet"]["layout"] == "long" and doc["sheet"]["delimiter"] == ","
    assert doc["workbook_sheet"] is None
    assert doc["headers"] == ["sample", "geometry", "quantity", "value", "uncertainty"]
    assert doc["header_line"] == 3  # after the two comment lines
    # Its bytes are the same sheet, named <bytes>.
    from_bytes = glossmeter.read_sheet(path.read_bytes())
    assert from_bytes["sheet"]["file"] == "<bytes>"
    assert from_bytes["rows"] == doc["rows"]


@pytest.mark.parametrize("name", ["byk-smart-chart-export.xlsx", "glass-n1.5-trigloss.csv", "rhopoint-iq.csv"])
def test_read_sheet_reads_what_compare_reads(name):
    path = SHEETS / name
    doc = glossmeter.read_sheet(path)
    cli = cli_json("compare", GLASS, path, "--format", "json")
    assert doc["sheet"] == cli["sheet"]
    # Every compared (sample, reading) is made of the sheet's values, at the sheet's lines.
    for c in cli["comparisons"]:
        rows = [r for r in doc["rows"] if r["line"] in c["lines"] and r["sample"] == c["sample"]
                and r["geometry"] == c["geometry"] and r["reading"] == c["reading"]]
        assert sorted(r["value"] for r in rows) == sorted(c["values"])


def test_a_workbook_is_read_with_its_sheet_named():
    doc = glossmeter.read_sheet(SHEETS / "byk-smart-chart-export.xlsx")
    assert doc["sheet"]["encoding"] == "xlsx workbook"
    assert doc["workbook_sheet"]
    again = glossmeter.read_sheet(SHEETS / "byk-smart-chart-export.xlsx", sheet_name=doc["workbook_sheet"])
    assert again == doc


# ---- compare ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("recipe, sheet, kwargs, flags", [
    (BLACK, "black-glass-check.csv", {}, []),
    (GLASS, "glass-n1.5-trigloss.csv", {"tolerance": 0.5}, ["--tolerance", "0.5"]),
    (GLASS, "glass-n1.5-trigloss.csv", {"tolerance": {"gloss": 0.1}, "k": 3},
     ["--tolerance", "gloss=0.1", "-k", "3"]),
    (GLASS, "rhopoint-iq.csv", {"tolerance": ["astm-d523-20/gloss=1", 2]},
     ["--tolerance", "astm-d523-20/gloss=1", "--tolerance", "2"]),
    (GLASS, "byk-smart-chart-export.xlsx", {"rtol": 1e-5}, ["--rtol", "1e-5"]),
    (RECIPES / "blue-metallic-spectral.json", "colour-blue-metallic.csv", {"max_de00": 2.0},
     ["--max-de00", "2"]),
    (ROUGH, "glass-n1.5-trigloss.csv", {"tolerance": 1, "max_evals": 60}, ["--tolerance", "1", "--max-evals", "60"]),
])
def test_compare_returns_the_command_line_s_document(recipe, sheet, kwargs, flags):
    doc = glossmeter.compare(recipe, SHEETS / sheet, **kwargs)
    assert doc == cli_json("compare", recipe, SHEETS / sheet, "--format", "json", *flags)


def test_compare_takes_a_dict_recipe_and_the_sheet_s_bytes():
    recipe = json.loads(BLACK.read_text())
    doc = glossmeter.compare(recipe, (SHEETS / "black-glass-check.csv").read_bytes())
    assert doc["summary"]["inside"] == 5
    assert {c["recipe"] for c in doc["comparisons"]} == {"<dict>"}


# ---- sweep --------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("kwargs, flags", [
    ({"vary": "/roughness=0.05..0.3:4", "geometries": ["astm-d523-60"]},
     ["--vary", "/roughness=0.05..0.3:4", "-g", "astm-d523-60"]),
    ({"vary": ["/roughness=0.01..0.3:3", "/ior=1.4..1.6:2"], "log": "/roughness"},
     ["--vary", "/roughness=0.01..0.3:3", "--vary", "/ior=1.4..1.6:2", "--log", "/roughness"]),
    ({"vary": ["/roughness=0.05..0.3"], "lhs": 5, "seed": 7, "geometries": "astm-d523-20"},
     ["--vary", "/roughness=0.05..0.3", "--lhs", "5", "--seed", "7", "-g", "astm-d523-20"]),
    ({"vary": "/roughness=0.05..0.3:5", "geometries": ["astm-d523-60"], "shard": (2, 3)},
     ["--vary", "/roughness=0.05..0.3:5", "-g", "astm-d523-60", "--shard", "2/3"]),
    ({"vary": "/roughness=0.05..0.3:5", "geometries": ["astm-d523-60"], "shard": "3/3", "rtol": 1e-4},
     ["--vary", "/roughness=0.05..0.3:5", "-g", "astm-d523-60", "--shard", "3/3", "--rtol", "1e-4"]),
])
def test_sweep_returns_the_command_line_s_lines(kwargs, flags):
    points = glossmeter.sweep(ROOT / "fixtures" / "recipes" / "rough-dielectric-ggx-vcavity.json", timing=False,
                              **kwargs)
    assert points == cli_json("sweep", ROUGH, "--format", "jsonl", "--no-timing", *flags, lines=True)


def test_a_sweep_reads_colour_under_the_given_conditions_as_the_command_line_does():
    pearl = RECIPES / "white-pearl-spectral.json"
    vary = "/pearlescent_flakes/tio2_thickness_nm=60..69:2"
    points = glossmeter.sweep(pearl, vary, geometries="astm-e2194-15", timing=False, illuminant="A", observer="2")
    cli = cli_json("sweep", pearl, "--vary", vary, "-g", "astm-e2194-15", "--illuminant", "A", "--observer", "2",
                   "--format", "jsonl", "--no-timing", lines=True)
    assert points == cli
    assert points != glossmeter.sweep(pearl, vary, geometries="astm-e2194-15", timing=False)
    with pytest.raises(ValueError, match="observer"):
        glossmeter.sweep(pearl, vary, geometries="astm-e2194-15", observer="7")


def test_the_shards_of_a_sweep_make_the_whole_sweep():
    whole = glossmeter.sweep(ROUGH, "/roughness=0.05..0.3:7", geometries="astm-d523-60", timing=False)
    parts = [p for k in (1, 2, 3) for p in
             glossmeter.sweep(ROUGH, "/roughness=0.05..0.3:7", geometries="astm-d523-60", timing=False,
                              shard=(k, 3))]
    assert parts == whole
    assert [p["index"] for p in whole] == list(range(7))
    timed = glossmeter.sweep(ROUGH, "/roughness=0.05..0.3:2", geometries="astm-d523-60")
    assert all(p["seconds"] >= 0 for p in timed)


# ---- fit ----------------------------------------------------------------------------------------------------

def test_fit_returns_the_command_line_s_document():
    doc = glossmeter.fit(ROUGH, ["astm-d523-60/gloss=60±0.2"], free=["/roughness=log:1e-3..0.5"], timing=False)
    cli = cli_json("fit", ROUGH, "--free", "/roughness=log:1e-3..0.5", "--target", "astm-d523-60/gloss=60±0.2",
                   "--format", "json", "--no-timing")
    assert doc == cli
    # The dict forms are the same request.
    same = glossmeter.fit(ROUGH, {"astm-d523-60/gloss": (60, 0.2)}, free={"/roughness": "log:1e-3..0.5"},
                          timing=False)
    assert same == doc
    assert abs(doc["targets"][0]["predicted"] - 60) < 0.2


def test_fit_to_a_sheet_returns_the_command_line_s_document():
    sheet = SHEETS / "glass-n1.5-trigloss.csv"
    doc = glossmeter.fit(GLASS, free=["/ior=1.3..1.8"], sheet=sheet, timing=False)
    cli = cli_json("fit", GLASS, "--free", "/ior=1.3..1.8", "--sheet", sheet, "--format", "json", "--no-timing")
    assert doc == cli
    # The sheet's readings are Fresnel ratios of n = 1.50 glass (their provenance): the fit finds 1.50.
    assert abs(doc["parameters"][0]["value"] - 1.5) < 0.01


def test_fit_reads_colour_targets_under_the_given_conditions_as_the_command_line_does():
    pearl = RECIPES / "white-pearl-spectral.json"
    free, target = "/pearlescent_flakes/tio2_thickness_nm=30..90", "astm-e2194-15/b*=22.75±0.05"
    doc = glossmeter.fit(pearl, [target], free=[free], restarts=0, illuminant="A", observer="2",
                         max_evals=100_000, timing=False)
    cli = cli_json("fit", pearl, "--free", free, "--target", target, "--restarts", "0", "--illuminant", "A",
                   "--observer", "2", "--max-evals", "100000", "--format", "json", "--no-timing")
    assert doc == cli
    d65 = glossmeter.fit(pearl, [target], free=[free], restarts=0, timing=False)
    assert d65["parameters"][0]["value"] != doc["parameters"][0]["value"]
    with pytest.raises(ValueError, match="illuminant"):
        glossmeter.fit(pearl, [target], free=[free], illuminant="D99")
    with pytest.raises(ValueError, match="max_evals"):
        glossmeter.fit(pearl, [target], free=[free], max_evals=0)


# ---- profile and convergence --------------------------------------------------------------------------------

def test_profile_returns_the_command_line_s_document():
    doc = glossmeter.profile(BLACK, max_total_evals=200_000)
    assert doc == cli_json("profile", BLACK, "--format", "json", "--max-total-evals", "200000")
    assert doc["geometry"] == "rspec-20" and len(doc["rows"]) == doc["pixels"]


def test_convergence_returns_the_command_line_s_document_but_its_times():
    doc = glossmeter.convergence(BLACK, "astm-d523-60", tolerances=[1e-3, 1e-5], min_time_ms=0, max_repetitions=1)
    cli = cli_json("convergence", BLACK, "-g", "astm-d523-60", "--tolerances", "1e-3,1e-5", "--min-time-ms", "0",
                   "--max-repetitions", "1", "--format", "json")

    def untimed(d):
        d = json.loads(json.dumps(d))
        for r in d["rows"]:
            del r["seconds"], r["plan_seconds"]
        d["reference"].pop("seconds")
        return d

    assert untimed(doc) == untimed(cli)
    assert [r["rtol"] for r in doc["rows"]] == [1e-3, 1e-5]
    # Colour under a chosen illuminant and observer, as the command line's flags.
    pearl = RECIPES / "white-pearl-spectral.json"
    doc = glossmeter.convergence(pearl, "astm-e2194-15", tolerances=[1e-3], min_time_ms=0, max_repetitions=1,
                                 illuminant="A", observer="2")
    cli = cli_json("convergence", pearl, "-g", "astm-e2194-15", "--tolerances", "1e-3", "--min-time-ms", "0",
                   "--max-repetitions", "1", "--illuminant", "A", "--observer", "2", "--format", "json")
    assert untimed(doc) == untimed(cli)
    assert {(r["illuminant"], r["observer"]) for r in doc["rows"]} == {("A", "2")}
    with pytest.raises(ValueError, match="illuminant"):
        glossmeter.convergence(pearl, "astm-e2194-15", tolerances=[1e-3], illuminant="F11")


# ---- as_frame ---------------------------------------------------------------------------------------------

def test_a_sheet_and_a_sweep_as_frames_hold_the_same_doubles():
    pytest.importorskip("pandas", reason="pandas is not installed (pip install pandas); .ci/run installs it")
    doc = glossmeter.read_sheet(SHEETS / "rhopoint-iq.csv")
    frame = glossmeter.read_sheet(SHEETS / "rhopoint-iq.csv", as_frame=True)
    assert list(frame.columns) == ["line", "column", "sample", "geometry", "reading", "value", "uncertainty",
                                   "not_predicted"]
    assert frame["value"].tolist() == [r["value"] for r in doc["rows"]]
    assert frame["geometry"].tolist() == [r["geometry"] for r in doc["rows"]]
    assert frame["uncertainty"].isna().all() and str(frame["uncertainty"].dtype) == "float64"

    args = (ROUGH, ["/roughness=0.05..0.3:3", "/ior=1.4..1.6:2"])
    kwargs = {"geometries": ["astm-d523-20", "astm-d523-60"], "timing": False}
    points = glossmeter.sweep(*args, **kwargs)
    frame = glossmeter.sweep(*args, **kwargs, as_frame=True)
    readings = [(p, r) for p in points for r in p["readings"]]
    assert len(frame) == len(readings) == 3 * 2 * 2
    assert frame["value"].tolist() == [r["value"] for _, r in readings]
    assert frame["/ior"].tolist() == [p["parameters"]["/ior"] for p, _ in readings]
    assert frame["index"].tolist() == [p["index"] for p, _ in readings]
    assert "seconds" not in frame
    assert "seconds" in glossmeter.sweep(ROUGH, "/roughness=0.1..0.2:2", geometries="astm-d523-60", as_frame=True)


def _same(column, values):
    """A frame's column holds these values (None as NaN in a float column), the same doubles."""
    import math

    got = column.tolist()
    assert len(got) == len(values)
    for g, v in zip(got, values):
        if v is None or (isinstance(v, float) and math.isnan(v)):
            assert g is None or (isinstance(g, float) and math.isnan(g)), (g, v)
        else:
            assert g == v, (g, v)


def test_compare_fit_and_profile_as_frames_hold_their_main_table_row_for_row():
    pytest.importorskip("pandas", reason="pandas is not installed (pip install pandas); .ci/run installs it")
    # compare: one row per compared (sample, reading), the verdict's scalars, the allowance's total.
    sheet = SHEETS / "glass-n1.5-trigloss.csv"
    doc = glossmeter.compare(GLASS, sheet, tolerance=0.5)
    frame = glossmeter.compare(GLASS, sheet, tolerance=0.5, as_frame=True)
    cs = doc["comparisons"]
    assert list(frame.columns) == list(glossmeter.COMPARE_COLUMNS) and len(frame) == len(cs) > 1
    for col in ("sample", "geometry", "reading", "verdict", "n", "mean", "predicted", "difference", "inside"):
        _same(frame[col], [c[col] for c in cs])
    _same(frame["allowance"], [c["allowance"]["total"] if c["allowance"] else None for c in cs])
    _same(frame["prediction_uncertainty"], [c.get("prediction_uncertainty") for c in cs])
    assert str(frame["predicted"].dtype) == "float64"
    # fit: one row per fitted parameter.
    fitted = glossmeter.fit(GLASS, free=["/ior=1.3..1.8"], sheet=sheet, timing=False)
    frame = glossmeter.fit(GLASS, free=["/ior=1.3..1.8"], sheet=sheet, timing=False, as_frame=True)
    assert list(frame.columns) == ["path", "value", "std_error", "lower", "upper", "at_bound"]
    assert frame.to_dict("records") == fitted["parameters"]
    # profile: one row per pixel.
    prof = glossmeter.profile(BLACK, max_total_evals=200_000)
    frame = glossmeter.profile(BLACK, max_total_evals=200_000, as_frame=True)
    assert len(frame) == prof["pixels"] == len(prof["rows"])
    for col in ("pixel", "angle_deg", "value", "error_estimate", "converged", "evaluations", "problem"):
        _same(frame[col], [r[col] for r in prof["rows"]])
    assert str(frame["value"].dtype) == "float64"


def test_a_point_without_readings_is_one_row_with_its_problem():
    rows = glossmeter.sweep_rows([{"index": 4, "parameters": {"/ior": 9.0}, "problem": "ior out of range"},
                                  {"index": 5, "parameters": {"/ior": 1.5}, "seconds": 0.25,
                                   "readings": [{"geometry": "g", "name": "gloss", "unit": "GU", "value": 1.0,
                                                 "error_estimate": 0.0, "converged": True}]}])
    assert rows[0] == {"index": 4, "/ior": 9.0, "geometry": None, "name": None, "unit": None, "value": None,
                       "error_estimate": None, "converged": False, "problem": "ior out of range",
                       "illuminant": None, "observer": None}
    assert rows[1]["seconds"] == 0.25 and rows[1]["value"] == 1.0 and rows[1]["problem"] is None


# ---- bad keywords -------------------------------------------------------------------------------------------

CHECK = SHEETS / "black-glass-check.csv"


@pytest.mark.parametrize("call, exc, words", [
    (lambda: glossmeter.read_sheet(CHECK, delimiter="|"), ValueError, ["`delimiter`", "tab"]),
    (lambda: glossmeter.read_sheet(CHECK, sheet_name="x"), ValueError, ["`sheet_name`", "workbook"]),
    (lambda: glossmeter.read_sheet(CHECK, header_row=0), ValueError, ["header_row", "≥ 1"]),
    (lambda: glossmeter.read_sheet(CHECK, header_row=-2), ValueError, ["header_row", "-2"]),
    (lambda: glossmeter.read_sheet(CHECK, header_row=1.5), TypeError, ["header_row:", "got float"]),
    (lambda: glossmeter.read_sheet(CHECK, ignore_columns=[3]), TypeError, ["ignore_columns[0]:", "got int"]),
    (lambda: glossmeter.read_sheet(42), TypeError, ["sheet:", "path", "bytes", "got int"]),
    (lambda: glossmeter.read_sheet(SHEETS / "byk-smart-chart-export.xlsx", delimiter=";"), ValueError,
     ["`delimiter`", "workbook"]),
    (lambda: glossmeter.compare(BLACK, CHECK, tolerance="gloss=x"), ValueError, ["`tolerance`", "not a number"]),
    (lambda: glossmeter.compare(BLACK, CHECK, tolerance=[1, 2]), ValueError, ["`tolerance`", "two plain"]),
    (lambda: glossmeter.compare(BLACK, CHECK, tolerance={"gloss": "x"}), TypeError, ['tolerance["gloss"]:']),
    (lambda: glossmeter.compare(BLACK, CHECK, max_de00=-1), ValueError, ["`max_de00`", "≥ 0"]),
    (lambda: glossmeter.compare(BLACK, CHECK, rtol=2), ValueError, ["`rtol`", "(0, 1)"]),
    (lambda: glossmeter.compare(BLACK, CHECK, k="2"), TypeError, ["k:", "got str"]),
    (lambda: glossmeter.compare(BLACK, CHECK, illuminant="D99"), ValueError, ["illuminant", "D65"]),
    (lambda: glossmeter.compare(BLACK, CHECK, delimiter="|"), ValueError, ["`delimiter`"]),
    (lambda: glossmeter.sweep(ROUGH, "/roughness=0.1..0.2"), ValueError, ["`vary`"]),
    (lambda: glossmeter.sweep(ROUGH, "/roughnes=0.1..0.2:3"), ValueError, ["`vary`", "/roughnes"]),
    (lambda: glossmeter.sweep(ROUGH, "/roughness=0.1..0.2:3", log="/ior"), ValueError, ["`log`", "`vary`"]),
    (lambda: glossmeter.sweep(ROUGH, "/roughness=0.1..0.2", lhs=0), ValueError, ["`lhs`"]),
    (lambda: glossmeter.sweep(ROUGH, "/roughness=0.1..0.2:3", shard="4/3"), ValueError, ["`shard`"]),
    (lambda: glossmeter.sweep(ROUGH, "/roughness=0.1..0.2:3", shard=3), TypeError, ["shard:", "got int"]),
    (lambda: glossmeter.sweep(ROUGH, "/roughness=0.1..0.2:3", rtol=0), ValueError, ["`rtol`"]),
    (lambda: glossmeter.sweep(ROUGH, "/roughness=0.1..0.2:3", max_evals=0), ValueError, ["`max_evals`"]),
    (lambda: glossmeter.sweep(ROUGH, 5), TypeError, ["vary:", "got int"]),
    (lambda: glossmeter.sweep(ROUGH, "/roughness=0.1..0.2:3", seed=-1), ValueError, ["seed", "-1"]),
    (lambda: glossmeter.fit(ROUGH, ["astm-d523-60/gloss=60"], free=["/roughnes=0..1"]), ValueError,
     ["`free`", "/roughnes"]),
    (lambda: glossmeter.fit(ROUGH, ["astm-d523-60/gloss=60"], free=[]), ValueError, ["`free`"]),
    (lambda: glossmeter.fit(ROUGH, ["x"], free=["/roughness=0.01..0.5"]), ValueError, ["`targets`", "x"]),
    (lambda: glossmeter.fit(ROUGH, free=["/roughness=0.01..0.5"]), ValueError, ["`targets`", "`sheet`"]),
    (lambda: glossmeter.fit(ROUGH, ["astm-d523-60/gloss=60"], free=["/roughness=0.01..0.5"], uncertainty=0),
     ValueError, ["`uncertainty`"]),
    (lambda: glossmeter.fit(ROUGH, ["astm-d523-60/gloss=60"], free=["/roughness=0.01..0.5"], rtol=1), ValueError,
     ["`rtol`"]),
    (lambda: glossmeter.fit(ROUGH, ["astm-d523-60/gloss=60"], free={"/roughness": (1, 2, 3)}), ValueError,
     ['free["/roughness"]', "(LO, HI)"]),
    (lambda: glossmeter.fit(GLASS, free=["/ior=1.3..1.8"], sheet=SHEETS / "qc-many-samples.csv"), ValueError,
     ["`sheet`", "`sample`"]),
    (lambda: glossmeter.fit(GLASS, free=["/ior=1.3..1.8"], sheet=CHECK, sample="nope"), ValueError,
     ["`sample`", "nope"]),
    (lambda: glossmeter.fit(GLASS, ["astm-d523-60/gloss=60"], free=["/ior=1.3..1.8"], sheet=CHECK), ValueError,
     ["targets and sheet"]),
    (lambda: glossmeter.profile(BLACK, "astm-d523-60"), ValueError, ["astm-d523-60", "profile"]),
    (lambda: glossmeter.profile(BLACK, max_total_evals=0), ValueError, ["`max_total_evals`"]),
    (lambda: glossmeter.profile(BLACK, rtol=5), ValueError, ["`rtol`"]),
    (lambda: glossmeter.convergence(BLACK, tolerances=[2.0]), ValueError, ["`tolerances`"]),
    (lambda: glossmeter.convergence(BLACK, tolerances="1e-3"), TypeError, ["tolerances:", "got str"]),
    (lambda: glossmeter.convergence(BLACK, max_repetitions=0), ValueError, ["`max_repetitions`"]),
    (lambda: glossmeter.convergence(BLACK, min_time_ms=-1), ValueError, ["`min_time_ms`"]),
    (lambda: glossmeter.convergence(BLACK, reference_run=1), TypeError, ["reference_run:", "True or False"]),
    (lambda: glossmeter.read_sheet(CHECK, as_frame=1), TypeError, ["as_frame:", "True or False"]),
    (lambda: glossmeter.sweep(ROUGH, "/roughness=0.1..0.2:3", as_frame="yes"), TypeError, ["as_frame:"]),
    (lambda: glossmeter.compare(BLACK, CHECK, as_frame=1), TypeError, ["as_frame:", "True or False"]),
    (lambda: glossmeter.fit(ROUGH, ["astm-d523-60/gloss=60"], free=["/roughness=0.01..0.5"], as_frame=None),
     TypeError, ["as_frame:"]),
    (lambda: glossmeter.profile(BLACK, as_frame="yes"), TypeError, ["as_frame:"]),
])
def test_a_bad_keyword_is_refused_naming_it(call, exc, words):
    with pytest.raises(exc) as e:
        call()
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_the_refusals_are_the_command_line_s_with_the_keyword_for_the_flag():
    with pytest.raises(ValueError) as e:
        glossmeter.sweep(ROUGH, "/roughness=0.1..0.2:3", log="/ior")
    exe = cli_binary()
    if exe is None:
        pytest.skip("the release CLI is not built")
    p = subprocess.run([exe, "sweep", str(ROUGH), "--vary", "/roughness=0.1..0.2:3", "--log", "/ior"],
                       capture_output=True, text=True)
    assert p.returncode == 2
    cli = p.stderr.strip().removeprefix("error: ")
    assert str(e.value) == cli.replace("--log", "`log`").replace("--vary", "`vary`")


# ---- Ctrl-C -------------------------------------------------------------------------------------------------

def interrupted_after(seconds, call):
    """Send the main thread SIGINT's KeyboardInterrupt `seconds` after starting `call`; return how long the
    call took to raise it (fails if it returned)."""
    timer = threading.Timer(seconds, _thread.interrupt_main)
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            call()
    finally:
        timer.cancel()
    return time.monotonic() - start


def test_a_long_sweep_stops_on_ctrl_c():
    # 40 points of this sweep take a fixed time t40; the 20 000 of the interrupted one would take 500·t40.
    start = time.monotonic()
    glossmeter.sweep(ROUGH, "/roughness=0.01..0.5:40", timing=False)
    t40 = time.monotonic() - start
    took = interrupted_after(0.3, lambda: glossmeter.sweep(ROUGH, "/roughness=0.01..0.5:20000", timing=False))
    assert took < 0.3 + 5 + 20 * t40, (took, t40)
    # The module works on after it.
    assert len(glossmeter.sweep(ROUGH, "/roughness=0.01..0.5:2", geometries="astm-d523-60")) == 2


def test_a_long_fit_stops_on_ctrl_c():
    pearl = ROOT / "fixtures" / "inverse" / "pearl-start.json"
    geometries = ["astm-d523-20", "astm-d523-60", "astm-d523-85"]
    targets = [f"{g}/gloss={v}" for g, v in zip(geometries, [80, 90, 95])]

    def call():
        return glossmeter.fit(pearl, targets, free=["/clear_coat/roughness=0.001..0.1"], rtol=1e-8, timing=False)

    # One forward run (the three readings) takes t1; this fit makes 75 of them (its `evaluations`), so
    # uninterrupted it takes about 75·t1, and stopped at its next integral about one t1 after the signal.
    start = time.monotonic()
    glossmeter.measure(pearl, geometries, 1e-8, timing=False)
    t1 = time.monotonic() - start
    bound = 0.3 + 0.3 + 10 * t1
    if 75 * t1 < 2 * bound:
        pytest.skip(f"one forward run takes {t1:.3f} s here: the whole fit is too short to tell a stop")
    took = interrupted_after(0.3, call)
    assert took < bound, (took, t1)


def test_a_colour_sheet_is_compared_only_under_the_conditions_it_states(tmp_path):
    sheet = tmp_path / "a2.csv"
    sheet.write_text((SHEETS / "colour-blue-metallic.csv").read_text(encoding="utf-8")
                     .replace("# illuminant/observer: D65/10°", "Illuminant: A,Observer: 2°"), encoding="utf-8")
    recipe = RECIPES / "blue-metallic-spectral.json"
    with pytest.raises(ValueError) as e:
        glossmeter.compare(recipe, sheet)
    assert "not comparable" in str(e.value) and 'give illuminant="A" observer="2" (the sheet\'s)' in str(e.value)
    doc = glossmeter.compare(recipe, sheet, illuminant="A", observer="2", max_de00=100)
    assert {(c["illuminant"], c["observer"]) for c in doc["comparisons"]} == {("A", "2")}
