"""measure(), standards(), geometry() and errors: the bindings against the library and the CLI."""
import json
import pathlib
import subprocess
import struct

import pytest

import glossmeter
from conftest import RECIPES, ROOT, cli_binary

FIELDS = {"geometry", "name", "quantity", "value", "unit", "error_estimate", "evaluations", "converged"}


def bits(x):
    return struct.pack(">d", x).hex()


def test_recipe_as_path_dict_and_json_string_read_the_same():
    path = RECIPES / "black-glass.json"
    text = path.read_text()
    a = glossmeter.measure(str(path), timing=False)
    b = glossmeter.measure(path, timing=False)  # os.PathLike
    c = glossmeter.measure(json.loads(text), timing=False)
    d = glossmeter.measure(text, timing=False)
    assert a == b == c == d
    assert [r["geometry"] for r in a][:3] == ["astm-d523-20", "astm-d523-60", "astm-d523-85"]
    for r in a:
        assert FIELDS <= set(r) and "seconds" not in r
    assert all("seconds" in r for r in glossmeter.measure(path, geometries=["astm-d523-60"]))


@pytest.mark.parametrize("fixture", ["bench-b2-beckmann-0.1", "rough-dielectric-ggx-vcavity", "grey-lambert"])
def test_readings_are_the_golden_bits(fixture):
    """The same bits as tests/golden.rs stores for the CLI's engine, on every builtin geometry."""
    golden = json.loads((ROOT / "fixtures" / "golden" / "readings.json").read_text())
    ids = [g["id"] for g in glossmeter.standards()]
    readings = glossmeter.measure(RECIPES / f"{fixture}.json", geometries=ids, rtol=1e-6, timing=False)
    checked = 0
    for r in readings:
        key = f"{fixture}|{r['geometry']}|{r['name']}"
        if key not in golden:
            continue
        value, err, evals, conv = golden[key].split()
        assert bits(r["value"]) == value, key
        assert bits(r["error_estimate"]) == err, key
        assert r["evaluations"] == int(evals) and str(r["converged"]).lower() == conv, key
        checked += 1
    assert checked == len(readings) > 10


def test_the_dicts_are_the_cli_json():
    exe = cli_binary()
    if exe is None:
        pytest.skip("the release CLI is not built (cargo build --release); .ci/run builds it first")
    path = RECIPES / "ward.json"
    out = subprocess.run([exe, "measure", str(path), "--format", "json", "--no-timing"], capture_output=True,
                         text=True, check=True)
    assert json.loads(out.stdout)["readings"] == glossmeter.measure(str(path), timing=False)


@pytest.mark.parametrize("rtol", [None, 1e-6])
def test_a_table_s_tolerance_is_chosen_as_the_command_line_chooses_it(rtol):
    # Without rtol a measured table is integrated to the tolerance its data uncertainty allows; a given rtol is
    # used as given, as `measure --rtol` uses it (docs/python.md, docs/accuracy.md §Data uncertainty).
    exe = cli_binary()
    if exe is None:
        pytest.skip("the release CLI is not built (cargo build --release); .ci/run builds it first")
    path = RECIPES.parent / "materials" / "rgl" / "beckmann-iso-32.json"
    args = [exe, "measure", str(path), "-g", "astm-d523-60", "--format", "json", "--no-timing"]
    if rtol is not None:
        args += ["--rtol", str(rtol)]
    out = subprocess.run(args, capture_output=True, text=True, check=True)
    assert json.loads(out.stdout)["readings"] == glossmeter.measure(str(path), "astm-d523-60", rtol, timing=False)


@pytest.mark.parametrize("fixture, ids, kwargs, flags", [
    ("rough-dielectric-ggx-vcavity", ["astm-d523-60", "astm-e430-30"], {"max_evals": 200, "rtol": 1e-9},
     ["--max-evals", "200", "--rtol", "1e-9"]),
    ("blue-metallic-spectral", ["astm-d523-60", "d8-sci"], {"illuminant": "A", "observer": "2"},
     ["--illuminant", "A", "--observer", "2"]),
    ("blue-metallic-spectral", ["astm-d523-60", "d8-sci"], {"rtol": 1e-4, "max_seconds": 600},
     ["--rtol", "1e-4", "--max-seconds", "600"]),
])
def test_measure_s_keywords_are_the_command_line_s_flags(fixture, ids, kwargs, flags):
    # measure converts its keywords into the library's MeasureRequest, as the command line converts its flags
    # (docs/python.md §API): the same request gives the same readings, to the bit.
    exe = cli_binary()
    if exe is None:
        pytest.skip("the release CLI is not built (cargo build --release); .ci/run builds it first")
    path = RECIPES / f"{fixture}.json"
    args = [exe, "measure", str(path), "-g", ids[0], "-g", ids[1], "--format", "json", "--no-timing", *flags]
    out = subprocess.run(args, capture_output=True, text=True)
    assert out.returncode in (0, 1), out.stderr
    readings = glossmeter.measure(str(path), ids, timing=False, **kwargs)
    assert json.loads(out.stdout)["readings"] == readings
    # Each keyword reaches the plan: a budget of 200 evaluations an integral leaves 10⁻⁹ readings unconverged
    # (without it they converge), and illuminant A with the 2° observer moves the colour.
    if "max_evals" in kwargs:
        default = glossmeter.measure(str(path), ids, timing=False, rtol=kwargs["rtol"])
        assert all(r["converged"] for r in default) and not any(r["converged"] for r in readings), readings
    if "illuminant" in kwargs:
        default = glossmeter.measure(str(path), ids, timing=False)
        colour = [(r["name"], r["value"]) for r in readings if r["geometry"] == "d8-sci"]
        assert colour and colour != [(r["name"], r["value"]) for r in default if r["geometry"] == "d8-sci"]


@pytest.mark.parametrize("kwargs, exc, words", [
    ({"max_evals": 0}, ValueError, ["`max_evals`", "at least 1"]),
    ({"max_evals": 1.5}, TypeError, ["max_evals:", "whole number", "got float"]),
    ({"max_seconds": -1}, ValueError, ["`max_seconds`", "≥ 0"]),
    ({"max_seconds": "10"}, TypeError, ["max_seconds:", "got str"]),
    ({"illuminant": "D99"}, ValueError, ["D99"]),
    ({"observer": 10}, TypeError, ["observer:", "got int"]),
    ({"rtol": 2.0}, ValueError, ["`rtol`", "(0, 1)"]),
])
def test_measure_s_request_refuses_a_bad_keyword_naming_it(kwargs, exc, words):
    with pytest.raises(exc) as e:
        glossmeter.measure({"model": "lambert", "albedo": 0.5}, "astm-d523-60", **kwargs)
    assert all(w in str(e.value) for w in words), str(e.value)


def cli_error(args):
    exe = cli_binary()
    if exe is None:
        return None
    p = subprocess.run([exe, *args], capture_output=True, text=True)
    assert p.returncode == 2
    return p.stderr.strip().removeprefix("error: ")


def test_bad_input_raises_value_error_with_the_cli_message(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"model": "microfacet", "distribution": "beckmann", "roughness": -1, "ior": 1.5}')
    with pytest.raises(ValueError) as e:
        glossmeter.measure(str(bad))
    msg = str(e.value)
    assert "roughness" in msg and str(bad) in msg
    expected = cli_error(["measure", str(bad)])
    if expected is not None:
        assert msg == expected
    with pytest.raises(ValueError, match="roughness"):
        glossmeter.measure({"model": "microfacet", "distribution": "beckmann", "roughness": -1, "ior": 1.5})
    with pytest.raises(ValueError, match="<string>"):
        glossmeter.measure('{"model": "lambert", "albedo": 0.5,')
    with pytest.raises(ValueError, match="model"):
        glossmeter.measure({"albedo": 0.5})


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -float("inf")])
def test_a_non_finite_number_in_a_dict_recipe_is_named_by_its_field(bad):
    recipe = {"model": "microfacet", "distribution": "ggx", "ior": 1.5,
              "populations": [{"roughness": 0.01}, {"weight": 0.5, "roughness": bad}]}
    with pytest.raises(ValueError) as e:
        glossmeter.measure(recipe)
    msg = str(e.value)
    assert "field `/populations/1/roughness`" in msg and "not a finite number" in msg, msg
    assert "malformed JSON" not in msg, msg
    with pytest.raises(ValueError, match="field `/albedo`"):
        glossmeter.measure({"model": "lambert", "albedo": bad})


def test_unknown_geometry_bad_rtol_and_missing_file():
    lam = {"model": "lambert", "albedo": 0.5}
    with pytest.raises(ValueError, match="unknown geometry id \"nope\"") as e:
        glossmeter.measure(lam, geometries=["nope"])
    expected = cli_error(["measure", str(RECIPES / "grey-lambert.json"), "-g", "nope"])
    if expected is not None:
        assert str(e.value) == expected
    with pytest.raises(ValueError, match="rtol"):
        glossmeter.measure(lam, rtol=0.0)
    with pytest.raises(ValueError, match="rtol"):
        glossmeter.measure(lam, rtol=float("nan"))
    with pytest.raises(FileNotFoundError, match="no-such-recipe.json"):
        glossmeter.measure("no-such-recipe.json")
    with pytest.raises(TypeError, match="recipe: expected a dict"):
        glossmeter.measure(42)


def test_a_panic_is_a_runtime_error_not_a_crash():
    with pytest.raises(RuntimeError, match="internal error"):
        glossmeter._glossmeter._panic()
    # the interpreter goes on working
    assert glossmeter.measure({"model": "lambert", "albedo": 0.5}, geometries="astm-d523-60")[0]["value"] > 0


def test_standards_and_one_geometry():
    all_ = glossmeter.standards()
    ids = [g["id"] for g in all_]
    for i in glossmeter.DEFAULT_GEOMETRIES:
        assert i in ids
    g = glossmeter.geometry("astm-d523-60")
    assert g == all_[ids.index("astm-d523-60")]
    assert g["angle_deg"]["value"] == 60 if isinstance(g["angle_deg"], dict) else g["angle_deg"] == 60
    assert "astm-d523-60" in glossmeter.describe_geometry("astm-d523-60")
    # a geometry given as a dict is validated like a file and measured like a builtin one
    lam = {"model": "lambert", "albedo": 0.5}
    assert glossmeter.measure(lam, geometries=[g], timing=False) == glossmeter.measure(
        lam, geometries=["astm-d523-60"], timing=False)
    broken = dict(g)
    del broken["angle_deg"]
    with pytest.raises(ValueError, match="angle_deg"):
        glossmeter.geometry(broken)


def test_schema_and_describe():
    assert "properties" in json.dumps(glossmeter.schema())
    assert "Beckmann" in glossmeter.describe(RECIPES / "bench-b2-beckmann-0.1.json") or "beckmann" in \
        glossmeter.describe(RECIPES / "bench-b2-beckmann-0.1.json").lower()


def test_a_huge_or_tiny_number_in_a_refusal_is_short():
    import numpy as np

    def f(wi, wo):
        return np.full(len(wi), 0.1)

    for bad in [1e308, -1e308]:
        with pytest.raises(ValueError) as e:
            glossmeter.measure_brdf(f, lobes=[bad], geometries=["astm-d523-60"])
        msg = str(e.value)
        assert "slope width" in msg and "0000000000" not in msg and len(msg) < 300, msg


def test_a_recipe_with_stated_uncertainties_gets_the_cli_prediction_uncertainty():
    """A recipe's `uncertainty` block gives every reading `prediction_uncertainty` and `uncertainty_budget`,
    as `glossmeter measure --format json` does (docs/python.md §measure); a recipe without one gives neither."""
    path = ROOT / "fixtures" / "uncertainty" / "semigloss-white.json"
    stated = {p for p in json.loads(path.read_text())["uncertainty"]}
    readings = glossmeter.measure(path, geometries=["astm-d523-20", "astm-d523-60"], timing=False)
    for r in readings:
        assert r["prediction_uncertainty"] > 0, r
        budget = r["uncertainty_budget"]
        assert {b["pointer"] for b in budget} == stated
        # u_pred² is the sum of the squared contributions (docs/instrument.md §The prediction's uncertainty).
        assert abs(sum(b["contribution"] ** 2 for b in budget) ** 0.5 - r["prediction_uncertainty"]) <= 1e-12 * r["prediction_uncertainty"]
    plain = glossmeter.measure(RECIPES / "semigloss-white.json", geometries=["astm-d523-60"], timing=False)
    assert "prediction_uncertainty" not in plain[0] and "uncertainty_budget" not in plain[0]
    exe = cli_binary()
    if exe is None:
        pytest.skip("the release CLI is not built (cargo build --release); .ci/run builds it first")
    out = subprocess.run([exe, "measure", str(path), "-g", "astm-d523-20", "-g", "astm-d523-60", "--format", "json",
                          "--no-timing"], capture_output=True, text=True, check=True)
    assert json.loads(out.stdout)["readings"] == readings
