"""glossmeter: a virtual gloss, haze and DOI meter (Python bindings of the Rust library).

    >>> import glossmeter
    >>> glossmeter.measure("fixtures/recipes/black-glass.json", geometries=["astm-d523-60"])

Every function is a thin layer over the library (see docs/python.md):

* ``measure(recipe, geometries=None, rtol=None, timing=True, *, max_evals=None, max_seconds=None,
  illuminant=None, observer=None, as_frame=False, as_arrays=False)``: readings
  of a recipe (dict, JSON string or path), one dict per reading with the fields of
  ``glossmeter measure --format json``; or a pandas DataFrame (``as_frame=True``), or a dict of NumPy arrays,
  one per field (``as_arrays=True``).
* ``measure_brdf(f, geometries=None, rtol=None, lobes=None, delta=None, wavelengths=None, timing=True, *,
  max_evals=None, max_seconds=None, as_frame=False, as_arrays=False)``: readings of a Python BRDF ``f(wi, wo)`` evaluated in batches of (N, 3)
  NumPy arrays.
* ``standards()``, ``geometry(id)``, ``describe_geometry(id)``, ``schema()``, ``describe(recipe)``.
* The other actions of the command line, each returning the document of ``glossmeter ACTION --format json``
  as dicts and lists: ``read_sheet(sheet, ...)`` (the one sheet reader: CSV and .xlsx/.xls/.ods workbooks),
  ``compare(recipe, sheet, tolerance=None, ...)``, ``sweep(template, vary, ...)``, ``fit(recipe, targets,
  free=..., ...)``, ``profile(recipe, geometry=None, ...)``, ``convergence(recipe, geometries=None, ...)``.
  ``sweep`` and ``fit`` (and ``compare``, ``profile``) release the GIL and stop on Ctrl-C
  (``KeyboardInterrupt``). ``read_sheet``, ``sweep``, ``compare``, ``fit`` and ``profile`` take
  ``as_frame=True`` for the rows of their main table as a pandas DataFrame (one row per value, per point and
  reading, per verdict, per fitted parameter, per profile pixel).

Bad input raises ``ValueError`` with the message the CLI prints; an argument of the wrong type raises
``TypeError`` naming the argument and what it allows; an unreadable file raises ``OSError``.
"""
from typing import TYPE_CHECKING, Any, Dict, List, Literal, Mapping, Optional, Sequence, Union, overload

import numpy as np
import numpy.typing as npt

from . import _glossmeter
from ._glossmeter import (
    DEFAULT_GEOMETRIES,
    HeightMap,
    __version__,
    convergence,
    describe,
    describe_geometry,
    geometry,
    height_map,
    schema,
    standards,
    topography,
)
from ._types import (
    Allowance,
    AllowancePart,
    Baseline,
    BrdfFunction,
    BudgetLine,
    ColourDifference,
    CompareReport,
    CompareSummary,
    Comparison,
    ConvergenceReference,
    ConvergenceReport,
    ConvergenceRow,
    ConvergenceTiming,
    Delta,
    Drift,
    Envelope,
    EnvelopeVariation,
    FitParameter,
    FitReport,
    FitTarget,
    FreeParameters,
    Geometries,
    Geometry,
    LobeHint,
    Lobes,
    Material,
    ProfileBudget,
    ProfileReport,
    ProfileRow,
    Reading,
    Readings,
    Recipe,
    Shard,
    Sheet,
    SheetInfo,
    SheetRow,
    SheetSource,
    SweepPoint,
    SweepReading,
    Targets,
    Tolerance,
    VerdictRule,
)

if TYPE_CHECKING:
    import pandas

__all__ = [
    "DEFAULT_GEOMETRIES",
    "Allowance",
    "AllowancePart",
    "Arrays",
    "Baseline",
    "BrdfFunction",
    "BudgetLine",
    "ColourDifference",
    "CompareReport",
    "CompareSummary",
    "Comparison",
    "ConvergenceReference",
    "ConvergenceReport",
    "ConvergenceRow",
    "ConvergenceTiming",
    "Delta",
    "Drift",
    "Envelope",
    "EnvelopeVariation",
    "FitParameter",
    "FitReport",
    "FitTarget",
    "FreeParameters",
    "Geometries",
    "Geometry",
    "LobeHint",
    "Lobes",
    "Material",
    "ProfileBudget",
    "ProfileReport",
    "ProfileRow",
    "Reading",
    "Readings",
    "Recipe",
    "Shard",
    "Sheet",
    "SheetInfo",
    "SheetRow",
    "SheetSource",
    "SweepPoint",
    "SweepReading",
    "Targets",
    "Tolerance",
    "VerdictRule",
    "__version__",
    "COMPARE_COLUMNS",
    "compare",
    "compare_rows",
    "convergence",
    "describe",
    "describe_geometry",
    "fit",
    "geometry",
    "measure",
    "measure_brdf",
    "profile",
    "read_sheet",
    "schema",
    "standards",
    "sweep",
    "sweep_rows",
    "to_arrays",
    "topography",
    "height_map",
    "HeightMap",
    "to_frame",
]

#: A table of readings as NumPy arrays, one per field.
Arrays = Dict[str, npt.NDArray[Any]]


def _flag(name: str, value: object) -> bool:
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise TypeError(f"{name}: expected True or False, got {type(value).__name__}")


def to_arrays(readings: Sequence[Reading]) -> Arrays:
    """Readings as NumPy arrays, one per field: ``value``, ``error_estimate`` and ``seconds`` float64 (NaN
    where a reading has no finite value: its ``problem`` says why), ``evaluations`` int64, ``converged``
    bool, ``geometry``, ``name``, ``quantity`` and ``unit`` str, ``problem``, ``note``, ``illuminant`` and
    ``observer`` object (None where absent: the last two are a colour reading's). ``seconds`` is there only if
    every reading has it."""
    rows = list(readings)
    out: Arrays = {}
    for key in ("geometry", "name", "quantity"):
        out[key] = np.array([r[key] for r in rows], dtype=str)
    out["value"] = np.array([np.nan if r["value"] is None else r["value"] for r in rows], dtype=np.float64)
    out["unit"] = np.array([r["unit"] for r in rows], dtype=str)
    out["error_estimate"] = np.array(
        [np.nan if r["error_estimate"] is None else r["error_estimate"] for r in rows], dtype=np.float64)
    out["evaluations"] = np.array([r["evaluations"] for r in rows], dtype=np.int64)
    out["converged"] = np.array([r["converged"] for r in rows], dtype=bool)
    if rows and all("seconds" in r for r in rows):
        out["seconds"] = np.array([r.get("seconds", np.nan) for r in rows], dtype=np.float64)
    out["problem"] = np.array([r.get("problem") for r in rows], dtype=object)
    out["note"] = np.array([r.get("note") for r in rows], dtype=object)
    out["illuminant"] = np.array([r.get("illuminant") for r in rows], dtype=object)
    out["observer"] = np.array([r.get("observer") for r in rows], dtype=object)
    return out


def to_frame(readings: Sequence[Reading]) -> "pandas.DataFrame":
    """Readings as a pandas DataFrame, one row per reading, the columns of :func:`to_arrays`. Needs pandas
    (``pip install pandas``), which glossmeter does not require otherwise."""
    try:
        import pandas as pd
    except ImportError as e:
        raise ImportError(
            "as_frame=True (a pandas DataFrame) needs pandas, which is not installed: pip install pandas "
            "(or pip install 'glossmeter[pandas]'); as_arrays=True gives the same columns as NumPy arrays "
            "without it"
        ) from e
    return pd.DataFrame(to_arrays(readings))


def _shaped(readings: Readings, as_frame: bool, as_arrays: bool) -> Union[Readings, Arrays, "pandas.DataFrame"]:
    if as_frame:
        return to_frame(readings)
    if as_arrays:
        return to_arrays(readings)
    return readings


def _check_shape_flags(as_frame: object, as_arrays: object) -> None:
    """Refuse bad ``as_frame``/``as_arrays`` before any work (and pandas missing, before a long measurement)."""
    frame, arrays = _flag("as_frame", as_frame), _flag("as_arrays", as_arrays)
    if frame and arrays:
        raise ValueError("as_frame and as_arrays: give at most one (a DataFrame, or a dict of NumPy arrays)")
    if frame:
        try:
            import pandas  # noqa: F401
        except ImportError:
            to_frame([])


@overload
def measure(recipe: Recipe, geometries: Geometries = ..., rtol: Optional[float] = ..., timing: bool = ..., *,
            max_evals: Optional[int] = ..., max_seconds: Optional[float] = ..., illuminant: Optional[str] = ...,
            observer: Optional[str] = ..., as_frame: Literal[False] = ..., as_arrays: Literal[False] = ...) -> Readings: ...
@overload
def measure(recipe: Recipe, geometries: Geometries = ..., rtol: Optional[float] = ..., timing: bool = ..., *,
            max_evals: Optional[int] = ..., max_seconds: Optional[float] = ..., illuminant: Optional[str] = ...,
            observer: Optional[str] = ..., as_frame: Literal[True], as_arrays: Literal[False] = ...) -> "pandas.DataFrame": ...
@overload
def measure(recipe: Recipe, geometries: Geometries = ..., rtol: Optional[float] = ..., timing: bool = ..., *,
            max_evals: Optional[int] = ..., max_seconds: Optional[float] = ..., illuminant: Optional[str] = ...,
            observer: Optional[str] = ..., as_frame: Literal[False] = ..., as_arrays: Literal[True]) -> Arrays: ...
def measure(recipe: Recipe, geometries: Geometries = None, rtol: Optional[float] = None, timing: bool = True, *,
            max_evals: Optional[int] = None, max_seconds: Optional[float] = None, illuminant: Optional[str] = None,
            observer: Optional[str] = None, as_frame: bool = False, as_arrays: bool = False) -> Union[Readings, Arrays, "pandas.DataFrame"]:
    """Read a recipe (a dict, a JSON string or a path) through instrument geometries (None: the default panel
    of ``glossmeter measure``; or one or a list of builtin ids, geometry files or geometry dicts). ``rtol``,
    ``max_evals``, ``max_seconds``, ``illuminant`` and ``observer`` are ``measure``'s ``--rtol``,
    ``--max-evals``, ``--max-seconds``, ``--illuminant`` and ``--observer`` (None: the command line's default).

    Returns one dict per reading with the fields of ``glossmeter measure --format json``; with
    ``as_frame=True`` a pandas DataFrame, with ``as_arrays=True`` a dict of NumPy arrays (:func:`to_arrays`).
    Bad input raises ValueError with the message the CLI prints; a reading without a finite value has value
    None (NaN in a frame or array) and a "problem"."""
    _check_shape_flags(as_frame, as_arrays)
    readings = _glossmeter.measure(recipe, geometries, rtol, timing, max_evals=max_evals, max_seconds=max_seconds,
                                   illuminant=illuminant, observer=observer)
    return _shaped(readings, as_frame, as_arrays)


@overload
def measure_brdf(f: BrdfFunction, geometries: Geometries = ..., rtol: Optional[float] = ..., lobes: Optional[Lobes] = ...,
                 delta: Optional[Delta] = ..., wavelengths: Optional[Sequence[float]] = ..., timing: bool = ..., *,
                 max_evals: Optional[int] = ..., max_seconds: Optional[float] = ..., as_frame: Literal[False] = ..., as_arrays: Literal[False] = ...) -> Readings: ...
@overload
def measure_brdf(f: BrdfFunction, geometries: Geometries = ..., rtol: Optional[float] = ..., lobes: Optional[Lobes] = ...,
                 delta: Optional[Delta] = ..., wavelengths: Optional[Sequence[float]] = ..., timing: bool = ..., *,
                 max_evals: Optional[int] = ..., max_seconds: Optional[float] = ..., as_frame: Literal[True], as_arrays: Literal[False] = ...) -> "pandas.DataFrame": ...
@overload
def measure_brdf(f: BrdfFunction, geometries: Geometries = ..., rtol: Optional[float] = ..., lobes: Optional[Lobes] = ...,
                 delta: Optional[Delta] = ..., wavelengths: Optional[Sequence[float]] = ..., timing: bool = ..., *,
                 max_evals: Optional[int] = ..., max_seconds: Optional[float] = ..., as_frame: Literal[False] = ..., as_arrays: Literal[True]) -> Arrays: ...
def measure_brdf(f: BrdfFunction, geometries: Geometries = None, rtol: Optional[float] = None, lobes: Optional[Lobes] = None,
                 delta: Optional[Delta] = None, wavelengths: Optional[Sequence[float]] = None, timing: bool = True,
                 *, max_evals: Optional[int] = None, max_seconds: Optional[float] = None, as_frame: bool = False,
                 as_arrays: bool = False) -> Union[Readings, Arrays, "pandas.DataFrame"]:
    """Read a Python BRDF ``f(wi, wo)`` through instrument geometries: f takes two (N, 3) float64 arrays of
    unit directions (local frame, z the normal) and returns f_r in sr⁻¹ as (N,) or (N, S). ``lobes`` hints the
    lobe widths (None: probe f; []: f is smooth), ``delta`` is a mirror component, ``wavelengths`` (nm) name
    S spectral samples other than 1 (grey) or 3 (linear RGB). Returns what :func:`measure` returns; an
    exception raised in f propagates as itself. See docs/python.md."""
    _check_shape_flags(as_frame, as_arrays)
    readings = _glossmeter.measure_brdf(f, geometries, rtol, lobes, delta, wavelengths, timing,
                                        max_evals=max_evals, max_seconds=max_seconds)
    return _shaped(readings, as_frame, as_arrays)


def _check_frame_flag(as_frame: object) -> bool:
    """Refuse a bad ``as_frame`` before any work (and pandas missing, before a long sweep)."""
    frame = _flag("as_frame", as_frame)
    if frame:
        try:
            import pandas  # noqa: F401
        except ImportError:
            to_frame([])
    return frame


@overload
def read_sheet(sheet: SheetSource, delimiter: Optional[str] = ..., sheet_name: Optional[str] = ...,
               header_row: Optional[int] = ..., ignore_columns: Union[None, str, Sequence[str]] = ..., *,
               as_frame: Literal[False] = ...) -> Sheet: ...
@overload
def read_sheet(sheet: SheetSource, delimiter: Optional[str] = ..., sheet_name: Optional[str] = ...,
               header_row: Optional[int] = ..., ignore_columns: Union[None, str, Sequence[str]] = ..., *,
               as_frame: Literal[True]) -> "pandas.DataFrame": ...
def read_sheet(sheet: SheetSource, delimiter: Optional[str] = None, sheet_name: Optional[str] = None,
               header_row: Optional[int] = None, ignore_columns: Union[None, str, Sequence[str]] = None, *,
               as_frame: bool = False) -> Union[Sheet, "pandas.DataFrame"]:
    """Read an instrument sheet (a CSV, or an .xlsx/.xls/.ods workbook; a path or its bytes) as ``glossmeter
    compare`` reads it: what the reader found out about the file and every value with its line, column,
    sample, geometry and reading (``schema("sheet")``). With ``as_frame=True``, the rows as a pandas
    DataFrame, one row per value (``uncertainty`` NaN where the sheet states none). See docs/python.md."""
    frame = _check_frame_flag(as_frame)
    doc = _glossmeter.read_sheet(sheet, delimiter, sheet_name, header_row, ignore_columns)
    if not frame:
        return doc
    import pandas as pd

    columns = ["line", "column", "sample", "geometry", "reading", "value", "uncertainty", "not_predicted"]
    out = pd.DataFrame(doc["rows"], columns=columns)
    out["uncertainty"] = out["uncertainty"].astype(np.float64)
    return out


def sweep_rows(points: Sequence[SweepPoint]) -> List[Dict[str, Any]]:
    """A sweep's points as flat rows, one per (point, reading): ``index``, one column per varied path,
    ``geometry``, ``name``, ``unit``, ``value``, ``error_estimate``, ``converged``, ``problem`` (the reading's,
    or the point's when its recipe is invalid: then one row with no reading), ``illuminant`` and ``observer``
    (a colour reading's, else None) and ``seconds`` when timed."""
    rows: List[Dict[str, Any]] = []
    for p in points:
        base: Dict[str, Any] = {"index": p["index"], **p["parameters"]}
        timed: Dict[str, Any] = {"seconds": p["seconds"]} if "seconds" in p else {}
        readings = p.get("readings") or []
        if not readings:
            rows.append({**base, "geometry": None, "name": None, "unit": None, "value": None,
                         "error_estimate": None, "converged": False, "problem": p.get("problem"),
                         "illuminant": None, "observer": None, **timed})
        for r in readings:
            rows.append({**base, "geometry": r["geometry"], "name": r["name"], "unit": r["unit"],
                         "value": r["value"], "error_estimate": r["error_estimate"], "converged": r["converged"],
                         "problem": r.get("problem"), "illuminant": r.get("illuminant"),
                         "observer": r.get("observer"), **timed})
    return rows


@overload
def sweep(template: Recipe, vary: Union[str, Sequence[str]], log: Union[None, str, Sequence[str]] = ...,
          lhs: Optional[int] = ..., seed: Optional[int] = ..., geometries: Geometries = ...,
          shard: Optional[Shard] = ..., rtol: Optional[float] = ..., max_evals: Optional[int] = ...,
          timing: bool = ..., *, illuminant: Optional[str] = ..., observer: Optional[str] = ...,
          as_frame: Literal[False] = ...) -> List[SweepPoint]: ...
@overload
def sweep(template: Recipe, vary: Union[str, Sequence[str]], log: Union[None, str, Sequence[str]] = ...,
          lhs: Optional[int] = ..., seed: Optional[int] = ..., geometries: Geometries = ...,
          shard: Optional[Shard] = ..., rtol: Optional[float] = ..., max_evals: Optional[int] = ...,
          timing: bool = ..., *, illuminant: Optional[str] = ..., observer: Optional[str] = ...,
          as_frame: Literal[True]) -> "pandas.DataFrame": ...
def sweep(template: Recipe, vary: Union[str, Sequence[str]], log: Union[None, str, Sequence[str]] = None,
          lhs: Optional[int] = None, seed: Optional[int] = None, geometries: Geometries = None,
          shard: Optional[Shard] = None, rtol: Optional[float] = None, max_evals: Optional[int] = None,
          timing: bool = True, *, illuminant: Optional[str] = None, observer: Optional[str] = None,
          as_frame: bool = False) -> Union[List[SweepPoint], "pandas.DataFrame"]:
    """Measure a template recipe over a grid (``vary`` "PATH=LO..HI:N", one or a list) or a Latin hypercube
    (``lhs`` N points, ``vary`` "PATH=LO..HI"): one dict per point, the lines of ``glossmeter sweep --format
    jsonl``. With ``as_frame=True``, a pandas DataFrame of :func:`sweep_rows`. Ctrl-C stops it
    (KeyboardInterrupt). See docs/python.md."""
    frame = _check_frame_flag(as_frame)
    points = _glossmeter.sweep(template, vary, log, lhs, seed, geometries, shard, rtol, max_evals, timing,
                               illuminant, observer)
    if not frame:
        return points
    import pandas as pd

    out = pd.DataFrame(sweep_rows(points))
    for c in ("value", "error_estimate"):
        if c in out:
            out[c] = out[c].astype(np.float64)
    return out


def _frame(rows: Sequence[Mapping[str, object]], columns: Sequence[str], floats: Sequence[str]) -> "pandas.DataFrame":
    """``rows`` as a DataFrame with ``columns`` in order, the ``floats`` columns float64 (None → NaN)."""
    import pandas as pd

    out = pd.DataFrame(list(rows), columns=list(columns))
    for c in floats:
        out[c] = out[c].astype(np.float64)
    return out


#: The columns of ``compare(..., as_frame=True)``: one row per compared (sample, reading), the scalar fields of
#: a comparison, ``allowance`` its total, ``prediction_uncertainty`` NaN without a recipe uncertainty block, and
#: ``illuminant`` and ``observer`` a colour prediction's (None on the other rows).
COMPARE_COLUMNS = ("sample", "material", "recipe", "geometry", "reading", "predicted_reading", "n", "mean", "std",
                   "min", "max", "uncertainty", "predicted", "error_estimate", "difference", "allowance",
                   "prediction_uncertainty", "verdict", "inside", "reason", "unchecked", "illuminant", "observer")
_COMPARE_FLOATS = ("mean", "std", "min", "max", "uncertainty", "predicted", "error_estimate", "difference",
                   "allowance", "prediction_uncertainty")


def compare_rows(report: CompareReport) -> List[Dict[str, Any]]:
    """A comparison document's verdicts as flat rows, one per compared (sample, reading), the columns of
    :data:`COMPARE_COLUMNS` (the per-line ``lines``/``columns``/``values`` and the allowance's parts stay in
    the document)."""
    rows: List[Dict[str, Any]] = []
    for c in report["comparisons"]:
        row: Dict[str, Any] = {k: c.get(k) for k in COMPARE_COLUMNS}
        allowance = c.get("allowance")
        row["allowance"] = None if allowance is None else allowance["total"]
        rows.append(row)
    return rows


@overload
def compare(recipe: Recipe, sheet: SheetSource, tolerance: Optional[Tolerance] = ..., k: Optional[float] = ...,
            max_de00: Optional[float] = ..., rtol: Optional[float] = ..., illuminant: Optional[str] = ...,
            observer: Optional[str] = ..., delimiter: Optional[str] = ..., sheet_name: Optional[str] = ...,
            header_row: Optional[int] = ..., ignore_columns: Union[None, str, Sequence[str]] = ..., *,
            max_evals: Optional[int] = ..., as_frame: Literal[False] = ...) -> CompareReport: ...
@overload
def compare(recipe: Recipe, sheet: SheetSource, tolerance: Optional[Tolerance] = ..., k: Optional[float] = ...,
            max_de00: Optional[float] = ..., rtol: Optional[float] = ..., illuminant: Optional[str] = ...,
            observer: Optional[str] = ..., delimiter: Optional[str] = ..., sheet_name: Optional[str] = ...,
            header_row: Optional[int] = ..., ignore_columns: Union[None, str, Sequence[str]] = ..., *,
            max_evals: Optional[int] = ..., as_frame: Literal[True]) -> "pandas.DataFrame": ...
def compare(recipe: Recipe, sheet: SheetSource, tolerance: Optional[Tolerance] = None, k: Optional[float] = None,
            max_de00: Optional[float] = None, rtol: Optional[float] = None, illuminant: Optional[str] = None,
            observer: Optional[str] = None, delimiter: Optional[str] = None, sheet_name: Optional[str] = None,
            header_row: Optional[int] = None, ignore_columns: Union[None, str, Sequence[str]] = None, *,
            max_evals: Optional[int] = None, as_frame: bool = False) -> Union[CompareReport, "pandas.DataFrame"]:
    """The recipe's predictions beside an instrument sheet, with the verdicts: the document of ``glossmeter
    compare RECIPE SHEET --format json``. With ``as_frame=True``, a pandas DataFrame of :func:`compare_rows`,
    one row per compared (sample, reading). See docs/python.md."""
    frame = _check_frame_flag(as_frame)
    doc = _glossmeter.compare(recipe, sheet, tolerance, k, max_de00, rtol, illuminant, observer, delimiter,
                              sheet_name, header_row, ignore_columns, max_evals)
    if not frame:
        return doc
    return _frame(compare_rows(doc), COMPARE_COLUMNS, _COMPARE_FLOATS)


@overload
def fit(recipe: Recipe, targets: Optional[Targets] = ..., *, free: FreeParameters,
        sheet: Optional[SheetSource] = ..., sample: Optional[str] = ..., uncertainty: Optional[float] = ...,
        restarts: Optional[int] = ..., rtol: Optional[float] = ..., geometries: Geometries = ...,
        timing: bool = ..., delimiter: Optional[str] = ..., sheet_name: Optional[str] = ...,
        header_row: Optional[int] = ..., ignore_columns: Union[None, str, Sequence[str]] = ...,
        max_evals: Optional[int] = ..., illuminant: Optional[str] = ..., observer: Optional[str] = ...,
        as_frame: Literal[False] = ...) -> FitReport: ...
@overload
def fit(recipe: Recipe, targets: Optional[Targets] = ..., *, free: FreeParameters,
        sheet: Optional[SheetSource] = ..., sample: Optional[str] = ..., uncertainty: Optional[float] = ...,
        restarts: Optional[int] = ..., rtol: Optional[float] = ..., geometries: Geometries = ...,
        timing: bool = ..., delimiter: Optional[str] = ..., sheet_name: Optional[str] = ...,
        header_row: Optional[int] = ..., ignore_columns: Union[None, str, Sequence[str]] = ...,
        max_evals: Optional[int] = ..., illuminant: Optional[str] = ..., observer: Optional[str] = ...,
        as_frame: Literal[True]) -> "pandas.DataFrame": ...
def fit(recipe: Recipe, targets: Optional[Targets] = None, *, free: FreeParameters,
        sheet: Optional[SheetSource] = None, sample: Optional[str] = None, uncertainty: Optional[float] = None,
        restarts: Optional[int] = None, rtol: Optional[float] = None, geometries: Geometries = None,
        timing: bool = True, delimiter: Optional[str] = None, sheet_name: Optional[str] = None,
        header_row: Optional[int] = None, ignore_columns: Union[None, str, Sequence[str]] = None,
        max_evals: Optional[int] = None, illuminant: Optional[str] = None, observer: Optional[str] = None,
        as_frame: bool = False) -> Union[FitReport, "pandas.DataFrame"]:
    """Recipe parameters from readings: the ``free`` parameters fitted to ``targets`` or to a ``sheet``'s
    ``sample``; the document of ``glossmeter fit --format json``. With ``as_frame=True``, a pandas DataFrame
    with one row per fitted parameter (``path``, ``value``, ``std_error``, ``lower``, ``upper``, ``at_bound``;
    the fit's verdict stays in the document). See docs/python.md."""
    frame = _check_frame_flag(as_frame)
    doc = _glossmeter.fit(recipe, targets, free=free, sheet=sheet, sample=sample, uncertainty=uncertainty,
                          restarts=restarts, rtol=rtol, geometries=geometries, timing=timing, delimiter=delimiter,
                          sheet_name=sheet_name, header_row=header_row, ignore_columns=ignore_columns,
                          max_evals=max_evals, illuminant=illuminant, observer=observer)
    if not frame:
        return doc
    columns = ("path", "value", "std_error", "lower", "upper", "at_bound")
    return _frame(doc["parameters"], columns, ("value", "std_error", "lower", "upper"))


@overload
def profile(recipe: Recipe, geometry: Optional[Geometry] = ..., rtol: Optional[float] = ...,
            max_evals: Optional[int] = ..., max_total_evals: Optional[int] = ..., *,
            as_frame: Literal[False] = ...) -> ProfileReport: ...
@overload
def profile(recipe: Recipe, geometry: Optional[Geometry] = ..., rtol: Optional[float] = ...,
            max_evals: Optional[int] = ..., max_total_evals: Optional[int] = ..., *,
            as_frame: Literal[True]) -> "pandas.DataFrame": ...
def profile(recipe: Recipe, geometry: Optional[Geometry] = None, rtol: Optional[float] = None,
            max_evals: Optional[int] = None, max_total_evals: Optional[int] = None, *,
            as_frame: bool = False) -> Union[ProfileReport, "pandas.DataFrame"]:
    """The goniophotometric profile of a recipe on a geometry with a profile array (None: rspec-20): the
    document of ``glossmeter profile --format json``. With ``as_frame=True``, a pandas DataFrame with one row
    per pixel (the document's ``rows``: ``pixel``, ``angle_deg``, ``angle_half_width_deg``, ``value``,
    ``error_estimate``, ``unit``, ``converged``, ``evaluations``, ``problem``). See docs/python.md."""
    frame = _check_frame_flag(as_frame)
    doc = _glossmeter.profile(recipe, geometry, rtol, max_evals, max_total_evals)
    if not frame:
        return doc
    columns = ("pixel", "angle_deg", "angle_half_width_deg", "value", "error_estimate", "unit", "converged",
               "evaluations", "problem")
    return _frame(doc["rows"], columns, ("angle_deg", "angle_half_width_deg", "value", "error_estimate"))
