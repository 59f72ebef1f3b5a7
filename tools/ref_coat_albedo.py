#!/usr/bin/env python3
"""Directional albedo E(mu) of a rough dielectric interface's single-scattering reflection lobe: independent
reference values for glossmeter's energy-exact rough clear coat (src/optics/coat_albedo.rs, tests/paint.rs).

Run by hand (not by CI):  python3 -m venv /tmp/venv && /tmp/venv/bin/pip install numpy scipy
                          /tmp/venv/bin/python tools/ref_coat_albedo.py
Writes fixtures/reference/coat-albedo.json.

Definition: E(mu) = integral over the outgoing hemisphere of f(wi, wo) cos(theta_o) d(omega_o), with
f = F(wi.h) D(h) G2(wi, wo) / (4 cos(theta_i) cos(theta_o)) (Walter et al. 2007, Eq. 20), D the normalised
Beckmann or GGX distribution (Walter et al. 2007, Eqs. 25 and 33), G2 = 1/(1 + Lambda(wi) + Lambda(wo)) the
height-correlated Smith term (Heitz 2014, Eq. 99) with the closed-form Lambdas (Heitz 2014, Eqs. 80 and 86),
F the unpolarised Fresnel reflectance of the interface air -> eta.
The chart is NOT the engine's: here the integral runs over the outgoing direction (u = cos theta_o in [0, 1],
phi_o in [0, pi], doubled by symmetry), where the horizon is the coordinate line u = 0, by nested adaptive
Gauss-Kronrod (scipy.integrate.quad, QUADPACK) at epsabs 1e-14 with break points graded about the specular
direction. The engine integrates in scaled half-vector slopes by a fixed rule (its reference rule), from which
the shipped table assets/coat-albedo-table.bin that paints read was generated (examples/make_coat_albedo_table.rs);
tests/paint.rs compares both the rule and the table with these values.
"""
import datetime
import json
import os
import warnings

import numpy as np
from scipy import integrate
from scipy.special import erfc

warnings.filterwarnings("ignore")
SQPI = np.sqrt(np.pi)
OUT = os.path.join(os.path.dirname(__file__), "..", "fixtures", "reference", "coat-albedo.json")
def fresnel(c, eta):
    c = np.clip(c, 0, 1)
    s2 = 1 - c*c
    st2 = s2/(eta*eta)
    ct = np.sqrt(np.maximum(1 - st2, 0))
    rs = (c - eta*ct)/(c + eta*ct)
    rp = (eta*c - ct)/(eta*c + ct)
    return 0.5*(rs*rs + rp*rp)

def lam(dist, alpha, z):
    # z = cos theta of a direction
    z = np.asarray(z, float)
    t = np.sqrt(np.maximum(1 - z*z, 0))/z
    with np.errstate(divide='ignore', invalid='ignore'):
        nu = 1/(alpha*t)
        if dist == 'beckmann':
            L = -0.5*erfc(nu) + np.exp(-nu*nu)/(2*nu*SQPI)
        else:
            L = 0.5*(-1 + np.sqrt(1 + 1/(nu*nu)))
    return np.where(t == 0, 0.0, L)

def D(dist, alpha, hz):
    c2 = hz*hz
    t2 = (1 - c2)/c2
    if dist == 'beckmann':
        return np.exp(-t2/alpha**2)/(np.pi*alpha**2*c2*c2)
    else:
        return 1/(np.pi*alpha**2*c2*c2*(1 + t2/alpha**2)**2)

def f_cos(dist, alpha, eta, wi, wo):
    """f * cos(theta_o) for the coat lobe."""
    h = wi + wo
    h = h/np.linalg.norm(h, axis=0)
    ih = np.sum(wi*h, axis=0)
    G = 1/(1 + lam(dist, alpha, wi[2]) + lam(dist, alpha, wo[2]))
    return fresnel(ih, eta)*D(dist, alpha, h[2])*G/(4*wi[2])

def reference(dist, alpha, eta, mu, tol=1e-14):
    s = np.sqrt(1 - mu*mu)
    wi = np.array([s, 0, mu])
    def inner(phi):
        cp, sp = np.cos(phi), np.sin(phi)
        def g(u):
            so = np.sqrt(1 - u*u)
            wo = np.array([[so*cp], [so*sp], [u]])
            return f_cos(dist, alpha, eta, wi[:, None], wo)[0]
        pts = [mu] if 0 < mu < 1 else None
        # breaks graded about the specular u
        w = 2*alpha*max(s, alpha)
        p = sorted(set([min(max(mu + k*w, 1e-300), 1) for k in (-8,-4,-2,-1,0,1,2,4,8)]))
        p = [x for x in p if 0 < x < 1]
        v, e = integrate.quad(g, 0, 1, points=p, epsabs=tol, epsrel=0, limit=400)
        return v
    w = 2*alpha/max(s, 1e-3)
    p = sorted(set([np.pi - k*w for k in (0, 1, 2, 4, 8, 16) if np.pi - k*w > 0]))
    v, e = integrate.quad(inner, 0, np.pi, points=p[:-1] if p[-1] == np.pi else p, epsabs=tol, epsrel=0, limit=400)
    return 2*v


def main():
    cases = []
    for d, a in [("beckmann", 0.01), ("beckmann", 0.05), ("beckmann", 0.3), ("beckmann", 1.0),
                 ("ggx", 0.02), ("ggx", 0.1), ("ggx", 0.5)]:
        for th in [0, 30, 60, 75, 80, 85, 88, 89]:
            cases.append((d, a, 1.5, th))
    for d, a in [("beckmann", 0.3), ("ggx", 0.5), ("ggx", 0.02)]:
        for eta in [1.3, 1.8]:
            for th in [60, 85]:
                cases.append((d, a, eta, th))
    rows = []
    for d, a, eta, th in cases:
        mu = float(np.cos(np.radians(th)))
        rows.append({"distribution": d, "alpha": a, "eta": eta, "theta_deg": th, "mu": mu,
                     "E": reference(d, a, eta, mu)})
        print(rows[-1], flush=True)
    doc = {"provenance": {"script": "tools/ref_coat_albedo.py", "date": str(datetime.date.today()),
                          "method": __doc__.strip()}, "cases": rows}
    with open(OUT, "w") as f:
        json.dump(doc, f, indent=1)


if __name__ == "__main__":
    main()
