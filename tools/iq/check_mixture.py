#!/usr/bin/env python3
"""The D523 glosses of check_85.py §3's best two-scale surface, with the Monte-Carlo standard error.

tests/brdf_models.rs (the slope-mixture test) compares glossmeter's `microfacet` recipe with `populations` against
these values. The optics are check_85.py's own (imported: exact unpolarised Fresnel, the D523 stops read from
standards/, 40 000 rays per geometry with the same seeds, so the `per-population G` column is check_85.py §3's
numbers at full precision); no glossmeter code is used.

Surface: a fraction w = 0.0675 of the facets with Gaussian slopes of rms s2 = 3.0° per axis, the rest with
s1 = 0.30°, index n from 60° = 88.3 (check_85.py §3's bisection). Beckmann roughness m = sqrt(2) tan(s) (the
Beckmann slope distribution exp(-(x² + y²)/m²)/(π m²) has rms slope m/sqrt(2) per axis).

Two shadowing forms (both with Λ at the macro angle θ, as check_85.py):
* per-population G: each population with its own Smith Λ (check_85.py §3: patches, each shadowed by itself);
* mixture G: Λ = (1 - w) Λ1 + w Λ2 for both (Smith's Λ of the mixture's slope distribution, Heitz 2014
  Eq. 72, which glossmeter uses; docs/optics.md §4.1).
The standard error is that of the ratio estimator (flux / standard's flux over the same rays):
se = 100 sqrt(Var(x - R y) / N) / mean(y), x and y the per-ray contributions.

Run by hand: python3 tools/iq/check_mixture.py (about a minute); output kept in check_mixture.out.txt.
"""
import importlib.util
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location("check_85", os.path.join(HERE, "check_85.py"))
c85 = importlib.util.module_from_spec(spec)
spec.loader.exec_module(c85)

S1, S2, W = 0.30, 3.0, 0.0675


def contributions(meter, s, n):
    """Per-ray flux into the receptor (no shadowing factor) of slope scale s (a slope, not degrees)."""
    out = []
    for d, w, zx, zy in meter.rays:
        m = c85.norm((-s * zx, -s * zy, 1.0))
        c = c85.dot(d, m)
        v = 0.0
        if c > 0.0:
            r = tuple(2.0 * c * m[k] - d[k] for k in range(3))
            a = c85.dot(r, meter.r_axis)
            if a > 0.0 and abs(c85.dot(r, meter.r_par) / a) <= meter.rp and abs(c85.dot(r, meter.perp) / a) <= meter.rq:
                v = w * (c / m[2] / d[2]) * c85.fresnel(c, n)
        out.append(v)
    return out


def ratio(x, y):
    n = len(x)
    mx, my = sum(x) / n, sum(y) / n
    r = mx / my
    var = sum((a - r * b) ** 2 for a, b in zip(x, y)) / (n - 1)
    return 100.0 * r, 100.0 * math.sqrt(var / n) / my


def main():
    meters = {a: c85.Meter(a, 40000, 28 + a) for a in (20, 60, 85)}
    t1, t2 = math.tan(math.radians(S1)), math.tan(math.radians(S2))
    std = {a: contributions(meters[a], 0.0, c85.N_STD) for a in meters}

    def lam(a, s):
        return c85.smith_lambda(1.0 / math.tan(meters[a].theta), s)

    def gloss(a, n, mixture_g):
        c1, c2 = contributions(meters[a], t1, n), contributions(meters[a], t2, n)
        l1, l2 = lam(a, t1), lam(a, t2)
        if mixture_g:
            lm = (1.0 - W) * l1 + W * l2
            g1 = g2 = 1.0 / (1.0 + 2.0 * lm)
        else:
            g1, g2 = 1.0 / (1.0 + 2.0 * l1), 1.0 / (1.0 + 2.0 * l2)
        x = [(1.0 - W) * g1 * u + W * g2 * v for u, v in zip(c1, c2)]
        return ratio(x, std[a])

    # n from 60° = 88.3 with the per-population G, as check_85.py §3 (bisection on [1.3, 1.8], 40 steps).
    lo, hi = 1.3, 1.8
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if gloss(60, mid, False)[0] < 88.3 else (lo, mid)
    n = 0.5 * (lo + hi)
    print(f"# output of: python3 tools/iq/check_mixture.py (standard library only; deterministic: check_85.py's seeds)")
    print(f"surface: w = {W}, s1 = {S1} deg, s2 = {S2} deg per axis; Beckmann m1 = {math.sqrt(2) * t1!r}, "
          f"m2 = {math.sqrt(2) * t2!r}; n = {n!r}")
    print("geometry  per-population G   (se)   mixture G   (se)   [GU]")
    for a in (20, 60, 85):
        g, se = gloss(a, n, False)
        gm, sem = gloss(a, n, True)
        print(f"{a:>4}      {g:10.4f}   {se:8.4f}   {gm:10.4f}   {sem:8.4f}")
    print("Lambda at the macro angle: " + ", ".join(
        f"{a}: s1 {lam(a, t1):.3e}, s2 {lam(a, t2):.3e}" for a in (20, 60, 85)))


if __name__ == "__main__":
    main()
