#!/usr/bin/env python3
"""Write small synthetic RGL `.bsdf` tensor files whose BRDF is known in closed form.

Run by hand (pure Python 3, no packages):  python3 tools/make_rgl_fixture.py fixtures/materials/rgl
The outputs are stored in fixtures/materials/rgl/ and read by tests/measured_formats.rs.

Written from the format's description (the tensor_file container and the fields that pbrt-v4's
MeasuredBxDFData::Create checks: theta_i, phi_i, ndf, sigma, vndf, luminance, spectra + wavelengths or rgb,
description, jacobian; Dupuy & Jakob 2018) and from pbrt-v4's evaluation
    f(w, w') = spectra(R^-1(u_m; phi, theta); phi, theta, lambda) * ndf(u_m) / (4 sigma(u_w) cos theta'),
where R^-1 is the inverse of the VNDF warp (PiecewiseLinear2D::Invert) and u = (sqrt(2 theta / pi),
phi / 2pi + 1/2) maps angles to the unit square.  To write a file for a known f, this script fills
  * ndf with the microfacet distribution D on the unit-square grid,
  * sigma with the projected area sigma(w) = int D(m) <w.m> dm,
  * vndf with the visible-normal density <w.m> D(m) / sigma(w) times the Jacobian of the u map,
  * spectra, at every node s of its grid, with f(w, w') * 4 sigma(w) cos theta' / D(m), where m is the
    normal the warp sends s to (found by bisection on the inverse, which is monotone in each coordinate),
so that the reader reproduces f exactly at the nodes and within the grid's interpolation error between them.

Materials:
  * lambert: f = rho / pi, rho = (0.2, 0.5, 0.8) as an `rgb` field; D = 1/pi (uniform NDF), whose
    projected area is sigma(w) = (1 + cos theta) / 2.
  * beckmann: f = F D G2 / (4 cos theta_i cos theta_o), Beckmann alpha = 0.15, unpolarised Fresnel of a
    dielectric n = 1.5, Smith height-correlated G2 = 1 / (1 + Lambda(w_i) + Lambda(w_o)); sigma =
    cos theta (1 + Lambda).  This is the engine's `microfacet` model with the same parameters.
The anisotropic file holds the same isotropic Beckmann BRDF, tabulated over phi_i in [-pi, pi] with the
absolute azimuth of m, so that the reader's anisotropic path must give the isotropic readings.
"""
import math
import struct
import sys
import os

ALPHA = 0.15
ETA = 1.5
RHO = (0.2, 0.5, 0.8)


def fresnel(cos_i, eta):
    cos_i = min(max(cos_i, 0.0), 1.0)
    sin2_t = (1.0 - cos_i * cos_i) / (eta * eta)
    if sin2_t >= 1.0:
        return 1.0
    cos_t = math.sqrt(1.0 - sin2_t)
    rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    return 0.5 * (rs * rs + rp * rp)


def beckmann_d(cos_m):
    if cos_m <= 0.0:
        return 0.0
    c2 = cos_m * cos_m
    tan2 = (1.0 - c2) / c2
    return math.exp(-tan2 / (ALPHA * ALPHA)) / (math.pi * ALPHA * ALPHA * c2 * c2)


def beckmann_lambda(cos_t):
    if cos_t >= 1.0:
        return 0.0
    tan_t = math.sqrt(max(1.0 - cos_t * cos_t, 0.0)) / cos_t
    if tan_t == 0.0:
        return 0.0
    a = 1.0 / (ALPHA * tan_t)
    return 0.5 * (math.erf(a) - 1.0) + math.exp(-a * a) / (2.0 * a * math.sqrt(math.pi))


class Lambert:
    channels = 3

    def d(self, m):
        return 1.0 / math.pi if m[2] > 0 else 0.0

    def sigma(self, w):
        return 0.5 * (1.0 + w[2])

    def f(self, wi, wo, c):
        return RHO[c] / math.pi


class Beckmann:
    channels = 1

    def d(self, m):
        return beckmann_d(m[2])

    def sigma(self, w):
        return w[2] * (1.0 + beckmann_lambda(w[2]))

    def f(self, wi, wo, c):
        h = [wi[k] + wo[k] for k in range(3)]
        n = math.sqrt(sum(x * x for x in h))
        h = [x / n for x in h]
        g2 = 1.0 / (1.0 + beckmann_lambda(wi[2]) + beckmann_lambda(wo[2]))
        return fresnel(sum(wi[k] * h[k] for k in range(3)), ETA) * beckmann_d(h[2]) * g2 / (4 * wi[2] * wo[2])


def u2theta(u):
    return u * u * math.pi / 2


def u2phi(u):
    return (2 * u - 1) * math.pi


def sph(theta, phi):
    return (math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta))


class Slice:
    """One normalised slice of a PiecewiseLinear2D with its CDFs (pbrt-v4 constructor, normalize=True)."""

    def __init__(self, data, nx, ny):
        self.nx, self.ny = nx, ny
        cond = [0.0] * (nx * ny)
        for y in range(ny):
            s = 0.0
            for x in range(nx - 1):
                i = y * nx + x
                s += 0.5 * (data[i] + data[i + 1])
                cond[i + 1] = s
        marg = [0.0] * ny
        s = 0.0
        for y in range(ny - 1):
            s += 0.5 * (cond[(y + 1) * nx - 1] + cond[(y + 2) * nx - 1])
            marg[y + 1] = s
        k = 1.0 / s
        self.data = [v * k for v in data]
        self.cond = [v * k for v in cond]
        self.marg = [v * k for v in marg]

    def invert(self, ux, uy):
        nx, ny = self.nx, self.ny
        sx, sy = ux * (nx - 1), uy * (ny - 1)
        px, py = min(int(sx), nx - 2), min(int(sy), ny - 2)
        fx, fy = sx - px, sy - py
        off = px + py * nx
        d = self.data
        c0 = (1 - fy) * d[off] + fy * d[off + nx]
        c1 = (1 - fy) * d[off + 1] + fy * d[off + nx + 1]
        x = fx * (c0 + 0.5 * fx * (c1 - c0))
        x += (1 - fy) * self.cond[off] + fy * self.cond[off + nx]
        r0, r1 = self.cond[py * nx + nx - 1], self.cond[py * nx + 2 * nx - 1]
        x /= (1 - fy) * r0 + fy * r1
        y = fy * (r0 + 0.5 * fy * (r1 - r0)) + self.marg[py]
        return x, y

    def forward(self, sx, sy):
        """The point u whose inverse is s (bisection; the inverse's y depends on u_y only)."""
        lo, hi = 0.0, 1.0
        for _ in range(48):
            mid = 0.5 * (lo + hi)
            if self.invert(0.5, mid)[1] < sy:
                lo = mid
            else:
                hi = mid
        uy = 0.5 * (lo + hi)
        lo, hi = 0.0, 1.0
        for _ in range(48):
            mid = 0.5 * (lo + hi)
            if self.invert(mid, uy)[0] < sx:
                lo = mid
            else:
                hi = mid
        return 0.5 * (lo + hi), uy


def write_tensor(path, fields):
    """fields: list of (name, type code, shape, bytes). tensor_file 1.0, little-endian."""
    header = b"tensor_file\0" + bytes([1, 0]) + struct.pack("<I", len(fields))
    size = len(header)
    for name, _, shape, _ in fields:
        size += 2 + len(name) + 2 + 1 + 8 + 8 * len(shape)
    out, data, offset = [header], [], size
    for name, code, shape, blob in fields:
        nb = name.encode()
        out.append(struct.pack("<H", len(nb)) + nb + struct.pack("<HBQ", len(shape), code, offset))
        out.append(b"".join(struct.pack("<Q", d) for d in shape))
        data.append(blob)
        offset += len(blob)
    with open(path, "wb") as f:
        f.write(b"".join(out) + b"".join(data))


def f32(values):
    return struct.pack("<%df" % len(values), *values)


def make(path, model, isotropic, thetas_deg, phis, n, n_ndf, description):
    thetas = [math.radians(t) for t in thetas_deg]
    nphi, nth = len(phis), len(thetas)
    ndf, sigma = [], []
    for y in range(n_ndf):
        for x in range(n_ndf):
            th, ph = u2theta(x / (n_ndf - 1)), u2phi(y / (n_ndf - 1))
            ndf.append(model.d(sph(th, ph)))
            sigma.append(model.sigma(sph(th, ph)))
    vndf, spectra = [], []
    for phi_i in phis:
        for theta_i in thetas:
            wi = sph(theta_i, phi_i)
            sw = model.sigma(wi)
            sl = []
            for y in range(n):
                for x in range(n):
                    ux, uy = x / (n - 1), y / (n - 1)
                    th = u2theta(ux)
                    ph = u2phi(uy) + (phi_i if isotropic else 0.0)
                    m = sph(th, ph)
                    dot = max(0.0, sum(wi[k] * m[k] for k in range(3)))
                    jac = math.sin(th) * math.pi * ux * 2 * math.pi
                    sl.append(dot * model.d(m) / sw * jac)
            vndf.extend(sl)
            warp = Slice(sl, n, n)
            nodes = []
            for y in range(n):
                for x in range(n):
                    ux, uy = warp.forward(x / (n - 1), y / (n - 1))
                    th = u2theta(ux)
                    ph = u2phi(uy) + (phi_i if isotropic else 0.0)
                    nodes.append(sph(th, ph))
            for c in range(model.channels):
                for m in nodes:
                    dot = sum(wi[k] * m[k] for k in range(3))
                    wo = [2 * dot * m[k] - wi[k] for k in range(3)]
                    d = model.d(m)
                    if wo[2] <= 0 or d <= 0:
                        spectra.append(0.0)
                    else:
                        spectra.append(model.f(wi, wo, c) * 4 * sw * wo[2] / d)
    fields = [
        ("description", 1, [len(description)], description.encode()),
        ("jacobian", 1, [1], bytes([1])),
        ("theta_i", 10, [nth], f32(thetas)),
        ("phi_i", 10, [nphi], f32(phis)),
        ("ndf", 10, [n_ndf, n_ndf], f32(ndf)),
        ("sigma", 10, [n_ndf, n_ndf], f32(sigma)),
        ("vndf", 10, [nphi, nth, n, n], f32(vndf)),
        ("luminance", 10, [nphi, nth, n, n], f32([1.0] * (nphi * nth * n * n))),
    ]
    if model.channels == 3:
        fields.append(("rgb", 10, [nphi, nth, 3, n, n], f32(spectra)))
    else:
        fields.append(("wavelengths", 10, [1], f32([550.0])))
        fields.append(("spectra", 10, [nphi, nth, 1, n, n], f32(spectra)))
    write_tensor(path, fields)
    print(path, os.path.getsize(path), "bytes")


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "fixtures/materials/rgl"
    os.makedirs(out, exist_ok=True)
    iso_thetas = list(range(0, 90, 5)) + [89]
    make(os.path.join(out, "lambert-rgb.bsdf"), Lambert(), True, iso_thetas, [0.0], 24, 24,
         "synthetic Lambertian rho = (0.2, 0.5, 0.8) (tools/make_rgl_fixture.py)")
    for n in (16, 32):
        make(os.path.join(out, "beckmann-iso-%d.bsdf" % n), Beckmann(), True, iso_thetas, [0.0], n, 2 * n,
             "synthetic Beckmann alpha = 0.15, n = 1.5, Smith height-correlated (tools/make_rgl_fixture.py)")
    make(os.path.join(out, "beckmann-aniso-24.bsdf"), Beckmann(), False, [0, 10, 15, 20, 25, 40, 55, 60, 65, 80, 85, 89],
         [-math.pi, -math.pi / 2, 0.0, math.pi / 2, math.pi], 24, 48,
         "synthetic Beckmann alpha = 0.15 over the full circle of phi_i (tools/make_rgl_fixture.py)")


if __name__ == "__main__":
    main()
