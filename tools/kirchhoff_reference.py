#!/usr/bin/env python3
"""An independent NumPy reference for the scalar Kirchhoff (Beckmann-Kirchhoff) reading of a topography by FFT
(docs/topography.md §Fixtures: the kirchhoff/ folder). Run by hand; it writes

* fixtures/topography/kirchhoff/*.gsf   the test surfaces (Gwyddion Simple Field, f32 heights in metres);
* fixtures/topography/kirchhoff/reference.json   per surface, per edge treatment, per ASTM D523 angle: the flux
  fraction, the gloss and this script's own discretisation-error estimate, with a provenance header;

and prints its self-checks (a flat map, Parseval, a sinusoidal grating against Bessel J_m², the Gaussian
surfaces' specular cell against exp(-(q_z σ)²)).

The spec (shared with the Rust implementation, written independently of it):

* heights z (Nx × Ny, spacings dx, dy in metres), levelled by a least-squares plane over the valid points
  (invalid = NaN points have weight 0); wavelength λ = 560 nm, k = 2π/λ;
* edge "periodic": w = 1; edge "taper": w = the separable Hann window w(x)w(y), here the periodic ("DFT-even")
  form w[n] = sin²(π n / N), n = 0 … N-1 (the symmetric form numpy.hanning is also evaluated, to show how
  much the choice moves the readings: "taper_symmetric_hann_gloss");
* q_z = k (cos θi + cos θo,c), θo,c = θi for the gloss receptors (the specular); u = w·exp(i q_z z);
  U = FFT2(u) (numpy.fft.fft2: U(f) = Σ u exp(-2πi f·x)); p(f) = |U(f)|² / (N Σw²), Σ_f p = 1 (Parseval);
  f on numpy.fft.fftfreq's grid, f_x along the map's x (the plane of measurement, docs/instrument.md §1.1);
* the scattered ray leaving cell f: its direction cosines (o_x, o_y) = mirror(s) − λ f, with mirror(s) =
  (-s_x, -s_y), s the source direction, o_z = sqrt(1 - o_x² - o_y²) (cells with o_x² + o_y² ≥ 1 are lost);
  p(f) is spread uniformly over its cell [f - Δf/2, f + Δf/2], Δf = (1/(Nx dx), 1/(Ny dy));
* flux fraction into a receptor = ⟨Σ_f p(f) · R_F(n, θh) · overlap(cell f, receptor | s)⟩_s, the average over
  source directions s filling the source stop uniformly (constant radiance), weighted by cos θi dω_i as in
  docs/instrument.md §1.4 (dω = dp dq / (1 + p² + q²)^{3/2}); R_F the unpolarised Fresnel reflectance of
  index n at the half angle θh between s and the ray (cos θh = sqrt((1 + s·o)/2): the facet that sends s into
  o), taken point by point over the cell's overlap;
* gloss = 100 × flux fraction / flux fraction of the black glass standard (n = 1.567, docs/instrument.md §1.5,
  the standards' "reference_index") read by the same formula (a flat map: p = δ(f)), through the same stops.

Stops (docs/instrument.md §1.1-§1.2): the stops of standards/astm-d523-{20,60,85}.json, rectangles in the
tangent coordinates (p, q) of their lens axis: p ∈ [tan(δ - a/2), tan(δ + a/2)], q ∈ [-tan(b/2), tan(b/2)];
point (p, q) is the direction normalize(axis + p e∥ + q e⊥). Source axis s0 = (-sin θ, 0, cos θ), e∥ =
(cos θ, 0, sin θ); receptor axis r0 = (sin θ, 0, cos θ), e∥ = (cos θ, 0, -sin θ); e⊥ = (0, 1, 0). A direction o
is inside the receptor when o·r0 > 0 and its gnomonic coordinates p = o·e∥/o·r0, q = o·e⊥/o·r0 fall in the
rectangle (the exact inverse of the map above).

How this script averages (its own method, not the Rust side's): the surface-independent acceptance kernel
K_n(f) = ⟨R_F(n, θh) · overlap(cell f, receptor | s)⟩_s is computed per geometry, for the sample's index and
the standard's, by stratified jittered sampling of the source rectangle (NS × NS strata in (p, q), weight
cos θi /(1 + p² + q²)^{3/2}) crossed with stratified jittered sub-cell offsets (NC × NC strata); then flux =
Σ_f p(f) K_n(f), and the standard's flux K_nref(0). R independent replicates (independent jitter) each give a
gloss (its sample and its standard from the same samples); the error estimate is 3 × the standard error of
the replicates' mean plus the range of the replicates / R (conservative).

The sign of f. With u = exp(+i q_z z) and a forward FFT exp(-2πi f·x), a tilt z = αx puts the power at
f_x = +2α cosθ/λ; geometrical optics sends the reflection of a plane tilted towards the source (α > 0) to
smaller o_x (mirror - 2α cos θ), so the ray of cell f leaves along mirror − λ f (the self-check "sign_of_f"
shows it). The first version of this script used mirror + λ f; its readings are kept beside the others as
"gloss_mirrored_f" (p(f) read at -f), so the difference is visible (it vanishes for a map symmetric under
x → -x, y → -y).

Usage: python3 tools/kirchhoff_reference.py  (from the repository root; NumPy ≥ 1.17; SciPy optional, for the
Bessel self-check, otherwise a power series is used).
"""
import datetime
import json
import os
import sys

import numpy as np

OUT = os.environ.get("KR_OUT", "fixtures/topography/kirchhoff/")  # KR_*: only for the convergence check
LAMBDA = 560e-9
K = 2 * np.pi / LAMBDA
N, DX = 256, 4e-6  # 256 × 256 points 4 µm apart: a 1.024 mm map
IOR = 1.5  # the sample's index (the recipe's "ior")
GEOMETRIES = ["astm-d523-20", "astm-d523-60", "astm-d523-85"]
# source strata per axis, sub-cell strata per axis, independent replicates (KR_NS, KR_NC, KR_R, KR_SEED override
# them for the convergence check of the README: a finer independent run writing elsewhere with KR_OUT)
NS, NC, REPLICATES = (int(os.environ.get(k, d)) for k, d in [("KR_NS", 24), ("KR_NC", 4), ("KR_R", 4)])
SEED = int(os.environ.get("KR_SEED", 20261206))


# --------------------------------------------------------------------------------------------- surfaces
def filtered_noise(seed, amplitude_filter, sq):
    """Seeded white noise (NumPy PCG64) filtered in the Fourier domain by amplitude_filter(|f| grid), scaled to
    Sq = sq (float64). Periodic by construction."""
    rng = np.random.Generator(np.random.PCG64(seed))
    noise = rng.standard_normal((N, N))
    fx = np.fft.fftfreq(N, DX)
    fr = np.sqrt(fx[None, :] ** 2 + fx[:, None] ** 2)
    z = np.real(np.fft.ifft2(np.fft.fft2(noise) * amplitude_filter(fr)))
    z -= z.mean()
    return z * (sq / np.sqrt(np.mean(z**2)))


ELL = 10e-6  # Gaussian PSD S ∝ exp(-(π ℓ |f|)²): autocovariance σ² exp(-r²/ℓ²), ℓ = 10 µm


def gaussian(fr):
    return np.sqrt(np.exp(-((np.pi * ELL * fr) ** 2)))


def orange_peel(fr):
    # a flat-topped band between the wavelengths 300 µm and 100 µm (|f| = 3.33 … 10 /mm), Hann-rolled edges
    lo, hi = 1 / 300e-6, 1 / 100e-6
    t = np.clip((fr - lo) / (hi - lo), 0, 1)
    band = (fr >= lo) & (fr <= hi)
    return band * np.sin(np.pi * t) ** 0.5


SURFACES = [
    ("gauss-5nm", "Gaussian random surface, Sq 5 nm, Gaussian PSD, correlation length 10 µm", 101, gaussian, 5e-9),
    ("gauss-20nm", "Gaussian random surface, Sq 20 nm, Gaussian PSD, correlation length 10 µm", 102, gaussian, 20e-9),
    ("gauss-60nm", "Gaussian random surface, Sq 60 nm, Gaussian PSD, correlation length 10 µm", 103, gaussian, 60e-9),
    ("orange-peel", "orange-peel-like long waves: band 100-300 µm wavelength (sin^(1/2) band weight), Sq 0.2 µm "
     "(component amplitudes ~0.3 µm)", 104, orange_peel, 0.2e-6),
]


def write_gsf(path, z, title):
    """GSF as tools/make_topography_fixtures.py writes it (docs/topography.md §Gwyddion GSF): header, NUL
    padding to a multiple of 4, little-endian f32 rows (x fastest)."""
    ny, nx = z.shape
    header = (f"Gwyddion Simple Field 1.0\nXRes = {nx}\nYRes = {ny}\nXReal = {nx * DX!r}\nYReal = {ny * DX!r}\n"
              f"XYUnits = m\nZUnits = m\nTitle = {title}\n").encode()
    header += b"\0" * (4 - len(header) % 4)
    with open(path, "wb") as f:
        f.write(header + z.astype("<f4").tobytes())


def read_gsf(path):
    """Reads back what was written: the f32 heights (as float64) and the spacings."""
    data = open(path, "rb").read()
    end = data.index(b"\0")
    keys = dict(line.split(" = ", 1) for line in data[:end].decode().splitlines()[1:])
    nx, ny = int(keys["XRes"]), int(keys["YRes"])
    start = end + (4 - end % 4)
    z = np.frombuffer(data[start:start + 4 * nx * ny], dtype="<f4").astype(np.float64).reshape(ny, nx)
    return z, float(keys["XReal"]) / nx, float(keys["YReal"]) / ny


# --------------------------------------------------------------------------------------------- the spec
def level(z):
    """Least-squares plane over the valid points (NaN: weight 0); invalid points stay NaN."""
    ny, nx = z.shape
    valid = np.isfinite(z)
    jj, ii = np.mgrid[0:ny, 0:nx]
    a = np.stack([np.ones(valid.sum()), ii[valid].astype(float), jj[valid].astype(float)], axis=1)
    c, *_ = np.linalg.lstsq(a, z[valid], rcond=None)
    return z - (c[0] + c[1] * ii + c[2] * jj)


def hann(n, symmetric=False):
    if symmetric:
        return np.hanning(n)
    return np.sin(np.pi * np.arange(n) / n) ** 2


def power(z, qz, edge, symmetric_hann=False):
    """p(f) on numpy's FFT grid (index [j, i] = (f_y, f_x)); invalid points have u = 0."""
    ny, nx = z.shape
    if edge == "periodic":
        w = np.ones((ny, nx))
    else:
        w = hann(ny, symmetric_hann)[:, None] * hann(nx, symmetric_hann)[None, :]
    valid = np.isfinite(z)
    w = np.where(valid, w, 0.0)
    u = w * np.exp(1j * qz * np.where(valid, z, 0.0))
    U = np.fft.fft2(u)
    return np.abs(U) ** 2 / (nx * ny * np.sum(w**2))


def fresnel(n, theta):
    """Unpolarised Fresnel reflectance of a dielectric of index n from air at angle theta (radians)."""
    return fresnel_cos(n, np.cos(theta))


def fresnel_cos(n, c):
    """The same at the cosine c of the angle of incidence (an array)."""
    s2 = 1 - c**2
    ct = np.sqrt(1 - s2 / n**2)
    rs = (c - n * ct) / (c + n * ct)
    rp = (n * c - ct) / (n * c + ct)
    return 0.5 * (rs**2 + rp**2)


# --------------------------------------------------------------------------------------------- the instrument
def load_geometry(gid):
    g = json.load(open(f"standards/{gid}.json"))
    src = g["source"]
    rec = next(r for r in g["receptors"] if r["name"] == g["readings"][0]["receptor"])
    return {
        "id": gid,
        "theta": np.radians(g["angle_deg"]["value"]),
        "n_ref": g["scale"]["reference_index"]["value"],
        "assigned": g["scale"]["assigned_gu"]["value"],
        "source": stop(src["in_plane_deg"]["value"], src["perpendicular_deg"]["value"], 0.0),
        "receptor": stop(rec["in_plane_deg"]["value"], rec["perpendicular_deg"]["value"], rec["offset_deg"]["value"]),
    }


def stop(a_deg, b_deg, offset_deg):
    """docs/instrument.md §1.2: Stop::from_angles(a, b, δ) in tangent coordinates."""
    a, b, d = np.radians([a_deg, b_deg, offset_deg])
    return (np.tan(d - a / 2), np.tan(d + a / 2), -np.tan(b / 2), np.tan(b / 2))


def source_samples(geo, rng):
    """Stratified jittered source points in tangent coordinates: (s_x, s_y, weight ∝ cos θi dω)."""
    p0, p1, q0, q1 = geo["source"]
    t = geo["theta"]
    g = (np.arange(NS)[:, None] + rng.random((NS, NS))) / NS
    h = (np.arange(NS)[None, :] + rng.random((NS, NS))) / NS
    p = (p0 + (p1 - p0) * g).ravel()
    q = (q0 + (q1 - q0) * h).ravel()
    norm = np.sqrt(1 + p**2 + q**2)
    sx = (-np.sin(t) + p * np.cos(t)) / norm
    sy = q / norm
    sz = (np.cos(t) + p * np.sin(t)) / norm
    weight = sz / norm**3
    return sx, sy, sz, weight / weight.sum()


def inside_receptor(ox, oy, geo):
    r2 = ox**2 + oy**2
    ok = r2 < 1
    oz = np.sqrt(np.where(ok, 1 - r2, 0.0))
    t = geo["theta"]
    d = ox * np.sin(t) + oz * np.cos(t)
    ok &= d > 0
    d = np.where(ok, d, 1.0)
    p = (ox * np.cos(t) - oz * np.sin(t)) / d
    q = oy / d
    p0, p1, q0, q1 = geo["receptor"]
    return ok & (p >= p0) & (p <= p1) & (q >= q0) & (q <= q1)


def kernel(geo, dfx, dfy, rng):
    """K_n[j, i] for the cell indices j, i ∈ [-N/2, N/2] (f = index × Δf), one replicate, for the sample's
    index n = IOR and the standard's n_ref: the source average of R_F(n, θh)·overlap, θh the half angle between
    the source direction and the ray (the facet that sends one into the other)."""
    sx, sy, sz, ws = source_samples(geo, rng)
    cu = ((np.arange(NC)[:, None] + rng.random((NC, NC))) / NC - 0.5).ravel()
    cv = ((np.arange(NC)[None, :] + rng.random((NC, NC))) / NC - 0.5).ravel()
    # joint samples: every source point with every sub-cell offset
    mx = (-sx)[:, None] + 0 * cu[None, :]
    my = (-sy)[:, None] + 0 * cv[None, :]
    du = np.broadcast_to(cu[None, :], mx.shape).ravel() * LAMBDA * dfx
    dv = np.broadcast_to(cv[None, :], mx.shape).ravel() * LAMBDA * dfy
    mx, my = mx.ravel(), my.ravel()
    sxj, syj, szj = (np.repeat(v, NC * NC) for v in (sx, sy, sz))
    wj = np.repeat(ws, NC * NC) / (NC * NC)
    idx = np.arange(-N // 2, N // 2 + 1)
    kern = np.zeros((idx.size, idx.size))
    kern_ref = np.zeros((idx.size, idx.size))
    # bounding box of the receptor's direction cosines (its edges sampled densely) → cells that can reach it
    p0, p1, q0, q1 = geo["receptor"]
    pe = np.concatenate([np.linspace(p0, p1, 400), np.full(400, p1), np.linspace(p1, p0, 400), np.full(400, p0)])
    qe = np.concatenate([np.full(400, q0), np.linspace(q0, q1, 400), np.full(400, q1), np.linspace(q1, q0, 400)])
    t = geo["theta"]
    nn = np.sqrt(1 + pe**2 + qe**2)
    ex, ey = (np.sin(t) + pe * np.cos(t)) / nn, qe / nn
    margin = 2.0
    fx_lo = (ex.min() - mx.max()) / (LAMBDA * dfx) - margin
    fx_hi = (ex.max() - mx.min()) / (LAMBDA * dfx) + margin
    fy_lo = (ey.min() - my.max()) / (LAMBDA * dfy) - margin
    fy_hi = (ey.max() - my.min()) / (LAMBDA * dfy) + margin
    ii = idx[(idx >= fx_lo) & (idx <= fx_hi)]
    jj = idx[(idx >= fy_lo) & (idx <= fy_hi)]
    cells = [(j, i) for j in jj for i in ii]
    chunk = max(1, 4_000_000 // mx.size)
    for c in range(0, len(cells), chunk):
        block = np.array(cells[c:c + chunk])
        ox = mx[None, :] + du[None, :] + LAMBDA * dfx * block[:, 1:2]
        oy = my[None, :] + dv[None, :] + LAMBDA * dfy * block[:, 0:1]
        oz = np.sqrt(np.clip(1 - ox**2 - oy**2, 0.0, None))
        cos_h = np.sqrt(np.clip(0.5 * (1 + sxj[None, :] * ox + syj[None, :] * oy + szj[None, :] * oz), 0.0, 1.0))
        inside = inside_receptor(ox, oy, geo)
        at = (block[:, 0] + N // 2, block[:, 1] + N // 2)
        kern[at] = (inside * fresnel_cos(IOR, cos_h)) @ wj
        kern_ref[at] = (inside * fresnel_cos(geo["n_ref"], cos_h)) @ wj
    return kern, kern_ref


def on_fft_grid(kern, ny, nx, at_minus_f=False):
    """K at numpy's fftfreq cell indices (or at their negatives: the ray of cell f leaving along mirror − λ f),
    as an (ny, nx) array."""
    iy = np.fft.fftfreq(ny, 1 / ny).astype(int)
    ix = np.fft.fftfreq(nx, 1 / nx).astype(int)
    if at_minus_f:
        iy, ix = -iy, -ix
    return kern[iy[:, None] + N // 2, ix[None, :] + N // 2]


# --------------------------------------------------------------------------------------------- self-checks
def bessel_j(m, x):
    try:
        from scipy.special import jv
        return float(jv(m, x))
    except ImportError:
        s, term = 0.0, (x / 2) ** abs(m) / np.prod(np.arange(1, abs(m) + 1, dtype=float))
        for k in range(60):
            s += term
            term *= -(x / 2) ** 2 / ((k + 1) * (k + 1 + abs(m)))
        return s * (-1) ** m if m < 0 else s


def self_checks(kernels, geos):
    out = {}
    # flat map: p = δ(0); flux fraction = K_n(0); the standard's index reads exactly the assigned value
    flat = {}
    for g in geos:
        kr = np.mean(kernels[g["id"]], axis=0)
        k0, std = kr[0, N // 2, N // 2], kr[1, N // 2, N // 2]
        flat[g["id"]] = {"K0": float(k0), "gloss_n_ref": float(100 * std / std),
                         "gloss_ior_1.5": float(100 * k0 / std)}
        print(f"  flat {g['id']}: K(0) = {float(k0)!r}, n = {g['n_ref']} reads {float(100 * std / std)!r} GU, "
              f"n = 1.5 reads {flat[g['id']]['gloss_ior_1.5']:.6f} GU")
    out["flat_map"] = flat
    # Bessel: z = a cos(2π x/Λ), 16 periods over the map, periodic edge, unlevelled heights
    a, periods = 50e-9, 16
    x = np.arange(N) * DX
    z = np.tile(a * np.cos(2 * np.pi * periods * x / (N * DX)), (N, 1))
    bess = {}
    for g in geos:
        qz = 2 * K * np.cos(g["theta"])
        p = power(z, qz, "periodic")
        worst = 0.0
        for m in range(-4, 5):
            want = bessel_j(m, qz * a) ** 2
            got = p[0, (m * periods) % N]
            worst = max(worst, abs(got - want))
        bess[g["id"]] = {"q_z_a": float(qz * a), "max_abs_error_orders_-4..4": worst,
                         "sum_p": float(p.sum())}
        print(f"  grating {g['id']}: q_z a = {qz * a:.4f}, max |p_m - J_m²| over m = -4..4: {worst:.2e}, "
              f"Σp = {float(p.sum())!r}")
    out["grating_bessel"] = bess
    # the sign of f: a plane tilted towards the source, z = αx (α > 0, an integer number m of phase cycles over
    # the map at 20°), reflects geometrically to o_x = sin θ − 2α cos θ + O(α²), i.e. to the cell f_x = −m; the
    # spec's p(f) (numpy's forward FFT of e^{+i q_z z}) has its power at f_x = +m
    g = geos[0]
    m = 5
    alpha = m * LAMBDA / (2 * N * DX * np.cos(g["theta"]))
    p = power(np.tile(alpha * np.arange(N) * DX, (N, 1)), 2 * K * np.cos(g["theta"]), "periodic")
    peak = int(np.fft.fftfreq(N, 1 / N)[np.argmax(p[0])])
    t = g["theta"]
    tilted = np.array([-alpha, 0.0, 1.0]) / np.sqrt(1 + alpha**2)  # the facet's normal
    s0 = np.array([-np.sin(t), 0.0, np.cos(t)])
    o = 2 * s0.dot(tilted) * tilted - s0
    geometric = (o[0] - np.sin(t)) / (LAMBDA / (N * DX))
    out["sign_of_f"] = {"alpha": alpha, "peak_cell_fx_of_spec": peak, "geometric_reflection_cell_fx": geometric}
    print(f"  sign of f: tilt α = {alpha:.3e} towards the source at 20°: p(f) peaks at cell f_x = {peak:+d}, "
          f"the geometrical reflection lies {geometric:+.3f} cells from the mirror (so o = mirror − λ f)")
    return out


# --------------------------------------------------------------------------------------------- main
def spread(values):
    """The error estimate of the replicates' mean: 3 × its standard error plus the replicates' range / R."""
    return 3 * values.std(ddof=1) / np.sqrt(REPLICATES) + np.ptp(values) / REPLICATES


def main():
    os.makedirs(OUT, exist_ok=True)
    geos = [load_geometry(g) for g in GEOMETRIES]
    dfx = dfy = 1 / (N * DX)
    kernels = {}
    for g in geos:
        rng = np.random.Generator(np.random.PCG64([SEED, GEOMETRIES.index(g["id"])]))
        kernels[g["id"]] = np.array([kernel(g, dfx, dfy, rng) for _ in range(REPLICATES)])
        print(f"kernel {g['id']}: Σ over cells of the replicates' spread "
              f"{np.abs(kernels[g['id']] - kernels[g['id']].mean(0)).max():.2e} (max per cell)", flush=True)
    print("self-checks:")
    checks = self_checks(kernels, geos)
    checks["parseval"] = {}
    checks["gaussian_specular"] = {}
    surfaces = {}
    for name, desc, seed, filt, sq in SURFACES:
        z64 = filtered_noise(seed, filt, sq)
        path = OUT + name + ".gsf"
        write_gsf(path, z64, desc)
        z, dx, dy = read_gsf(path)  # the f32 values written, read back
        assert abs(dx - DX) < 1e-15 and abs(dy - DX) < 1e-15
        zl = level(z)
        sq_l = float(np.sqrt(np.nanmean(zl**2)))
        entry = {"file": path, "description": desc, "seed": seed, "nx": N, "ny": N, "dx_m": DX, "dy_m": DX,
                 "sq_levelled_m": sq_l, "readings": {}}
        for edge in ["periodic", "taper"]:
            entry["readings"][edge] = {}
            for g in geos:
                qz = 2 * K * np.cos(g["theta"])
                p = power(zl, qz, edge)
                psum = float(p.sum())
                checks["parseval"][f"{name}/{edge}/{g['id']}"] = psum - 1
                reps = kernels[g["id"]]  # (replicate, sample | standard, cell j, cell i)
                stds = reps[:, 1, N // 2, N // 2]  # each replicate's flat standard
                ff = np.array([np.sum(p * on_fft_grid(kr[0], N, N, True)) for kr in reps])
                ff_o = np.array([np.sum(p * on_fft_grid(kr[0], N, N)) for kr in reps])
                glosses = g["assigned"] * ff / stds  # a replicate's sample and standard share its samples
                gloss = glosses.mean()
                rec = {
                    "flux_fraction": float(ff.mean()),
                    "flux_fraction_error": float(spread(ff)),
                    "flux_fraction_standard": float(stds.mean()),
                    "gloss": float(gloss),
                    "gloss_error": float(spread(glosses)),
                    "gloss_mirrored_f": float(np.mean(g["assigned"] * ff_o / stds)),
                    "specular_cell_power": float(p[0, 0]),
                    "sum_p": psum,
                }
                if edge == "taper":
                    ps = power(zl, qz, edge, symmetric_hann=True)
                    fs = np.array([np.sum(ps * on_fft_grid(kr[0], N, N, True)) for kr in reps])
                    rec["taper_symmetric_hann_gloss"] = float(np.mean(g["assigned"] * fs / stds))
                if edge == "periodic" and name.startswith("gauss"):
                    want = float(np.exp(-((qz * sq_l) ** 2)))
                    checks["gaussian_specular"][f"{name}/{g['id']}"] = {
                        "p0": float(p[0, 0]), "exp(-(q_z Sq)^2)": want, "ratio": float(p[0, 0] / want)}
                entry["readings"][edge][g["id"]] = rec
                print(f"{name:12s} {edge:8s} {g['id']}: flux {rec['flux_fraction']:.6e} ± {rec['flux_fraction_error']:.1e}, gloss {gloss:9.4f} "
                      f"± {rec['gloss_error']:.1e} (mirrored f {rec['gloss_mirrored_f']:9.4f}"
                      + (f", symmetric Hann {rec['taper_symmetric_hann_gloss']:9.4f}" if edge == "taper" else "")
                      + f"), p(0) {p[0, 0]:.4e}, Σp-1 {psum - 1:.1e}", flush=True)
        surfaces[name] = entry
    print("  Parseval: max |Σp - 1| =", max(abs(v) for v in checks["parseval"].values()))
    for k, v in checks["gaussian_specular"].items():
        print(f"  specular {k}: p(0) = {v['p0']:.5f}, exp(-(q_z Sq)²) = {v['exp(-(q_z Sq)^2)']:.5f}, "
              f"ratio {v['ratio']:.4f}")
    header = {
        "script": "tools/kirchhoff_reference.py",
        "numpy": np.__version__,
        "python": sys.version.split()[0],
        "date_utc": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "wavelength_m": LAMBDA,
        "ior": IOR,
        "levelling": "least-squares plane over the valid points",
        "q_z": "k (cos θi + cos θo,c), θo,c = θi (the gloss receptor's centre is the specular)",
        "power": "p(f) = |FFT2(w exp(i q_z z))|² / (N Σw²), numpy.fft.fft2 (exp(-2πi f·x)), fftfreq grid",
        "direction": "(o_x, o_y) = (-s_x, -s_y) - λ f; p(f) uniform over its cell; o_x² + o_y² ≥ 1 lost",
        "edges": {"periodic": "w = 1", "taper": "w = h(x) h(y), h[n] = sin²(π n / N) (periodic Hann)"},
        "source_average": "uniform radiance over the source stop, weight cos θi dω (docs/instrument.md §1.4)",
        "fresnel": "unpolarised R_F(n, θh) at the half angle between the source direction and the ray, point by "
                   "point; sample n = ior, standard n = reference_index (1.567) read by the same formula as a "
                   "flat map",
        "stops": "standards/astm-d523-{20,60,85}.json, docs/instrument.md §1.2 tangent coordinates",
        "method": f"kernel K(f) by stratified jittered sampling: {NS}x{NS} source strata × {NC}x{NC} sub-cell "
                  f"strata per replicate, {REPLICATES} independent replicates (seed {SEED})",
        "error_estimate": "3 × standard error of the replicates' mean + their range / R, of the flux fraction and "
                          "of the gloss (each replicate's gloss from its own sample and standard fluxes)",
        "mirrored_f": "gloss_mirrored_f: the direction (-s_x, -s_y) + λ f of the script's first version",
        "surfaces": "white noise (PCG64, per-surface seed) filtered in the Fourier domain, float64, written "
                    "as f32 GSF; the reference is computed from the f32 values read back",
    }
    doc = {"header": header, "self_checks": checks, "surfaces": surfaces}
    with open(OUT + "reference.json", "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    print("wrote", OUT + "reference.json")


if __name__ == "__main__":
    main()
