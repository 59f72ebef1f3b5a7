"""measure_brdf: a Python BRDF through the apertures, against the same model in the library."""
import re

import numpy as np
import pytest

import glossmeter
from conftest import fresnel_dielectric, microfacet_vcavity

D523 = ["astm-d523-20", "astm-d523-60", "astm-d523-85"]


def values(readings):
    return {(r["geometry"], r["name"]): r for r in readings}


def assert_agree(py, rust, rtol):
    """Readings agree within both error estimates plus rtol (the two integrands differ in the last bits)."""
    a, b = values(py), values(rust)
    assert a.keys() == b.keys()
    for k in a:
        va, vb = a[k]["value"], b[k]["value"]
        tol = a[k]["error_estimate"] + b[k]["error_estimate"] + rtol * abs(vb)
        assert abs(va - vb) <= tol, (k, va, vb, tol)


class Counting:
    """Wraps f and records the batch sizes it is called with."""

    def __init__(self, f):
        self.f, self.sizes = f, []

    def __call__(self, wi, wo):
        assert wi.dtype == np.float64 and wi.shape == wo.shape and wi.shape[1] == 3
        self.sizes.append(len(wi))
        return self.f(wi, wo)


def test_lambert_reads_like_the_recipe():
    f = Counting(lambda wi, wo: np.full(len(wi), 0.5 / np.pi))
    py = glossmeter.measure_brdf(f, lobes=[], rtol=1e-8)
    rust = glossmeter.measure({"model": "lambert", "albedo": 0.5}, rtol=1e-8)
    assert_agree(py, rust, 1e-7)


def test_the_evaluation_budget_reaches_the_plan():
    # measure_brdf's max_evals is the request's (as measure's): a budget far below what a 10⁻⁸ tolerance needs
    # leaves the readings unconverged, each within it, and the same budget of a recipe gives the same verdicts.
    recipe = {"model": "microfacet", "distribution": "ggx", "roughness": 0.05, "ior": 1.5, "shadowing": "v-cavity"}
    f = microfacet_vcavity("ggx", 0.05, 1.5)
    full = glossmeter.measure_brdf(f, geometries=D523, rtol=1e-8, lobes=[0.05], timing=False)
    tight = glossmeter.measure_brdf(f, geometries=D523, rtol=1e-8, lobes=[0.05], timing=False, max_evals=200)
    assert all(r["converged"] for r in full)
    assert not any(r["converged"] for r in tight), tight
    assert sum(r["evaluations"] for r in tight) < sum(r["evaluations"] for r in full)
    rust = glossmeter.measure(recipe, geometries=D523, rtol=1e-8, timing=False, max_evals=200)
    assert [r["converged"] for r in rust] == [r["converged"] for r in tight]


@pytest.mark.parametrize("hint", [True, False])
def test_ggx_vcavity_dielectric_with_and_without_hint(hint):
    recipe = {"model": "microfacet", "distribution": "ggx", "roughness": 0.05, "ior": 1.5, "shadowing": "v-cavity"}
    f = Counting(microfacet_vcavity("ggx", 0.05, 1.5))
    py = glossmeter.measure_brdf(f, geometries=D523, rtol=1e-6, lobes=[0.05] if hint else None)
    rust = glossmeter.measure(recipe, geometries=D523, rtol=1e-6)
    assert_agree(py, rust, 1e-6)
    notes = [r.get("note", "") for r in py]
    if hint:
        assert not any("probed" in n for n in notes)
    else:
        assert all("lobe probed" in n for n in notes), notes


def test_a_narrow_lobe_without_hint_is_found_not_zero():
    """A Beckmann lobe of width 1e-4 (far narrower than any aperture) and no hint: the probe finds it."""
    recipe = {"model": "microfacet", "distribution": "beckmann", "roughness": 1e-4, "ior": 1.5,
              "shadowing": "v-cavity"}
    f = microfacet_vcavity("beckmann", 1e-4, 1.5)
    py = glossmeter.measure_brdf(f, geometries=D523, rtol=1e-6)
    rust = glossmeter.measure(recipe, geometries=D523, rtol=1e-6)
    for r in py:
        assert r["value"] > 10.0, r  # a near-mirror: tens of GU, not 0
        assert "lobe probed" in r["note"]
        # the probe reports a width not wider than the lobe (it may be a ladder step narrower)
        m = float(re.search(r"slope width ([0-9.]+e[-+]?[0-9]+)", r["note"]).group(1))
        assert 1e-4 / 2 < m <= 1e-4 * 1.001, r["note"]
    assert_agree(py, rust, 1e-6)


def test_without_the_probe_a_narrow_lobe_is_missed():
    """Why the probe exists: declared smooth (lobes=[]), the same lobe reads as (nearly) nothing."""
    f = microfacet_vcavity("beckmann", 1e-4, 1.5)
    py = glossmeter.measure_brdf(f, geometries=["astm-d523-60"], rtol=1e-4, lobes=[])
    rust = glossmeter.measure({"model": "microfacet", "distribution": "beckmann", "roughness": 1e-4, "ior": 1.5,
                               "shadowing": "v-cavity"}, geometries=["astm-d523-60"], rtol=1e-4)
    assert py[0]["value"] < 0.5 * rust[0]["value"]


def test_delta_component_as_a_callable_and_as_a_number():
    rust = glossmeter.measure({"model": "smooth-dielectric", "ior": 1.5}, geometries=D523, rtol=1e-8)
    zero = lambda wi, wo: np.zeros(len(wi))  # noqa: E731
    py = glossmeter.measure_brdf(zero, geometries=D523, rtol=1e-8, lobes=[],
                                 delta=lambda wi: fresnel_dielectric(wi[:, 2], 1.5))
    assert_agree(py, rust, 1e-8)
    # a constant R = 1 mirror reads 100 GU × 1 / R_standard(θ) at each angle
    py1 = glossmeter.measure_brdf(zero, geometries=["astm-d523-60"], lobes=[], delta=1.0)
    assert py1[0]["value"] > 100.0


def test_rgb_and_spectral_samples():
    grey = glossmeter.measure_brdf(lambda wi, wo: np.full(len(wi), 0.3), geometries=["astm-d523-60"], lobes=[],
                                   timing=False)
    rgb = glossmeter.measure_brdf(lambda wi, wo: np.full((len(wi), 3), 0.3), geometries=["astm-d523-60"],
                                  lobes=[], timing=False)
    assert rgb[0]["value"] == pytest.approx(grey[0]["value"], rel=1e-12)
    with pytest.raises(ValueError, match="wavelengths"):
        glossmeter.measure_brdf(lambda wi, wo: np.full((len(wi), 5), 0.3), lobes=[])
    five = glossmeter.measure_brdf(lambda wi, wo: np.full((len(wi), 5), 0.3), geometries=["astm-d523-60"],
                                   lobes=[], wavelengths=[450, 500, 550, 600, 650], timing=False)
    assert five[0]["value"] == pytest.approx(grey[0]["value"], rel=1e-12)


class MyError(Exception):
    pass


def test_an_exception_in_f_propagates_as_itself():
    raised = []
    calls = [0]

    def f(wi, wo):
        calls[0] += 1
        if calls[0] > 2:
            e = MyError("boom from f")
            raised.append(e)
            raise e
        return np.full(len(wi), 0.1)

    with pytest.raises(MyError, match="boom from f") as info:
        glossmeter.measure_brdf(f, lobes=[])
    assert info.value is raised[0]
    assert calls[0] == 3  # not called again after it raised

    def g(wi, wo):
        raise KeyError("on the first call")

    with pytest.raises(KeyError):
        glossmeter.measure_brdf(g)


def test_bad_values_from_f_are_value_errors():
    with pytest.raises(ValueError, match="shape"):
        glossmeter.measure_brdf(lambda wi, wo: np.zeros(len(wi) + 1), lobes=[])
    with pytest.raises(ValueError, match="NaN"):
        glossmeter.measure_brdf(lambda wi, wo: np.full(len(wi), np.nan), lobes=[])
    with pytest.raises(ValueError, match="≥ 0"):
        glossmeter.measure_brdf(lambda wi, wo: -np.ones(len(wi)), lobes=[])
    with pytest.raises(TypeError, match="callable"):
        glossmeter.measure_brdf(42)
    with pytest.raises(ValueError, match=r"lobes\[0\]"):
        glossmeter.measure_brdf(lambda wi, wo: np.zeros(len(wi)), lobes=[-1.0])
    with pytest.raises(ValueError, match="unknown key"):
        glossmeter.measure_brdf(lambda wi, wo: np.zeros(len(wi)), lobes=[{"slope": 0.1, "width": 2}])
    with pytest.raises(ValueError, match="unknown geometry"):
        glossmeter.measure_brdf(lambda wi, wo: np.zeros(len(wi)), geometries=["nope"])
    # float32 and lists are accepted (converted to float64)
    r = glossmeter.measure_brdf(lambda wi, wo: np.full(len(wi), 0.1, dtype=np.float32), lobes=[],
                                geometries="astm-d523-60")
    assert r[0]["value"] > 0


def test_f_is_called_in_batches():
    f = Counting(lambda wi, wo: np.full(len(wi), 0.5 / np.pi))
    glossmeter.measure_brdf(f, geometries=["astm-d523-60"], lobes=[0.05])
    points = sum(f.sizes)
    assert points / len(f.sizes) >= 16, (len(f.sizes), points)
