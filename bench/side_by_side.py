#!/usr/bin/env python3
"""The engine, the limit and two peers side by side, in one run, on the 24 wide-lobe integrals of
docs/performance.md §"At the limit" (Beckmann and GGX microfacet dielectric n = 1.5, m = 0.003, 0.01, 0.03, at
astm-d523-20/60/85 and astm-e430-30 with its 8 receptors: 66 specimen integrals, default rtol 1e-6). Run by hand.

1. The engine: `BENCH_CASES=WIDE BENCH_JSON=FILE cargo bench --bench integrators` (the WIDE section of
   benches/integrators/ writes every specimen integral's planner evaluations, value and error estimate to
   FILE), or `--engine-json FILE` to reuse a previous run (the bench's JSON, or this script's own JSON output).
2. The limit: tools/limit_wide_lobes.py, imported (`case_run`: oracle tensor Gauss–Legendre orders, evaluations of
   the final rule alone), with its reference value and target per integral; `--limit-json FILE` reuses the limit
   part of this script's JSON output.
3. The peers on the limit script's integrand (`brdf_flux`, the same NumPy code) over the raw 4-D box of the stops
   (p_s, q_s, p_r, q_r): C hcubature (Steven G. Johnson, PyPI `cubature`) and `scipy.integrate.cubature` (rule
   genz-malik), each at the limit's tolerance (relative 0.9 × 0.99 × rtol, absolute the limit's floor), each run
   capped at `--cap` seconds (a capped run is reported as "capped at N", never as a result). Evaluations are
   counted in the integrand (points passed in); each peer's value is checked against the limit's reference.
4. One Markdown report (per geometry with the total over the 24, per case, per integral) to
   bench/results/side-by-side-<UTC date>.md, and the data behind it to the .json beside it.

Usage: /tmp/benchvenv/bin/python bench/side_by_side.py [--cap 15] [--engine-json FILE] [--limit-json FILE]
       [--cases beckmann:0.01:astm-d523-20,...] [--peers hcubature,scipy] [--out FILE]
Needs numpy, scipy, cubature (pip); cargo on PATH unless --engine-json. See bench/README.md.
"""
import argparse
import datetime
import json
import os
import platform
import shlex
import subprocess
import sys
import tempfile
import time

import numpy as np
import scipy
from scipy import integrate

try:
    from cubature import cubature as hcubature
    import importlib.metadata

    HCUBATURE = "PyPI cubature " + importlib.metadata.version("cubature")
except ImportError as e:  # pragma: no cover
    hcubature = None
    HCUBATURE = f"NOT available ({e})"

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import limit_wide_lobes as L  # noqa: E402

RTOL = 1e-6  # the engine's default, the bench's WIDE section's
GEOMETRIES = ["astm-d523-20", "astm-d523-60", "astm-d523-85", "astm-e430-30"]
LOBES = [(d, m) for d in ("beckmann", "ggx") for m in ("0.003", "0.01", "0.03")]
# docs/performance.md §"At the limit": the targets (engine / limit) per geometry and over the 24.
TARGETS = {"astm-d523-20": 2.0, "astm-e430-30": 3.0, "all": 2.0}


def log(*a):
    print(*a, file=sys.stderr, flush=True)


def load_average():
    """The load averages of `uptime`."""
    u = sh("uptime")
    return u.split("load average:")[-1].strip() if "load average:" in u else u


def shown(path):
    """A path as the report shows it: relative to the repository when inside it."""
    rel = os.path.relpath(os.path.abspath(path), ROOT)
    return os.path.abspath(path) if rel.startswith("..") else rel


def sh(*cmd):
    try:
        return subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "?"


# ---------------------------------------------------------------------------------------------------------
# 1. The engine.


def run_engine(path):
    env = dict(os.environ, BENCH_CASES="WIDE", BENCH_JSON=path)
    cmd = ["cargo", "bench", "--bench", "integrators"]
    log(f"[side-by-side] engine: BENCH_CASES=WIDE BENCH_JSON={path} {' '.join(cmd)}"
        f" (CARGO_TARGET_DIR={os.environ.get('CARGO_TARGET_DIR', 'unset')})")
    # The bench's own Markdown goes to stderr with its progress: stdout is left to nothing else.
    subprocess.run(cmd, cwd=ROOT, env=env, check=True, stdout=sys.stderr)


def engine_integrals(doc):
    """{(d, m, geometry, receptor): record} of the microfacet integrals of the bench's JSON."""
    out = {}
    for r in doc["integrals"]:
        if r.get("distribution") is None:
            continue
        m = next((m for d, m in LOBES if d == r["distribution"] and float(m) == r["roughness"]), None)
        if m is None:
            continue
        g, rec = r["used_by"][0].split("/", 1)
        if len(r["used_by"]) > 1:
            log(f"[side-by-side] note: one engine integral used by {r['used_by']}: counted once, at {g}/{rec}")
        out[(r["distribution"], m, g, rec)] = r
    return out


# ---------------------------------------------------------------------------------------------------------
# 2. The limit.


def limit_case(d, m, g):
    """The limit script's rows of one case, with each integral's reference, tolerance and stops."""
    target = 0.9 * 0.99 * RTOL  # as limit_wide_lobes.main
    theta, src, recs = L.stops(g)
    # The absolute floor as limit_wide_lobes.case_run computes it.
    floor = 0.99 * 1e-4 * RTOL * max(L.standard_flux(theta, src, rec) for _, rec in recs)
    rows = L.case_run(d, float(m), g, target, RTOL)
    out = {}
    for (name, ref, refcheck, part, orders, evals, rel), (name2, rec) in zip(rows, recs):
        assert name == name2
        out[name] = dict(reference=ref, ref_check=refcheck, partition=part,
                         orders=list(orders) if orders is not None else None, evaluations=evals,
                         actual_rel=rel, tol=max(target * abs(ref), floor), floor=floor, rtol=target,
                         theta=theta, source=list(src), receptor=list(rec))
    return out


# ---------------------------------------------------------------------------------------------------------
# 3. The peers.


class Capped(Exception):
    pass


CHUNK = 1 << 18


def run_peer(name, f, box, rtol, atol, cap):
    """One peer on the raw box: dict(status, evaluations, value, error, seconds)."""
    n, capped = [0], [False]
    t0 = time.perf_counter()

    def g(x):
        # In chunks of CHUNK points (hcubature's late batches hold millions: NumPy's temporaries stay bounded),
        # the cap checked before each.
        out = np.empty(x.shape[0])
        for k in range(0, x.shape[0], CHUNK):
            if time.perf_counter() - t0 > cap:
                capped[0] = True
                raise Capped()
            y = x[k:k + CHUNK]
            out[k:k + CHUNK] = f(y[:, 0], y[:, 1], y[:, 2], y[:, 3])
            n[0] += y.shape[0]
        return out

    lo = np.array([box[0], box[2], box[4], box[6]])
    hi = np.array([box[1], box[3], box[5], box[7]])
    try:
        if name == "hcubature":
            v, e = hcubature(g, 4, 1, lo, hi, relerr=rtol, abserr=atol, maxEval=0, vectorized=True)
            v, e = float(v[0]), float(e[0])
            status = "converged" if e <= max(rtol * abs(v), atol) else "not converged"
        else:
            r = integrate.cubature(g, lo, hi, rule="genz-malik", rtol=rtol, atol=atol, max_subdivisions=10**9)
            v, e, status = float(r.estimate), float(r.error), r.status.replace("_", " ")
    except Exception:  # Capped, or the SystemError hcubature's wrapper turns it into
        if not capped[0]:
            raise
        return dict(status="capped", evaluations=n[0], value=None, error=None, seconds=time.perf_counter() - t0)
    return dict(status=status, evaluations=n[0], value=v, error=e, seconds=time.perf_counter() - t0)


def run_peers(d, m, g, lim, peers, cap):
    theta = lim["theta"]
    f = L.brdf_flux(theta, d, float(m))
    s, r = lim["source"], lim["receptor"]
    box = (s[0], s[1], s[2], s[3], r[0], r[1], r[2], r[3])
    out = {}
    for p in peers:
        x = run_peer(p, f, box, lim["rtol"], lim["floor"], cap)
        if x["value"] is not None:
            x["actual"] = abs(x["value"] - lim["reference"])
        out[p] = x
    return out


# ---------------------------------------------------------------------------------------------------------
# 4. The report.


def fmt_n(n):
    return f"{n:,}".replace(",", " ")


def fmt_e(x):
    return "–" if x is None or x != x else f"{x:.1e}"


def peer_cell(x):
    if x is None:
        return "–"
    if x["status"] == "capped":
        return f"capped at {fmt_n(x['evaluations'])}"
    if x["status"] != "converged":
        return f"{fmt_n(x['evaluations'])} ({x['status']})"
    return fmt_n(x["evaluations"])


def peer_err(x, lim):
    """The peer's actual error: relative to the reference and in units of the tolerance."""
    if x is None or x.get("actual") is None:
        return "–"
    rel = x["actual"] / abs(lim["reference"]) if lim["reference"] != 0 else float("nan")
    flag = " **above tol**" if x["actual"] > lim["tol"] else ""
    return f"{fmt_e(rel)} ({x['actual'] / lim['tol']:.2g} tol){flag}"


def peer_sum(xs):
    """Sum of a peer's evaluations over integrals: exact when every run converged, else a lower bound."""
    xs = [x for x in xs if x is not None]
    if not xs:
        return "–"
    total = sum(x["evaluations"] for x in xs)
    capped = sum(x["status"] == "capped" for x in xs)
    other = sum(x["status"] not in ("capped", "converged") for x in xs)
    if capped or other:
        what = ", ".join(s for s in (f"{capped} capped" if capped else "", f"{other} not converged" if other else "") if s)
        return f"≥ {fmt_n(total)} ({what} of {len(xs)})"
    return fmt_n(total)


def worst_peer_err(xs, lims):
    vals = [x["actual"] / lim["tol"] for x, lim in zip(xs, lims) if x is not None and x.get("actual") is not None]
    return f"{max(vals):.2g} tol" if vals else "–"


def engine_ratio(r):
    """|engine value − limit reference| / the engine's own error estimate, or None."""
    if not r["engine"] or not r["engine"]["planner"]["error"] > 0:
        return None
    pl = r["engine"]["planner"]
    return abs(pl["value"] - r["limit"]["reference"]) / pl["error"]


def engine_worst(sel):
    vals = [x for x in map(engine_ratio, sel) if x is not None]
    return f"{max(vals):.3f}" if vals else "–"


def table_head(w, head, sep, peers, peer_cols):
    """A Markdown table's head and separator, each peer adding its columns (`peer_cols`: names with {p})."""
    for p in peers:
        head += "".join(f" {c.format(p=p)} |" for c in peer_cols)
        sep += "---:|" * len(peer_cols)
    w(head)
    w(sep)


def ratio_cell(e, lim):
    """engine / limit as a table cell: "–" where the limit spent nothing (never nan)."""
    return f"{e / lim:.2f}×" if lim else "–"


def report(rows, peers, meta):
    """rows: list of dict(d, m, g, rec, engine, limit, peers) in case order."""
    md = []
    w = md.append
    w("# Side by side: the engine, the limit and the peers on the 24 wide-lobe integrals\n")
    w(f"Commit `{meta['commit']}`{meta['dirty']}, {meta['date']}; load average (`uptime`) at the start "
      f"{meta['load_start']}, at the end {meta['load_end']}; {os.cpu_count()} logical cores; "
      f"Python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}, hcubature: "
      f"{HCUBATURE}.\n")
    w(f"Command: `{meta['command']}`\n")
    w(f"* **Engine**: {meta['engine_source']}; exact evaluation counts of each specimen integral with the "
      "planner's methods (plan of the six lobes over the four geometries, rtol 10⁻⁶).")
    w("* **Limit**: `tools/limit_wide_lobes.py` imported (`case_run`), run here: oracle tensor Gauss–Legendre orders "
      "on the best lobe partition, evaluations of the final rule alone (no error estimate); its reference "
      "(the same rule at orders (48, 10, 48, 10) on the refined partition) is the reference of every check below. "
      f"{meta['limit_source']}")
    w(f"* **Peers** on the limit script's integrand (`brdf_flux`) over the raw 4-D box of the stops (p_s, q_s, p_r, "
      "q_r), at the limit's tolerance per integral (relative 0.9 × 0.99 × 10⁻⁶ = 8.91·10⁻⁷, absolute the limit's "
      f"floor): {', '.join(peers) if peers else 'none run'}; each run capped at {meta['cap']:g} s of wall clock "
      "(\"capped at N\": the evaluations spent when the cap stopped it; no value). hcubature: C `hcubature` via PyPI "
      "`cubature` (vectorized, maxEval unlimited); scipy: `scipy.integrate.cubature(rule=\"genz-malik\")` "
      "(max_subdivisions unlimited). Evaluations counted in the integrand. Error = |value − limit reference|, "
      "relative, and in units of the integral's tolerance (tol).")
    w("* Evaluation counts are exact and machine-independent; times are not compared (load above; the cap is wall "
      "clock, so which peer runs are capped depends on the load).\n")

    def sums(sel):
        e = sum(r["engine"]["planner"]["evaluations"] for r in sel if r["engine"])
        missing = sum(1 for r in sel if not r["engine"])
        lim = sum(r["limit"]["evaluations"] or 0 for r in sel)
        return e, missing, lim

    w("## Per geometry (and the 24)\n")
    table_head(w, "| geometry | integrals | engine | limit | engine / limit | target | engine worst error / est. |",
               "|---|---:|---:|---:|---:|---|---:|", peers, ["{p}", "{p} worst error"])
    groups = [(g, [r for r in rows if r["g"] == g]) for g in GEOMETRIES] + [("all", rows)]
    for g, sel in groups:
        if not sel:
            continue
        e, missing, lim = sums(sel)
        ncases = len({(r["d"], r["m"], r["g"]) for r in sel})
        ratio = e / lim if lim else float("inf")
        t = TARGETS.get(g)
        full = ncases == (len(LOBES) * len(GEOMETRIES) if g == "all" else len(LOBES))
        tgt = "" if t is None else f"≤ {t:g}× — " + (
            ("met" if ratio <= t and not missing else "**missed**") if full else "not judged (not all cases run)")
        label = f"**all {ncases}**" if g == "all" else g
        line = (f"| {label} | {ncases} ({len(sel)}) | {fmt_n(e)}{' (%d missing)' % missing if missing else ''} | "
                f"{fmt_n(lim)} | {ratio_cell(e, lim)} | {tgt} | {engine_worst(sel)} |")
        for p in peers:
            xs = [r["peers"].get(p) for r in sel]
            line += f" {peer_sum(xs)} | {worst_peer_err(xs, [r['limit'] for r in sel])} |"
        w(line)
    w("\nIntegrals: cases (lobe × geometry) and, in brackets, specimen integrals (E430 30° has 8 receptors). "
      "Targets from docs/performance.md §\"At the limit\". A peer's sum with capped runs is a lower bound.\n")

    w("## Per case (lobe × geometry)\n")
    table_head(w, "| D | m | geometry | engine | limit | engine / limit |", "|---|---|---|---:|---:|---:|", peers, ["{p}"])
    cases = []
    for r in rows:
        k = (r["d"], r["m"], r["g"])
        if k not in cases:
            cases.append(k)
    for k in cases:
        sel = [r for r in rows if (r["d"], r["m"], r["g"]) == k]
        e, missing, lim = sums(sel)
        line = f"| {k[0]} | {k[1]} | {k[2]} | {fmt_n(e)} | {fmt_n(lim)} | {ratio_cell(e, lim)} |"
        for p in peers:
            line += f" {peer_sum([r['peers'].get(p) for r in sel])} |"
        w(line)

    w("\n## Per integral\n")
    w("Engine error = |engine value − limit reference| / the engine's own error estimate (≤ 1: the estimate covers "
      "it; a tail bound reads a flux ≈ 0 as Φ̄/2 ± Φ̄/2, hence its ratios just below 1). Peer error = |value − limit "
      "reference|, relative (and in tol). The limit's column: its partition (boxes) and orders (u, t_p, v, t_q).\n")
    table_head(w, "| D | m | geometry | receptor | reference flux | tol | engine | engine rule | engine est. (rel.) | "
               "engine error / est. | limit | limit partition, orders |",
               "|---|---|---|---|---:|---:|---:|---|---:|---:|---:|---|", peers, ["{p}", "{p} error"])
    for r in rows:
        lim, eng = r["limit"], r["engine"]
        ref = lim["reference"]
        if eng:
            pl = eng["planner"]
            est = pl["error"] / abs(pl["value"]) if pl["value"] else float("nan")
            ratio = engine_ratio(r)
            ratio = "–" if ratio is None else f"{ratio:.3g}"
            rule = eng["rule"].split(",")[0]
            if eng["boxes"] and "tail bound" not in rule:
                rule += f", {eng['boxes']} initial box{'es' if eng['boxes'] > 1 else ''}"
            ecells = f"{fmt_n(pl['evaluations'])} | {rule} | {fmt_e(est)} | {ratio} |"
        else:
            ecells = "missing | | | |"
        orders = "" if lim["orders"] is None else f", {tuple(lim['orders'])}"
        lcell = fmt_n(lim["evaluations"]) if lim["evaluations"] is not None else "none reached"
        line = (f"| {r['d']} | {r['m']} | {r['g']} | {r['rec']} | {ref:.6e} | {lim['tol']:.1e} | {ecells} "
                f"{lcell} | {lim['partition']}{orders} |")
        for p in peers:
            x = r["peers"].get(p)
            line += f" {peer_cell(x)} | {peer_err(x, lim)} |"
        w(line)
    return "\n".join(md) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cap", type=float, default=15.0, help="seconds of wall clock per peer run (default 15)")
    ap.add_argument("--engine-json", help="reuse the engine's JSON (the bench's BENCH_JSON file, or this script's .json)")
    ap.add_argument("--limit-json", help="reuse the limit part of this script's .json output")
    ap.add_argument("--cases", default="", help="d:m:geometry,... (default: the 24)")
    ap.add_argument("--peers", default="hcubature,scipy", help="hcubature,scipy (empty: none)")
    ap.add_argument("--out", help="Markdown output (default bench/results/side-by-side-<UTC date>.md)")
    args = ap.parse_args()
    started = datetime.datetime.now(datetime.timezone.utc)
    meta = dict(commit=sh("git", "rev-parse", "--short", "HEAD"), date=started.strftime("%Y-%m-%d %H:%M UTC"),
                load_start=load_average(), cap=args.cap,
                command=" ".join(shlex.quote(a) for a in [sys.executable, os.path.relpath(__file__, ROOT)] + sys.argv[1:]))
    dirty = sh("git", "status", "--short", "--", "src", "benches", "tools", "bench/side_by_side.py")
    meta["dirty"] = f" (uncommitted changes: {dirty.replace(chr(10), '; ')})" if dirty and dirty != "?" else ""
    peers = [p for p in args.peers.split(",") if p]
    if "hcubature" in peers and hcubature is None:
        log(f"[side-by-side] hcubature {HCUBATURE}: scipy only")
        peers.remove("hcubature")
    cases = ([tuple(c.split(":")) for c in args.cases.split(",")] if args.cases
             else [(d, m, g) for d, m in LOBES for g in GEOMETRIES])
    out_md = args.out or os.path.join(ROOT, "bench", "results", f"side-by-side-{started:%Y-%m-%d}.md")
    out_json = os.path.splitext(out_md)[0] + ".json"

    # 1. The engine.
    if args.engine_json:
        with open(args.engine_json) as fh:
            edoc = json.load(fh)
        edoc = edoc.get("engine", edoc)
        meta["engine_source"] = (f"reused from `{shown(args.engine_json)}` (the bench at commit "
                                 f"`{edoc.get('commit')}`, {edoc.get('date')})")
    else:
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "engine.json")
            run_engine(path)
            with open(path) as fh:
                edoc = json.load(fh)
        meta["engine_source"] = (f"`BENCH_CASES=WIDE BENCH_JSON=… cargo bench --bench integrators`, run by this "
                                 f"script (the bench at commit `{edoc.get('commit')}`, {edoc.get('date')}; "
                                 f"uncommitted src/: {edoc.get('uncommitted_src')})")
    engine = engine_integrals(edoc)

    # 2. The limit.
    limits = {}
    if args.limit_json:
        with open(args.limit_json) as fh:
            for x in json.load(fh)["rows"]:
                limits.setdefault((x["d"], x["m"], x["g"]), {})[x["rec"]] = x["limit"]
        meta["limit_source"] = f"(Reused from `{shown(args.limit_json)}`.)"
    else:
        meta["limit_source"] = ""
    rows = []
    for d, m, g in cases:
        if (d, m, g) not in limits:
            t = time.perf_counter()
            limits[(d, m, g)] = limit_case(d, m, g)
            log(f"[side-by-side] limit {d} {m} {g}: {sum(x['evaluations'] or 0 for x in limits[(d, m, g)].values())} "
                f"({time.perf_counter() - t:.0f} s)")
        for rec, lim in limits[(d, m, g)].items():
            rows.append(dict(d=d, m=m, g=g, rec=rec, limit=lim, engine=engine.get((d, m, g, rec)), peers={}))

    # 3. The peers.
    for r in rows:
        r["peers"] = run_peers(r["d"], r["m"], r["g"], r["limit"], peers, args.cap)
        log(f"[side-by-side] peers {r['d']} {r['m']} {r['g']} {r['rec']}: "
            + ", ".join(f"{p} {peer_cell(x)} {peer_err(x, r['limit'])} ({x['seconds']:.1f} s)" for p, x in r["peers"].items()))

    # 4. The report.
    meta["load_end"] = load_average()
    md = report(rows, peers, meta)
    os.makedirs(os.path.dirname(out_md), exist_ok=True)
    with open(out_md, "w") as fh:
        fh.write(md)
    with open(out_json, "w") as fh:
        json.dump(dict(meta=meta, peers=peers, engine=edoc, rows=rows), fh, indent=1)
    print(md)
    log(f"[side-by-side] wrote {out_md} and {out_json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
