"""Per-call overhead of measure_brdf against the same model in Rust (docs/performance.md §Python).

Runs, side by side in one process: the library's `microfacet` recipe (GGX α = 0.05, n = 1.5, V-cavity) through
`measure`, and the same formula in NumPy through `measure_brdf` with the lobe hint (so both integrate the same
points), plus a constant f (Lambert) to separate the bindings' cost from NumPy's. Reports wall times (best of
`--repeat`), the time spent inside f, the exact evaluation counts, the number of calls of f and the mean batch
size. "µs/call" is (Python − Rust)/calls, NumPy's work included; "boundary µs/call" leaves out the time inside
f: the cost of crossing into Python (arrays in, checks and copy out) and of the fixed set-up (probe call, plan),
spread over the calls.

    nice python python/bench/overhead.py --repeat 5
"""
import argparse
import pathlib
import sys
import time

import numpy as np

import glossmeter

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
from conftest import microfacet_vcavity  # noqa: E402

GEOS = ["astm-d523-20", "astm-d523-60", "astm-d523-85"]


class Counting:
    def __init__(self, f):
        self.f, self.calls, self.points, self.inside = f, 0, 0, 0.0

    def __call__(self, wi, wo):
        self.calls += 1
        self.points += len(wi)
        t = time.perf_counter()
        out = self.f(wi, wo)
        self.inside += time.perf_counter() - t
        return out


def best(fn, repeat):
    ts = []
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t)
    return min(ts), out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    # None: the library's default relative tolerance (DEFAULT_RTOL), not a copy of its value here.
    ap.add_argument("--rtol", type=float, default=None)
    a = ap.parse_args()
    cases = [
        ("GGX α=0.05 V-cavity", {"model": "microfacet", "distribution": "ggx", "roughness": 0.05, "ior": 1.5,
                                 "shadowing": "v-cavity"}, microfacet_vcavity("ggx", 0.05, 1.5), [0.05]),
        ("Lambert 0.5", {"model": "lambert", "albedo": 0.5}, lambda wi, wo: np.full(len(wi), 0.5 / np.pi), []),
        ("Beckmann m=1e-4 V-cav.", {"model": "microfacet", "distribution": "beckmann", "roughness": 1e-4, "ior": 1.5,
                                    "shadowing": "v-cavity"}, microfacet_vcavity("beckmann", 1e-4, 1.5), [1e-4]),
    ]
    print(f"{'model':22} {'Rust s':>9} {'Python s':>9} {'in f s':>8} {'evals':>9} {'calls':>7} {'pts/call':>8} "
          f"{'µs/call':>8} {'µs/point':>8} {'boundary µs/call':>16}")
    for name, recipe, f, lobes in cases:
        t_rust, rr = best(lambda: glossmeter.measure(recipe, geometries=GEOS, rtol=a.rtol), a.repeat)
        counters = []

        def run():
            c = Counting(f)
            counters.append(c)
            return glossmeter.measure_brdf(c, geometries=GEOS, rtol=a.rtol, lobes=lobes)

        t_py, rp = best(run, a.repeat)
        c = counters[-1]
        evals_r = sum(r["evaluations"] for r in rr)
        evals_p = sum(r["evaluations"] for r in rp)
        over = t_py - t_rust
        boundary = (over - c.inside) / c.calls
        print(f"{name:22} {t_rust:9.4f} {t_py:9.4f} {c.inside:8.4f} {evals_p:9d} {c.calls:7d} "
              f"{c.points / c.calls:8.1f} {over / c.calls * 1e6:8.1f} {over / c.points * 1e6:8.2f} "
              f"{boundary * 1e6:16.1f}"
              + ("" if evals_r == evals_p else f"  (Rust evaluations {evals_r})"))


if __name__ == "__main__":
    main()
