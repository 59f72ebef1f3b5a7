#!/usr/bin/env python3
"""Summarise what moved between two golden files (fixtures/golden/readings.json format): per moved reading the
value change in units of the old and new error estimates, the estimate ratio and the evaluation counts; and the
totals. Usage: tools/golden_moves.py OLD.json NEW.json [--list]. By hand, for re-bless commit messages."""
import json
import struct
import sys


def f64(bits):
    return None if bits == "none" else struct.unpack(">d", bytes.fromhex(bits))[0]


def parse(line):
    v, e, n, c = line.split()
    return f64(v), f64(e), int(n), c == "true"


def main():
    old, new = (json.load(open(p)) for p in sys.argv[1:3])
    listing = "--list" in sys.argv
    moved = [k for k in new if k in old and old[k] != new[k]]
    added = [k for k in new if k not in old]
    gone = [k for k in old if k not in new]
    ev_old = sum(parse(old[k])[2] for k in old)
    ev_new = sum(parse(new[k])[2] for k in new if k in old)
    vmoved = emoved = 0
    worst_old = worst_new = 0.0
    conv = []
    by_geo = {}
    for k in moved:
        vo, eo, no, co = parse(old[k])
        vn, en, nn, cn = parse(new[k])
        geo = k.split("|")[1]
        by_geo[geo] = by_geo.get(geo, 0) + 1
        if co != cn:
            conv.append(k)
        d = None if vo is None or vn is None else abs(vn - vo)
        if vo != vn:
            vmoved += 1
        if eo != en:
            emoved += 1
        r_old = d / eo if d is not None and eo else 0.0
        r_new = d / en if d is not None and en else 0.0
        worst_old, worst_new = max(worst_old, r_old), max(worst_new, r_new)
        if listing:
            def g(x):
                return "none" if x is None else f"{x:.3g}"

            print(f"{k}: value {vo!r} -> {vn!r} (|d| = {g(d)} = {r_old:.3g} old est, {r_new:.3g} new est); "
                  f"estimate {g(eo)} -> {g(en)}; evaluations {no} -> {nn}; converged {co} -> {cn}")
    print(f"{len(moved)} of {len(old)} readings moved ({vmoved} values, {emoved} estimates), {len(added)} added, "
          f"{len(gone)} gone; by geometry: " + ", ".join(f"{g} {n}" for g, n in sorted(by_geo.items())))
    print(f"largest |value change| / old estimate {worst_old:.3g}, / new estimate {worst_new:.3g}; "
          f"converged flag changed: {len(conv)} {conv}")
    print(f"evaluations over the readings of both files: {ev_old} -> {ev_new} ({100.0 * (ev_new - ev_old) / ev_old:+.2f} %)")


main()
