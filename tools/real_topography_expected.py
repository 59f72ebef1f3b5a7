#!/usr/bin/env python3
"""Writes fixtures/topography/real/expected.json: the statistics of the real measured surface
fixtures/topography/real/sample-land.x3p computed here with NumPy, independently of glossmeter's code
(docs/topography.md §Fixtures); tests/topography.rs compares what glossmeter reads with them.

The file is read with zipfile and NumPy alone: its members sit in one top folder (`sample-land/main.xml`,
`sample-land/bindata/data.bin`), the heights are CZ DataType D (little-endian f64, x fastest), NaN where the
microscope returned no height. Levelling: the least-squares polynomial of total degree 2 in
u = 2i/(Nx − 1) − 1, v = 2j/(Ny − 1) − 1 over the valid points (docs/topography.md §Levelling); then Sq, Sa,
Sdq from the cells of four valid points (the bilinear gradient at the cell's centre, §Slopes), the tilt removed
and the PSD's power (NumPy FFT, invalid points filled with 0 and the power scaled by N/N_valid, §Power spectral
density).

Usage: python3 tools/real_topography_expected.py  (from the repository root; NumPy ≥ 1.17).
"""
import json
import re
import zipfile

import numpy as np

PATH = "fixtures/topography/real/sample-land.x3p"
OUT = "fixtures/topography/real/expected.json"


def read_x3p(path):
    with zipfile.ZipFile(path) as zf:
        xml = zf.read("sample-land/main.xml").decode()
        data = zf.read("sample-land/bindata/data.bin")

    def tag(name, text=xml):
        return re.search(rf"<{name}>([^<]*)</{name}>", text).group(1)

    cx = re.search(r"<CX>(.*?)</CX>", xml, re.S).group(1)
    cy = re.search(r"<CY>(.*?)</CY>", xml, re.S).group(1)
    nx, ny = int(tag("SizeX")), int(tag("SizeY"))
    z = np.frombuffer(data, dtype="<f8").reshape(ny, nx).astype(float)
    return z, float(tag("Increment", cx)), float(tag("Increment", cy))


def stats(z, dx, dy, degree=2):
    ny, nx = z.shape
    valid = np.isfinite(z)
    jj, ii = np.mgrid[0:ny, 0:nx]
    u = 2 * ii / (nx - 1) - 1
    v = 2 * jj / (ny - 1) - 1
    powers = [(a, b) for a in range(degree + 1) for b in range(degree + 1 - a)]
    a = np.stack([u[valid] ** p * v[valid] ** q for p, q in powers], axis=1)
    coef, *_ = np.linalg.lstsq(a, z[valid], rcond=None)
    form = sum(c * u**p * v**q for c, (p, q) in zip(coef, powers))
    lev = np.where(valid, z - form, np.nan)
    h = lev[valid]
    cell = valid[:-1, :-1] & valid[1:, :-1] & valid[:-1, 1:] & valid[1:, 1:]
    gx = (lev[:-1, 1:] - lev[:-1, :-1] + lev[1:, 1:] - lev[1:, :-1]) / (2 * dx)
    gy = (lev[1:, :-1] - lev[:-1, :-1] + lev[1:, 1:] - lev[:-1, 1:]) / (2 * dy)
    filled = np.where(valid, lev, 0.0)
    n = nx * ny
    s = dx * dy * np.abs(np.fft.fft2(filled)) ** 2 / n * (n / valid.sum())
    c10 = coef[powers.index((1, 0))]
    c01 = coef[powers.index((0, 1))]
    return {
        "waves_um": waves(lev, dx),
        "points": [nx, ny],
        "invalid": int(n - valid.sum()),
        "sq_um": float(np.sqrt(np.mean(h**2))) * 1e6,
        "sa_um": float(np.mean(np.abs(h))) * 1e6,
        "sdq": float(np.sqrt(np.mean(gx[cell] ** 2 + gy[cell] ** 2))),
        "psd_power_um2": float(s.sum() / (nx * dx * ny * dy)) * 1e12,
        "tilt_x": float(c10 / ((nx - 1) * dx / 2)),
        "tilt_y": float(c01 / ((ny - 1) * dy / 2)),
    }


# The orange-peel bands of docs/topography.md §Orange-peel bands, mm (as `topography::waves::BANDS`).
BANDS = [("Wa", 0.1, 0.3), ("Wb", 0.3, 1.0), ("Wc", 1.0, 3.0), ("Wd", 3.0, 10.0), ("We", 10.0, 30.0),
         ("SW", 0.3, 1.2), ("LW", 1.2, 12.0)]


def waves(lev, dx):
    """The rms height (µm) of the rows' components in each band the map resolves, by numpy.fft.rfft: rows with
    at least half their points valid, less the mean of those, invalid points at it, power × N/N_valid."""
    ny, nx = lev.shape
    length = nx * dx
    k = np.arange(nx // 2 + 1)
    fold = np.where((k == 0), 0.0, np.where(2 * k == nx, 1.0, 2.0))
    spectra = []
    for r in lev:
        ok = np.isfinite(r)
        if 2 * ok.sum() < nx:
            continue
        u = np.where(ok, r - r[ok].mean(), 0.0)
        spectra.append(fold * np.abs(np.fft.rfft(u)) ** 2 / nx**2 * (nx / ok.sum()))
    power = np.mean(spectra, axis=0)
    out = {"rows": len(spectra)}
    with np.errstate(divide="ignore"):
        wavelength = np.where(k > 0, length / np.maximum(k, 1), np.inf)
    for name, lo, hi in BANDS:
        lo, hi = lo * 1e-3, hi * 1e-3
        if hi <= length and lo >= 2 * dx:
            out[name] = float(np.sqrt(power[(wavelength >= lo) & (wavelength < hi)].sum())) * 1e6
    return out


def main():
    z, dx, dy = read_x3p(PATH)
    doc = {
        "provenance": f"tools/real_topography_expected.py (NumPy {np.__version__}), poly2 levelling, cells' bilinear gradients",
        "sample_land_poly2": stats(z, dx, dy),
    }
    with open(OUT, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
