#!/usr/bin/env python3
"""SciPy / hcubature baselines for the glossmeter benchmarks B1–B4 (issue 4), run by hand.

The same integrands as benches/integrators/, re-implemented here: the specimen flux through the gloss
receptor,

    Φ = ∫ dp_s dq_s ∫ dp_r dq_r  f(ωi, ωo) cos θi cos θo (1+p_s²+q_s²)^(-3/2) (1+p_r²+q_r²)^(-3/2),

over the raw 4-D box of the two stops (tangent coordinates), with f the Lambertian 0.5/π (B1) or a
dielectric (n = 1.5) microfacet BRDF F(ωi·h) D(h) G / (4 cos θi cos θo) with Smith height-correlated G
(Beckmann Λ through erfc, GGX Λ without cancellation) — the same formulas as `BenchMicrofacet` in the bench.
The geometry numbers are read from standards/astm-d523-*.json (angle, source and gloss-receptor sizes).

Methods: scipy.integrate.nquad (iterated QUADPACK), scipy.integrate.cubature (rule genz-malik) and the C
hcubature of Steven G. Johnson through PyPI `cubature` (if installed), at relative tolerances 1e-3, 1e-4,
1e-6, each run capped at CAP seconds (nquad, scipy cubature: an exception raised from the integrand;
hcubature: maxEval). After a capped run the tighter tolerances of that method and case are skipped.

Reference values: our engine at rtol 1e-12 (B2–B4) and Lambert's closed form (B1), hard-coded below from
the output of `cargo bench --bench integrators` (the "References" list of bench/results/latest.md);
override with --ref B2=3.555e-7 etc.

Usage: /tmp/venv/bin/python bench/scipy_baselines.py [--cap 60] [--cases B1,B2] [--ref B2=...]
"""
import argparse
import json
import math
import os
import platform
import sys
import time

import numpy as np
import scipy
from scipy import integrate
from scipy.special import erfc

try:
    from cubature import cubature as hcubature
except ImportError:  # pragma: no cover
    hcubature = None

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# Our engine (rtol 1e-12) / closed form, from benches/integrators/ output (see docstring).
REFERENCE = {
    "B1": 3.549063401989875e-7,  # closed form (Lambert's polygon formula)
    "B2": 3.555078509693765e-7,  # our engine at rtol 1e-12 (est. rel. err 5e-13)
    "B3": 2.160813804305120e-5,  # our engine at rtol 1e-12 (est. rel. err 5e-13)
    "B4": 4.026407581361105e-7,  # our engine at rtol 1e-12 (est. rel. err 5e-13)
}

CASES = {
    "B1": dict(model="lambert", albedo=0.5, geometry="astm-d523-60"),
    "B2": dict(model="beckmann", alpha=0.1, n=1.5, geometry="astm-d523-20"),
    "B3": dict(model="beckmann", alpha=1e-4, n=1.5, geometry="astm-d523-20"),
    "B4": dict(model="ggx", alpha=0.3, n=1.5, geometry="astm-d523-85"),
}


def geometry(gid):
    """(theta, source stop, gloss receptor stop) with stops as (p0, p1, q0, q1), as Stop::from_angles."""
    with open(os.path.join(ROOT, "standards", gid + ".json")) as fh:
        g = json.load(fh)
    theta = math.radians(g["angle_deg"]["value"])

    def stop(inp, perp, off):
        inp, perp, off = math.radians(inp), math.radians(perp), math.radians(off)
        return (math.tan(off - inp / 2), math.tan(off + inp / 2), -math.tan(perp / 2), math.tan(perp / 2))

    src = g["source"]
    source = stop(src["in_plane_deg"]["value"], src["perpendicular_deg"]["value"], 0.0)
    rec = next(r for r in g["receptors"] if r["name"] == "gloss")
    receptor = stop(rec["in_plane_deg"]["value"], rec["perpendicular_deg"]["value"], rec["offset_deg"]["value"])
    return theta, source, receptor


def fr_dielectric(c, eta):
    """Unpolarised Fresnel reflectance, vectorised (Born & Wolf; eta > 1 so no TIR here)."""
    c = np.clip(c, 0.0, 1.0)
    st2 = (1.0 - c * c) / (eta * eta)
    ct = np.sqrt(np.maximum(0.0, 1.0 - st2))
    rs = (c - eta * ct) / (c + eta * ct)
    rp = (eta * c - ct) / (eta * c + ct)
    return 0.5 * (rs * rs + rp * rp)


def make_integrand(case):
    """Vectorised f(x) for x of shape (npt, 4) → shape (npt,)."""
    theta, _, _ = geometry(case["geometry"])
    s, c = math.sin(theta), math.cos(theta)

    def dirs(ps, qs, pr, qr):
        ns = np.sqrt(1 + ps * ps + qs * qs)
        nr = np.sqrt(1 + pr * pr + qr * qr)
        wi = np.stack([(-s + ps * c) / ns, qs / ns, (c + ps * s) / ns])
        wo = np.stack([(s + pr * c) / nr, qr / nr, (c - pr * s) / nr])
        return wi, wo, 1.0 / ns**3, 1.0 / nr**3

    if case["model"] == "lambert":
        rho = case["albedo"]

        def f(x):
            wi, wo, ds, dr = dirs(x[:, 0], x[:, 1], x[:, 2], x[:, 3])
            ok = (wi[2] > 0) & (wo[2] > 0)
            return np.where(ok, rho / math.pi * wi[2] * wo[2] * ds * dr, 0.0)

        return f

    alpha, eta, ggx = case["alpha"], case["n"], case["model"] == "ggx"
    a2 = alpha * alpha

    def lam(w):
        t2 = (w[0] ** 2 + w[1] ** 2) / (w[2] ** 2)
        if ggx:
            xx = a2 * t2
            return 0.5 * xx / (np.sqrt(1 + xx) + 1)
        with np.errstate(divide="ignore", invalid="ignore"):
            a = 1.0 / (alpha * np.sqrt(t2))
            v = 0.5 * (np.exp(-a * a) / (a * math.sqrt(math.pi)) - erfc(a))
        return np.where(t2 == 0, 0.0, np.nan_to_num(v))

    def f(x):
        wi, wo, ds, dr = dirs(x[:, 0], x[:, 1], x[:, 2], x[:, 3])
        h = wi + wo
        h = h / np.linalg.norm(h, axis=0)
        t2 = (h[0] ** 2 + h[1] ** 2) / (h[2] ** 2)
        c4 = h[2] ** 4
        if ggx:
            k = a2 + t2
            d = a2 / (math.pi * c4 * k * k)
        else:
            d = np.exp(-t2 / a2) / (math.pi * a2 * c4)
        g = 1.0 / (1.0 + lam(wi) + lam(wo))
        fr = fr_dielectric(np.sum(wi * h, axis=0), eta)
        val = fr * d * g / 4.0 * ds * dr  # f·cosθi·cosθo with f = F D G / (4 cosθi cosθo)
        return np.where((wi[2] > 0) & (wo[2] > 0), val, 0.0)

    return f


def make_scalar_integrand(case):
    """The same integrand for scalar arguments with `math` (numpy per call is ~50× slower for nquad)."""
    theta, _, _ = geometry(case["geometry"])
    s, c = math.sin(theta), math.cos(theta)
    lambert = case["model"] == "lambert"
    alpha, eta = case.get("alpha", 0.0), case.get("n", 1.0)
    ggx = case["model"] == "ggx"
    a2 = alpha * alpha

    def lam(x, y, z):
        t2 = (x * x + y * y) / (z * z)
        if t2 == 0.0:
            return 0.0
        if ggx:
            xx = a2 * t2
            return 0.5 * xx / (math.sqrt(1 + xx) + 1)
        a = 1.0 / (alpha * math.sqrt(t2))
        return 0.5 * (math.exp(-a * a) / (a * math.sqrt(math.pi)) - math.erfc(a))

    def f(ps, qs, pr, qr):
        ns = math.sqrt(1 + ps * ps + qs * qs)
        nr = math.sqrt(1 + pr * pr + qr * qr)
        ix, iy, iz = (-s + ps * c) / ns, qs / ns, (c + ps * s) / ns
        ox, oy, oz = (s + pr * c) / nr, qr / nr, (c - pr * s) / nr
        if iz <= 0 or oz <= 0:
            return 0.0
        dens = 1.0 / (ns * ns * ns * nr * nr * nr)
        if lambert:
            return case["albedo"] / math.pi * iz * oz * dens
        hx, hy, hz = ix + ox, iy + oy, iz + oz
        hn = math.sqrt(hx * hx + hy * hy + hz * hz)
        hx, hy, hz = hx / hn, hy / hn, hz / hn
        t2 = (hx * hx + hy * hy) / (hz * hz)
        c4 = hz ** 4
        if ggx:
            k = a2 + t2
            d = a2 / (math.pi * c4 * k * k)
        else:
            d = math.exp(-t2 / a2) / (math.pi * a2 * c4)
        g = 1.0 / (1.0 + lam(ix, iy, iz) + lam(ox, oy, oz))
        ci = min(1.0, max(0.0, ix * hx + iy * hy + iz * hz))
        ct = math.sqrt(max(0.0, 1.0 - (1.0 - ci * ci) / (eta * eta)))
        rs = (ci - eta * ct) / (ci + eta * ct)
        rp = (eta * ci - ct) / (eta * ci + ct)
        return 0.5 * (rs * rs + rp * rp) * d * g / 4.0 * dens

    return f


class Capped(Exception):
    pass


def run_nquad(f, box, rtol, cap):
    """f: the scalar integrand."""
    n = [0]
    t0 = time.perf_counter()

    def g(a, b, c_, d):
        n[0] += 1
        if (n[0] & 1023) == 0 and time.perf_counter() - t0 > cap:
            raise Capped()
        return f(a, b, c_, d)

    ranges = [(box[0], box[1]), (box[2], box[3]), (box[4], box[5]), (box[6], box[7])]
    try:
        v, e = integrate.nquad(g, ranges, opts={"epsrel": rtol, "epsabs": 0.0, "limit": 200})
        return v, e, n[0], time.perf_counter() - t0, "ok"
    except Capped:
        return float("nan"), float("nan"), n[0], time.perf_counter() - t0, f"capped at {cap:.0f} s"


def run_scipy_cubature(f, box, rtol, cap):
    n = [0]
    t0 = time.perf_counter()

    def g(x):
        n[0] += x.shape[0]
        if time.perf_counter() - t0 > cap:
            raise Capped()
        return f(x)

    a = [box[0], box[2], box[4], box[6]]
    b = [box[1], box[3], box[5], box[7]]
    try:
        r = integrate.cubature(g, a, b, rule="genz-malik", rtol=rtol, atol=0.0, max_subdivisions=10**9)
        return float(r.estimate), float(r.error), n[0], time.perf_counter() - t0, r.status
    except Capped:
        return float("nan"), float("nan"), n[0], time.perf_counter() - t0, f"capped at {cap:.0f} s"


def run_hcubature(f, box, rtol, cap, max_eval):
    n = [0]
    t0 = time.perf_counter()

    def g(x):
        n[0] += x.shape[0]
        return f(x)

    xmin = np.array([box[0], box[2], box[4], box[6]])
    xmax = np.array([box[1], box[3], box[5], box[7]])
    v, e = hcubature(g, 4, 1, xmin, xmax, relerr=rtol, abserr=0.0, maxEval=max_eval, vectorized=True)
    status = "ok" if e[0] <= rtol * abs(v[0]) else f"maxEval {max_eval:.0e} reached"
    return float(v[0]), float(e[0]), n[0], time.perf_counter() - t0, status


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cap", type=float, default=60.0, help="seconds per run (nquad, scipy cubature)")
    ap.add_argument("--max-eval", type=float, default=3e7, help="hcubature maxEval")
    ap.add_argument("--cases", default="B1,B2,B3,B4")
    ap.add_argument("--rtols", default="1e-3,1e-4,1e-6")
    ap.add_argument("--ref", action="append", default=[], help="override a reference, e.g. B2=3.555e-7")
    args = ap.parse_args()
    for r in args.ref:
        k, v = r.split("=")
        REFERENCE[k] = float(v)
    rtols = [float(x) for x in args.rtols.split(",")]
    print(f"# SciPy / hcubature baselines, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")
    print(f"# Python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}, "
          f"hcubature (PyPI cubature) {'available' if hcubature else 'NOT installed'}; "
          f"load {os.getloadavg()}; {os.cpu_count()} cores; cap {args.cap:.0f} s per run")
    print("# references: " + ", ".join(f"{k} = {v:.15e}" for k, v in REFERENCE.items()))
    print()
    print("| case | method | rtol | value | claimed err (rel) | actual rel. err | evaluations | time | status |")
    print("|---|---|---|---|---|---|---|---|---|")
    for cid in args.cases.split(","):
        case = CASES[cid]
        f = make_integrand(case)
        _, s, r = geometry(case["geometry"])
        box = (s[0], s[1], s[2], s[3], r[0], r[1], r[2], r[3])
        ref = REFERENCE[cid]
        fs = make_scalar_integrand(case)
        x0 = np.array([[0.3 * box[1], 0.2 * box[3], -0.25 * box[5], 0.1 * box[7]]])
        assert abs(fs(*x0[0]) - f(x0)[0]) <= 1e-12 * abs(f(x0)[0]), "scalar and vector integrands differ"
        # Sanity: a 24⁴ midpoint grid (cheap, vectorised) next to the reference.
        m = 24
        axes = [box[2 * k] + (box[2 * k + 1] - box[2 * k]) * (np.arange(m) + 0.5) / m for k in range(4)]
        pts = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 4)
        vol = np.prod([box[2 * k + 1] - box[2 * k] for k in range(4)])
        grid = float(np.sum(f(pts)) * vol / m**4)
        print(f"| {cid} | numpy midpoint grid 24⁴ (sanity) | – | {grid:.10e} | – | {abs(grid - ref) / ref:.1e} | {m**4} | – | – |")
        methods = [("nquad", lambda rt: run_nquad(fs, box, rt, args.cap)),
                   ("scipy cubature genz-malik", lambda rt: run_scipy_cubature(f, box, rt, args.cap))]
        if hcubature is not None:
            methods.append(("hcubature (C)", lambda rt: run_hcubature(f, box, rt, args.cap, int(args.max_eval))))
        for name, run in methods:
            for rt in rtols:
                v, e, n, dt, status = run(rt)
                rel = abs(v - ref) / ref if v == v else float("nan")
                claimed = e / abs(v) if v == v and v != 0 else float("nan")
                flag = ""
                if v == v and rel > 10 * max(claimed, rt) and status in ("ok", "converged"):
                    flag = " **claims convergence, silently wrong**"
                print(f"| {cid} | {name} | {rt:.0e} | {v:.10e} | {claimed:.1e} | {rel:.1e} | {n} | {dt:.3g} s | {status}{flag} |",
                      flush=True)
                if status.startswith("capped") or status.startswith("maxEval") or status == "not_converged":
                    break
    return 0


if __name__ == "__main__":
    sys.exit(main())
