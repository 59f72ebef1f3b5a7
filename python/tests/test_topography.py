"""Height maps from Python (docs/python.md §Topography): a NumPy array with its pixel spacing gives the same
document as the same surface read from the shipped fixture file (the same doubles in, the same bits out), the
statistics NumPy computed for it (fixtures/topography/expected.json), and bad arrays are refused naming the
keyword, never a crash."""
import json
import zipfile

import numpy as np
import pytest

import glossmeter
from conftest import ROOT

TOPO = ROOT / "fixtures" / "topography"


def expected(which):
    return json.loads((TOPO / "expected.json").read_text())[which]


def x3p_heights(name, dtype):
    with zipfile.ZipFile(TOPO / name) as z:
        data = np.frombuffer(z.read("bindata/data.bin"), dtype=dtype).reshape(64, 64)
        valid = None
        if "bindata/valid.bin" in z.namelist():
            bits = np.frombuffer(z.read("bindata/valid.bin"), dtype=np.uint8)
            valid = np.unpackbits(bits, bitorder="little")[: 64 * 64].astype(bool).reshape(64, 64)
    return data, valid


def same_but_source(a, b):
    """Two documents equal in every field but the map's file and format (where the heights came from)."""
    for doc in (a, b):
        doc["map"].pop("file")
        doc["map"].pop("format")
    assert a == b


def test_an_array_reads_as_the_fixture_file_it_came_from():
    # gaussian.x3p holds f64 metres: the same doubles as an array in metres.
    z, _ = x3p_heights("gaussian.x3p", "<f8")
    from_array = glossmeter.topography(z, dx_um=1.0, unit="m")
    assert from_array["map"]["format"] == "array" and from_array["map"]["file"] == "<array>"
    from_file = glossmeter.topography(TOPO / "gaussian.x3p")
    assert from_file["map"]["format"] == "x3p"
    same_but_source(from_array, from_file)
    # The CSV in µm, read by NumPy, and the same file read by the library with its calibration.
    csv = np.loadtxt(TOPO / "gaussian.csv", delimiter=",", comments="#")
    same_but_source(
        glossmeter.topography(csv, dx_um=1, dy_um=1.0, unit="um"),
        glossmeter.topography(str(TOPO / "gaussian.csv"), dx_um=1.0, unit="um"),
    )
    # And NumPy's statistics of the surface (tools/make_topography_fixtures.py).
    doc = glossmeter.topography(csv, dx_um=1.0)
    want = expected("gaussian")
    assert doc["heights"]["sq_um"] == pytest.approx(want["sq_um"], rel=1e-11)
    assert doc["slopes"]["sdq"] == pytest.approx(want["sdq"], rel=1e-11)
    assert doc["tilt_x"] == pytest.approx(want["tilt_x"], rel=1e-11)


def test_a_mask_and_nan_heights_are_invalid_points():
    # gaussian-masked.x3p: i16 counts of 1 nm and a mask of three invalid points.
    z, valid = x3p_heights("gaussian-masked.x3p", "<i2")
    assert (~valid).sum() == 3
    from_array = glossmeter.topography(z, dx_um=1.0, unit="nm", mask=valid)
    assert from_array["map"]["invalid_points"] == 3
    same_but_source(from_array, glossmeter.topography(TOPO / "gaussian-masked.x3p"))
    # NaN marks the same points.
    zn = z.astype(float)
    zn[~valid] = np.nan
    same_but_source(
        glossmeter.topography(zn, dx_um=1.0, unit="nm"),
        glossmeter.topography(z, dx_um=1.0, unit="nm", mask=valid),
    )
    want = expected("gaussian_masked")
    doc = glossmeter.topography(zn, dx_um=1.0, unit="nm")
    assert doc["heights"]["sq_um"] == pytest.approx(want["sq_um"], rel=1e-9)


def test_the_levelling_and_a_non_square_spacing_are_taken():
    z = np.add.outer(np.arange(8.0) * 0.02, np.arange(6.0) * 0.01)  # a plane, 8 rows × 6 columns, µm
    doc = glossmeter.topography(z, dx_um=2.0, dy_um=4.0, levelling="plane")
    assert (doc["map"]["points_x"], doc["map"]["points_y"]) == (6, 8)
    assert (doc["map"]["spacing_x_um"], doc["map"]["spacing_y_um"]) == (2.0, 4.0)
    assert doc["tilt_x"] == pytest.approx(0.005) and doc["tilt_y"] == pytest.approx(0.005)
    assert doc["heights"]["sq_um"] < 1e-12
    assert glossmeter.topography(z, dx_um=2.0, dy_um=4.0, levelling="mean")["heights"]["sq_um"] > 0.01


@pytest.mark.parametrize(
    "kwargs, error, words",
    [
        (dict(source=np.zeros(16), dx_um=1.0), ValueError, ["array", "2-D", "1 dimensions"]),
        (dict(source=np.zeros((2, 2, 2)), dx_um=1.0), ValueError, ["array", "3 dimensions"]),
        (dict(source=np.zeros((4, 4), dtype=complex), dx_um=1.0), TypeError, ["array", "complex"]),
        (dict(source=np.array([["a", "b"], ["c", "d"]]), dx_um=1.0), TypeError, ["array", "dtype"]),
        (dict(source=np.zeros((4, 4), dtype=bool), dx_um=1.0), TypeError, ["array", "bool"]),
        (dict(source=np.zeros((1, 4)), dx_um=1.0), ValueError, ["array", "4 × 1 points"]),
        (dict(source=np.broadcast_to(0.0, (5000, 5000)), dx_um=1.0), ValueError, ["array", "too large"]),
        (dict(source=[[0.0, 1.0], [2.0, 3.0]], dx_um=1.0), TypeError, ["source", "list"]),
        (dict(source=np.zeros((4, 4))), ValueError, ["dx_um", "missing"]),
        (dict(source=np.zeros((4, 4)), dx_um=0.0), ValueError, ["dx_um", "spacing"]),
        (dict(source=np.zeros((4, 4)), dx_um=float("nan")), ValueError, ["dx_um"]),
        (dict(source=np.zeros((4, 4)), dx_um="1"), TypeError, ["dx_um", "str"]),
        (dict(source=np.zeros((4, 4)), dx_um=1.0, dy_um=2e7), ValueError, ["dy_um"]),
        (dict(source=np.zeros((4, 4)), dx_um=1.0, unit="inch"), ValueError, ["unit", "inch"]),
        (dict(source=np.zeros((4, 4)), dx_um=1.0, unit=3), TypeError, ["unit"]),
        (dict(source=np.zeros((4, 4)), dx_um=1.0, levelling="poly9"), ValueError, ["levelling", "poly9"]),
        (dict(source=np.full((4, 4), np.nan), dx_um=1.0), ValueError, ["array", "every point"]),
        (dict(source=np.array([[0.0, 1.0], [np.inf, 0.0]]), dx_um=1.0), ValueError, ["array", "(0, 1)"]),
        (dict(source=np.array([[0.0, 1.0], [2.0, 0.0]]), dx_um=1.0, unit="m"), ValueError, ["array", "|height|"]),
        (dict(source=np.zeros((4, 4)), dx_um=1.0, mask=np.ones((4, 3), dtype=bool)), ValueError, ["mask", "4 × 3"]),
        (dict(source=np.zeros((4, 4)), dx_um=1.0, mask=np.ones((4, 4))), TypeError, ["mask", "bool"]),
        (dict(source=np.zeros((4, 4)), dx_um=1.0, mask=[[True] * 4] * 4), TypeError, ["mask", "list"]),
        (dict(source=np.zeros((4, 4)), dx_um=1.0, mask=np.zeros((4, 4), dtype=bool)), ValueError, ["every point"]),
        (dict(source=str(TOPO / "gaussian.x3p"), mask=np.ones((64, 64), dtype=bool)), ValueError, ["mask"]),
        (dict(source=str(TOPO / "missing.x3p")), FileNotFoundError, ["missing.x3p"]),
    ],
)
def test_bad_arrays_are_refused_naming_the_keyword(kwargs, error, words):
    with pytest.raises(error) as e:
        glossmeter.topography(**kwargs)
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_a_non_contiguous_view_reads_as_its_copy():
    z, _ = x3p_heights("gaussian.x3p", "<f8")
    view = z.T[::2, ::2]  # strided, Fortran-ordered
    same_but_source(
        glossmeter.topography(view, dx_um=1.0, unit="m"),
        glossmeter.topography(np.ascontiguousarray(view), dx_um=1.0, unit="m"),
    )
