#!/usr/bin/env python3
"""The four-value test as a Monte Carlo over the noise (docs/inverse.md §The paper's four-value claim).

Runs the metallic (or pearl) case of tools/four_values.py for N noise draws (random.Random(seed) for seed =
1..N, each target moved by N(0, u)), fits each with `glossmeter fit --rtol 1e-6`, and prints one row per
draw (exit status, χ², p, the verdict flags, the fitted parameters, the held-out 20° gloss, haze, DOI and
ΔE00 at E2194 25°/75°) and a summary. Run from the repository root after `cargo build --release`:

    python3 tools/four_values_mc.py [--bin target/release/glossmeter] [--case metallic] [--n 20]

Only the standard library is used.
"""
import argparse
import json
import os
import random
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import four_values as fv  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default="target/release/glossmeter")
    ap.add_argument("--case", default="metallic", choices=sorted(fv.CASES))
    ap.add_argument("--n", type=int, default=20)
    ap.add_argument("--rtol", default="1e-6")
    a = ap.parse_args()
    c = fv.CASES[a.case]
    out = tempfile.mkdtemp(prefix="four-mc-")
    truth_path = os.path.join(out, "truth.json")
    start_path = os.path.join(out, "start.json")
    fv.write_recipe(truth_path, c["source"], c["truth"], "truth")
    fv.write_recipe(start_path, c["source"], {**c["truth"], **c["start"]}, "start")
    truth = fv.measure(a.bin, truth_path, fv.FOUR + fv.HELD_OUT)
    held = [("astm-d523-20", "gloss"), ("iso-13803-20", "haze"), ("astm-e430-30", "doi")]
    print(f"# {a.case}: {a.n} draws, fits at rtol {a.rtol}, truth readings at 1e-8")
    print("| draw | exit | χ² | p | reproduces | identifiable | stationary | fitted | Δ 20° gloss, haze, DOI | ΔE00 25°, 75° |")
    print("truth held-out: " + ", ".join(f"{g}/{q} = {fv.value(truth, g, q):.3f}" for g, q in held))
    rows = []
    for seed in range(1, a.n + 1):
        rng = random.Random(seed)
        tgt = fv.targets(truth, rng)
        fitted_path = os.path.join(out, f"fitted-{seed}.json")
        args = [a.bin, "fit", start_path, "--format", "json", "--no-timing", "--rtol", a.rtol, "-o", fitted_path]
        for f in c["free"]:
            args += ["--free", f]
        for t in tgt:
            args += ["--target", t]
        p = subprocess.run(args, capture_output=True, text=True)
        rep = json.loads(p.stdout) if p.stdout.strip() else {}
        row = {"seed": seed, "exit": p.returncode, "chi2": rep.get("chi2"), "p": rep.get("p_value"),
               "reproduces": rep.get("reproduces"), "identifiable": rep.get("identifiable"),
               "stationary": rep.get("stationary"), "converged": rep.get("converged"),
               "values": [q["value"] for q in rep.get("parameters", [])]}
        if os.path.exists(fitted_path):
            f = fv.measure(a.bin, fitted_path, fv.FOUR + fv.HELD_OUT)
            row["held"] = [fv.value(f, g, q) - fv.value(truth, g, q) for g, q in held]
            _, colours = fv.held_out_table(truth, f)
            row["de"] = [de for g, _, _, de in colours if g in ("astm-e2194-25", "astm-e2194-75")]
        rows.append(row)
        vals = " ".join(f"{v:.5g}" for v in row["values"])
        hd = " ".join(f"{d:+.2f}" for d in row.get("held", []))
        de = " ".join(f"{d:.2f}" for d in row.get("de", []))
        print(f"| {seed} | {row['exit']} | {row['chi2']:.3f} | {row['p']:.3g} | {row['reproduces']} | "
              f"{row['identifiable']} | {row['stationary']} | {vals} | {hd} | {de} |", flush=True)
        if p.returncode != 0:
            for v in rep.get("verdict", []) or [p.stderr.strip()]:
                print(f"    - {v[:220]}", flush=True)
    print(f"\nexit 0: {sum(r['exit'] == 0 for r in rows)}, exit 1: {sum(r['exit'] == 1 for r in rows)}, "
          f"other: {sum(r['exit'] not in (0, 1) for r in rows)}")
    print(f"cannot reproduce: {sum(r['reproduces'] is False for r in rows)}; stationary: "
          f"{sum(bool(r['stationary']) for r in rows)}; not identifiable: {sum(r['identifiable'] is False for r in rows)}")
    for k, name in enumerate(c["free"]):
        xs = [r["values"][k] for r in rows if r["exit"] == 0 and len(r["values"]) > k]
        if len(xs) > 1:
            print(f"{name}: exit-0 fits {len(xs)}, mean {statistics.mean(xs):.5g}, sd {statistics.stdev(xs):.3g}")
    for j, (g, q) in enumerate(held):
        ds = [r["held"][j] for r in rows if "held" in r]
        ok = [r["held"][j] for r in rows if "held" in r and r["exit"] == 0]
        if ds:
            print(f"{g}/{q} fitted − truth: all {min(ds):+.2f} … {max(ds):+.2f}; exit-0 fits "
                  f"{(min(ok) if ok else float('nan')):+.2f} … {(max(ok) if ok else float('nan')):+.2f}")


if __name__ == "__main__":
    main()
