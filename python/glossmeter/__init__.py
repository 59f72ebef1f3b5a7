"""glossmeter: a virtual gloss, haze and DOI meter (Python bindings of the Rust library).

    >>> import glossmeter
    >>> glossmeter.measure("fixtures/recipes/black-glass.json", geometries=["astm-d523-60"])

Every function is a thin layer over the library (see docs/python.md):

* ``measure(recipe, geometries=None, rtol=1e-6)``: readings of a recipe (dict, JSON string or path), one
  dict per reading with the fields of ``glossmeter measure --format json``.
* ``measure_brdf(f, geometries=None, rtol=1e-6, lobes=None, delta=None)``: readings of a Python BRDF
  ``f(wi, wo)`` evaluated in batches of (N, 3) NumPy arrays.
* ``standards()``, ``geometry(id)``, ``describe_geometry(id)``, ``schema()``, ``describe(recipe)``.

Bad input raises ``ValueError`` with the message the CLI prints; an unreadable file raises ``OSError``.
"""
from ._glossmeter import (  # noqa: F401
    DEFAULT_GEOMETRIES,
    __version__,
    describe,
    describe_geometry,
    geometry,
    measure,
    measure_brdf,
    schema,
    standards,
)

__all__ = [
    "DEFAULT_GEOMETRIES",
    "describe",
    "describe_geometry",
    "geometry",
    "measure",
    "measure_brdf",
    "schema",
    "standards",
]
