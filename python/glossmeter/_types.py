"""The types of glossmeter's Python API, for annotations (``from glossmeter import Reading``) and for the stubs
of the compiled module (``_glossmeter.pyi``)."""
import os
from typing import Any, Callable, Dict, List, Literal, Mapping, Optional, Sequence, Tuple, TypedDict, Union

import numpy as np
import numpy.typing as npt

#: A recipe: a dict, a JSON string (first non-blank character ``{``) or the path of a recipe file.
Recipe = Union[Mapping[str, Any], str, os.PathLike[str]]
#: One geometry: a builtin id (``"astm-d523-60"``), the path of a geometry file, or a dict in the standards format.
Geometry = Union[str, os.PathLike[str], Mapping[str, Any]]
#: ``None`` (the default panel of ``glossmeter measure``), one geometry, or a list of them.
Geometries = Union[None, Geometry, Sequence[Geometry]]
#: An array of unit directions, shape (N, 3), float64, in the local frame (z the specimen normal).
Directions = npt.NDArray[np.float64]
#: A user's BRDF ``f(wi, wo)``: f_r in sr⁻¹ as (N,) or (N, S).
BrdfFunction = Callable[[Directions, Directions], npt.ArrayLike]
#: A mirror component: R as a number, a list of S numbers, or a callable ``R(wi)`` returning (N,) or (N, S).
Delta = Union[float, Sequence[float], Callable[[Directions], npt.ArrayLike]]


class _LobeRequired(TypedDict):
    slope: float


class LobeHint(_LobeRequired, total=False):
    """A lobe of a user's BRDF: its facet slope width (Beckmann m or GGX α), tail, medium index and label."""

    tail: Literal["heavy", "gaussian"]
    eta: float
    label: str


#: ``lobes=`` of ``measure_brdf``: slope widths or :class:`LobeHint` dicts; ``[]`` declares f smooth.
Lobes = Sequence[Union[float, LobeHint]]


class _ReadingRequired(TypedDict):
    geometry: str
    name: str
    quantity: str
    value: Optional[float]
    unit: str
    error_estimate: Optional[float]
    evaluations: int
    converged: bool


class EnvelopeVariation(TypedDict):
    """One varied parameter of a reading's envelope (``measure --envelope``)."""

    pointer: str
    kind: str
    nominal: float
    low: float
    high: float
    status: str


class Envelope(TypedDict):
    """How a reading's envelope was found (``measure --envelope``)."""

    method: str
    variants: int
    varied: List[EnvelopeVariation]


class BudgetLine(TypedDict):
    """One line of a prediction's uncertainty budget (docs/instrument.md §The prediction's uncertainty): a
    number of the recipe (its JSON Pointer), its stated standard uncertainty, the reading's sensitivity to it
    and its contribution |∂y/∂x|·u(x), with how the sensitivity was differenced."""

    pointer: str
    u: float
    sensitivity: float
    contribution: float
    difference: Literal["central", "forward", "backward"]


class Reading(_ReadingRequired, total=False):
    """One reading, with the fields of ``glossmeter measure --format json`` (``value`` and ``error_estimate``
    are None when there is no finite value, and ``problem`` says why; ``seconds`` is left out with
    ``timing=False``). The ``envelope`` fields are the command line's ``--envelope``, and
    ``prediction_uncertainty`` / ``uncertainty_budget`` the command line's for a recipe with an ``uncertainty``
    block; ``measure`` here computes neither yet: they are in the type because they are in the document's
    schema."""

    seconds: float
    problem: str
    note: str
    #: The reading's uncertainty from its data (measured tables; absent elsewhere), in its unit.
    data_uncertainty: float
    #: A colour reading's CIE illuminant and observer (absent on gloss, haze and DOI readings).
    illuminant: Literal["D65", "D50", "A", "C"]
    observer: Literal["2", "10"]
    envelope_min: Optional[float]
    envelope_max: Optional[float]
    envelope: Optional[Envelope]
    envelope_cut: bool
    #: With a recipe's ``uncertainty`` block: the prediction's standard uncertainty u_pred, in its unit.
    prediction_uncertainty: float
    #: With ``prediction_uncertainty``: each stated number's share of it.
    uncertainty_budget: List[BudgetLine]


Readings = List[Reading]

# ---- The arguments of the actions (docs/python.md §Actions) ------------------------------------------------

#: A sheet: the path of a CSV or an .xlsx/.xls/.ods workbook (str or os.PathLike), or its bytes.
SheetSource = Union[str, os.PathLike[str], bytes, bytearray]
#: ``tolerance=`` of ``compare``: a number for every reading, ``"KEY=NUMBER"`` (``"gloss=2"``,
#: ``"astm-e430-30/doi=3"``), a dict ``{KEY: NUMBER}``, or a list of numbers and such strs.
Tolerance = Union[float, str, Mapping[str, float], Sequence[Union[float, str]]]
#: ``free=`` of ``fit``: ``"PATH=LO..HI"`` / ``"PATH=log:LO..HI"`` strs, or a dict ``{PATH: (LO, HI) or "log:LO..HI"}``.
FreeParameters = Union[str, Sequence[str], Mapping[str, Union[str, Tuple[float, float]]]]
#: ``targets=`` of ``fit``: ``"GEOMETRY/READING=VALUE[±U]"`` strs, or a dict ``{"GEOMETRY/READING": VALUE or (VALUE, U)}``.
Targets = Union[str, Sequence[str], Mapping[str, Union[float, Tuple[float, float]]]]
#: ``shard=`` of ``sweep``: ``"K/M"`` or ``(K, M)``, the K-th of M contiguous slices.
Shard = Union[str, Tuple[int, int]]

# ---- The documents of the actions: the fields of `glossmeter ACTION --format json` -------------------------
# Each TypedDict has the properties of its definition in `glossmeter schema --output-format ...`, the required
# ones required (python/tests/test_types.py checks it).


class SheetInfo(TypedDict):
    """The sheet read: its file, encoding, delimiter, layout, ``# key: value`` lines and ignored columns."""

    file: str
    encoding: str
    delimiter: str
    layout: Literal["long", "wide", "colour"]
    metadata: Dict[str, str]
    ignored_columns: List[str]


class SheetRow(TypedDict):
    """One value of a sheet: where it stands, what it is a reading of, its value."""

    line: int
    column: str
    sample: str
    geometry: str
    reading: str
    value: float
    uncertainty: Optional[float]
    not_predicted: Optional[str]


class Sheet(TypedDict):
    """What ``read_sheet`` returns (``schema("sheet")``)."""

    sheet: SheetInfo
    workbook_sheet: Optional[str]
    header_line: int
    headers: List[str]
    statistics_checked: int
    rows: List[SheetRow]


class AllowancePart(TypedDict):
    """One part of an allowance, named, with its formula (``k·√(s²/n + u_pred²)``, ...) and value."""

    name: Literal["statistical", "statistical and prediction uncertainty", "stated", "numerical"]
    formula: str
    value: float


class Allowance(TypedDict):
    """The allowed difference: total = random + stated + prediction (docs/instrument.md §The prediction's
    uncertainty)."""

    statistical: float
    prediction_uncertainty: float
    random: float
    stated: float
    prediction: float
    total: float
    parts: List[AllowancePart]


class _ComparisonOptional(TypedDict, total=False):
    #: With a recipe's ``uncertainty`` block: the prediction's standard uncertainty u_pred.
    prediction_uncertainty: float
    #: With ``prediction_uncertainty``: each stated number's share of it.
    uncertainty_budget: List[BudgetLine]
    #: A colour prediction's CIE illuminant and observer (absent on the other rows).
    illuminant: Literal["D65", "D50", "A", "C"]
    observer: Literal["2", "10"]


class Comparison(_ComparisonOptional):
    """One compared (sample, reading) of ``compare``."""

    sample: str
    material: str
    recipe: str
    geometry: str
    reading: str
    predicted_reading: Optional[str]
    lines: List[int]
    columns: List[str]
    values: List[float]
    n: int
    mean: float
    std: float
    min: float
    max: float
    uncertainty: Optional[float]
    predicted: Optional[float]
    error_estimate: Optional[float]
    difference: Optional[float]
    allowance: Optional[Allowance]
    verdict: Literal["ok", "OUTSIDE", "unchecked", "not predicted"]
    inside: Optional[bool]
    reason: Optional[str]
    unchecked: Optional[str]


class VerdictRule(TypedDict):
    k: float
    tolerance: Optional[float]
    tolerances: Dict[str, float]


class CompareSummary(TypedDict):
    readings: int
    inside: int
    outside: int
    no_value: int
    no_allowance: int
    not_predicted: int


class ColourDifference(TypedDict):
    sample: str
    geometry: str
    line: int
    measured: List[float]
    predicted: List[float]
    de00: float
    inside: Optional[bool]


class Drift(TypedDict):
    material: str
    geometry: str
    reading: str
    then: float
    now: float
    allowed: float
    moved: bool


class Baseline(TypedDict):
    file: str
    checks: List[Drift]
    moved: int


class _CompareReportRequired(TypedDict):
    sheet: SheetInfo
    rule: VerdictRule
    comparisons: List[Comparison]
    summary: CompareSummary
    colour_differences: List[ColourDifference]


class CompareReport(_CompareReportRequired, total=False):
    """What ``compare`` returns: ``glossmeter compare --format json`` (``baseline`` only with the command
    line's ``--baseline``)."""

    baseline: Optional[Baseline]


class _SweepReadingRequired(TypedDict):
    geometry: str
    name: str
    unit: str
    value: Optional[float]
    error_estimate: Optional[float]
    converged: bool


class SweepReading(_SweepReadingRequired, total=False):
    problem: Optional[str]
    #: A colour reading's CIE illuminant and observer (absent on gloss, haze and DOI readings).
    illuminant: Literal["D65", "D50", "A", "C"]
    observer: Literal["2", "10"]


class _SweepPointRequired(TypedDict):
    index: int
    parameters: Dict[str, float]


class SweepPoint(_SweepPointRequired, total=False):
    """One point of ``sweep``: a line of ``glossmeter sweep --format jsonl`` (``readings``, or ``problem`` when
    the recipe at the point is invalid; ``seconds`` left out with ``timing=False``)."""

    readings: Optional[List[SweepReading]]
    problem: Optional[str]
    seconds: Optional[float]


class FitParameter(TypedDict):
    path: str
    value: Optional[float]
    std_error: Optional[float]
    lower: float
    upper: float
    at_bound: bool


class _FitTargetRequired(TypedDict):
    geometry: str
    name: str
    measured: float
    uncertainty: float
    predicted: Optional[float]
    residual: Optional[float]


class FitTarget(_FitTargetRequired, total=False):
    #: A colour target's CIE illuminant and observer (absent on the other targets).
    illuminant: Literal["D65", "D50", "A", "C"]
    observer: Literal["2", "10"]


class FitReport(TypedDict):
    """What ``fit`` returns: ``glossmeter fit --format json`` (``seconds`` None with ``timing=False``)."""

    parameters: List[FitParameter]
    targets: List[FitTarget]
    converged: bool
    identifiable: bool
    stationary: bool
    chi2: Optional[float]
    dof: int
    p_value: Optional[float]
    reproduces: bool
    error_scale: Optional[float]
    singular_values: List[Optional[float]]
    correlation: List[List[Optional[float]]]
    verdict: List[str]
    evaluations: int
    seconds: Optional[float]
    recipe: Dict[str, Any]


class Material(TypedDict):
    name: str
    file: str
    model: str


class ProfileBudget(TypedDict):
    max_evals: int
    max_total_evals: int
    per_part: int
    rule: str


class ProfileRow(TypedDict):
    pixel: int
    angle_deg: float
    angle_half_width_deg: float
    value: Optional[float]
    error_estimate: Optional[float]
    unit: str
    converged: bool
    evaluations: int
    problem: Optional[str]


class ProfileReport(TypedDict):
    """What ``profile`` returns: ``glossmeter profile --format json``."""

    material: Material
    geometry: str
    pixels: int
    pixel_deg: float
    perpendicular_deg: float
    normalisation: str
    evaluations: int
    budget: ProfileBudget
    rows: List[ProfileRow]


class ConvergenceReference(TypedDict):
    kind: str
    rtol: Optional[float]
    seconds: Optional[float]


class ConvergenceTiming(TypedDict):
    statistic: str
    min_seconds: float
    max_repetitions: int


class _ConvergenceRowRequired(TypedDict):
    rtol: float
    geometry: str
    reading: str
    quantity: str
    unit: str
    value: Optional[float]
    error_estimate: Optional[float]
    actual_error: Optional[float]
    reference: Optional[float]
    reference_error: Optional[float]
    reference_kind: str
    evaluations: int
    seconds: float
    plan_seconds: float
    repetitions: int
    converged: bool
    problem: Optional[str]


class ConvergenceRow(_ConvergenceRowRequired, total=False):
    #: A colour reading's CIE illuminant and observer (``convergence``'s ``illuminant`` and ``observer``).
    illuminant: Literal["D65", "D50", "A", "C"]
    observer: Literal["2", "10"]


class ConvergenceReport(TypedDict):
    """What ``convergence`` returns: ``glossmeter convergence --format json``."""

    material: Material
    tolerances: List[float]
    reference: ConvergenceReference
    timing: ConvergenceTiming
    rows: List[ConvergenceRow]
