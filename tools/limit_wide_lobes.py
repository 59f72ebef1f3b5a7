#!/usr/bin/env python3
"""The fewest evaluations a tensor Gauss–Legendre rule needs for lobes about as wide as the stops, measured
with code independent of the engine (issue 29 item 4; docs/performance.md § "Lobes as wide as the stops").

Integrand: the specimen flux through one receptor (docs/instrument.md §1.4),

    Φ = ∫ dp_s dq_s ∫ dp_r dq_r  f(ωi, ωo) cos θi cos θo (1+p_s²+q_s²)^(-3/2) (1+p_r²+q_r²)^(-3/2),

f = F(ωi·h) D(h) G / (4 cos θi cos θo), dielectric n = 1.5, Beckmann or GGX D (Walter et al. 2007 Eqs. 25,
33), Smith height-correlated G (Heitz 2014 Eq. 99; Beckmann Λ through erfc, GGX Λ = (√(1+α²tan²θ) − 1)/2),
re-implemented here with NumPy (after bench/scipy_baselines.py, which takes the geometry the same way).
Stops from standards/*.json: in-plane [tan(off − a/2), tan(off + a/2)], across [−tan(b/2), tan(b/2)], the
source clipped to the horizon p ≥ −cot θ and the receptor to p ≤ cot θ.

Variables (docs/instrument.md §Quadrature, "Lobe variables"): per axis u = p_s + p_r and the position
t ∈ [0, 1] along the exact overlap, p_s = lo + t(hi − lo), lo = max(s0, u − r1), hi = min(s1, u − r0),
Jacobian hi − lo. The overlap length kinks at s1 + r0 and s0 + r1: the "kink partition" cuts u and v there
(3 × 3 boxes); the integrand is analytic on each box.

Rule measured: the tensor product of Gauss–Legendre rules of orders (n_u, n_tp, n_v, n_tq), the same orders
on every box of the kink partition. Reference: the same rule on the kink partition refined at 0, ±w, ±3w,
±10w (w the lobe width 2m in u, 2m cos θ in v) at orders (40, 8, 40, 8) per piece, checked against (48,
10, 48, 10) (their difference is printed; it must be far below the target).

The limit: oracle orders. Each axis's order is found with the others at the reference orders (the smallest
n whose error is ≤ target/4); then the product is raised one axis at a time (the axis that lowers the error
most per point) until the error is ≤ target and stays ≤ target with any one axis raised by one step
("robust": no lucky cancellation), then lowered one axis at a time while that still holds. The count is
boxes × n_u n_tp n_v n_tq: the evaluations of that final rule alone, no error estimate (an honest adaptive
rule also pays for the lower rules its estimate compares with).

Target: the regular part's share of a reading at the default rtol 1e-6: 0.9 (SPECIMEN_SHARE) × 0.99
(1 − DELTA_SHARE) × 1e-6 of the flux, relative, or the engine's absolute floor (0.99 × 10⁻⁴·rtol of the
largest gloss-standard flux at that angle, black glass n = 1.567), whichever is larger.

Usage: python3 tools/limit_wide_lobes.py [--rtol 1e-6] [--cases beckmann:0.01:astm-d523-20,...]
Needs numpy, scipy (pip). Prints a Markdown table. Run by hand; docs/performance.md quotes its output.
"""
import argparse
import json
import math
import os

import numpy as np
from scipy.special import erfc

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ETA = 1.5


def stops(gid):
    with open(os.path.join(ROOT, "standards", gid + ".json")) as fh:
        g = json.load(fh)
    theta = math.radians(g["angle_deg"]["value"])

    def stop(r):
        a = math.radians(r["in_plane_deg"]["value"])
        b = math.radians(r["perpendicular_deg"]["value"])
        off = math.radians(r.get("offset_deg", {"value": 0.0})["value"])
        return [math.tan(off - a / 2), math.tan(off + a / 2), -math.tan(b / 2), math.tan(b / 2)]

    src = stop(g["source"])
    cot = math.cos(theta) / math.sin(theta)
    src[0] = max(src[0], -cot)
    out = []
    for r in g["receptors"]:
        rec = stop(r)
        rec[1] = min(rec[1], cot)
        out.append((r["name"], rec))
    return theta, src, out


def brdf_flux(theta, dist, alpha):
    s, c = math.sin(theta), math.cos(theta)
    a2 = alpha * alpha

    def lam(wx, wy, wz):
        t2 = (wx * wx + wy * wy) / (wz * wz)
        if dist == "ggx":
            xx = a2 * t2
            return 0.5 * xx / (np.sqrt(1 + xx) + 1)
        with np.errstate(divide="ignore", invalid="ignore"):
            a = 1.0 / (alpha * np.sqrt(t2))
            v = 0.5 * (np.exp(-a * a) / (a * math.sqrt(math.pi)) - erfc(a))
        return np.where(t2 == 0, 0.0, np.nan_to_num(v))

    def f(ps, qs, pr, qr):
        ns = np.sqrt(1 + ps * ps + qs * qs)
        nr = np.sqrt(1 + pr * pr + qr * qr)
        ix, iy, iz = (-s + ps * c) / ns, qs / ns, (c + ps * s) / ns
        ox, oy, oz = (s + pr * c) / nr, qr / nr, (c - pr * s) / nr
        hx, hy, hz = ix + ox, iy + oy, iz + oz
        hn = np.sqrt(hx * hx + hy * hy + hz * hz)
        hx, hy, hz = hx / hn, hy / hn, hz / hn
        t2 = (hx * hx + hy * hy) / (hz * hz)
        c4 = hz**4
        if dist == "ggx":
            k = a2 + t2
            d = a2 / (math.pi * c4 * k * k)
        else:
            d = np.exp(-t2 / a2) / (math.pi * a2 * c4)
        g = 1.0 / (1.0 + lam(ix, iy, iz) + lam(ox, oy, oz))
        ci = np.clip(ix * hx + iy * hy + iz * hz, 0.0, 1.0)
        ct = np.sqrt(np.maximum(0.0, 1.0 - (1.0 - ci * ci) / (ETA * ETA)))
        rs = (ci - ETA * ct) / (ci + ETA * ct)
        rp = (ETA * ci - ct) / (ETA * ci + ct)
        val = 0.5 * (rs * rs + rp * rp) * d * g / 4.0 / (ns**3 * nr**3)
        return np.where((iz > 0) & (oz > 0), val, 0.0)

    return f


_GL = {}


def gl01(n):
    if n not in _GL:
        x, w = np.polynomial.legendre.leggauss(n)
        _GL[n] = (0.5 * (x + 1), 0.5 * w)
    return _GL[n]


def axis_breaks(s0, s1, r0, r1, extra):
    lo, hi = s0 + r0, s1 + r1
    b = {lo, hi, s1 + r0, s0 + r1}
    for e in extra:
        if lo < e < hi:
            b.add(e)
    b = sorted(b)
    return [x for i, x in enumerate(b) if i == 0 or x - b[i - 1] > 1e-15 * (hi - lo)]


def rule(f, src, rec, bu, bv, orders):
    """Σ over boxes [bu_i, bu_i+1] × [bv_j, bv_j+1] of the tensor GL rule of `orders` in (u, t_p, v, t_q)."""
    nu, ntp, nv, ntq = orders
    (xu, wu), (xtp, wtp), (xv, wv), (xtq, wtq) = gl01(nu), gl01(ntp), gl01(nv), gl01(ntq)
    total = 0.0
    for i in range(len(bu) - 1):
        ua, ub = bu[i], bu[i + 1]
        u = ua + (ub - ua) * xu
        lo = np.maximum(src[0], u - rec[1])
        hi = np.minimum(src[1], u - rec[0])
        jp = np.maximum(hi - lo, 0.0)
        ps = lo[:, None] + xtp[None, :] * (hi - lo)[:, None]
        pr = u[:, None] - ps
        wp = ((ub - ua) * wu * jp)[:, None] * wtp[None, :]
        for j in range(len(bv) - 1):
            va, vb = bv[j], bv[j + 1]
            v = va + (vb - va) * xv
            loq = np.maximum(src[2], v - rec[3])
            hiq = np.minimum(src[3], v - rec[2])
            jq = np.maximum(hiq - loq, 0.0)
            qs = loq[:, None] + xtq[None, :] * (hiq - loq)[:, None]
            qr = v[:, None] - qs
            wq = ((vb - va) * wv * jq)[:, None] * wtq[None, :]
            P_s = ps[:, :, None, None]
            P_r = pr[:, :, None, None]
            Q_s = qs[None, None, :, :]
            Q_r = qr[None, None, :, :]
            vals = f(P_s, Q_s, P_r, Q_r)
            total += float(np.sum(vals * wp[:, :, None, None] * wq[None, None, :, :]))
    return total


# The partitions tried: the overlap kinks alone, and the kinks with lobe splits at these multiples of w.
PARTITIONS = [("kinks", ()), ("kinks+0", (0,)), ("kinks+0,2w", (0, 2)), ("kinks+0,w,3w", (0, 1, 3)),
              ("kinks+0,w,3w,10w", (0, 1, 3, 10))]
CAPS = [32, 8, 32, 8]


def oracle(f, src, rec, bu, bv, ref, tol):
    """Oracle orders on the partition bu × bv (see the module docstring): (orders, evaluations, error) or None
    when no orders up to CAPS reach the tolerance."""
    nboxes = (len(bu) - 1) * (len(bv) - 1)
    cache = {}

    def err(o):
        o = tuple(o)
        if o not in cache:
            cache[o] = abs(rule(f, src, rec, bu, bv, o) - ref)
        return cache[o]

    if err(CAPS) > tol / 4:
        return None
    orders = []
    for k in range(4):
        n = 1
        while n < CAPS[k]:
            o = list(CAPS)
            o[k] = n
            if err(o) <= tol / 4:
                break
            n += 1
        orders.append(n)

    def robust(o):
        if err(o) > tol:
            return False
        for k in range(4):
            p = list(o)
            p[k] = p[k] + 1
            if err(p) > tol:
                return False
        return True

    o = list(orders)
    while not robust(o):
        best = None
        for k in range(4):
            if o[k] >= CAPS[k]:
                continue
            p = list(o)
            p[k] += 1
            gain = (err(o) - err(p)) / (np.prod(p) - np.prod(o))
            if best is None or gain > best[0]:
                best = (gain, p)
        if best is None:
            return None
        o = best[1]
    improved = True
    while improved:
        improved = False
        for k in sorted(range(4), key=lambda k: -o[k]):
            if o[k] > 1:
                p = list(o)
                p[k] -= 1
                if robust(p):
                    o, improved = p, True
                    break
    return o, nboxes * int(np.prod(o)), err(o)


def standard_flux(theta, src, rec, n=1.567):
    """The gloss standard's (black glass, index 1.567) mirror flux through `rec`: ∫ R(θi) cos θi
    (1 + p² + q²)^(-3/2) dp dq over the source points whose mirror (−p, −q) is in the receptor."""
    p0, p1 = max(src[0], -rec[1]), min(src[1], -rec[0])
    q0, q1 = max(src[2], -rec[3]), min(src[3], -rec[2])
    if p1 <= p0 or q1 <= q0:
        return 0.0
    x, w = gl01(24)
    p = p0 + (p1 - p0) * x[:, None]
    q = q0 + (q1 - q0) * x[None, :]
    s, c = math.sin(theta), math.cos(theta)
    ns = np.sqrt(1 + p * p + q * q)
    ci = (c + p * s) / ns
    ct = np.sqrt(np.maximum(0.0, 1.0 - (1.0 - ci * ci) / (n * n)))
    rs = (ci - n * ct) / (ci + n * ct)
    rp = (n * ci - ct) / (n * ci + ct)
    val = 0.5 * (rs * rs + rp * rp) * ci / ns**3
    return float(np.sum(val * w[:, None] * w[None, :]) * (p1 - p0) * (q1 - q0))


def case_run(dist, m, gid, target_rel, rtol):
    theta, src, recs = stops(gid)
    f = brdf_flux(theta, dist, m)
    # The engine's absolute floor of a specimen flux (plan::compile): 1e-4·rtol of the largest standard flux at
    # the angle; the regular part gets 0.99 of it.
    floor = 0.99 * 1e-4 * rtol * max(standard_flux(theta, src, rec) for _, rec in recs)
    wu, wv = 2 * m, 2 * m * math.cos(theta)
    rows = []
    for name, rec in recs:
        lobe_u = [k * s * wu for k in (0, 1, 3, 10) for s in (-1, 1)]
        lobe_v = [k * s * wv for k in (0, 1, 3, 10) for s in (-1, 1)]
        fu = axis_breaks(src[0], src[1], rec[0], rec[1], lobe_u)
        fv = axis_breaks(src[2], src[3], rec[2], rec[3], lobe_v)
        ref = rule(f, src, rec, fu, fv, (40, 8, 40, 8))
        ref2 = rule(f, src, rec, fu, fv, (48, 10, 48, 10))
        refdiff = abs(ref - ref2) / abs(ref2) if ref2 != 0 else abs(ref - ref2)
        ref = ref2
        tol = max(target_rel * abs(ref), floor)
        best = None
        for pname, extra in PARTITIONS:
            eu = [k * s * wu for k in extra for s in (-1, 1)]
            ev = [k * s * wv for k in extra for s in (-1, 1)]
            bu = axis_breaks(src[0], src[1], rec[0], rec[1], eu)
            bv = axis_breaks(src[2], src[3], rec[2], rec[3], ev)
            r = oracle(f, src, rec, bu, bv, ref, tol)
            if r is not None and (best is None or r[1] < best[2]):
                best = (pname, r[0], r[1], r[2], (len(bu) - 1) * (len(bv) - 1))
        if best is None:
            rows.append((name, ref, refdiff, "-", None, None, None))
            continue
        pname, o, evals, e, nboxes = best
        rows.append((name, ref, refdiff, f"{pname} ({nboxes})", o, evals, e / abs(ref) if ref != 0 else e))
        continue
        rows.append((name, ref, refdiff, nboxes, o, evals, err(o) / abs(ref)))
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rtol", type=float, default=1e-6)
    ap.add_argument("--cases", default="")
    args = ap.parse_args()
    target = 0.9 * 0.99 * args.rtol
    if args.cases:
        cases = [tuple(c.split(":")) for c in args.cases.split(",")]
    else:
        cases = [
            (d, m, g)
            for d in ("beckmann", "ggx")
            for m in ("0.003", "0.01", "0.03")
            for g in ("astm-d523-20", "astm-d523-60", "astm-d523-85", "astm-e430-30")
        ]
    print(f"target: relative error <= {target:.3g} of each specimen flux (reading rtol {args.rtol:g})\n")
    print("| D | m | geometry | receptor | flux (ref) | ref check | partition (boxes) | orders (u, t_p, v, t_q) | evaluations | actual rel. |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    grand = {}
    for d, m, g in cases:
        rows = case_run(d, float(m), g, target, args.rtol)
        tot = 0
        for name, ref, rd, nb, o, ev, e in rows:
            if o is None:
                print(f"| {d} | {m} | {g} | {name} | {ref:.12e} | {rd:.1e} | none reached | | | |", flush=True)
                continue
            tot += ev
            print(f"| {d} | {m} | {g} | {name} | {ref:.12e} | {rd:.1e} | {nb} | {tuple(o)} | {ev} | {e:.1e} |", flush=True)
        grand[(d, m, g)] = tot
    print("\nPer case (sum over the receptors):")
    for k, v in grand.items():
        print(f"- {k[0]} {k[1]} {k[2]}: {v}")
    print(f"- total: {sum(grand.values())}")


if __name__ == "__main__":
    main()
