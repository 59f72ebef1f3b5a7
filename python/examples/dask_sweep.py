"""A sweep of many recipes split into shards over a Dask cluster, gathered into one table.

Each recipe travels as a JSON string, so a task is a plain list of strings (picklable, small) and a worker needs
nothing but `import glossmeter`. The table is the same, reading for reading and bit for bit, as the sweep run in
one process: every reading is deterministic (the engine's integrals are single-threaded and ordered), and the
shards are put back in recipe order.

    python examples/dask_sweep.py                      # 10^4 recipes on a LocalCluster, checked against one process
    python examples/dask_sweep.py --scheduler tcp://scheduler-host:8786 --n 1000000 --out table.csv

On a real cluster: start `dask scheduler` on one machine and `dask worker tcp://scheduler-host:8786` on each
worker (each with `pip install ./python` done, the same glossmeter version everywhere), then pass the scheduler's
address. Or build the client from any deployment (dask-jobqueue's SLURMCluster, dask-kubernetes, Coiled) and
call `sweep_on_dask(client, recipes)`. See docs/python.md.
"""
import argparse
import json
import struct
import sys
import time

import glossmeter

GEOMETRIES = ["astm-d523-20", "astm-d523-60", "astm-d523-85"]
COLUMNS = ["recipe", "geometry", "name", "value", "error_estimate", "evaluations", "converged"]


def design(n):
    """n recipes as JSON strings: rough dielectrics over a grid of roughness, index and distribution."""
    out = []
    for i in range(n):
        out.append(json.dumps({
            "name": f"design-{i}",
            "model": "microfacet",
            "distribution": "ggx" if i % 2 else "beckmann",
            "roughness": 0.02 + 0.28 * ((i // 2) % 50) / 49,
            "ior": 1.3 + 0.5 * ((i // 100) % 100) / 99,
        }))
    return out


def measure_shard(start, recipes, geometries=GEOMETRIES, rtol=1e-4):
    """Rows (recipe index, geometry, reading, value, error, evaluations, converged) of one shard."""
    rows = []
    for k, text in enumerate(recipes):
        for r in glossmeter.measure(text, geometries=geometries, rtol=rtol, timing=False):
            rows.append((start + k, r["geometry"], r["name"], r["value"], r["error_estimate"], r["evaluations"],
                         r["converged"]))
    return rows


def sweep_in_process(recipes, **kw):
    return measure_shard(0, recipes, **kw)


def sweep_on_dask(client, recipes, shard_size=250, **kw):
    """Submit one task per shard, gather the rows in recipe order."""
    starts = list(range(0, len(recipes), shard_size))
    futures = [client.submit(measure_shard, s, recipes[s:s + shard_size], pure=False, **kw) for s in starts]
    rows = []
    for part in client.gather(futures):  # gather keeps the order of `futures`
        rows.extend(part)
    return rows


def same_bits(a, b):
    """Tables equal reading for reading, floats compared as bits."""
    if len(a) != len(b):
        return False
    f = lambda x: struct.pack(">d", x).hex() if isinstance(x, float) else x  # noqa: E731
    return all(tuple(map(f, x)) == tuple(map(f, y)) for x, y in zip(a, b))


def write_csv(rows, path):
    with open(path, "x") as out:  # never overwrite a file
        out.write(",".join(COLUMNS) + "\n")
        for r in rows:
            out.write(",".join(repr(x) if isinstance(x, float) else str(x) for x in r) + "\n")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000, help="number of recipes (default 10^4)")
    ap.add_argument("--shard-size", type=int, default=250)
    ap.add_argument("--workers", type=int, default=2, help="LocalCluster workers (without --scheduler)")
    ap.add_argument("--scheduler", help="address of a running Dask scheduler, e.g. tcp://host:8786")
    ap.add_argument("--no-check", action="store_true", help="skip the one-process run and the comparison")
    ap.add_argument("--out", help="write the table as CSV to this new file")
    args = ap.parse_args(argv)

    from dask.distributed import Client, LocalCluster

    recipes = design(args.n)
    if args.scheduler:
        client, cluster = Client(args.scheduler), None
    else:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    try:
        t = time.perf_counter()
        rows = sweep_on_dask(client, recipes, shard_size=args.shard_size)
        t_dask = time.perf_counter() - t
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    print(f"{len(recipes)} recipes, {len(rows)} readings on Dask in {t_dask:.1f} s "
          f"({(len(recipes) + args.shard_size - 1) // args.shard_size} shards)")
    status = 0
    if not args.no_check:
        t = time.perf_counter()
        one = sweep_in_process(recipes)
        print(f"one process: {time.perf_counter() - t:.1f} s")
        if same_bits(rows, one):
            print("the gathered table equals the one-process table bit for bit")
        else:
            print("MISMATCH between the Dask table and the one-process table", file=sys.stderr)
            status = 1
    if args.out:
        write_csv(rows, args.out)
    return status


if __name__ == "__main__":
    sys.exit(main())
