"""Shared fixtures of the Python tests: paths into the repository and NumPy versions of library models."""
import os
import pathlib

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
RECIPES = ROOT / "fixtures" / "recipes"


@pytest.fixture
def root():
    return ROOT


def fresnel_dielectric(cos_i, n):
    """Unpolarised Fresnel reflectance of a dielectric interface (air → n), Born & Wolf §1.5."""
    cos_i = np.clip(cos_i, 0.0, 1.0)
    sin_t2 = (1.0 - cos_i**2) / n**2
    cos_t = np.sqrt(np.maximum(0.0, 1.0 - sin_t2))
    rs = (cos_i - n * cos_t) / (cos_i + n * cos_t)
    rp = (n * cos_i - cos_t) / (n * cos_i + cos_t)
    return 0.5 * (rs**2 + rp**2)


def half_vector(wi, wo):
    h = wi + wo
    return h / np.linalg.norm(h, axis=1, keepdims=True)


def beckmann_d(h, m):
    """Beckmann NDF D(h) = exp(−tan²θh/m²) / (π m² cos⁴θh) (Walter et al. 2007, Eq. 25)."""
    c2 = h[:, 2] ** 2
    t2 = (1.0 - c2) / c2
    return np.exp(-t2 / m**2) / (np.pi * m**2 * c2**2)


def ggx_d(h, a):
    """GGX NDF D(h) = α² / (π cos⁴θh (α² + tan²θh)²) (Walter et al. 2007, Eq. 33)."""
    c2 = h[:, 2] ** 2
    t2 = (1.0 - c2) / c2
    return a**2 / (np.pi * c2**2 * (a**2 + t2) ** 2)


def vcavity_g(wi, wo, h):
    """Cook & Torrance (1982) V-cavity masking–shadowing."""
    k = 2.0 * h[:, 2]
    oh = np.sum(wo * h, axis=1)
    ih = np.sum(wi * h, axis=1)
    return np.minimum(1.0, np.minimum(k * wo[:, 2] / oh, k * wi[:, 2] / ih))


def microfacet_vcavity(distribution, alpha, n):
    """f_r = F(ωi·h) D(h) G(ωi, ωo) / (4 cos θi cos θo): the library's `microfacet` model with
    `"shadowing": "v-cavity"`, written independently in NumPy."""
    d = beckmann_d if distribution == "beckmann" else ggx_d

    def f(wi, wo):
        h = half_vector(wi, wo)
        return (
            fresnel_dielectric(np.sum(wi * h, axis=1), n)
            * d(h, alpha)
            * vcavity_g(wi, wo, h)
            / (4.0 * wi[:, 2] * wo[:, 2])
        )

    return f


def cli_binary():
    """The release CLI if it has been built (`.ci/run` builds it before pytest), else None."""
    exe = os.environ.get("GLOSSMETER_BIN") or str(ROOT / "target" / "release" / "glossmeter")
    return exe if os.path.exists(exe) else None
