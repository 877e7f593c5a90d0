"""Property tests of the public Python API over the whole double range (hypothesis).

Every numeric argument is drawn from the whole range of doubles (NaN, ±inf, ±0, subnormals, the
largest finite values) mixed with values inside the documented domain, and every call must
either return finite numbers (never NaN; +inf only as the open upper end of a ratio range) or
raise a ValueError subclass (roughscope.Error) - never another exception, never a crash.

The profile is derandomized (the same examples on every run) and bounded, so CI is reproducible
and the file runs in well under a minute.
"""

import math

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import example, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from roughscope import _core as rs  # noqa: E402

FAST = settings(derandomize=True, max_examples=150, deadline=None, database=None)
SLOW = settings(derandomize=True, max_examples=25, deadline=None, database=None)

any_double = st.floats(allow_nan=True, allow_infinity=True, allow_subnormal=True)
extremes = st.sampled_from([0.0, -0.0, 5e-324, 1e-320, 1e-300, 1e-8, 1e8, 1e300,
                            1.7976931348623157e308, -5e-324, -1e300, math.inf, -math.inf,
                            math.nan])
positive = st.floats(min_value=5e-324, max_value=1.7976931348623157e308)
angle = st.one_of(st.floats(min_value=0.0, max_value=89.99999999999999), extremes, any_double)
azimuth = st.one_of(st.floats(min_value=-720.0, max_value=720.0), extremes, any_double)
length = st.one_of(positive, st.floats(min_value=1e-3, max_value=1e3), extremes)
number = st.one_of(positive, any_double, extremes)
correlation = st.sampled_from(["gaussian", "exponential"])
factor = st.sampled_from(["vh", "beckmann", "ogilvy", "kirchhoff"])
radiometry = st.sampled_from(["radiance", "intensity"])
regime = st.sampled_from(["auto", "series", "slightly_rough", "very_rough",
                          "very_rough_series_limit"])


def finite_everywhere(value, allow_inf=False, where="result"):
    """Asserts every number inside `value` (float, array, tuple, list, dict) is finite."""
    if value is None or isinstance(value, (str, bool)):
        return
    if isinstance(value, dict):
        for k, v in value.items():
            finite_everywhere(v, allow_inf, f"{where}[{k!r}]")
    elif isinstance(value, (list, tuple)):
        for i, v in enumerate(value):
            finite_everywhere(v, allow_inf, f"{where}[{i}]")
    elif isinstance(value, np.ndarray):
        if value.dtype.kind == "f":
            assert not np.isnan(value).any(), f"NaN in {where}: {value}"
            if not allow_inf:
                assert np.isfinite(value).all(), f"inf in {where}: {value}"
    elif isinstance(value, (float, int, np.floating, np.integer)):
        assert not math.isnan(value), f"NaN in {where}"
        assert allow_inf or math.isfinite(value), f"{value} in {where}"


def call(fn, *args, allow_inf=False, **kwargs):
    """Calls fn; a ValueError subclass is an accepted outcome, any result must be finite."""
    try:
        result = fn(*args, **kwargs)
    except ValueError as exc:
        assert isinstance(exc, rs.Error) or "must" in str(exc) or "invalid" in str(exc), exc
        assert str(exc), "empty error message"
        return None
    finite_everywhere(result, allow_inf, f"{fn.__name__}{args}")
    return result


# ---- B-K model (Eq. 1-5) ------------------------------------------------------------------

@FAST
@given(angle, angle, azimuth, length, length, correlation, factor, regime, radiometry, length,
       length, length)
@example(30.0, 20.0, 45.0, 1e300, 1.0, "gaussian", "vh", "auto", "radiance", 0.555, 500.0, 500.0)
@example(30.0, 20.0, 45.0, 0.1, 1.0, "gaussian", "vh", "auto", "radiance", 0.555, 5e-324, 500.0)
def test_mean_scattered_power(ti, ts, ps, sigma, T, corr, fac, reg, rad, wl, px, py):
    out = call(rs.mean_scattered_power, ti, ts, ps, sigma, T, correlation=corr, factor=fac,
               regime=reg, radiometry=rad, wavelength_um=wl, patch_x_um=px, patch_y_um=py)
    if out is not None:
        assert out["diffuse"] >= 0 and out["coherent"] >= 0
        assert out["method"] in ("closed_form", "summation", "large_g_expansion")
        assert out["relative_error_bound"] >= 0


@FAST
@given(angle, angle, azimuth, number, correlation, factor, radiometry)
@example(30.0, 30.0, 0.0, 1e-300, "gaussian", "vh", "radiance")  # was NaN (0/0 at q_xy = 0)
@example(30.0, 30.0, 0.0, 5e-324, "exponential", "vh", "radiance")
def test_very_rough_brightness(ti, ts, ps, m, corr, fac, rad):
    call(rs.very_rough_brightness, ti, ts, ps, m, correlation=corr, factor=fac, radiometry=rad)


@FAST
@given(st.lists(angle, min_size=1, max_size=5), st.lists(angle, min_size=1, max_size=5),
       azimuth, st.lists(number, min_size=1, max_size=5), correlation, factor)
def test_very_rough_brightness_arrays(ti, ts, ps, m, corr, fac):
    n = min(len(ti), len(ts), len(m))
    call(rs.very_rough_brightness, np.array(ti[:n]), np.array(ts[:n]), ps, np.array(m[:n]),
         correlation=corr, factor=fac)


@FAST
@given(number, number)
def test_series_sums(g, a):
    for fn in (rs.gaussian_series_sum, rs.exponential_series_sum):
        out = call(fn, g, a)
        if out is not None:
            assert 0.0 <= out <= 1.0


@SLOW
@given(correlation, number, length, number, st.one_of(number, st.floats(0, 2e4)),
       st.one_of(number, st.floats(0, 1e4)))
def test_diffuse_power_quadrature(corr, F2, T, A, g, vxy2):
    out = call(rs.diffuse_power_quadrature, corr, F2, T, A, g, vxy2)
    if out is not None:
        assert out >= 0.0


@FAST
@given(angle, number)
def test_retro_forms(theta, m):
    for fn in (rs.retro_beckmann_gaussian_very_rough, rs.retro_beckmann_exponential_very_rough,
               rs.retro_vh_gaussian_very_rough, rs.retro_vh_exponential_very_rough):
        call(fn, theta, m)


@FAST
@given(angle, length, length, length)
def test_retro_slightly_rough(theta, sigma, T, wl):
    call(rs.retro_vh_gaussian_slightly_rough, theta, sigma, T, wl)


@FAST
@given(angle, angle, azimuth, length)
def test_geometry_quantities(ti, ts, ps, wl):
    call(rs.scattering_vector, ti, ts, ps, wl)
    call(rs.roughness_g, ti, ts, wl, wl)
    call(rs.geometric_factor_beckmann, ti, ts, ps)
    for fac in ("vh", "beckmann", "ogilvy", "kirchhoff"):
        call(rs.geometric_factor_squared, fac, ti, ts, ps)
    call(rs.lambert_brightness, ti)


@FAST
@given(number, number, length, length)
def test_coherent_terms(a, b, px, py):
    call(rs.coherent_power, a, b)
    call(rs.specular_amplitude_rho0, a, b, px, py)
    call(rs.roughness_class, b)
    for fn in (rs.rms_slope, rs.caron_theta_K_deg, rs.caron_xi_K):
        call(fn, a)


# ---- Comparison models (section 5) ----------------------------------------------------------

@FAST
@given(angle, angle, azimuth, number, st.one_of(st.floats(0, 1), extremes))
@example(30.0, 20.0, 45.0, 1e300, 0.5)  # was NaN (inf/inf in the coefficients)
def test_oren_nayar(ti, ts, ps, sigma, albedo):
    call(rs.oren_nayar_radiance, ti, ts, ps, sigma, albedo)
    call(rs.oren_nayar_qualitative_radiance, ti, ts, ps, sigma, albedo)


@FAST
@given(angle, angle, azimuth, number, number, number, number)
def test_lafortune(ti, ts, ps, n, cx, cz, rho_d):
    call(rs.lafortune_diffuse_brightness, ti, ts, ps, n)
    call(rs.lafortune_brdf, ti, ts, ps, [{"Cx": cx, "Cy": cx, "Cz": cz, "n": n, "albedo": 1.0}],
         rho_d)


# ---- Estimation (section 4) ---------------------------------------------------------------

@FAST
@given(number, angle, length, number, number)
@example(1e-320, 10.0, 0.555, 1.0, 0.01)  # sigma was inf (R0/R_spec overflowed)
def test_specular_estimates(R, theta, wl, R0, E):
    sigma = call(rs.sigma_from_specular, R, theta, wl, R0)
    if sigma is not None:
        out = call(rs.estimate_sigma_specular, R_spec=R, theta_deg=theta, wavelength_um=wl,
                   R0=R0)
        assert out["sigma_um"] is not None, "sigma known but reported as unknown"
    call(rs.specular_reflectance_from_brightness, E, R)
    call(rs.estimate_sigma_specular, R_spec=R, theta_deg=theta, wavelength_um=wl, R0=R0,
         noise=E)


@FAST
@given(number, angle, angle, factor, number)
def test_slope_estimates(ratio, t1, t2, fac, noise):
    call(rs.sigma_over_T_gaussian, ratio, t1, t2, fac)
    call(rs.sigma_over_T_exponential, ratio, t1, t2, fac)
    call(rs.ratio_range_gaussian, t1, t2, fac, allow_inf=True)
    call(rs.ratio_range_exponential, t1, t2, fac, allow_inf=True)
    call(rs.estimate_slope, ratio, t1, t2, factor=fac, noise=noise)


@FAST
@given(number, length, angle, angle, length, number)
def test_correlation_length_estimates(ratio, sigma, t1, t2, wl, stderr):
    call(rs.correlation_length_from_ratio, ratio, sigma, t1, t2, wl)
    call(rs.ratio_range_correlation_length, sigma, t1, t2, wl, allow_inf=True)
    call(rs.estimate_correlation_length, ratio, sigma, t1, t2, sigma_um_stderr=stderr,
         wavelength_um=wl)


@SLOW
@given(number, angle, angle, azimuth, angle, angle, azimuth, correlation, length)
def test_two_geometry_solvers(ratio, ti1, ts1, ps1, ti2, ts2, ps2, corr, sigma):
    call(rs.sigma_over_T_two_geometries, ratio, ti1, ts1, ps1, ti2, ts2, ps2, correlation=corr)
    call(rs.correlation_length_two_geometries, ratio, sigma, ti1, ts1, ps1, ti2, ts2, ps2,
         correlation=corr)
