#!/usr/bin/env python3
"""How much each assumed number of standards/rhopoint-iq-20.json moves each IQ reading (docs/instrument.md §1.9).

Run by hand from the repository root after `cargo build --release`:

    python3 tools/iq/sensitivity.py MATERIAL.json [MATERIAL.json ...] > study.md

For every assumed number it writes a user geometry equal to the shipped one except that number (the ids differ,
as user geometries must), reads it with `glossmeter measure --geometry-file`, and prints the readings and their
change from the nominal geometry, one markdown table per material. Nothing is fitted; the study is the forward
model's sensitivity, one number at a time (the others nominal).
"""
import copy
import csv
import io
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
GM = os.path.join(ROOT, "target", "release", "glossmeter")
BASE = json.load(open(os.path.join(ROOT, "standards", "rhopoint-iq-20.json")))
READINGS = ["gloss", "haze", "log-haze", "doi", "rspec"]


def receptor(g, name):
    return next(r for r in g["receptors"] if r["name"] == name)


def shift_window(g, name, first, last):
    r = receptor(g, name)
    r["pixel_first"]["value"], r["pixel_last"]["value"] = first, last


def variants():
    """(label, function that edits a copy of the geometry)."""
    out = []
    for v in (0.05, 0.1982):
        out.append((f"source in plane {v}° (nominal 0.1°)", lambda g, v=v: g["source"]["in_plane_deg"].update(value=v)))
    for v in (1.0, 3.0):
        out.append((f"source height {v}° (nominal 2.5°)", lambda g, v=v: g["source"]["perpendicular_deg"].update(value=v)))
    for v in (3.0, 5.0):
        out.append((f"pixel height {v}° (nominal 3.6°)", lambda g, v=v: g["profile"]["perpendicular_deg"].update(value=v)))
    # Haze windows: half and twice as wide (7 and 28 pixels) about the same centre ±1.9°; centre at ±1.7° and ±2.1°.
    for label, lo, hi in (("haze windows 7 px (nominal 14)", 319, 325), ("haze windows 28 px (nominal 14)", 309, 336),
                          ("haze windows centred 1.7° (nominal 1.9°)", 309, 322),
                          ("haze windows centred 2.1° (nominal 1.9°)", 323, 336)):
        def f(g, lo=lo, hi=hi):
            shift_window(g, "haze-plus", lo, hi)
            shift_window(g, "haze-minus", 511 - hi, 511 - lo)
        out.append((label, f))
    # Rspec window: centred on pixel 256 instead of 255; 5 and 9 pixels.
    out.append(("Rspec peak pixel 256 (nominal 255)", lambda g: shift_window(g, "rspec", 253, 259)))
    out.append(("Rspec window 5 px (nominal 7)", lambda g: shift_window(g, "rspec", 253, 257)))
    out.append(("Rspec window 9 px (nominal 7)", lambda g: shift_window(g, "rspec", 251, 259)))
    # DOI windows: 10 and 12 pixels off (0.283°, 0.340°) instead of 11.
    for off in (10, 12):
        def f(g, off=off):
            shift_window(g, "doi-plus", 255 + off - 3, 255 + off + 3)
            shift_window(g, "doi-minus", 255 - off - 3, 255 - off + 3)
        out.append((f"DOI windows {off} px off (nominal 11)", f))
    # Gloss window: 62 and 66 pixels.
    out.append(("gloss window 62 px (nominal 64)", lambda g: shift_window(g, "gloss", 225, 286)))
    out.append(("gloss window 66 px (nominal 64)", lambda g: shift_window(g, "gloss", 223, 288)))
    return out


def read(material, geometry_file, gid):
    out = subprocess.run([GM, "measure", material, "--geometry-file", geometry_file, "--format", "csv"],
                         capture_output=True, text=True)
    if out.returncode not in (0, 1):
        sys.exit(f"glossmeter failed on {geometry_file}: {out.stderr}")
    rows = list(csv.DictReader(io.StringIO(out.stdout)))
    return {r["name"]: float(r["value"]) for r in rows}


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    with tempfile.TemporaryDirectory() as tmp:
        runs = [("nominal", lambda g: None)] + variants()
        files = []
        for i, (label, edit) in enumerate(runs):
            g = copy.deepcopy(BASE)
            edit(g)
            g["id"] = f"iq-study-{i}"
            path = os.path.join(tmp, f"v{i}.json")
            json.dump(g, open(path, "w"))
            files.append((label, path, g["id"]))
        for material in sys.argv[1:]:
            print(f"\n**{os.path.basename(material)}**\n")
            print("| geometry | " + " | ".join(READINGS) + " |")
            print("|---|" + "---|" * len(READINGS))
            nominal = None
            for label, path, gid in files:
                r = read(material, path, gid)
                if nominal is None:
                    nominal = r
                    print(f"| {label} | " + " | ".join(f"{r[k]:.2f}" for k in READINGS) + " |")
                else:
                    print(f"| {label} | " + " | ".join(f"{r[k] - nominal[k]:+.2f}" for k in READINGS) + " |")


main()
