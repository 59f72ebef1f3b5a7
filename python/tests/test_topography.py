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


# -- Maps held in memory for recipes (docs/python.md §Topography: a recipe's map from an array) -----------------

PANEL = json.loads((TOPO / "gaussian-panel.json").read_text())
GEOMETRIES = ["astm-d523-20", "astm-d523-60", "astm-d523-85"]


def values(readings):
    """(geometry, name, value, error estimate) of each reading: what the surface decides, not where it came from."""
    return [(r["geometry"], r["name"], r["value"], r["error_estimate"]) for r in readings]


def panel_from(file, **extra):
    return {**PANEL, "file": file, **extra}


def gsf_heights(name, n):
    """The f32 heights of a Gwyddion Simple Field of n × n points: its last 4·n² bytes (after the header's padding)."""
    data = (TOPO / name).read_bytes()[-4 * n * n :]
    return np.frombuffer(data, dtype="<f4").reshape(n, n)


@pytest.mark.parametrize(
    "name, heights, dx_um, method",
    [
        # The two-scale default on the 64 × 64 Gaussian panel (1 µm: the file's increment).
        ("gaussian.x3p", lambda: x3p_heights("gaussian.x3p", "<f8")[0], 1.0, {}),
        # Kirchhoff on the 256 × 256, 4 µm Sq 5 nm map (XReal/XRes = 0.001024/256 and 4·10⁻⁶ are the same double).
        ("kirchhoff/gauss-5nm.gsf", lambda: gsf_heights("kirchhoff/gauss-5nm.gsf", 256), 4.0, {"method": "kirchhoff"}),
    ],
)
def test_a_recipe_reads_a_height_map_as_the_file_it_came_from(name, heights, dx_um, method):
    z = heights()  # the file's own numbers, metres
    hm = glossmeter.height_map(z, dx_um=dx_um, unit="m")
    assert hm.shape == z.shape and hm.dx_um == dx_um and hm.dy_um == dx_um
    assert hm.label.startswith("<height map ") and hm.label in repr(hm)
    from_map = glossmeter.measure(panel_from(hm, **method), GEOMETRIES)
    from_file = glossmeter.measure(panel_from(str(TOPO / name), **method), GEOMETRIES)
    assert len(from_map) == 3 and all(r["value"] is not None for r in from_map), from_map
    assert values(from_map) == values(from_file)
    # The map's statistics through `topography` are the array's.
    same_but_source(glossmeter.topography(hm), glossmeter.topography(z, dx_um=dx_um, unit="m"))


def test_a_sweep_reads_the_map_at_every_point_and_a_pickled_map_reads_the_same():
    import pickle

    z, _ = x3p_heights("gaussian.x3p", "<f8")
    hm = glossmeter.height_map(z * 1e9, dx_um=1.0, unit="nm")
    points = glossmeter.sweep(panel_from(hm), "/ior=1.4..1.6:3", geometries=["astm-d523-60"], timing=False)
    assert [list(p["parameters"].values())[0] for p in points] == pytest.approx([1.4, 1.5, 1.6])
    assert all(p["readings"][0]["value"] is not None for p in points)
    again = pickle.loads(pickle.dumps(hm))  # as a Dask worker receives it: registered again, the same doubles
    assert again.label != hm.label and again.shape == hm.shape
    assert values(glossmeter.measure(panel_from(again), GEOMETRIES)) == values(
        glossmeter.measure(panel_from(hm), GEOMETRIES)
    )


def test_a_recipe_without_its_map_is_refused_with_the_reason():
    hm = glossmeter.height_map(np.zeros((8, 8)), dx_um=1.0)
    label = hm.label
    del hm
    with pytest.raises(ValueError) as e:
        glossmeter.measure(panel_from(label), GEOMETRIES)
    assert "/file" in str(e.value) and "held in memory" in str(e.value)
    with pytest.raises(TypeError) as e:
        glossmeter.measure(panel_from(np.zeros((8, 8))), GEOMETRIES)
    assert "height_map" in str(e.value)
    with pytest.raises(TypeError) as e:
        glossmeter.measure(panel_from(object()), GEOMETRIES)
    assert "not JSON serializable" in str(e.value)
    with pytest.raises(ValueError) as e:
        glossmeter.topography(glossmeter.height_map(np.zeros((8, 8)), dx_um=1.0), dx_um=2.0)
    assert "HeightMap" in str(e.value)
    for kwargs, error, word in [
        (dict(array=np.zeros((8, 8)), dx_um=None), ValueError, "dx_um"),
        (dict(array=np.zeros(8), dx_um=1.0), ValueError, "2-D"),
        (dict(array=np.full((4, 4), np.nan), dx_um=1.0), ValueError, "every point"),
    ]:
        with pytest.raises(error) as e:
            glossmeter.height_map(**kwargs)
        assert word in str(e.value), str(e.value)


def test_a_paints_applied_texture_reads_a_height_map_as_its_file(tmp_path):
    # A 64 × 64 wave 16 µm apart (fl(16·10⁻⁶) is both 16 × fl(10⁻⁶) and fl(0.001024)/64), as f32 in a GSF file.
    n, dx_um = 64, 16.0
    i = np.arange(n)
    z = np.tile(5e-6 * np.cos(2 * np.pi * i / n), (n, 1)).astype("<f4")
    header = f"Gwyddion Simple Field 1.0\nXRes = {n}\nYRes = {n}\nXReal = 0.001024\nYReal = 0.001024\nXYUnits = m\nZUnits = m\n"
    head = header.encode()
    (tmp_path / "wave.gsf").write_bytes(head + b"\0" * (4 - len(head) % 4) + z.tobytes())
    paint = json.loads((ROOT / "fixtures" / "recipes" / "clear-coat-2k-levelled.json").read_text())
    # A stiff film (10⁴ Pa·s throughout), so that the wave survives the flow as a rough coat (1/e at Λ ≈ 0.66 mm).
    paint["clear_coat"]["application"]["viscosity"] = [{"t_s": 0, "eta_pa_s": 1e4}, {"t_s": 600, "eta_pa_s": 1e4}]
    hm = glossmeter.height_map(z, dx_um=dx_um, unit="m")

    def with_texture(file):
        p = json.loads(json.dumps(paint))
        p["clear_coat"]["application"]["texture"] = {"file": file, "levelling": "mean"}
        return p

    from_map = glossmeter.measure(with_texture(hm), GEOMETRIES)
    assert all(r["value"] is not None for r in from_map)
    assert values(from_map) == values(glossmeter.measure(with_texture(str(tmp_path / "wave.gsf")), GEOMETRIES))
    # The map is what is read: twice its amplitude levels to a rougher coat.
    rougher = glossmeter.measure(with_texture(glossmeter.height_map(2 * z, dx_um=dx_um, unit="m")), GEOMETRIES)
    assert rougher[0]["value"] < from_map[0]["value"]
