"""The B–K series sums through the Python module, against the stored 40-digit mpmath values.

tests/data/series_reference.csv is generated once by scripts/gen_reference.py (mpmath, 50 digits);
these tests only read it. Both the scalar path and the array (broadcast) path of
roughscope.gaussian_series_sum / exponential_series_sum are checked.
"""

import csv
import math
import pathlib

import numpy as np
import pytest

import roughscope as rs

REFERENCE = pathlib.Path(__file__).resolve().parents[1] / "data" / "series_reference.csv"


def _load():
    with open(REFERENCE, newline="", encoding="utf-8") as fh:
        reader = csv.DictReader(fh)
        assert reader.fieldnames == ["kind", "g", "T2_vxy2", "value"]
        return [(r["kind"], float(r["g"]), float(r["T2_vxy2"]), float(r["value"]))
                for r in reader]


ROWS = _load()
SUMS = {"gaussian": rs.gaussian_series_sum, "exponential": rs.exponential_series_sum}


def test_reference_file_covers_both_kinds_over_twelve_decades():
    for kind in SUMS:
        gs = [g for k, g, _, _ in ROWS if k == kind]
        assert len(gs) >= 230
        assert min(gs) == 1e-6 and max(gs) == 1e6


@pytest.mark.parametrize("kind,g,X", [
    ("gaussian", 1e-6, 0.0),
    ("gaussian", 0.3, 100.0),
    ("gaussian", 710.0, 1e3),
    ("gaussian", 1e6, 1e5),
    ("exponential", 1e-3, 1e4),
    ("exponential", 2.0, 0.1),
    ("exponential", 750.0, 0.0),
    ("exponential", 3e5, 1e5),
])
def test_scalar_rows_match_reference(kind, g, X):
    (value,) = [v for k, gg, XX, v in ROWS if (k, gg, XX) == (kind, g, X)]
    got = SUMS[kind](g, X)
    assert isinstance(got, float)
    assert got == pytest.approx(value, rel=1e-12)


@pytest.mark.parametrize("kind", sorted(SUMS))
def test_every_row_through_the_array_path(kind):
    rows = [(g, X, v) for k, g, X, v in ROWS if k == kind]
    g, X, ref = (np.array(c) for c in zip(*rows))
    got = SUMS[kind](g, X)
    assert isinstance(got, np.ndarray) and got.shape == ref.shape
    rel = np.abs(got / ref - 1.0)
    worst = int(np.argmax(rel))
    assert rel[worst] <= 1e-12, (
        f"{kind}: worst row g={g[worst]}, T2_vxy2={X[worst]}: {got[worst]!r} vs {ref[worst]!r}")
    # The array path agrees with the scalar path.
    scalar = np.array([SUMS[kind](float(a), float(b)) for a, b in zip(g, X)])
    np.testing.assert_allclose(got, scalar, rtol=1e-14, atol=0.0)


def test_gaussian_sum_at_zero_X_is_an_exponential_integral():
    # Σ gⁿ/(n! n) = ∫₀^g (e^t − 1)/t dt: check the integral by Simpson's rule at g = 3.
    g = 3.0
    t = np.linspace(0.0, g, 20001)
    f = np.ones_like(t)
    f[1:] = np.expm1(t[1:]) / t[1:]
    h = t[1] - t[0]
    simpson = h / 3.0 * (f[0] + f[-1] + 4.0 * f[1:-1:2].sum() + 2.0 * f[2:-1:2].sum())
    assert rs.gaussian_series_sum(g, 0.0) == pytest.approx(math.exp(-g) * simpson, rel=1e-12)


@pytest.mark.parametrize("name", sorted(SUMS))
@pytest.mark.parametrize("g,X,bad", [
    (-1.0, 0.0, "g"),
    (float("nan"), 0.0, "g"),
    (1.0, -2.0, "T2_vxy2"),
    (1.0, float("inf"), "T2_vxy2"),
])
def test_bad_input_raises_value_error_naming_the_argument(name, g, X, bad):
    with pytest.raises(ValueError, match=rf"^{bad}\b") as info:
        SUMS[name](g, X)
    assert isinstance(info.value, rs.InvalidArgument)


def test_bad_element_in_array_is_reported():
    with pytest.raises(ValueError, match=r"index 1: g = -1 "):
        rs.gaussian_series_sum(np.array([1.0, -1.0]), np.array([0.0, 0.0]))
