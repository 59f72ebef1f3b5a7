#!/usr/bin/env python3
"""Reference luminous reflectances for src/spectrum.rs, computed independently with colour-science.

Run by hand:  python3 tools/ref_luminous.py   (colour-science 0.4.7)
Writes fixtures/reference/luminous.json: Y/100 of test reflectance spectra under CIE illuminant C with the
CIE 1931 2-degree observer, by colour.sd_to_XYZ(..., method="Integration") on a 5 nm grid 380-780 nm
(perfect reflector: Y = 100). glossmeter's Sampling::spectral uses trapezoid widths on the same grid; the
two differ only by the half-weights of the end samples, where illuminant C x ybar is ~1e-4 of its peak.
"""
import json
import pathlib
import warnings

warnings.filterwarnings("ignore")
import colour  # noqa: E402
import numpy as np  # noqa: E402

grid = np.arange(380, 781, 5)
spectra = {
    "ramp 0.2..0.8": 0.2 + 0.6 * (grid - 380) / 400.0,
    "green bump": 0.1 + 0.7 * np.exp(-(((grid - 550) / 40.0) ** 2)),
    "blue edge": np.where(grid < 500, 0.9, 0.05),
}
shape = colour.SpectralShape(380, 780, 5)
cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
illum = colour.SDS_ILLUMINANTS["C"].copy().align(shape)
out = {
    "provenance": f"tools/ref_luminous.py, colour-science {colour.__version__}, sd_to_XYZ method Integration, "
    "illuminant C, CIE 1931 2-degree observer, 5 nm 380-780 nm; generated 2026-11-22",
    "wavelengths_nm": grid.tolist(),
    "cases": [],
}
for name, r in spectra.items():
    sd = colour.SpectralDistribution(dict(zip(grid.tolist(), r.tolist())))
    xyz = colour.sd_to_XYZ(sd, cmfs, illum, method="Integration")
    out["cases"].append({"name": name, "reflectance": r.tolist(), "Y_over_100": float(xyz[1] / 100.0)})
path = pathlib.Path(__file__).resolve().parent.parent / "fixtures" / "reference" / "luminous.json"
path.write_text(json.dumps(out, indent=1) + "\n")
print("wrote", path, [c["Y_over_100"] for c in out["cases"]])
