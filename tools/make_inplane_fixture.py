#!/usr/bin/env python3
"""Write synthetic in-plane goniometer tables (the in-plane CSV export and an ASTM E1392-style text table)
whose BRDF is known in closed form: a Lambertian (rho = 0.5) and the Beckmann lobe of
tools/make_rgl_fixture.py (alpha = 0.15, dielectric n = 1.5, Smith height-correlated), the engine's
`microfacet` model with the same parameters.

Run by hand (pure Python 3):  python3 tools/make_inplane_fixture.py fixtures/materials/inplane
Read by tests/measured_formats.rs.  Layouts: docs/recipe-format.md §inplane-csv and §e1392.
theta_o is signed, + on the specular side; in the E1392 file the specular side is phi_s = phi_i + 180.
Angles of incidence: every degree over 15-25 and 50-89 (what the 20, 60 and 85 degree geometries reach);
theta_o every 0.1 degree within 10 degrees of the specular direction, every degree elsewhere.
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_rgl_fixture import Beckmann  # noqa: E402

RHO = 0.5


def thetas_o(theta_i):
    out = set()
    for k in range(-89, 90):
        out.add(float(k))
    for k in range(-100, 101):
        t = round(theta_i + 0.1 * k, 1)
        if -90 < t < 90:
            out.add(t)
    return sorted(out)


def direction(theta_deg, side):
    t = math.radians(theta_deg)
    return (side * math.sin(t), 0.0, math.cos(t))


def rows():
    # Every degree over the angles of incidence that the gloss geometries' apertures reach through the
    # isotropic extension (an off-plane pair maps to the in-plane pair with its (theta_h, theta_d), whose
    # theta_i lies up to ~8 degrees from the geometry's at 60 and down to ~68 at 85).
    for ti in list(range(15, 26)) + list(range(50, 90)):
        for to in thetas_o(ti):
            yield float(ti), to


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "fixtures/materials/inplane"
    os.makedirs(out, exist_ok=True)
    b = Beckmann()
    with open(os.path.join(out, "lambert-cos.csv"), "w") as f:
        f.write("# Lambertian rho = 0.5 as f_r cos(theta_o) (tools/make_inplane_fixture.py)\n")
        f.write("theta_i,theta_o,brdf_cos\n")
        for ti, to in rows():
            f.write("%g,%g,%.12e\n" % (ti, to, RHO / math.pi * math.cos(math.radians(to))))
    with open(os.path.join(out, "beckmann.csv"), "w") as f:
        f.write("# Beckmann alpha = 0.15, n = 1.5, Smith height-correlated (tools/make_inplane_fixture.py)\n")
        f.write("theta_o,theta_i,brdf\n")
        for ti, to in rows():
            f.write("%g,%g,%.12e\n" % (to, ti, b.f(direction(ti, -1), direction(to, 1), 0)))
    with open(os.path.join(out, "beckmann-e1392.txt"), "w") as f:
        f.write("SAMPLE: synthetic Beckmann alpha = 0.15, n = 1.5 (tools/make_inplane_fixture.py)\n")
        f.write("WAVELENGTH: 550 nm\nQUANTITY: cosine-corrected BRDF\n")
        f.write("theta_i phi_i theta_s phi_s CCBRDF\n")
        for ti, to in rows():
            v = b.f(direction(ti, -1), direction(to, 1), 0) * math.cos(math.radians(to))
            f.write("%g 0 %g %g %.12e\n" % (ti, abs(to), 180 if to >= 0 else 0, v))
        # Out-of-plane rows (not used by the reader, counted in its description).
        for ps in (170, 190):
            f.write("20 0 20 %d 1.0\n" % ps)
    for name in ("lambert-cos.csv", "beckmann.csv", "beckmann-e1392.txt"):
        p = os.path.join(out, name)
        print(p, os.path.getsize(p), "bytes")


if __name__ == "__main__":
    main()
