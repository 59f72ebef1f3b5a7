#!/usr/bin/env python3
"""Write the tiny MERL-format table shipped as fixtures/materials/merl/lambert-tiny.binary.

Run by hand:  python3 tools/make_merl_fixture.py
Format (Matusik et al. 2003, as read by src/measured/merl.rs): 3 little-endian int32 dimensions
(theta_h, theta_d, phi_d), then 3*n little-endian float64 values in channel blocks R, G, B, stored
divided by the MERL channel scales (1/1500, 1.15/1500, 1.66/1500). The table here is a Lambertian of
albedo (0.2, 0.5, 0.8), i.e. every entry is albedo/pi, on a 4 x 4 x 8 grid (the reader accepts any
dimensions its header states). It is a format fixture, not measured data.
"""
import math
import pathlib
import struct

DIMS = (4, 4, 8)
ALBEDO = (0.2, 0.5, 0.8)
SCALE = (1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0)
out = pathlib.Path(__file__).resolve().parent.parent / "fixtures" / "materials" / "merl" / "lambert-tiny.binary"
n = DIMS[0] * DIMS[1] * DIMS[2]
with open(out, "wb") as f:
    f.write(struct.pack("<3i", *DIMS))
    for a, s in zip(ALBEDO, SCALE):
        f.write(struct.pack(f"<{n}d", *([a / math.pi / s] * n)))
print("wrote", out, out.stat().st_size, "bytes")
