#!/usr/bin/env python3
"""Python-boundary benchmark: roughscope.very_rough_brightness against NumPy, same run.

Run with Debian's interpreter and the built module on the path:

    PYTHONPATH=build/python /usr/bin/python3 bench/python_bench.py [--n 1000000] [--repeats 7]

Both sides get the same 1M random geometries (θi, θs uniform in [0, 85) degrees, φs uniform in
[0, 360) degrees, σ/T = 0.5) and compute the same thing: the very-rough diffuse brightness with
the Vernold–Harvey factor (F² = cos θi), radiance interpretation,
    Gaussian (Eq. 4 shape):    F²/q_z² exp(−q_xy² / (4 (σ/T)² q_z²))
    exponential (Eq. 5 shape): F² / (q_z² [1 + q_xy² / ((σ/T)² q_z²)]^{3/2})
The NumPy side is a straightforward vectorised expression (no Python loop, no validation; the
roughscope side validates every element first). Each timing is the minimum of several repeats;
results are checked to agree before any time is printed.
"""
import argparse
import os
import sys
import time

import numpy as np

import roughscope


def numpy_very_rough(theta_i_deg, theta_s_deg, phi_s_deg, m, correlation):
    ti = np.radians(theta_i_deg)
    ts = np.radians(theta_s_deg)
    ph = np.radians(phi_s_deg)
    si, ci = np.sin(ti), np.cos(ti)
    ss, cs = np.sin(ts), np.cos(ts)
    qxy2 = si * si + ss * ss - 2.0 * si * ss * np.cos(ph)
    qz2 = (ci + cs) ** 2
    F2 = ci
    if correlation == "gaussian":
        return F2 / qz2 * np.exp(-qxy2 / (4.0 * m * m * qz2))
    t = 1.0 + qxy2 / (m * m * qz2)
    return F2 / (qz2 * t ** 1.5)


def best_time(fn, repeats):
    """(min wall time, min process CPU time over all threads, last result) over `repeats`."""
    best_wall = best_cpu = float("inf")
    result = None
    for _ in range(repeats):
        c0, t0 = time.process_time(), time.perf_counter()
        result = fn()
        best_wall = min(best_wall, time.perf_counter() - t0)
        best_cpu = min(best_cpu, time.process_time() - c0)
    return best_wall, best_cpu, result


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=1_000_000, help="number of geometries")
    parser.add_argument("--repeats", type=int, default=7, help="repeats per timing (min taken)")
    parser.add_argument("--seed", type=int, default=20070101)
    args = parser.parse_args(argv)
    if args.n < 1 or args.repeats < 1:
        print("error: --n and --repeats must be >= 1", file=sys.stderr)
        return 2

    rng = np.random.default_rng(args.seed)
    theta_i = rng.uniform(0.0, 85.0, args.n)
    theta_s = rng.uniform(0.0, 85.0, args.n)
    phi_s = rng.uniform(0.0, 360.0, args.n)
    m = 0.5

    from roughscope import _core

    isa = _core._set_vector_isa("best")
    print(f"roughscope {roughscope.__version__} (array kernel: {isa}), numpy {np.__version__}, "
          f"{args.n} geometries, min of {args.repeats} repeats, {os.cpu_count()} CPUs")
    print("wall: elapsed time (what a caller waits); cpu: CPU time of all threads (the work "
          "done, less sensitive to other load on the machine)")
    print(f"{'correlation':<12} {'roughscope wall/cpu [ms]':>25} {'numpy wall/cpu [ms]':>20} "
          f"{'ratio wall':>11} {'ratio cpu':>10} {'max rel diff':>13}")
    worst_ratio = float("inf")
    for correlation in ("gaussian", "exponential"):
        t_rs, c_rs, out_rs = best_time(
            lambda: roughscope.very_rough_brightness(theta_i, theta_s, phi_s, m,
                                                     correlation=correlation, factor="vh"),
            args.repeats)
        t_np, c_np, out_np = best_time(
            lambda: numpy_very_rough(theta_i, theta_s, phi_s, m, correlation), args.repeats)
        scale = np.maximum(np.abs(out_np), np.finfo(float).tiny)
        rel = float(np.max(np.abs(out_rs - out_np) / scale))
        if not rel < 1e-9:
            print(f"error: roughscope and numpy disagree ({correlation}): max relative "
                  f"difference {rel:.3g}", file=sys.stderr)
            return 1
        ratio = t_np / t_rs
        worst_ratio = min(worst_ratio, ratio)
        cpu_ratio = c_np / c_rs if c_rs > 0 else float("inf")
        print(f"{correlation:<12} {t_rs * 1e3:12.2f} /{c_rs * 1e3:9.2f}  "
              f"{t_np * 1e3:9.2f} /{c_np * 1e3:8.2f} {ratio:10.1f}x {cpu_ratio:9.1f}x "
              f"{rel:13.2e}")
    print(f"wall-clock speed-up over numpy (worst of the two): {worst_ratio:.1f}x "
          f"(target >= 20x)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
