"""Stubs of the compiled module ``glossmeter._glossmeter`` (python/src/lib.rs, python/src/pybrdf.rs). The
public API is ``glossmeter`` (``__init__.py``), which re-exports these with ``as_frame``/``as_arrays`` added."""
from typing import Any, Dict, List, Literal, Optional, Sequence

from ._types import BrdfFunction, Delta, Geometries, Geometry, Lobes, Reading, Recipe

__version__: str
DEFAULT_GEOMETRIES: List[str]

def measure(
    recipe: Recipe,
    geometries: Geometries = None,
    rtol: Optional[float] = None,
    timing: bool = True,
) -> List[Reading]: ...
def measure_brdf(
    f: BrdfFunction,
    geometries: Geometries = None,
    rtol: Optional[float] = None,
    lobes: Optional[Lobes] = None,
    delta: Optional[Delta] = None,
    wavelengths: Optional[Sequence[float]] = None,
    timing: bool = True,
) -> List[Reading]: ...
def standards() -> List[Dict[str, Any]]: ...
def geometry(id: Geometry) -> Dict[str, Any]: ...
def describe_geometry(id: Geometry) -> str: ...
def schema(output_format: Optional[Literal["measure", "compare", "sweep", "fit"]] = None) -> Dict[str, Any]: ...
def describe(recipe: Recipe) -> str: ...
def _cli(argv: List[str]) -> int: ...
def _panic() -> None: ...
