#!/usr/bin/env python3
"""Writes the topography fixtures of fixtures/topography/ (docs/topography.md §Fixtures) and, beside them,
`expected.json`: the same statistics computed here with NumPy, independently of glossmeter's code, which
tests/topography.rs compares with what glossmeter reads.

The surface: a Gaussian random surface of 64 × 64 points, 1 µm apart, with the Gaussian PSD
S(f) ∝ exp(−(π ℓ |f|)²), ℓ = 8 µm (autocovariance σ² exp(−r²/ℓ²)), scaled to Sq = 0.1 µm, from seeded white
noise (NumPy's PCG64, seed 41) filtered in the Fourier domain (random phases, the PSD's amplitudes). It is
written, the same heights each time, as:

* gaussian.x3p          ISO 25178-72: main.xml + bindata/data.bin (D, f64) + md5checksum.hex;
* gaussian-masked.x3p   the same with I (i16) data, CZ Increment 1 nm, and bindata/valid.bin marking 3 points
                        invalid (one bit per point, least significant bit first);
* gaussian.gsf          Gwyddion Simple Field (f32 heights: compared at f32 precision);
* gaussian-text.sdf     ISO 25178-71 text form, DataType 7 (f64), Zscale 1e-9 (heights in nm, 17 digits);
* gaussian-binary.sdf   ISO 25178-71 binary form, DataType 7 (f64);
* gaussian.csv          a comma-separated matrix in µm (17 digits): read with --pixel-size 1um --height-unit um;
* gaussian.sur          Digital Surf (docs/topography.md §Digital Surf SUR): 32-bit integers, Z step 1e-5 µm (as
                        f32), Z offset 0.5 µm, a comment and a private zone, the points of INVALID non-measured
                        (zmin − 2).

Usage: python3 tools/make_topography_fixtures.py  (from the repository root; NumPy ≥ 1.17).
"""
import hashlib
import io
import json
import struct
import zipfile

import numpy as np

OUT = "fixtures/topography/"
NX, NY, DX = 64, 64, 1e-6
SQ, ELL = 0.1e-6, 8e-6
INVALID = [(3, 0), (10, 20), (63, 63)]  # (i, j) points masked in gaussian-masked.x3p and gaussian.sur


def surface():
    rng = np.random.Generator(np.random.PCG64(41))
    noise = rng.standard_normal((NY, NX))
    fx = np.fft.fftfreq(NX, DX)
    fy = np.fft.fftfreq(NY, DX)
    f2 = fx[None, :] ** 2 + fy[:, None] ** 2
    amp = np.sqrt(np.exp(-((np.pi * ELL) ** 2) * f2))
    z = np.real(np.fft.ifft2(np.fft.fft2(noise) * amp))
    z -= z.mean()
    return z * (SQ / np.sqrt(np.mean(z**2)))


def stats(z, dx, dy, mask=None):
    """Plane levelling by least squares over the valid points, then Sq, Sa, Sdq (cells of four valid points,
    the bilinear gradient at the cell centre) and the PSD's power (NumPy FFT, N/N_valid normalisation)."""
    ny, nx = z.shape
    valid = np.ones_like(z, dtype=bool) if mask is None else mask
    jj, ii = np.mgrid[0:ny, 0:nx]
    u = 2 * ii / (nx - 1) - 1
    v = 2 * jj / (ny - 1) - 1
    a = np.stack([np.ones(valid.sum()), u[valid], v[valid]], axis=1)
    coef, *_ = np.linalg.lstsq(a, z[valid], rcond=None)
    lev = z - (coef[0] + coef[1] * u + coef[2] * v)
    h = lev[valid]
    sq = float(np.sqrt(np.mean(h**2)))
    sa = float(np.mean(np.abs(h)))
    cell = valid[:-1, :-1] & valid[1:, :-1] & valid[:-1, 1:] & valid[1:, 1:]
    gx = (lev[:-1, 1:] - lev[:-1, :-1] + lev[1:, 1:] - lev[1:, :-1]) / (2 * dx)
    gy = (lev[1:, :-1] - lev[:-1, :-1] + lev[1:, 1:] - lev[:-1, 1:]) / (2 * dy)
    sdq = float(np.sqrt(np.mean(gx[cell] ** 2 + gy[cell] ** 2)))
    filled = np.where(valid, lev, 0.0)
    n = nx * ny
    s = dx * dy * np.abs(np.fft.fft2(filled)) ** 2 / n * (n / valid.sum())
    power = float(s.sum() / (nx * dx * ny * dy))
    return {"sq_um": sq * 1e6, "sa_um": sa * 1e6, "sdq": sdq, "psd_power_um2": power * 1e12,
            "tilt_x": float(coef[1] / ((nx - 1) * dx / 2)), "tilt_y": float(coef[2] / ((ny - 1) * dy / 2))}


def main_xml(ty, z_increment, link):
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<p:ISO5436_2 xmlns:p="http://www.opengps.eu/2008/ISO5436_2" xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance">
 <Record1>
  <Revision>ISO5436 - 2000</Revision>
  <FeatureType>SUR</FeatureType>
  <Axes>
   <CX><AxisType>I</AxisType><DataType>D</DataType><Increment>{DX!r}</Increment><Offset>0</Offset></CX>
   <CY><AxisType>I</AxisType><DataType>D</DataType><Increment>{DX!r}</Increment><Offset>0</Offset></CY>
   <CZ><AxisType>A</AxisType><DataType>{ty}</DataType><Increment>{z_increment!r}</Increment><Offset>0</Offset></CZ>
  </Axes>
 </Record1>
 <Record2>
  <Date>2026-12-05T00:00:00+00:00</Date>
  <Instrument><Manufacturer>glossmeter</Manufacturer><Model>tools/make_topography_fixtures.py</Model><Serial>0</Serial><Version>1</Version></Instrument>
  <CalibrationDate>2026-12-05T00:00:00+00:00</CalibrationDate>
  <ProbingSystem><Type>NonContacting</Type><Identification>synthetic</Identification></ProbingSystem>
  <Comment>Gaussian random surface, Sq 0.1 um, correlation length 8 um, seed 41</Comment>
 </Record2>
 <Record3>
  <MatrixDimension><SizeX>{NX}</SizeX><SizeY>{NY}</SizeY><SizeZ>1</SizeZ></MatrixDimension>
  {link}
 </Record3>
 <Record4><ChecksumFile>md5checksum.hex</ChecksumFile></Record4>
</p:ISO5436_2>
"""


def x3p(path, xml, members):
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
        # Fixed timestamps: the same bytes on every run.
        def put(name, data):
            info = zipfile.ZipInfo(name, date_time=(2026, 12, 5, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            zf.writestr(info, data)

        put("main.xml", xml.encode())
        put("md5checksum.hex", (hashlib.md5(xml.encode()).hexdigest() + " *main.xml\n").encode())
        for name, data in members:
            put(name, data)
    open(path, "wb").write(buf.getvalue())


def sur(path, z, mask):
    """Write z (metres) as a Digital Surf .sur surface, its masked points non-measured; return the heights, metres,
    as a reader computes them from the file (value·Δz + offset in µm, Δz and the offset the header's f32)."""
    dz = float(np.float32(1e-5))  # µm a count
    offset = 0.5  # µm
    zi = np.round((z * 1e6 - offset) / dz).astype("<i4")
    zmin, zmax = int(zi.min()), int(zi.max())
    zi[~mask] = zmin - 2
    comment, private = b"Gaussian random surface, seed 41", b"\x01\x02\x03\x04\x05\x06\x07\x08"
    h = bytearray(512)

    def put(at, fmt, *v):
        struct.pack_into("<" + fmt, h, at, *v)

    put(0, "12s", b"DIGITAL SURF")
    put(12, "3h", 0, 1, 1)  # PC format, one object, version 1
    put(18, "h", 2)  # a surface
    put(20, "30s", b"gaussian")
    put(86, "h", 1)  # non-measured points present
    put(98, "h", 32)
    put(100, "5i", zmin, zmax, NX, NY, NX * NY)
    put(120, "3f", DX * 1e6, DX * 1e6, dz)
    for k, name in enumerate([b"X", b"Y", b"Z"] + [b"\xb5m"] * 6):  # axis names, step units, length units (Latin-1)
        put(132 + 16 * k, "16s", name)
    put(276, "3f", 1.0, 1.0, 1.0)
    put(334, "2h", len(comment), len(private))
    put(474, "f", offset)
    open(path, "wb").write(bytes(h) + comment + private + zi.tobytes())
    dz_m = float(np.float32(dz)) * 1e-6
    zs = zi.astype(float) * dz_m + float(np.float32(offset)) * 1e-6
    return np.where(mask, zs, 0.0)


def main():
    z = surface()
    link = "<DataLink><PointDataLink>bindata/data.bin</PointDataLink><MD5ChecksumPointData>{}</MD5ChecksumPointData></DataLink>"
    data = z.astype("<f8").tobytes()
    x3p(OUT + "gaussian.x3p", main_xml("D", 1.0, link.format(hashlib.md5(data).hexdigest())), [("bindata/data.bin", data)])

    # Integer data in nm, three points invalid.
    zi = np.round(z * 1e9).astype("<i2")
    mask = np.ones((NY, NX), dtype=bool)
    for i, j in INVALID:
        mask[j, i] = False
    bits = np.packbits(mask.ravel(), bitorder="little").tobytes()
    ilink = ("<DataLink><PointDataLink>bindata/data.bin</PointDataLink><ValidPointsLink>bindata/valid.bin"
             "</ValidPointsLink></DataLink>")
    x3p(OUT + "gaussian-masked.x3p", main_xml("I", 1e-9, ilink), [("bindata/data.bin", zi.tobytes()), ("bindata/valid.bin", bits)])

    # GSF: f32 heights in metres.
    header = f"Gwyddion Simple Field 1.0\nXRes = {NX}\nYRes = {NY}\nXReal = {NX * DX!r}\nYReal = {NY * DX!r}\nXYUnits = m\nZUnits = m\nTitle = Gaussian random surface\n".encode()
    header += b"\0" * (4 - len(header) % 4)
    open(OUT + "gaussian.gsf", "wb").write(header + z.astype("<f4").tobytes())

    # SDF text and binary, f64 heights in nm (Zscale 1e-9).
    znm = z * 1e9
    text = ("aISO-1.0\nManufacID   = glossmeter\nCreateDate  = 051220260000\nModDate     = 051220260000\n"
            f"NumPoints   = {NX}\nNumProfiles = {NY}\nXscale      = {DX!r}\nYscale      = {DX!r}\nZscale      = 1e-09\n"
            "Zresolution = -1\nCompression = 0\nDataType    = 7\nCheckType   = 0\n*\n")
    text += "\n".join(" ".join(repr(float(v)) for v in row) for row in znm) + "\n*\n"
    open(OUT + "gaussian-text.sdf", "w").write(text)
    head = b"bISO-1.0" + b"glossmeter" + b"051220260000" * 2 + struct.pack("<HH4d3B", NX, NY, DX, DX, 1e-9, -1.0, 0, 7, 0)
    assert len(head) == 81
    open(OUT + "gaussian-binary.sdf", "wb").write(head + znm.astype("<f8").tobytes())

    # CSV in µm.
    open(OUT + "gaussian.csv", "w").write(
        "# Gaussian random surface (tools/make_topography_fixtures.py): heights in um, 1 um apart\n"
        + "\n".join(",".join(repr(float(v)) for v in row) for row in z * 1e6) + "\n")

    zs_m = sur(OUT + "gaussian.sur", z, mask)

    zi_m = zi.astype(float) * 1e-9
    expected = {
        "provenance": "tools/make_topography_fixtures.py (NumPy), plane levelling, cells' bilinear gradients",
        "gaussian": stats(z, DX, DX),
        "gaussian_masked": stats(zi_m, DX, DX, mask),
        "gaussian_f32": stats(z.astype("<f4").astype(float), DX, DX),
        "gaussian_sur": stats(zs_m, DX, DX, mask),
    }
    open(OUT + "expected.json", "w").write(json.dumps(expected, indent=1) + "\n")


if __name__ == "__main__":
    main()
