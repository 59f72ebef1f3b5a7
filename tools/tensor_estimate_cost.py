#!/usr/bin/env python3
"""What an honest error estimate costs a tensor Gauss rule on one integral, measured with code independent of the
engine (docs/performance.md, "B4"): the engine's adaptive scheme re-implemented (per-axis orders raised one step
at a time, the estimate the sum over axes of |Q(n) - Q(n - e_k)|, each calibrated from its last two
differences as `quadrature::tensor::calibrate`, shrink at most 8) on the kink partition of
tools/limit_wide_lobes.py, with two families of 1-D rules:

  gauss   Gauss-Legendre at the engine's orders 1, 2, 3, 4, 6, 8, 12, ...: every lower neighbour is new points;
  nested  symmetric Leja points about the centre (1, 3, 5, 7, ... points, each level adding a pair; interpolatory
          weights): every lower rule is a subset of the final grid, so the count is the final grid alone.

Prints the evaluations, final levels, estimate / tolerance and actual error / estimate against the limit
script's reference (orders 48, 10, 48, 10 on the kink partition refined at the lobe widths).

Usage: python3 tools/tensor_estimate_cost.py ggx:0.3:astm-d523-85:gloss[,...] [rtol]
Needs numpy, scipy. Run by hand; docs/performance.md quotes its output.
"""
import math
import os
import sys
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np
import limit_wide_lobes as L

def gl(n):
    x, w = np.polynomial.legendre.leggauss(n); return 0.5*(x+1), 0.5*w
GORD = [1, 2, 3, 4, 6, 8, 12, 16, 20, 24, 32, 48]

def sym_leja(npairs):
    grid = np.linspace(0, 0.5, 100001)[1:]
    d = []
    for _ in range(npairs):
        pts = [0.0] + [s*x for x in d for s in (1, -1)]
        prod = np.ones_like(grid)
        for p in pts:
            prod *= np.abs(grid - p) * np.abs(-grid - p)
        d.append(float(grid[np.argmax(prod)]))
    return d
SL = sym_leja(20)
def nested_nodes(level):  # level 0: 1 point, level l: 2l+1 points
    x = np.array([0.0] + [s*v for v in SL[:level] for s in (1, -1)])
    return x + 0.5
def interp_w(x):
    n = len(x); t = 2*x - 1
    V = np.polynomial.legendre.legvander(t, n-1).T
    mom = np.zeros(n); mom[0] = 2.0
    return np.linalg.solve(V, mom) * 0.5
NESTED = [(nested_nodes(l), interp_w(nested_nodes(l))) for l in range(15)]
# Clenshaw-Curtis-ish nested with step: chebyshev extrema sets 1,3,5,9,17,33
def cc(n):
    if n == 1: return np.array([0.5]), np.array([1.0])
    x = 0.5*(1-np.cos(np.pi*np.arange(n)/(n-1)))
    return x, interp_w(x)

def rule_nodes(f, src, rec, bu, bv, nodes, per_box=False):
    (xu, wu), (xtp, wtp), (xv, wv), (xtq, wtq) = nodes
    out = []
    for i in range(len(bu)-1):
        ua, ub = bu[i], bu[i+1]
        u = ua + (ub-ua)*xu
        lo = np.maximum(src[0], u-rec[1]); hi = np.minimum(src[1], u-rec[0]); jp = np.maximum(hi-lo, 0.0)
        ps = lo[:, None] + xtp[None, :]*(hi-lo)[:, None]; pr = u[:, None]-ps
        wp = ((ub-ua)*wu*jp)[:, None]*wtp[None, :]
        for j in range(len(bv)-1):
            va, vb = bv[j], bv[j+1]
            v = va + (vb-va)*xv
            loq = np.maximum(src[2], v-rec[3]); hiq = np.minimum(src[3], v-rec[2]); jq = np.maximum(hiq-loq, 0.0)
            qs = loq[:, None] + xtq[None, :]*(hiq-loq)[:, None]; qr = v[:, None]-qs
            wq = ((vb-va)*wv*jq)[:, None]*wtq[None, :]
            vals = f(ps[:, :, None, None], qs[None, None, :, :], pr[:, :, None, None], qr[None, None, :, :])
            out.append(float(np.sum(vals*wp[:, :, None, None]*wq[None, None, :, :])))
    return out if per_box else sum(out)

def drive(f, src, rec, bu, bv, tol, family, start=(1,1,1,1), maxshrink=8.0, maxlev=11):
    nb = (len(bu)-1)*(len(bv)-1)
    cache = {}
    def nodes(l):
        if family == 'gauss': return gl(GORD[l])
        return NESTED[l]
    def npts(l): return GORD[l] if family == 'gauss' else 2*l+1
    evals = [0]
    def Q(n):
        n = tuple(n)
        if n not in cache:
            cache[n] = rule_nodes(f, src, rec, bu, bv, [nodes(l) for l in n])
            if family == 'gauss': evals[0] += nb*np.prod([npts(l) for l in n])
        return cache[n]
    n = list(start)
    prev = [None]*4; term = [None]*4
    q = Q(n)
    for k in range(4):
        m = list(n); m[k] -= 1
        term[k] = q - Q(m)
    def cal(k):
        d = abs(term[k])
        if prev[k] is None or prev[k] == 0: return d
        r = d/abs(prev[k])
        return max(3*r*d, d/maxshrink) if 3*r < 1 else d
    while True:
        q = Q(n)
        est = sum(cal(k) for k in range(4))
        if est <= tol: break
        k = max(range(4), key=cal)
        if n[k] >= maxlev: return None
        n[k] += 1
        qn = Q(n)
        prev[k] = term[k]; term[k] = qn - q
    if family != 'gauss':
        evals[0] = nb*np.prod([npts(l) for l in n])
    return Q(n), est, n, evals[0]

def setup(dist, m, gid, recname, rtol=1e-6, extra=()):
    theta, src, recs = L.stops(gid)
    rec = dict(recs)[recname]
    f = L.brdf_flux(theta, dist, m)
    floor = 0.99*1e-4*rtol*max(L.standard_flux(theta, src, r) for _, r in recs)
    wu, wv = 2*m, 2*m*math.cos(theta)
    lu = [k*s*wu for k in (0,1,3,10) for s in (-1,1)]; lv = [k*s*wv for k in (0,1,3,10) for s in (-1,1)]
    fu = L.axis_breaks(src[0], src[1], rec[0], rec[1], lu); fv = L.axis_breaks(src[2], src[3], rec[2], rec[3], lv)
    ref = L.rule(f, src, rec, fu, fv, (48,10,48,10))
    tol = max(0.9*0.99*rtol*abs(ref), floor)
    eu = [k*s*wu for k in extra for s in (-1,1)]; ev = [k*s*wv for k in extra for s in (-1,1)]
    bu = L.axis_breaks(src[0], src[1], rec[0], rec[1], eu); bv = L.axis_breaks(src[2], src[3], rec[2], rec[3], ev)
    return f, src, rec, bu, bv, ref, tol

if __name__ == '__main__':
    cases = [a.split(':') for a in sys.argv[1].split(',')]
    rtol = float(sys.argv[2]) if len(sys.argv) > 2 else 1e-6
    for dist, m, gid, rn in cases:
        f, src, rec, bu, bv, ref, tol = setup(dist, float(m), gid, rn, rtol)
        for fam in ('gauss', 'nested'):
            r = drive(f, src, rec, bu, bv, tol, fam)
            if r is None: print(dist, m, gid, rn, fam, 'FAILED'); continue
            v, est, n, ev = r
            print(f"{dist} {m} {gid} {rn} {fam:6s} evals {ev:6d} levels {n} est/tol {est/tol:.2e} actual/est {abs(v-ref)/est:.3f} actual/tol {abs(v-ref)/tol:.2e}")
