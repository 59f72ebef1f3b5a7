"""Stubs of the compiled module ``glossmeter._glossmeter`` (python/src/lib.rs, python/src/pybrdf.rs). The
public API is ``glossmeter`` (``__init__.py``), which re-exports these with ``as_frame``/``as_arrays`` added."""
import os
from typing import Any, Dict, List, Literal, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from ._types import (
    BrdfFunction,
    CompareReport,
    ConvergenceReport,
    Delta,
    FitReport,
    FreeParameters,
    Geometries,
    Geometry,
    Lobes,
    ProfileReport,
    Reading,
    Recipe,
    Shard,
    Sheet,
    SheetSource,
    SweepPoint,
    Targets,
    Tolerance,
)

__version__: str
DEFAULT_GEOMETRIES: List[str]

def measure(
    recipe: Recipe,
    geometries: Geometries = None,
    rtol: Optional[float] = None,
    timing: bool = True,
    *,
    max_evals: Optional[int] = None,
    max_seconds: Optional[float] = None,
    illuminant: Optional[str] = None,
    observer: Optional[str] = None,
) -> List[Reading]: ...
def measure_brdf(
    f: BrdfFunction,
    geometries: Geometries = None,
    rtol: Optional[float] = None,
    lobes: Optional[Lobes] = None,
    delta: Optional[Delta] = None,
    wavelengths: Optional[Sequence[float]] = None,
    timing: bool = True,
    *,
    max_evals: Optional[int] = None,
    max_seconds: Optional[float] = None,
) -> List[Reading]: ...
def standards() -> List[Dict[str, Any]]: ...
def geometry(id: Geometry) -> Dict[str, Any]: ...
def describe_geometry(id: Geometry) -> str: ...
def schema(
    output_format: Optional[Literal["measure", "compare", "sweep", "fit", "profile", "convergence", "sheet"]] = None,
) -> Dict[str, Any]: ...
def describe(recipe: Recipe) -> str: ...
def read_sheet(
    sheet: SheetSource,
    delimiter: Optional[str] = None,
    sheet_name: Optional[str] = None,
    header_row: Optional[int] = None,
    ignore_columns: Union[None, str, Sequence[str]] = None,
) -> Sheet: ...
def compare(
    recipe: Recipe,
    sheet: SheetSource,
    tolerance: Optional[Tolerance] = None,
    k: Optional[float] = None,
    max_de00: Optional[float] = None,
    rtol: Optional[float] = None,
    illuminant: Optional[str] = None,
    observer: Optional[str] = None,
    delimiter: Optional[str] = None,
    sheet_name: Optional[str] = None,
    header_row: Optional[int] = None,
    ignore_columns: Union[None, str, Sequence[str]] = None,
    max_evals: Optional[int] = None,
) -> CompareReport: ...
def sweep(
    template: Recipe,
    vary: Union[str, Sequence[str]],
    log: Union[None, str, Sequence[str]] = None,
    lhs: Optional[int] = None,
    seed: Optional[int] = None,
    geometries: Geometries = None,
    shard: Optional[Shard] = None,
    rtol: Optional[float] = None,
    max_evals: Optional[int] = None,
    timing: bool = True,
    illuminant: Optional[str] = None,
    observer: Optional[str] = None,
) -> List[SweepPoint]: ...
def fit(
    recipe: Recipe,
    targets: Optional[Targets] = None,
    *,
    free: FreeParameters,
    sheet: Optional[SheetSource] = None,
    sample: Optional[str] = None,
    uncertainty: Optional[float] = None,
    restarts: Optional[int] = None,
    rtol: Optional[float] = None,
    geometries: Geometries = None,
    timing: bool = True,
    delimiter: Optional[str] = None,
    sheet_name: Optional[str] = None,
    header_row: Optional[int] = None,
    ignore_columns: Union[None, str, Sequence[str]] = None,
    max_evals: Optional[int] = None,
    illuminant: Optional[str] = None,
    observer: Optional[str] = None,
) -> FitReport: ...
def profile(
    recipe: Recipe,
    geometry: Optional[Geometry] = None,
    rtol: Optional[float] = None,
    max_evals: Optional[int] = None,
    max_total_evals: Optional[int] = None,
) -> ProfileReport: ...
def convergence(
    recipe: Recipe,
    geometries: Geometries = None,
    tolerances: Optional[Sequence[float]] = None,
    min_time_ms: Optional[float] = None,
    max_repetitions: Optional[int] = None,
    reference_run: bool = False,
    illuminant: Optional[str] = None,
    observer: Optional[str] = None,
) -> ConvergenceReport: ...
class HeightMap:
    """A height map held in memory for recipes: a recipe's ``file`` (a topography's, a paint's applied
    texture) may be one. Made by :func:`height_map`; pickles (to a Dask worker) bit for bit."""

    @property
    def label(self) -> str: ...
    @property
    def shape(self) -> Tuple[int, int]: ...
    @property
    def dx_um(self) -> float: ...
    @property
    def dy_um(self) -> float: ...

def height_map(
    array: npt.NDArray[Any],
    dx_um: float,
    dy_um: Optional[float] = None,
    unit: Optional[Literal["m", "mm", "um", "µm", "nm", "pm"]] = None,
    mask: Optional[npt.NDArray[np.bool_]] = None,
) -> HeightMap: ...
def topography(
    source: Union[npt.NDArray[Any], HeightMap, str, os.PathLike[str]],
    dx_um: Optional[float] = None,
    dy_um: Optional[float] = None,
    unit: Optional[Literal["m", "mm", "um", "µm", "nm", "pm"]] = None,
    mask: Optional[npt.NDArray[np.bool_]] = None,
    levelling: Optional[str] = None,
) -> Dict[str, Any]: ...
def _cli(argv: List[str]) -> int: ...
def _panic() -> None: ...
