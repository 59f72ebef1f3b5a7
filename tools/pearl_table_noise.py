#!/usr/bin/env python3
"""An independent evaluation of the pearl's flake reflectance rho(mu) near grazing, and the verified
Chebyshev tables of it (docs/model.md, section Evaluation cost, "Where the direct evaluation is the noise").

The stack is resin (index eta) / TiO2 (coherent) / mica (incoherent) / TiO2 (coherent) / resin, unpolarised,
as in src/optics/thin_film.rs (Byrnes, arXiv:1603.02720, Eqs. 13-14 for the coherent groups; Katsidis &
Siapkas, Appl. Opt. 41 (2002) 3978 for the incoherent combination R = Rf + Tf Tb P^2 R'/(1 - Rb P^2 R')).
Written from those formulas, not from the Rust code, with one difference on purpose: the exit medium is the
resin again and its cosine is taken as mu itself (the Rust stack computed it as sqrt(eta^2 - eta^2 (1 - mu^2))
and lost digits as mu -> 0; since 2026-12-07 it takes mu too, and its other cosines without cancellation,
optics::thin_film::medium_cos). Every other cosine is computed here the usual way,
n cos = sqrt(n^2 - eta^2 (1 - mu^2)).

The tables are those of src/optics/tabulated.rs: 16 Chebyshev-Gauss nodes a piece, the deviation checked at
the 17 Chebyshev-Lobatto points of every piece; on a table cut at a kink mu_c, mu = mu_c + h s^2 and the
check leaves out s = 0. Pure Python (no NumPy); about a minute.

Usage: python3 tools/pearl_table_noise.py
"""
import cmath
import math

N = 16
NODES = [math.cos(math.pi * (j + 0.5) / N) for j in range(N)]


def n_cos(eta, mu, n):
    """n cos(theta) in a medium of index n, forward/decaying branch (Im >= 0)."""
    v = cmath.sqrt(n * n - eta * eta * (1 - mu * mu))
    return -v if v.imag < 0 else v


def film(na_ca, nf, nf_cf, nb_cb, d_nm, lam_nm, pol, n_a, n_b):
    """(R, T) of one coherent film between two semi-infinite media, from the first (Byrnes Eqs. 13-14)."""
    def amp(n1, c1n1, n2, c2n2):
        # s: (n1c1 - n2c2)/(n1c1 + n2c2); p: (n2c1 - n1c2)/(n2c1 + n1c2), with ci = (ni ci)/ni.
        c1, c2 = c1n1 / n1, c2n2 / n2
        if pol == "s":
            den = n1 * c1 + n2 * c2
            return (n1 * c1 - n2 * c2) / den, 2 * n1 * c1 / den
        den = n2 * c1 + n1 * c2
        return (n2 * c1 - n1 * c2) / den, 2 * n1 * c1 / den

    r1, t1 = amp(n_a, na_ca, nf, nf_cf)
    r2, t2 = amp(nf, nf_cf, n_b, nb_cb)
    e = cmath.exp(2j * math.pi * d_nm * nf_cf / lam_nm)
    den = 1 + r1 * r2 * e * e
    r, t = (r1 + r2 * e * e) / den, t1 * t2 * e / den
    ca, cb = na_ca / n_a, nb_cb / n_b
    top = (n_a * ca).real if pol == "s" else (n_a * ca.conjugate()).real
    bottom = (n_b * cb).real if pol == "s" else (n_b * cb.conjugate()).real
    return abs(r) ** 2, (abs(t) ** 2 * bottom / top if top > 0 else 0.0)


def rho(mu, eta, lam_nm, d_tio2=135.0, n_tio2=2.5, n_mica=1.58, d_mica=400.0):
    """The pearl's unpolarised reflectance, clamped to [0, 1]; 1 at mu <= 0 (the grazing limit)."""
    if mu <= 0:
        return 1.0
    resin = complex(eta * mu)  # the ambient's and the exit medium's n cos: exactly eta mu
    t_nc, m_nc = n_cos(eta, mu, n_tio2), n_cos(eta, mu, n_mica)
    p = math.exp(-4 * math.pi * d_mica * m_nc.imag / lam_nm)
    out = 0.0
    for pol in "sp":
        rf, tf = film(resin, n_tio2, t_nc, m_nc, d_tio2, lam_nm, pol, eta, n_mica)
        rb, tb = film(m_nc, n_tio2, t_nc, resin, d_tio2, lam_nm, pol, n_mica, eta)
        r_below = rb  # the lower group seen from the mica is the upper one seen from below (symmetric stack)
        out += 0.5 * (rf + tf * tb * p * p * r_below / (1 - rb * p * p * r_below) if tf != 0 else rf)
    return min(max(out, 0.0), 1.0)


def rho_on_segment(s, h, mc, eta, lam_nm, d_tio2=135.0, n_tio2=2.5, n_mica=1.58, d_mica=400.0):
    """rho at mu = mc + h s^2 with the mica's n cos from the segment variable, eta sqrt((mu - mc)(mu + mc)),
    mu - mc = h s^2 exactly (the cure of docs/model.md, optics::fresnel::ncos_near_critical): no cancellation
    next to the kink."""
    dmu = h * s * s
    mu = mc + dmu
    if mu <= 0:
        return 1.0
    resin = complex(eta * mu)
    t_nc = n_cos(eta, mu, n_tio2)
    m_nc = eta * cmath.sqrt(complex(dmu * (mu + mc)))
    m_nc = -m_nc if m_nc.imag < 0 else m_nc
    p = math.exp(-4 * math.pi * d_mica * m_nc.imag / lam_nm)
    out = 0.0
    for pol in "sp":
        rf, tf = film(resin, n_tio2, t_nc, m_nc, d_tio2, lam_nm, pol, eta, n_mica)
        rb, tb = film(m_nc, n_tio2, t_nc, resin, d_tio2, lam_nm, pol, n_mica, eta)
        out += 0.5 * (rf + tf * tb * p * p * rb / (1 - rb * p * p * rb) if tf != 0 else rf)
    return min(max(out, 0.0), 1.0)


def coefficients(vals):
    return [(1 if k == 0 else 2) / N * sum(v * math.cos(math.pi * k * (j + 0.5) / N) for j, v in enumerate(vals))
            for k in range(N)]


def clenshaw(c, t):
    b1 = b2 = 0.0
    for ck in reversed(c[1:]):
        b1, b2 = ck + 2 * t * b1 - b2, b1
    return c[0] + t * b1 - b2


def piece_deviation(f, lo, hi, skip_lo=False):
    """Largest |interpolant - f| at the 17 Lobatto points of [lo, hi] (without lo when skip_lo)."""
    c = coefficients([f(0.5 * (lo + hi) + 0.5 * (hi - lo) * x) for x in NODES])
    worst = 0.0
    for j in range(N + 1):
        if skip_lo and j == N:
            continue
        t = math.cos(math.pi * j / N)
        worst = max(worst, abs(clenshaw(c, t) - f(0.5 * (lo + hi) + 0.5 * (hi - lo) * t)))
    return worst


def main():
    lams = [700.0, 546.1, 435.8]
    print("Uniform tables (no kink below the mica's index), largest deviation over the 3 samples:")
    for eta in [1.5, 1.54, 1.56, 1.58]:
        row = []
        for pieces in [8, 16, 32, 64, 128, 1024]:
            w = max(piece_deviation(lambda x: rho(x, eta, lam), p / pieces, (p + 1) / pieces)
                    for lam in lams for p in range(pieces))
            row.append(f"{pieces}: {w:.1e}")
        print(f"  eta {eta}: " + ", ".join(row), flush=True)
    print("Tables cut at the kink (mu = mu_c + h s^2; pieces a segment), largest deviation over the 3 samples:")
    for eta in [1.59, 1.6]:
        mc = math.sqrt(1 - (1.58 / eta) ** 2)
        row = []
        for per in [4, 8, 16, 32, 64]:
            w = max(piece_deviation(lambda s: rho(mc + h * s * s, eta, lam), p / per, (p + 1) / per, p == 0)
                    for lam in lams for h in [-mc, 1 - mc] for p in range(per))
            row.append(f"{2 * per}: {w:.1e}")
        print(f"  eta {eta} (mu_c {mc:.4f}): " + ", ".join(row), flush=True)
    print("The same, the mica's cosine from the segment variable (rho_on_segment):")
    for eta in [1.59, 1.6]:
        mc = math.sqrt(1 - (1.58 / eta) ** 2)
        row = []
        for per in [4, 8, 16, 32, 64]:
            w = max(piece_deviation(lambda s: rho_on_segment(s, h, mc, eta, lam), p / per, (p + 1) / per, p == 0)
                    for lam in lams for h in [-mc, 1 - mc] for p in range(per))
            row.append(f"{2 * per}: {w:.1e}")
        print(f"  eta {eta}: " + ", ".join(row), flush=True)


if __name__ == "__main__":
    main()
