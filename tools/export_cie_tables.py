#!/usr/bin/env python3
"""Export the CIE tables glossmeter needs to standards/cie/*.csv, with provenance headers.

Run by hand (not by CI):  python3 tools/export_cie_tables.py
Requires: colour-science 0.4.7 (pip install colour-science==0.4.7).

Tables written:
  standards/cie/illuminant-c.csv   CIE illuminant C relative SPD, 5 nm, 360-780 nm (CIE 15 tabulates C only
                                   to 780 nm; src/spectrum.rs holds the 780 nm value beyond, and says so)
  standards/cie/cie1931-ybar.csv   CIE 1931 2-degree ybar(lambda) = V(lambda), 5 nm, 360-830 nm (the whole
                                   range of the CIE 1931 table)
  standards/cie/cie1931-2deg-xyz.csv    CIE 1931 2-degree xbar, ybar, zbar, 1 nm, 360-830 nm
  standards/cie/cie1964-10deg-xyz.csv   CIE 1964 10-degree xbar10, ybar10, zbar10, 1 nm, 360-830 nm
  standards/cie/illuminant-d65.csv      CIE illuminant D65 relative SPD, 5 nm, 300-780 nm
  standards/cie/illuminant-d50.csv      CIE illuminant D50 relative SPD, 5 nm, 300-780 nm
  standards/cie/illuminant-a.csv        CIE illuminant A relative SPD, 5 nm, 300-780 nm
All tables use one format, read by one loader (glossmeter::spectrum::parse_columns): `#` comment lines
(provenance), one header line starting with `wavelength_nm`, then comma-separated numbers.
colour-science takes them from CIE 15:2004 (illuminant C, Table T.1) and CIE 018:2019 / the CIE
1931 2-degree standard observer (cvrl.org / CIE S 014-1). We copy values, not code.
"""
import pathlib
import warnings

warnings.filterwarnings("ignore")
import colour  # noqa: E402

OUT = pathlib.Path(__file__).resolve().parent.parent / "standards" / "cie"
OUT.mkdir(parents=True, exist_ok=True)
GRID_C = range(360, 781, 5)  # illuminant C is tabulated by the CIE to 780 nm
GRID_YBAR = range(360, 831, 5)  # the CIE 1931 observer to 830 nm

c = colour.SDS_ILLUMINANTS["C"]
assert c.wavelengths[-1] == 780, "illuminant C ends at 780 nm in CIE 15 (and colour-science)"
cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]

header_common = (
    "# exported by tools/export_cie_tables.py from colour-science {v}\n"
    "# columns: wavelength in nm, value\n"
).format(v=colour.__version__)

with open(OUT / "illuminant-c.csv", "w") as f:
    f.write("# CIE standard illuminant C, relative spectral power distribution (the scale of CIE 15 Table T.1; only ratios matter).\n")
    f.write("# Source: CIE 15:2004 Colorimetry, 3rd ed., Table T.1, as tabulated in colour-science\n")
    f.write("# colour.SDS_ILLUMINANTS['C'] (5 nm steps). Used as the source spectrum of ASTM D523 / ISO 2813.\n")
    f.write(header_common)
    f.write("wavelength_nm,value\n")
    for w in GRID_C:
        f.write(f"{w},{c[w]:.6g}\n")

with open(OUT / "cie1931-ybar.csv", "w") as f:
    f.write("# CIE 1931 2-degree standard observer colour-matching function ybar = photopic V(lambda).\n")
    f.write("# Source: CIE 018:2019 / CIE 15:2004 Table T.4 (1 nm data, sampled here every 5 nm), as tabulated in\n")
    f.write("# colour-science colour.MSDS_CMFS['CIE 1931 2 Degree Standard Observer'].\n")
    f.write(header_common)
    f.write("wavelength_nm,value\n")
    for w in GRID_YBAR:
        f.write(f"{w},{cmfs[w][1]:.6g}\n")

CMF_SOURCES = {
    "cie1931-2deg-xyz.csv": (
        "CIE 1931 2 Degree Standard Observer",
        "# CIE 1931 2-degree standard colorimetric observer: colour-matching functions xbar, ybar, zbar.\n"
        "# Source: CIE 018:2019 / CIE 15:2004 Table T.4 (1 nm, 360-830 nm), as tabulated in colour-science\n"
        "# colour.MSDS_CMFS['CIE 1931 2 Degree Standard Observer'] (from cvrl.org).\n",
    ),
    "cie1964-10deg-xyz.csv": (
        "CIE 1964 10 Degree Standard Observer",
        "# CIE 1964 10-degree supplementary standard colorimetric observer: xbar10, ybar10, zbar10.\n"
        "# Source: CIE 15:2004 Table T.5 (1 nm, 360-830 nm), as tabulated in colour-science\n"
        "# colour.MSDS_CMFS['CIE 1964 10 Degree Standard Observer'] (from cvrl.org).\n",
    ),
}
for name, (key, head) in CMF_SOURCES.items():
    m = colour.MSDS_CMFS[key]
    with open(OUT / name, "w") as f:
        f.write(head)
        f.write("# exported by tools/export_cie_tables.py from colour-science {v}\n".format(v=colour.__version__))
        f.write("# columns: wavelength in nm, xbar, ybar, zbar\n")
        f.write("wavelength_nm,xbar,ybar,zbar\n")
        for w in range(360, 831):
            x, y, z = m[w]
            f.write(f"{w},{float(x)!r},{float(y)!r},{float(z)!r}\n")  # shortest round-trip repr: exact

ILLUMINANT_SOURCES = {
    "illuminant-d65.csv": ("D65", "CIE standard illuminant D65 (daylight, CCT ~6504 K)", "CIE 15:2004 Table T.1 / ISO 11664-2:2007"),
    "illuminant-d50.csv": ("D50", "CIE illuminant D50 (daylight, CCT ~5003 K)", "CIE 15:2004 Table T.1 (computed from the D-series basis, CIE 15:2004 Sec. 3.1)"),
    "illuminant-a.csv": ("A", "CIE standard illuminant A (Planckian, 2856 K)", "CIE 15:2004 Table T.1 / ISO 11664-2:2007"),
}
for name, (key, what, cite) in ILLUMINANT_SOURCES.items():
    sd = colour.SDS_ILLUMINANTS[key]
    with open(OUT / name, "w") as f:
        f.write(f"# {what}, relative spectral power distribution (only ratios matter).\n")
        f.write(f"# Source: {cite}, as tabulated in colour-science colour.SDS_ILLUMINANTS['{key}'] (5 nm steps).\n")
        f.write(header_common)
        f.write("wavelength_nm,value\n")
        for w in range(300, 781, 5):
            f.write(f"{w},{float(sd[w])!r}\n")
print("wrote", OUT)
