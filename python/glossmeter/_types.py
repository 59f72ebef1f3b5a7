"""The types of glossmeter's Python API, for annotations (``from glossmeter import Reading``) and for the stubs
of the compiled module (``_glossmeter.pyi``)."""
import os
from typing import Any, Callable, List, Literal, Mapping, Optional, Sequence, TypedDict, Union

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


class Reading(_ReadingRequired, total=False):
    """One reading, with the fields of ``glossmeter measure --format json`` (``value`` and ``error_estimate``
    are None when there is no finite value, and ``problem`` says why; ``seconds`` is left out with
    ``timing=False``)."""

    seconds: float
    problem: str
    note: str
    #: The reading's uncertainty from its data (measured tables; absent elsewhere), in its unit.
    data_uncertainty: float


Readings = List[Reading]
