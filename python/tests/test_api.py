"""The API's edges: every refusal names the argument and what it allows; readings as a pandas DataFrame or as
NumPy arrays; the stubs and py.typed ship with the package."""
import json
import math
import pathlib
import sys

import numpy as np
import pytest

import glossmeter
from conftest import RECIPES

LAMBERT = {"model": "lambert", "albedo": 0.5}
PATH = RECIPES / "black-glass.json"


def smooth(wi, wo):
    return np.full(len(wi), 0.1)


@pytest.mark.parametrize("call, exc, words", [
    # the three of the issue: the argument named, and what is allowed
    (lambda: glossmeter.measure(PATH, geometries=5), TypeError,
     ["geometries:", "geometry id", "list", "got int"]),
    (lambda: glossmeter.measure(PATH, rtol="x"), TypeError, ["rtol:", "number", "(0, 1)", "got str"]),
    (lambda: glossmeter.measure_brdf(lambda wi, wo: None), TypeError,
     ["f returned None", "shape (", ",) or (", "S)"]),
    # and the rest of the API's arguments
    (lambda: glossmeter.measure(42), TypeError, ["recipe:", "dict", "JSON string", "path", "got int"]),
    (lambda: glossmeter.measure(LAMBERT, geometries=[5]), TypeError, ["geometries[0]:", "geometry id", "got int"]),
    (lambda: glossmeter.measure(LAMBERT, geometries=["astm-d523-60", 2.0]), TypeError, ["geometries[1]:"]),
    (lambda: glossmeter.measure(LAMBERT, geometries=[]), ValueError, ["geometries:", "empty", "None"]),
    (lambda: glossmeter.measure(LAMBERT, rtol=True), TypeError, ["rtol:", "got bool"]),
    (lambda: glossmeter.measure(LAMBERT, rtol=2.0), ValueError, ["rtol", "(0, 1)", "2"]),
    (lambda: glossmeter.measure(LAMBERT, rtol=-1), ValueError, ["rtol", "(0, 1)"]),
    (lambda: glossmeter.measure(LAMBERT, timing=1), TypeError, ["timing:", "True or False", "got int"]),
    (lambda: glossmeter.measure(LAMBERT, timing="yes"), TypeError, ["timing:", "True or False", "got str"]),
    (lambda: glossmeter.measure(LAMBERT, as_frame=1), TypeError, ["as_frame:", "True or False", "got int"]),
    (lambda: glossmeter.measure(LAMBERT, as_arrays="x"), TypeError, ["as_arrays:", "True or False"]),
    (lambda: glossmeter.measure(LAMBERT, as_frame=True, as_arrays=True), ValueError, ["as_frame and as_arrays"]),
    (lambda: glossmeter.geometry(7), TypeError, ["id:", "geometry id", "got int"]),
    (lambda: glossmeter.describe_geometry(None), TypeError, ["id:", "got NoneType"]),
    (lambda: glossmeter.describe(3.5), TypeError, ["recipe:", "got float"]),
    (lambda: glossmeter.measure_brdf(42), TypeError, ["f:", "callable", "got int"]),
    (lambda: glossmeter.measure_brdf(lambda wi, wo: 0.5, lobes=[]), ValueError,
     ["f returned float", "shape (1,)", "not broadcast"]),
    (lambda: glossmeter.measure_brdf(lambda wi, wo: "abc", lobes=[]), TypeError, ["f returned str", "shape ("]),
    (lambda: glossmeter.measure_brdf(smooth, rtol="1e-6"), TypeError, ["rtol:", "got str"]),
    (lambda: glossmeter.measure_brdf(smooth, lobes=[], rtol=2.0), ValueError, ["`rtol`", "(0, 1)"]),
    (lambda: glossmeter.measure_brdf(smooth, lobes=[], max_evals=0), ValueError, ["`max_evals`", "at least 1"]),
    (lambda: glossmeter.measure_brdf(smooth, lobes=[], max_evals=-3), ValueError, ["max_evals:", "got -3"]),
    (lambda: glossmeter.measure_brdf(smooth, lobes=[], max_seconds=float("nan")), ValueError, ["`max_seconds`"]),
    (lambda: glossmeter.measure_brdf(smooth, timing=None, lobes=5), TypeError,
     ["lobes:", "None", "[]", "slope", "got int"]),
    (lambda: glossmeter.measure_brdf(smooth, lobes="0.1"), TypeError, ["lobes:", "got str"]),
    (lambda: glossmeter.measure_brdf(smooth, lobes=["wide"]), TypeError, ["lobes[0]:", "slope width", "got str"]),
    (lambda: glossmeter.measure_brdf(smooth, lobes=[{"slope": "x"}]), TypeError, ['lobes[0]["slope"]:', "got str"]),
    (lambda: glossmeter.measure_brdf(smooth, lobes=[{"slope": 0.1, "eta": None}]), TypeError,
     ['lobes[0]["eta"]:', "[1, 4]"]),
    (lambda: glossmeter.measure_brdf(smooth, lobes=[{"slope": 0.1, "tail": 1}]), TypeError,
     ['lobes[0]["tail"]:', '"heavy" or "gaussian"', "got int"]),
    (lambda: glossmeter.measure_brdf(smooth, lobes=[{"slope": 0.1, "tail": "fat"}]), ValueError,
     ["lobes[0]:", '"heavy", "gaussian"']),
    (lambda: glossmeter.measure_brdf(smooth, lobes=[{"slope": 0.1, "label": 3}]), TypeError,
     ['lobes[0]["label"]:', "str"]),
    (lambda: glossmeter.measure_brdf(smooth, lobes=[{}]), ValueError, ["lobes[0]:", "missing", "slope"]),
    (lambda: glossmeter.measure_brdf(smooth, lobes=[20.0]), ValueError, ["lobes[0]:", "(0, 10]"]),
    (lambda: glossmeter.measure_brdf(smooth, lobes=[], delta="x"), TypeError,
     ["delta:", "[0, 1]", "callable", "got str"]),
    (lambda: glossmeter.measure_brdf(smooth, lobes=[], delta=[0.1, 0.2]), ValueError,
     ["delta:", "2 values", "1 spectral sample"]),
    (lambda: glossmeter.measure_brdf(smooth, lobes=[], delta=1.5), ValueError, ["delta:", "[0, 1]"]),
    (lambda: glossmeter.measure_brdf(smooth, lobes=[], wavelengths=550), TypeError,
     ["wavelengths:", "list of numbers", "nm", "got int"]),
    (lambda: glossmeter.measure_brdf(smooth, lobes=[], wavelengths=["green"]), TypeError,
     ["wavelengths[0]:", "nm", "got str"]),
    (lambda: glossmeter.measure_brdf(smooth, lobes=[], wavelengths=[450, 550]), ValueError,
     ["wavelengths:", "2 entries", "1 spectral sample"]),
    (lambda: glossmeter.measure_brdf(lambda wi, wo: np.ones((len(wi), 4)), lobes=[]), ValueError,
     ["wavelengths:", "4 spectral samples"]),
])
def test_every_refusal_names_the_argument_and_what_is_allowed(call, exc, words):
    with pytest.raises(exc) as e:
        call()
    msg = str(e.value)
    for w in words:
        assert w in msg, (w, msg)


def test_what_the_arguments_accept(tmp_path):
    """The other side of the refusals: what the messages say is allowed is accepted."""
    one = glossmeter.measure(LAMBERT, geometries="astm-d523-60", timing=False)
    assert glossmeter.measure(LAMBERT, geometries=("astm-d523-60",), timing=False) == one
    assert glossmeter.measure(LAMBERT, geometries=["astm-d523-60"], rtol=1e-6, timing=np.bool_(False)) == one
    assert glossmeter.measure(LAMBERT, ["astm-d523-60"], np.float64(1e-6), False) == one  # positional, NumPy
    assert glossmeter.measure(LAMBERT, geometries=None, timing=False) == glossmeter.measure(LAMBERT, timing=False)
    # a geometry file as os.PathLike, alone (not in a list)
    spec = glossmeter.geometry("astm-d523-60")
    spec["id"] = "my-d523-60"
    geo = tmp_path / "my-d523-60.json"
    geo.write_text(json.dumps(spec))
    mine = glossmeter.measure(LAMBERT, geometries=geo, timing=False)
    assert mine[0]["geometry"] == "my-d523-60" and mine[0]["value"] == one[0]["value"]
    r = glossmeter.measure_brdf(smooth, geometries="astm-d523-60", lobes=[{"slope": 0.1, "tail": "gaussian",
                                "eta": 1.5, "label": "mine"}], delta=[0.04], wavelengths=None, timing=False)
    assert r[0]["value"] > 0


def test_as_frame_and_as_arrays_hold_the_same_readings():
    pd = pytest.importorskip("pandas", reason="pandas is not installed (pip install pandas); .ci/run installs it")
    # a black body: its DOI has no value (None, with a problem); D4039 adds a note
    black, geos = {"model": "lambert", "albedo": 0.0}, ["astm-d523-60", "astm-e430-30", "astm-d4039"]
    readings = glossmeter.measure(black, geos, timing=False)
    arrays = glossmeter.measure(black, geos, timing=False, as_arrays=True)
    frame = glossmeter.measure(black, geos, timing=False, as_frame=True)
    assert isinstance(frame, pd.DataFrame) and len(frame) == len(readings)
    assert list(frame.columns) == list(arrays) == ["geometry", "name", "quantity", "value", "unit",
                                                   "error_estimate", "evaluations", "converged", "problem", "note",
                                                   "illuminant", "observer"]
    assert arrays["value"].dtype == np.float64 and arrays["evaluations"].dtype == np.int64
    assert arrays["converged"].dtype == bool
    for i, r in enumerate(readings):
        for key in ("geometry", "name", "quantity", "unit", "evaluations", "converged"):
            assert arrays[key][i] == r[key] == frame[key].iloc[i]
        for key in ("value", "error_estimate"):
            if r[key] is None:
                assert math.isnan(arrays[key][i]) and math.isnan(frame[key].iloc[i])
            else:
                assert arrays[key][i] == r[key] == frame[key].iloc[i]  # the same bits
        assert arrays["problem"][i] == r.get("problem") and arrays["note"][i] == r.get("note")
        assert arrays["illuminant"][i] is None and arrays["observer"][i] is None  # no colour reading here
    # A colour reading says what it is computed under; the gloss reading beside it does not.
    grey = {"model": "lambert", "albedo": 0.5}
    colour = glossmeter.measure(grey, ["astm-d523-60", "d8-sci"], timing=False, illuminant="A", observer="2")
    colour_arrays = glossmeter.measure(grey, ["astm-d523-60", "d8-sci"], timing=False, illuminant="A", observer="2",
                                       as_arrays=True)
    for i, r in enumerate(colour):
        want = ("A", "2") if r["geometry"] == "d8-sci" else (None, None)
        assert (r.get("illuminant"), r.get("observer")) == want, r
        assert (colour_arrays["illuminant"][i], colour_arrays["observer"][i]) == want
    assert sum(r["geometry"] == "d8-sci" for r in colour) >= 3
    assert any(r["value"] is None for r in readings) and any(r["value"] is not None for r in readings)
    assert any("problem" in r for r in readings)
    timed = glossmeter.measure(LAMBERT, geometries="astm-d523-60", as_frame=True)
    assert "seconds" in timed.columns and timed["seconds"].iloc[0] >= 0
    brdf = glossmeter.measure_brdf(smooth, geometries="astm-d523-60", lobes=[], as_arrays=True, timing=False)
    assert brdf["value"].shape == (1,) and brdf["value"][0] > 0


def test_as_frame_without_pandas_says_how_to_get_it(monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)  # `import pandas` now raises ImportError
    with pytest.raises(ImportError, match=r"as_frame=True.*needs pandas.*pip install pandas.*as_arrays=True"):
        glossmeter.measure(LAMBERT, geometries="astm-d523-60", as_frame=True)
    # NumPy arrays need nothing more
    assert glossmeter.measure(LAMBERT, geometries="astm-d523-60", as_arrays=True)["value"][0] > 0


def test_the_package_ships_its_types():
    pkg = pathlib.Path(glossmeter.__file__).parent
    assert (pkg / "py.typed").is_file()
    assert (pkg / "_glossmeter.pyi").is_file()
    stub = (pkg / "_glossmeter.pyi").read_text()
    for name in ("measure", "measure_brdf", "standards", "geometry", "describe_geometry", "schema", "describe"):
        assert f"def {name}(" in stub
        assert callable(getattr(glossmeter, name))


def test_schema_names_an_unknown_output():
    with pytest.raises(ValueError, match="output_format"):
        glossmeter.schema("pie")
