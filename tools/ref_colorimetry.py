#!/usr/bin/env python3
"""Reference tristimulus values and CIELAB of ColorChecker spectra, computed independently with colour-science.

Run by hand:  python3 tools/ref_colorimetry.py   (colour-science 0.4.7)
Writes fixtures/reference/colorimetry.json for src/colorimetry (tests/colorimetry.rs).

Method, the one glossmeter states (src/colorimetry/mod.rs, docs/colour.md), carried out with colour-science's own
data and functions: the reflectance is aligned to 360-780 nm at 1 nm with colour's LinearInterpolator and
constant (nearest-value) extrapolation; the illuminant (colour.SDS_ILLUMINANTS, 5 nm) is aligned to the same
shape with the LinearInterpolator; the CMFs (colour.MSDS_CMFS, 1 nm) are trimmed to it; then
colour.sd_to_XYZ(method="Integration") (X = k sum S xbar R dlambda, k = 100 / sum S ybar dlambda) and
colour.XYZ_to_Lab with the white point of the perfect reflecting diffuser computed the same way.
Spectra: colour.SDS_COLOURCHECKERS["BabelColor Average"] (380-730 nm, 10 nm; BabelColor ColorChecker averages).
"""
import json
import pathlib
import warnings

warnings.filterwarnings("ignore")
import colour  # noqa: E402
import numpy as np  # noqa: E402
from colour.algebra import LinearInterpolator  # noqa: E402

shape = colour.SpectralShape(360, 780, 1)
PATCHES = ["dark skin", "blue sky", "foliage", "blue", "green", "red", "yellow", "cyan", "white 9.5 (.05 D)",
           "neutral 5 (.70 D)", "black 2 (1.5 D)"]
OBSERVERS = {"2": "CIE 1931 2 Degree Standard Observer", "10": "CIE 1964 10 Degree Standard Observer"}
ILLUMINANTS = ["D65", "D50", "A", "C"]

cc = colour.SDS_COLOURCHECKERS["BabelColor Average"]
grid = [float(w) for w in cc[PATCHES[0]].wavelengths]


def aligned(sd):
    return sd.copy().align(shape, interpolator=LinearInterpolator, extrapolator_kwargs={"method": "Constant"})


out = {
    "provenance": f"tools/ref_colorimetry.py, colour-science {colour.__version__}: BabelColor Average ColorChecker "
    "spectra, linear interpolation to 1 nm with constant extrapolation over 360-780 nm, illuminant linearly "
    "interpolated from 5 nm, sd_to_XYZ method Integration, XYZ_to_Lab against the perfect diffuser's XYZ",
    "wavelengths_nm": grid,
    "cases": [],
    "white": [],
}
for obs_id, obs in OBSERVERS.items():
    cmfs = colour.MSDS_CMFS[obs].copy().trim(shape)
    for ill in ILLUMINANTS:
        s = colour.SDS_ILLUMINANTS[ill].copy().align(shape, interpolator=LinearInterpolator)
        ones = colour.SpectralDistribution(dict(zip(shape.wavelengths, np.ones(len(shape.wavelengths)))))
        white = colour.sd_to_XYZ(ones, cmfs, s, method="Integration")
        out["white"].append({"observer": obs_id, "illuminant": ill, "XYZ": [float(x) for x in white]})
        xy_w = colour.XYZ_to_xy(white / 100.0)
        for name in PATCHES:
            sd = cc[name]
            xyz = colour.sd_to_XYZ(aligned(sd), cmfs, s, method="Integration")
            lab = colour.XYZ_to_Lab(xyz / 100.0, xy_w)
            out["cases"].append({
                "patch": name, "observer": obs_id, "illuminant": ill,
                "reflectance": [float(v) for v in sd.values],
                "XYZ": [float(x) for x in xyz], "Lab": [float(x) for x in lab],
            })
path = pathlib.Path(__file__).resolve().parent.parent / "fixtures" / "reference" / "colorimetry.json"
path.write_text(json.dumps(out, indent=1) + "\n")
print("wrote", path, len(out["cases"]), "cases")
for w in out["white"]:
    print(w)
