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


# ---- Every finite g: 40-digit references computed here, and the large-g limit ------------------
#
# The stored table stops at g = 1e6. Beyond, the sums switch to their large-g expansion where the
# summation underflows or loses digits (beckmann.hpp); these tests compute references with mpmath
# independently of the library: a direct sum for small g, and for large g the integral of the
# analytic continuation t(x) = exp(-g) g^x/Gamma(x+1) h(x) over the Poisson peak (equal to the sum
# up to exp(-2 pi^2 g), by Poisson summation). Above g = 1e13 the fact checked is the g -> infinity
# limit (Eq. 4, and g/(g^2 + b)^{3/2} for the exponential series) with its first correction.

mpmath = pytest.importorskip("mpmath")


def _h(kind, x, X):
    if kind == "gaussian":  # exp(-a/x)/x, a = T^2 v_xy^2 / 4
        return mpmath.exp(-mpmath.mpf(X) / 4 / x) / x
    return x / (x * x + X) ** mpmath.mpf(1.5)


def _reference(kind, g, X):
    """S(g, X) = exp(-g) sum_{n>=1} g^n/n! h(n) to ~30 digits."""
    with mpmath.workdps(60):
        g, X = mpmath.mpf(g), mpmath.mpf(X)

        def t(x):
            return mpmath.exp(-g + x * mpmath.log(g) - mpmath.loggamma(x + 1)) * _h(kind, x, X)

        if g < 1e4:  # direct sum outward from n = 1 until the terms are negligible
            total, n, peak = mpmath.mpf(0), 1, mpmath.mpf(0)
            while True:
                term = t(mpmath.mpf(n))
                total += term
                peak = max(peak, term)
                if n > g + 10 and term < peak * mpmath.mpf(10) ** -40:
                    return float(total)
                n += 1
        s = mpmath.sqrt(g)
        nodes = [g + s * z for z in (-45, -20, -10, -5, -2, 0, 2, 5, 10, 20, 45)]
        return float(mpmath.quad(t, nodes))


@pytest.mark.parametrize("kind", ["gaussian", "exponential"])
@pytest.mark.parametrize("g,X", [
    (5e-324, 0.0), (1e-320, 3.0), (1e-300, 0.0), (1e-300, 10.0), (1e-100, 1.0), (1e-10, 50.0),
    (3.0, 7.0), (4e3, 0.0), (2e4, 1e4), (3e5, 3e5), (1e7, 4e7), (1e7, 0.0), (1e9, 4e9),
    (1e11, 0.0), (1e12, 4e13),
])
def test_series_against_mpmath_for_tiny_and_large_g(kind, g, X):
    if kind == "exponential" and g >= 1e4:
        X = X * g  # b = T^2 v_xy^2 of the same relative size in the exponential lobe
    ref = _reference(kind, g, X)
    got = SUMS[kind](g, X)
    if ref < 2.2250738585072014e-308:  # subnormal: absolute, not relative, precision
        assert abs(got - ref) <= 2e-323, (got, ref)
    else:
        assert got == pytest.approx(ref, rel=1e-12 + 1e-21 * g, abs=0.0), (got, ref)


@pytest.mark.parametrize("kind", ["gaussian", "exponential"])
@pytest.mark.parametrize("g", [1e13, 1e15, 1.671604872e15, 1e20, 1e50, 1e100, 1e200, 1e300])
@pytest.mark.parametrize("c", [0.0, 0.5, 3.0, 40.0])
def test_series_approach_the_very_rough_limit_with_its_bound(kind, g, c):
    """S/L - 1 = R1/g + O(1/g^2): the g -> infinity limit L (Eq. 4, or g/(g^2 + b)^{3/2})
    computed in mpmath; R1 = c^2/2 - 2c + 1 (Gaussian, c = a/g) or 3(2 - 3c)/(2(1 + c)^2)
    (exponential, c = b/g^2)."""
    with mpmath.workdps(40):
        G = mpmath.mpf(g)
        if kind == "gaussian":
            X = 4 * c * g
            limit = mpmath.exp(-mpmath.mpf(c)) / G
            R1 = c * c / 2 - 2 * c + 1
        else:
            X = c * g * g
            if not math.isfinite(X):
                pytest.skip("b = c g^2 is not a double")
            limit = G / (G * G + mpmath.mpf(X)) ** mpmath.mpf(1.5)
            R1 = 3 * (2 - 3 * c) / (2 * (1 + c) ** 2)
        expected = float(limit)
    got = SUMS[kind](g, X)
    if expected < 2.2250738585072014e-308:  # subnormal or 0: absolute precision
        assert abs(got - expected) <= 1e-320
        return
    assert got / expected - 1 == pytest.approx(R1 / g, abs=1e-14)
    assert got > 0.0  # never the underflow to 0 the summation gave near g = 1e15


def test_model_reports_the_large_g_method_and_its_bound():
    # g = 1.67e15 (sigma = 2 m): the summation underflowed to diffuse = 0; the very-rough form
    # (Eq. 4) gives 2.506e-8.
    out = rs.mean_scattered_power(30, 20, 45, 2e6, 4e6)
    very_rough = rs.mean_scattered_power(30, 20, 45, 2e6, 4e6, regime="very_rough")
    assert out["regime"] == "series" and out["method"] == "large_g_expansion"
    assert 0.0 < out["relative_error_bound"] < 1e-12
    assert out["diffuse"] == pytest.approx(very_rough["diffuse"], rel=1e-14)
    assert out["diffuse"] == pytest.approx(2.5061086778e-8, rel=1e-10)
    small = rs.mean_scattered_power(30, 20, 45, 0.3, 1.0)
    assert small["method"] == "summation" and 0.0 < small["relative_error_bound"] <= 1e-12
    closed = rs.mean_scattered_power(30, 20, 45, 0.3, 1.0, regime="very_rough")
    assert closed["method"] == "closed_form" and closed["relative_error_bound"] == 0.0


def test_model_rejects_lengths_outside_the_documented_range():
    with pytest.raises(rs.InvalidArgument, match=r"sigma = 1e\+300 um is outside the valid range"):
        rs.mean_scattered_power(30, 20, 45, 1e300, 1.0)
    with pytest.raises(rs.InvalidArgument, match="patch_x"):
        rs.mean_scattered_power(30, 20, 45, 0.1, 1.0, patch_x_um=5e-324)


# ---- Quadrature: accurate inside its documented domain, a named error outside ---------------

@pytest.mark.parametrize("kind", ["gaussian", "exponential"])
@pytest.mark.parametrize("g,w", [(1e-3, 0.5), (0.5, 1.0), (10.0, 5.0), (50.0, 50.0),
                                 (1e3, 3.0), (1e4, 100.0), (1e4, 0.0), (3.0, 10.0)])
def test_quadrature_agrees_with_the_series_inside_its_domain(kind, g, w):
    series = (rs.diffuse_power_gaussian_series if kind == "gaussian"
              else rs.diffuse_power_exponential_series)
    quad = rs.diffuse_power_quadrature(kind, 0.8, 2.0, 1e4, g, (w / 2.0) ** 2)
    ref = series(0.8, 2.0, 1e4, g, (w / 2.0) ** 2)
    # absolute error against the integral's size at the lobe centre (beckmann.hpp)
    p = 1 if kind == "gaussian" else 2
    scale = 2 * math.pi / 1e4 * 0.8 * 4.0 * -math.expm1(-g) / max(g, 1.0) ** p
    assert quad >= 0.0
    assert abs(quad - ref) <= 1e-12 * scale, (quad, ref)


@pytest.mark.parametrize("g,vxy2,match", [
    (2e4, 1.0, r"g = 20000 is outside the domain of diffuse_power_quadrature"),
    (1e300, 1.0, r"g = 1e\+300 is outside the domain"),
    (1.0, 1e6, r"T v_xy = 2000 is outside the domain of diffuse_power_quadrature"),
])
def test_quadrature_outside_its_domain_is_a_named_error(g, vxy2, match):
    for kind in ("gaussian", "exponential"):
        with pytest.raises(rs.InvalidArgument, match=match):
            rs.diffuse_power_quadrature(kind, 1.0, 2.0, 1.0, g, vxy2)
