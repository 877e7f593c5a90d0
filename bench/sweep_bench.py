#!/usr/bin/env python3
"""Sweep benchmark: roughscope.sweep.run_sweep serial, in a process pool and on dask, same run.

Run with Debian's interpreter and the built module on the path:

    PYTHONPATH=build/python /usr/bin/python3 bench/sweep_bench.py [--realisations 200] [--workers 2]

One grid (Gaussian and exponential correlation, σ = 0.05 and 0.1 µm, T = 1 µm, λ = 0.5 µm, four
geometries: 16 points, the grid chosen) is run

* serially in this process with one thread per point (the baseline),
* serially with all cores per point (simulate_scatter's own threads),
* in a pool of --workers processes (one thread each),
* on a dask.distributed LocalCluster of --workers processes (one thread each; the cluster's
  start-up is timed apart; one run, as a repeat would reuse the cluster's results).

Every mode must give the baseline's results (==) before any time is printed. Times are the
minimum of --repeats runs; ratios are baseline time / mode time.
"""
import argparse
import os
import sys
import time

import distributed

from roughscope import sweep


def best_time(run, repeats):
    best, result = float("inf"), None
    for _ in range(repeats):
        start = time.perf_counter()
        result = run()
        best = min(best, time.perf_counter() - start)
    return best, result


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--realisations", type=int, default=200)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()

    points = sweep.grid(correlation=["gaussian", "exponential"], sigma_um=[0.05, 0.1], T_um=1.0,
                        wavelength_um=0.5,
                        geometries=[(10, 0, 0), (30, 0, 0), (45, 20, 90), (60, 30, 180)],
                        realisations=args.realisations, seed=2026)
    base_t, base = best_time(lambda: sweep.run_sweep(points, processes=1, threads=1), args.repeats)
    rows = [("serial, 1 thread per point (baseline)", base_t)]

    t, r = best_time(lambda: sweep.run_sweep(points, processes=1, threads=0), args.repeats)
    assert r == base, "serial with all threads differs from the baseline"
    rows.append((f"serial, all {os.cpu_count()} cores per point", t))

    t, r = best_time(lambda: sweep.run_sweep(points, processes=args.workers), args.repeats)
    assert r == base, "process pool differs from the baseline"
    rows.append((f"process pool, {args.workers} processes (start-up included)", t))

    start = time.perf_counter()
    with distributed.LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster, set_as_default=False) as client:
        startup = time.perf_counter() - start
        client.run(lambda: __import__("roughscope.sweep"))  # warm the workers' imports
        # One run only: the cluster keeps a finished point's result under its key (client.map is
        # pure by default), so a repeat would fetch the results instead of computing them.
        t, r = best_time(lambda: sweep.run_sweep(points, scheduler=client), 1)
        assert r == base, "dask differs from the baseline"
    rows.append((f"dask LocalCluster, {args.workers} workers (start-up {startup:.2f} s apart)", t))

    print(f"{len(points)} points x {args.realisations} realisations, min of {args.repeats}")
    print(f"{'mode':<60} {'time [s]':>9} {'speed-up':>9}")
    for name, t in rows:
        print(f"{name:<60} {t:9.3f} {base_t / t:9.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
