#!/usr/bin/env python3
"""Independent reference values for glossmeter's smooth-surface (Rayleigh–Rice) scatter (docs/optics.md
§Near-specular scatter).

Run by hand (not by CI), with numpy and scipy installed:
    python3 -m venv /tmp/venv && /tmp/venv/bin/pip install numpy scipy
    /tmp/venv/bin/python tools/ref_scatter.py
Writes fixtures/reference/scatter-rayleigh-rice.json.

Route (deliberately different from the Rust code in src/optics/scatter.rs):
* The K-correlation PSD's constants by quadrature, not by Gamma functions: the 2-D PSD is
  S2(f) = K/(1 + (B f)^2)^((C+1)/2); K is fixed by requiring that the one-sided profile PSD at fx = 0,
  2 * integral over all fy of S2(0, fy), equals A (scipy.integrate.quad), and A for a given rms roughness by
  sigma^2 = integral_0^inf A/(1 + (B fx)^2)^(C/2) dfx (quad). The Gaussian PSD is pi l^2 sigma^2 exp(-(pi l f)^2).
* The polarisation factor Q from the published component formulas (Stover 2012 Ch. 5; Elson & Bennett 1979) written in
  the angles (theta_i, theta_s, phi_s) with numpy's complex square root; checked against the textbook Fresnel
  reflectances at the specular direction.
* The BRDF at chosen (theta_i, theta_s, phi_s) from spherical angles (the Rust code works in vectors).
* The band-limited mean-square roughness by a 2-D adaptive quadrature (scipy dblquad) of S2 over the disc of
  propagating frequencies, in polar coordinates about the specular frequency, with the radial limit solved
  numerically (brentq) rather than by the closed form; the Rust code uses the radial closed form.
* The halo's hemispherical integral H(theta_i) = integral of f_r cos theta_s d omega_s by dblquad in the same
  polar frequency coordinates (cos theta_s d omega_s = lambda^2 d^2 f), with the BRDF's own Q and cos theta_s
  at each point: the exact first-order scatter, to compare with the specular loss R g the model uses.
"""
import json
import datetime
import numpy as np
import scipy
from scipy import integrate, optimize

SCRIPT = "tools/ref_scatter.py"
DATE = datetime.date.today().isoformat()


class KCorr:
    def __init__(self, a=None, b=None, c=2.0, sigma=None, ell=None):
        self.c = c
        if sigma is not None:
            self.b = 2 * np.pi * ell
            prof, _ = integrate.quad(lambda f: (1 + (self.b * f) ** 2) ** (-c / 2), 0, np.inf, epsabs=0, epsrel=1e-13)
            self.a = sigma ** 2 / prof
        else:
            self.a, self.b = a, b
        # 2 * int_{-inf}^{inf} K (1 + B^2 fy^2)^(-(C+1)/2) dfy = A
        j, _ = integrate.quad(lambda fy: (1 + (self.b * fy) ** 2) ** (-(c + 1) / 2), 0, np.inf, epsabs=0, epsrel=1e-13)
        self.k = self.a / (4 * j)

    def s2(self, f):
        return self.k * (1 + (self.b * f) ** 2) ** (-(self.c + 1) / 2)

    def sigma2(self):
        v, _ = integrate.quad(lambda f: 2 * np.pi * f * self.s2(f), 0, np.inf, epsabs=0, epsrel=1e-12, limit=500)
        return v

    def describe(self):
        return {"psd": "k-correlation", "a_nm2_um": self.a, "b_um": self.b, "c": self.c}


class Gauss:
    def __init__(self, sigma, ell):
        self.sigma, self.ell = sigma, ell

    def s2(self, f):
        return np.pi * self.ell ** 2 * self.sigma ** 2 * np.exp(-((np.pi * self.ell * f) ** 2))

    def sigma2(self):
        return self.sigma ** 2

    def describe(self):
        return {"psd": "gaussian", "rms_roughness_nm": self.sigma, "correlation_length_um": self.ell}


def q_factor(eps, ti, ts, ps):
    eps = complex(eps)
    si, ss = np.sin(ti), np.sin(ts)
    ci, cs = np.cos(ti), np.cos(ts)
    ki = np.sqrt(eps - si ** 2 + 0j)
    ks = np.sqrt(eps - ss ** 2 + 0j)
    d_s = (ci + ki) * (cs + ks)
    qss = abs((eps - 1) * np.cos(ps) / d_s) ** 2
    qsp = abs((eps - 1) * ks * np.sin(ps) / ((ci + ki) * (eps * cs + ks))) ** 2
    qps = abs((eps - 1) * ki * np.sin(ps) / ((eps * ci + ki) * (cs + ks))) ** 2
    qpp = abs((eps - 1) * (ki * ks * np.cos(ps) - eps * si * ss) / ((eps * ci + ki) * (eps * cs + ks))) ** 2
    return 0.5 * (qss + qsp + qps + qpp)


def fresnel_unpolarised(n, ti):
    n = complex(n)
    ci = np.cos(ti)
    ct = np.sqrt(1 - (np.sin(ti) / n) ** 2 + 0j)
    rs = (ci - n * ct) / (ci + n * ct)
    rp = (n * ci - ct) / (n * ci + ct)
    return 0.5 * (abs(rs) ** 2 + abs(rp) ** 2)


def brdf(psd, eps, lam_nm, ti, ts, ps):
    lam_um = lam_nm * 1e-3
    fx = (np.sin(ts) * np.cos(ps) - np.sin(ti)) / lam_um
    fy = np.sin(ts) * np.sin(ps) / lam_um
    f = np.hypot(fx, fy)
    return 16 * np.pi ** 2 / (lam_nm ** 2 * lam_um ** 2) * np.cos(ti) * np.cos(ts) * q_factor(eps, ti, ts, ps) * psd.s2(f)


def rho_max(s, lam_um, psi):
    # |lam rho u(psi) + (s, 0)| = 1 solved numerically for rho >= 0
    g = lambda r: (lam_um * r * np.cos(psi) + s) ** 2 + (lam_um * r * np.sin(psi)) ** 2 - 1
    return optimize.brentq(g, 0, 2.0 / lam_um, xtol=1e-15, rtol=1e-15)


def polar_disc(fun, s, lam_um, knee):
    """int over the propagating disc of fun(fx, fy) d^2 f, in polar coordinates about f = 0, with the radial
    variable split at multiples of the PSD's knee (the integrand is concentrated there)."""

    def radial(psi):
        top = rho_max(s, lam_um, psi)
        edges = [0.0] + [k * knee for k in (0.3, 1, 3, 10, 30, 100, 300, 1000) if k * knee < top] + [top]
        tot = 0.0
        for lo, hi in zip(edges[:-1], edges[1:]):
            v, _ = integrate.quad(lambda r: fun(r * np.cos(psi), r * np.sin(psi)) * r, lo, hi, epsabs=0, epsrel=1e-11, limit=200)
            tot += v
        return tot

    v, _ = integrate.quad(radial, 0, 2 * np.pi, epsabs=0, epsrel=1e-10, limit=200)
    return v


def band_limited(psd, s, lam_um, knee):
    return polar_disc(lambda fx, fy: psd.s2(np.hypot(fx, fy)), s, lam_um, knee)


def halo_integral(psd, eps, lam_nm, ti, knee):
    lam_um = lam_nm * 1e-3
    s = np.sin(ti)

    def integrand(fx, fy):
        # the scattered direction cosines
        ax, ay = s + lam_um * fx, lam_um * fy
        st = min(np.hypot(ax, ay), 1.0)
        ts = np.arcsin(st)
        ps = np.arctan2(ay, ax)
        # cos theta_s d omega = lam^2 d^2 f
        return brdf(psd, eps, lam_nm, ti, ts, ps) * lam_um ** 2

    return polar_disc(integrand, s, lam_um, knee)


def main():
    deg = np.deg2rad
    cases = []
    psds = [
        ("k-correlation from sigma 3 nm, l 10 um, C 2", KCorr(sigma=3.0, ell=10.0, c=2.0), {"rms_roughness_nm": 3.0, "correlation_length_um": 10.0, "c": 2.0}, 1.0 / (2 * np.pi * 10.0)),
        ("k-correlation A 40 nm2um, B 20 um, C 3.5", KCorr(a=40.0, b=20.0, c=3.5), None, 1.0 / 20.0),
        ("gaussian sigma 2 nm, l 3 um", Gauss(2.0, 3.0), None, 1.0 / (np.pi * 3.0)),
        ("k-correlation from sigma 1 nm, l 0.5 um, C 1.5 (broad)", KCorr(sigma=1.0, ell=0.5, c=1.5), {"rms_roughness_nm": 1.0, "correlation_length_um": 0.5, "c": 1.5}, 1.0 / (2 * np.pi * 0.5)),
    ]
    media = [("dielectric n 1.5", 1.5 + 0j), ("conductor n 0.96 + 6.69i (Al near 560 nm)", 0.96 + 6.69j)]
    for label, psd, given, knee in psds:
        for mlabel, n in media:
            eps = n * n
            lam = 560.0
            pts = []
            for ti_d, ts_d, ps_d in [(20, 20, 0), (20, 22, 0), (20, 18, 0), (20, 21, 5), (60, 61, 0), (60, 55, 40), (0, 3, 70), (85, 84, 0), (45, 30, 120)]:
                v = brdf(psd, eps, lam, deg(ti_d), deg(ts_d), deg(ps_d))
                pts.append({"theta_i_deg": ti_d, "theta_s_deg": ts_d, "phi_s_deg": ps_d, "brdf": v})
            spec = []
            for ti_d in [0, 20, 60, 85]:
                ti = deg(ti_d)
                s = np.sin(ti)
                sbl = band_limited(psd, s, lam * 1e-3, knee)
                r = fresnel_unpolarised(n, ti)
                rq = q_factor(eps, ti, ti, 0.0)
                assert abs(r - rq) < 1e-13, (r, rq)
                g = (4 * np.pi * np.cos(ti) / lam) ** 2 * sbl
                h = halo_integral(psd, eps, lam, ti, knee)
                spec.append({"theta_i_deg": ti_d, "sigma2_band_limited_nm2": sbl, "fresnel_r": r, "loss_g": g,
                             "halo_hemispherical": h, "halo_over_r_g": h / (r * g)})
            cases.append({"label": f"{label}; {mlabel}", "psd": psd.describe(), "given": given,
                          "sigma2_nm2": psd.sigma2(), "index": [n.real, n.imag], "wavelength_nm": lam,
                          "brdf": pts, "specular": spec})
    out = {
        "provenance": {
            "script": SCRIPT, "date": DATE, "numpy": np.__version__, "scipy": scipy.__version__,
            "route": "PSD constants by quadrature, Q from angles with complex sqrt, band-limited roughness and the halo's hemispherical integral by adaptive 2-D quadrature over the propagating disc (see the script's docstring)",
            "units": "nm for sigma and wavelength, um for lengths, 1/um for frequencies, PSD in nm^2 um^2, BRDF in 1/sr",
        },
        "cases": cases,
    }
    with open("fixtures/reference/scatter-rayleigh-rice.json", "w") as fh:
        json.dump(out, fh, indent=1)
        fh.write("\n")


if __name__ == "__main__":
    main()
