#!/usr/bin/python3
"""Generate tests/data/series_reference.csv: 40-digit reference values of the B–K series sums.

    S_G(g, X) = e^{-g} Σ_{n≥1} gⁿ/(n! n) exp(-X/(4n))          (Eq. 2 without prefactor)
    S_E(g, X) = e^{-g} Σ_{n≥1} gⁿ/n! · n/(n² + X)^{3/2}          (exact exponential series)

with X = T² v_xy². Run once with Debian's interpreter (python3-mpmath, python3-numpy,
python3-scipy); the C++ and Python tests only read the stored CSV and never run mpmath:

    /usr/bin/python3 scripts/gen_reference.py            # writes tests/data/series_reference.csv
    /usr/bin/python3 scripts/gen_reference.py --check    # recompute and compare with the file

Method. Every sum is done exactly, in mpmath at 50 significant digits: the log-summand
L(n) = n ln g − ln n! − g + ln f(n) is concave in n, so a double-precision scan over n locates its
peak n* and the range where L(n) > L(n*) − 135 (every term outside it is < e^{-135} ≈ 2e-59 of the
largest, and the terms outside decay at least geometrically, so the omitted total is far below
1e-45 relative). Inside that range the Poisson weights wₙ = e^{-g} gⁿ/n! are generated in mpmath
by the recurrence w_{n+1} = wₙ g/(n+1) started from one exactly evaluated weight (the
recurrence loses ~1e-50 per step, < 1e-44 over the ≤ 1e5 steps used), and Σ wₙ f(n) is
accumulated term by term. Pairs whose value underflows double (< 1e-300) are dropped.

Self-checks run before anything is written (the script aborts if one fails):
  * S_G(g, 0) = e^{-g} [Ei(g) − γ − ln g]                  (independent closed form: the
    derivative of Σ gⁿ/(n! n) is (e^g − 1)/g, so the sum is ∫₀^g (e^t − 1)/t dt = −Ein(−g);
    note that Ein(g) = ∫₀^g (1 − e^{−t})/t dt itself has alternating signs)
  * S_E(g, 0) = e^{-g} g ₃F₃(1,1,1; 2,2,2; g)              (independent closed form)
  * for g ≤ 50, the raw series from n = 1 summed term by term (independent summation)
"""

import argparse
import csv
import math
import os
import sys
import time

import mpmath as mp
import numpy as np
from scipy.special import gammaln

mp.mp.dps = 50

# g values: every decade 1e-6 .. 1e6 plus in-between values, as the exact decimal strings that
# are written to the CSV.
G_STRINGS = (
    [("1" if k == 0 else f"1e{k}") for k in range(-6, 7)]
    + ["0.3", "0.5", "2", "3", "7", "20", "50", "150", "700", "710", "750", "2000", "3e4", "3e5"]
)
X_STRINGS = ["0", "1e-3", "0.1", "1", "10", "100", "1e3", "1e4", "1e5"]

LOG_CUT = 135.0  # terms below e^{-LOG_CUT} of the peak term are omitted
UNDERFLOW = mp.mpf("1e-300")


def log_summand(kind, g, X, n):
    """Double-precision log of the n-th summand (n: numpy float array)."""
    L = n * math.log(g) - gammaln(n + 1.0) - g
    if kind == "gaussian":
        return L - np.log(n) - X / (4.0 * n)
    return L + np.log(n) - 1.5 * np.log(n * n + X)


def summation_range(kind, g, X):
    """[n_lo, n_hi] outside which every term is < e^{-LOG_CUT} of the peak term."""
    n_max = int(g + 60.0 * math.sqrt(g) + 400.0)
    while True:
        n = np.arange(1, n_max + 1, dtype=float)
        L = log_summand(kind, g, X, n)
        i_peak = int(np.argmax(L))
        keep = np.nonzero(L > L[i_peak] - LOG_CUT)[0]
        # The summand is unimodal: the kept indices are contiguous. Make sure the range closes
        # before the end of the scanned array.
        if keep[-1] < len(n) - 1:
            return int(n[keep[0]]), int(n[keep[-1]]), float(L[i_peak])
        n_max *= 2


def f_gaussian(n, X):
    return mp.exp(-X / (4 * n)) / n


def f_exponential(n, X):
    return n / mp.power(n * n + X, mp.mpf(3) / 2)


def exact_sum(kind, g_str, X_str):
    g = mp.mpf(g_str)
    X = mp.mpf(X_str)
    n_lo, n_hi, log_peak = summation_range(kind, float(g_str), float(X_str))
    if log_peak < math.log(1e-300) - 50.0:
        return mp.mpf(0)  # hopelessly underflowed: not written
    f = f_gaussian if kind == "gaussian" else f_exponential
    # One exactly evaluated Poisson weight, then the recurrence.
    w = mp.exp(n_lo * mp.log(g) - mp.loggamma(n_lo + 1) - g)
    total = mp.mpf(0)
    for n in range(n_lo, n_hi + 1):
        total += w * f(mp.mpf(n), X)
        w = w * g / (n + 1)
    return total


def closed_form_X0(kind, g_str):
    with mp.workdps(90):  # Ei(g) − γ − ln g cancels ~|ln g|/g digits at small g
        g = mp.mpf(g_str)
        if kind == "gaussian":
            value = mp.exp(-g) * (mp.ei(g) - mp.euler - mp.log(g))
        else:
            value = mp.exp(-g) * g * mp.hyper([1, 1, 1], [2, 2, 2], g)
    return +value


def brute_force_reference(kind, g_str, X_str):
    """Every term from n = 1 to g + 40√g + 300 from gⁿ and n! directly, at 70 digits (no range
    selection, no recurrence). mpmath.nsum is not used: its extrapolation is fooled when the
    summand peaks at n > 1 (large X, small g)."""
    with mp.workdps(70):
        g = mp.mpf(g_str)
        X = mp.mpf(X_str)
        f = f_gaussian if kind == "gaussian" else f_exponential
        n_max = int(float(g_str) + 40 * math.sqrt(float(g_str)) + 300)
        value = mp.exp(-g) * mp.fsum(g**n / mp.factorial(n) * f(mp.mpf(n), X)
                                     for n in range(1, n_max + 1))
    return +value


def relative_difference(a, b):
    if a == b:
        return mp.mpf(0)
    return abs(a - b) / max(abs(a), abs(b))


def compute_rows():
    rows = []
    for kind in ("gaussian", "exponential"):
        for g_str in G_STRINGS:
            for X_str in X_STRINGS:
                value = exact_sum(kind, g_str, X_str)
                if value < UNDERFLOW:
                    continue
                rows.append((kind, g_str, X_str, value))
    return rows


def self_check(rows):
    worst = mp.mpf(0)
    checked = 0
    for kind, g_str, X_str, value in rows:
        refs = []
        if X_str == "0":
            # ₃F₃ converges slowly in mpmath for very large g; the closed form is checked where
            # mpmath evaluates it reliably.
            if kind == "gaussian" or float(g_str) <= 2000:
                refs.append(closed_form_X0(kind, g_str))
        if float(g_str) <= 50:
            refs.append(brute_force_reference(kind, g_str, X_str))
        for ref in refs:
            d = relative_difference(value, ref)
            checked += 1
            worst = max(worst, d)
            if d > mp.mpf("1e-40"):
                sys.exit(f"self-check failed: {kind} g={g_str} X={X_str}: "
                         f"{mp.nstr(value, 45)} vs {mp.nstr(ref, 45)} (rel. diff {mp.nstr(d, 3)})")
    print(f"self-check: {checked} comparisons, worst relative difference {mp.nstr(worst, 3)}")


def format_value(value):
    return mp.nstr(value, 40, min_fixed=1, max_fixed=0, strip_zeros=False)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    default_out = os.path.normpath(os.path.join(here, "..", "tests", "data", "series_reference.csv"))
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--output", default=default_out, help="CSV to write")
    parser.add_argument("--check", action="store_true",
                        help="recompute and compare with the existing file instead of writing")
    args = parser.parse_args()

    start = time.time()
    rows = compute_rows()
    print(f"computed {len(rows)} rows in {time.time() - start:.1f} s")
    self_check(rows)

    if args.check:
        with open(args.output, newline="") as fh:
            stored = {(r["kind"], r["g"], r["T2_vxy2"]): mp.mpf(r["value"])
                      for r in csv.DictReader(fh)}
        bad = [(k, g, X) for k, g, X, v in rows
               if (k, g, X) not in stored or relative_difference(stored[(k, g, X)], v) > 1e-38]
        if bad or len(stored) != len(rows):
            sys.exit(f"{args.output} differs from a fresh computation: {bad[:5]}")
        print(f"{args.output}: all {len(rows)} rows agree")
        return

    tmp = args.output + ".tmp"
    with open(tmp, "w", newline="") as fh:
        fh.write("kind,g,T2_vxy2,value\n")
        for kind, g_str, X_str, value in rows:
            fh.write(f"{kind},{g_str},{X_str},{format_value(value)}\n")
    os.replace(tmp, args.output)
    print(f"wrote {args.output} ({time.time() - start:.1f} s)")


if __name__ == "__main__":
    main()
