"""The core API through the Python module: the same physical facts the C++ tests check (limits,
identities between the paper's equations, paper tables, high-precision references), plus the
Python boundary itself (broadcasting, return types, errors) and the report.

Every success test has a bad-input partner asserting the error type.
"""

import math
import pathlib
import re
import subprocess
import sys

import numpy as np
import pytest

import roughscope as rs

FACTORS = ("beckmann", "vh", "ogilvy", "kirchhoff")
CORRELATIONS = ("gaussian", "exponential")
RADIOMETRIES = ("radiance", "intensity")


def available_isas():
    """Instruction sets the array kernels can use on this CPU (always 'generic')."""
    from roughscope import _core

    names = []
    for isa in ("generic", "avx2", "avx512"):
        if _core._set_vector_isa(isa) == isa:
            names.append(isa)
    _core._set_vector_isa("best")
    return names


def random_geometries(n, seed=7, theta_max=85.0):
    rng = np.random.default_rng(seed)
    return (rng.uniform(0.0, theta_max, n), rng.uniform(0.0, theta_max, n),
            rng.uniform(0.0, 360.0, n))


# =============================================================================================
# Module, version, error classes
# =============================================================================================

def test_version_and_error_hierarchy():
    assert re.fullmatch(r"\d+\.\d+\.\d+.*", rs.__version__)
    assert issubclass(rs.Error, ValueError)
    for cls in (rs.InvalidArgument, rs.NoSolution, rs.DataError):
        assert issubclass(cls, rs.Error) and cls is not rs.Error
    assert rs.Error.__module__ == "roughscope"


def test_import_does_not_pull_in_matplotlib(python_env):
    code = "import sys, roughscope; print('matplotlib' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], env=python_env, capture_output=True,
                         text=True, check=True)
    assert out.stdout.strip() == "False"


def test_error_carries_the_library_message():
    with pytest.raises(rs.InvalidArgument, match=r"theta_i.*95.*\[0, 90\)"):
        rs.lambert_brightness(95.0)


# =============================================================================================
# Retro-scattering closed forms (Eq. 7–10) = general very-rough forms at φs = 180°, θi = θs
# =============================================================================================

@pytest.mark.parametrize("closed, correlation, factor", [
    (rs.retro_beckmann_gaussian_very_rough, "gaussian", "beckmann"),       # Eq. 7
    (rs.retro_beckmann_exponential_very_rough, "exponential", "beckmann"),  # Eq. 8
    (rs.retro_vh_gaussian_very_rough, "gaussian", "vh"),                   # Eq. 9
    (rs.retro_vh_exponential_very_rough, "exponential", "vh"),             # Eq. 10
])
def test_retro_closed_forms_are_the_general_form_at_retro(closed, correlation, factor):
    theta = np.linspace(0.0, 85.0, 69)
    for m in (0.2, 0.71, 1.8):
        eq = closed(theta, m)
        general = rs.very_rough_brightness(theta, theta, 180.0, m, correlation=correlation,
                                           factor=factor)
        assert np.count_nonzero(eq) > theta.size // 2  # (far tails underflow to 0 in both)
        # θ-independent constant: q_z² = 4cos²θ in the general form gives exactly 4.
        np.testing.assert_allclose(eq, 4.0 * general, rtol=1e-12, atol=0.0)


def test_retro_eq9_matches_its_printed_formula():
    theta = np.linspace(0.0, 80.0, 17)
    m = 0.71
    t = np.radians(theta)
    printed = np.exp(-np.tan(t) ** 2 / (4 * m * m)) / np.cos(t)  # Eq. 9, K = 1
    np.testing.assert_allclose(rs.retro_vh_gaussian_very_rough(theta, m), printed, rtol=1e-13)


def test_retro_eq11_is_eq3_at_retro():
    theta = np.array([0.0, 15.0, 35.0, 60.0, 80.0])
    sigma, T, wl = 0.03, 1.2, 0.555
    k = 2 * np.pi / wl
    area = 4 * 500.0 * 500.0
    eq11 = rs.retro_vh_gaussian_slightly_rough(theta, sigma, T, wl)
    p = rs.mean_scattered_power(theta, theta, 180.0, sigma, T, regime="slightly_rough",
                                factor="vh", wavelength_um=wl)
    np.testing.assert_allclose(p["diffuse"] * area / (4 * np.pi * T**2 * sigma**2 * k**2), eq11,
                               rtol=1e-12)


@pytest.mark.parametrize("fn", [rs.retro_beckmann_gaussian_very_rough,
                                rs.retro_beckmann_exponential_very_rough,
                                rs.retro_vh_gaussian_very_rough,
                                rs.retro_vh_exponential_very_rough])
@pytest.mark.parametrize("theta, m", [(90.0, 0.5), (-1.0, 0.5), (float("nan"), 0.5),
                                      (30.0, -0.5), (30.0, 0.0), (30.0, float("nan"))])
def test_retro_closed_forms_reject_bad_input(fn, theta, m):
    with pytest.raises(rs.InvalidArgument):
        fn(theta, m)


def test_retro_slightly_rough_rejects_bad_input():
    for args in [(90.0, 0.03, 1.0), (30.0, -0.03, 1.0), (30.0, 0.03, 0.0),
                 (float("nan"), 0.03, 1.0)]:
        with pytest.raises(rs.InvalidArgument):
            rs.retro_vh_gaussian_slightly_rough(*args)


# =============================================================================================
# Regimes: Eq. 2 → Eq. 3 as g → 0, Eq. 2 → Eq. 4 as g → ∞ (shrinking relative error)
# =============================================================================================

def test_series_tends_to_slightly_rough_as_g_to_zero():
    geom = dict(theta_i_deg=30.0, theta_s_deg=20.0, phi_s_deg=40.0)
    errors = []
    for sigma in (0.05, 0.015, 0.005, 0.0015, 0.0005):
        series = rs.mean_scattered_power(**geom, sigma_um=sigma, T_um=0.8, regime="series")
        first = rs.mean_scattered_power(**geom, sigma_um=sigma, T_um=0.8,
                                        regime="slightly_rough")
        assert series["regime"] == "series" and first["regime"] == "slightly_rough"
        errors.append(abs(first["diffuse"] - series["diffuse"]) / series["diffuse"])
    assert all(b < a for a, b in zip(errors, errors[1:])), errors
    assert errors[-1] < 1e-4


def test_series_tends_to_very_rough_as_g_to_infinity():
    geom = dict(theta_i_deg=30.0, theta_s_deg=20.0, phi_s_deg=40.0)
    errors = []
    gs = []
    for sigma in (0.5, 1.5, 5.0, 15.0, 50.0):
        T = 3.0 * sigma  # fixed slope: the lobe stays put while g grows
        series = rs.mean_scattered_power(**geom, sigma_um=sigma, T_um=T, regime="series")
        vr = rs.mean_scattered_power(**geom, sigma_um=sigma, T_um=T, regime="very_rough")
        gs.append(series["g"])
        errors.append(abs(vr["diffuse"] - series["diffuse"]) / series["diffuse"])
    assert all(b > a for a, b in zip(gs, gs[1:]))
    assert all(b < a for a, b in zip(errors, errors[1:])), errors
    assert errors[-1] < 1e-3


def test_pure_diffuse_terms_agree_with_mean_scattered_power():
    ti, ts, ps, sigma, T, wl = 25.0, 40.0, 75.0, 0.2, 1.1, 0.555
    vx, vy, vz = rs.scattering_vector(ti, ts, ps, wl)
    F2 = rs.geometric_factor_squared("vh", ti, ts, ps)
    g = rs.roughness_g(ti, ts, sigma, wl)
    area = 4 * 500.0 * 500.0
    assert g == pytest.approx(sigma**2 * vz**2, rel=1e-14)
    d2 = rs.diffuse_power_gaussian_series(F2, T, area, g, vx**2 + vy**2)
    p = rs.mean_scattered_power(ti, ts, ps, sigma, T, regime="series")
    assert d2 == pytest.approx(p["diffuse"], rel=1e-13)
    d4 = rs.diffuse_power_very_rough_gaussian(F2, sigma, T, area, vz**2, vx**2 + vy**2)
    p4 = rs.mean_scattered_power(ti, ts, ps, sigma, T, regime="very_rough")
    assert d4 == pytest.approx(p4["diffuse"], rel=1e-13)


def test_pure_diffuse_terms_reject_bad_input():
    with pytest.raises(rs.InvalidArgument, match="T_um"):
        rs.diffuse_power_gaussian_series(1.0, -1.0, 1e6, 1.0, 1.0)
    with pytest.raises(rs.InvalidArgument, match="vz2"):
        rs.diffuse_power_very_rough_gaussian(1.0, 1.0, 1.0, 1e6, 0.0, 1.0)
    with pytest.raises(rs.InvalidArgument, match="g"):
        rs.diffuse_power_exponential_series(1.0, 1.0, 1e6, float("nan"), 1.0)


def test_gaussian_series_sum_against_exponential_integral():
    # S_G(g, 0) = e^{−g} Σ_{n≥1} gⁿ/(n! n) = e^{−g} (Ei(g) − γ − ln g)
    from scipy.special import expi

    for g in (0.3, 2.0, 17.0, 150.0):
        expected = math.exp(-g) * (expi(g) - np.euler_gamma - math.log(g))
        assert rs.gaussian_series_sum(g, 0.0) == pytest.approx(expected, rel=1e-12)


def test_series_sums_against_high_precision_sums():
    import mpmath

    mpmath.mp.dps = 40
    for g, b in [(0.5, 2.0), (4.0, 30.0), (40.0, 900.0)]:
        gm = mpmath.mpf(g)
        sg = mpmath.exp(-gm) * mpmath.nsum(
            lambda n: gm**n / (mpmath.factorial(n) * n) * mpmath.exp(-b / 4 / n), [1, mpmath.inf])
        se = mpmath.exp(-gm) * mpmath.nsum(
            lambda n: gm**n / mpmath.factorial(n) * n / (n * n + b) ** 1.5, [1, mpmath.inf])
        assert rs.gaussian_series_sum(g, b) == pytest.approx(float(sg), rel=1e-12)
        assert rs.exponential_series_sum(g, b) == pytest.approx(float(se), rel=1e-12)


def test_series_sums_reject_bad_input():
    for args in [(-1.0, 0.0), (1.0, -1.0), (float("nan"), 0.0), (1.0, float("inf"))]:
        with pytest.raises(rs.InvalidArgument):
            rs.gaussian_series_sum(*args)
        with pytest.raises(rs.InvalidArgument):
            rs.exponential_series_sum(*args)


def test_quadrature_agrees_with_series():
    F2, T, area = 0.8, 1.3, 1e6
    g = np.array([0.5, 3.0])
    q = rs.diffuse_power_quadrature("gaussian", F2, T, area, g, 2.5)
    np.testing.assert_allclose(q, rs.diffuse_power_gaussian_series(F2, T, area, g, 2.5),
                               rtol=1e-7)
    # Exponential correlation: J0's slowly decaying tail makes the quadrature slow for large
    # T·v_xy, so a near-specular case (seconds, not minutes).
    qe = rs.diffuse_power_quadrature("exponential", F2, T, area, [0.5, 0.5], [0.0, 0.1])
    np.testing.assert_allclose(
        qe, rs.diffuse_power_exponential_series(F2, T, area, 0.5, [0.0, 0.1]), rtol=1e-7)


def test_quadrature_rejects_bad_correlation():
    with pytest.raises(rs.InvalidArgument, match="gaussian"):
        rs.diffuse_power_quadrature("lorentzian", 1.0, 1.0, 1e6, 1.0, 1.0)


# =============================================================================================
# Geometric factors, ρ0, scattering vector (§3.1–3.2)
# =============================================================================================

def test_geometric_factors_at_normal_incidence():
    phi = np.array([0.0, 45.0, 90.0, 180.0, 270.0])
    np.testing.assert_allclose(rs.geometric_factor_beckmann(0.0, 0.0, phi), 1.0, rtol=1e-15)
    ts = np.array([0.0, 20.0, 60.0, 85.0])
    np.testing.assert_allclose(rs.geometric_factor_squared("vh", 0.0, ts, 30.0), 1.0,
                               rtol=1e-15)
    for factor in FACTORS:  # all four agree at θi = θs = 0 (F = 1)
        assert rs.geometric_factor_squared(factor, 0.0, 0.0, 0.0) == pytest.approx(1.0,
                                                                                   rel=1e-15)


def test_beckmann_factor_at_retro_is_inverse_cos_squared():
    theta = np.linspace(0.0, 80.0, 9)
    np.testing.assert_allclose(rs.geometric_factor_beckmann(theta, theta, 180.0),
                               1.0 / np.cos(np.radians(theta)) ** 2, rtol=1e-13)


def test_geometric_factor_rejects_bad_input():
    with pytest.raises(rs.InvalidArgument, match="beckmann"):
        rs.geometric_factor_squared("lambert", 10.0, 10.0, 0.0)
    with pytest.raises(rs.InvalidArgument):
        rs.geometric_factor_squared("vh", 90.0, 10.0, 0.0)
    with pytest.raises(rs.InvalidArgument):
        rs.geometric_factor_beckmann(10.0, float("nan"), 0.0)


def test_rho0_is_one_in_the_specular_direction():
    theta = np.array([0.0, 10.0, 45.0, 80.0])
    vx, vy, vz = rs.scattering_vector(theta, theta, 0.0)
    assert np.all(np.abs(vx) < 1e-12) and np.all(np.abs(vy) < 1e-12)
    np.testing.assert_allclose(rs.specular_amplitude_rho0(vx, vy, 500.0, 500.0), 1.0,
                               rtol=1e-12)
    p = rs.mean_scattered_power(theta, theta, 0.0, 0.05, 1.0)
    np.testing.assert_allclose(p["coherent"], np.exp(-p["g"]), rtol=1e-12)
    # Away from specular the patch term vanishes like sinc: ρ0 < 1.
    vx2, vy2, _ = rs.scattering_vector(30.0, 35.0, 10.0)
    assert abs(rs.specular_amplitude_rho0(vx2, vy2)) < 0.1


def test_scattering_vector_components():
    ti, ts, ps, wl = 30.0, 50.0, 120.0, 0.6
    k = 2 * np.pi / wl
    vx, vy, vz = rs.scattering_vector(ti, ts, ps, wl)
    a, b, c = np.radians([ti, ts, ps])
    assert vx == pytest.approx(k * (np.sin(a) - np.sin(b) * np.cos(c)), rel=1e-14)
    assert vy == pytest.approx(-k * np.sin(b) * np.sin(c), rel=1e-14)
    assert vz == pytest.approx(-k * (np.cos(a) + np.cos(b)), rel=1e-14)


def test_scattering_vector_and_rho0_reject_bad_input():
    with pytest.raises(rs.InvalidArgument, match="wavelength"):
        rs.scattering_vector(10.0, 10.0, 0.0, wavelength_um=0.0)
    with pytest.raises(rs.InvalidArgument):
        rs.scattering_vector(10.0, 90.0, 0.0)
    with pytest.raises(rs.InvalidArgument, match="patch_x_um"):
        rs.specular_amplitude_rho0(0.0, 0.0, -1.0, 500.0)
    with pytest.raises(rs.InvalidArgument, match="sigma"):
        rs.roughness_g(10.0, 10.0, -0.1)


# =============================================================================================
# very_rough_brightness: the array fast path against the library's scalar function
# =============================================================================================

@pytest.mark.parametrize("isa", available_isas())
def test_very_rough_array_path_matches_scalar_library(isa, vector_isa):
    assert vector_isa(isa) == isa
    ti, ts, ps = random_geometries(1037, seed=3)  # not a multiple of any vector width
    ps[::97] += 3600.0  # large azimuths take the exact-reduction path
    m = np.random.default_rng(4).uniform(0.1, 3.0, ti.size)
    for corr in CORRELATIONS:
        for factor in FACTORS:
            for radiometry in RADIOMETRIES:
                arr = rs.very_rough_brightness(ti, ts, ps, m, correlation=corr, factor=factor,
                                               radiometry=radiometry)
                ref = np.array([rs.very_rough_brightness(a, b, c, d, correlation=corr,
                                                         factor=factor, radiometry=radiometry)
                                for a, b, c, d in zip(ti[::7], ts[::7], ps[::7], m[::7])])
                np.testing.assert_allclose(arr[::7], ref, rtol=1e-12, atol=1e-300,
                                           err_msg=f"{isa} {corr} {factor} {radiometry}")


def test_very_rough_matches_numpy_formula_on_a_large_parallel_array():
    ti, ts, ps = random_geometries(200_000, seed=11)
    m = 0.6
    a, b, c = np.radians(ti), np.radians(ts), np.radians(ps)
    qxy2 = np.sin(a) ** 2 + np.sin(b) ** 2 - 2 * np.sin(a) * np.sin(b) * np.cos(c)
    qz2 = (np.cos(a) + np.cos(b)) ** 2
    gauss = np.cos(a) / qz2 * np.exp(-qxy2 / (4 * m * m * qz2))       # Eq. 4 shape, F_VH
    expo = np.cos(a) / (qz2 * (1 + qxy2 / (m * m * qz2)) ** 1.5)       # Eq. 5 shape, F_VH
    np.testing.assert_allclose(rs.very_rough_brightness(ti, ts, ps, m), gauss, rtol=1e-10)
    np.testing.assert_allclose(rs.very_rough_brightness(ti, ts, ps, m, correlation="exponential"),
                               expo, rtol=1e-10)


def test_very_rough_reproduces_paper_table2_ratios(paper_tables):
    # §4.2: viewer on the normal, E1/E2 at θ1 = 30°, θ2 = 45° from the printed σ/T.
    rows = paper_tables["table2_very_rough"]["rows"]
    for row in rows:
        for key, corr in (("sigma_over_T_G", "gaussian"), ("sigma_over_T_E", "exponential")):
            e = rs.very_rough_brightness([30.0, 45.0], 0.0, 0.0, row[key], correlation=corr)
            # E1/E2 is printed to 3 decimals (and the slopes to 4 digits).
            assert e[0] / e[1] == pytest.approx(row["E1_over_E2"], abs=6e-4), row["surface"]


def test_very_rough_reproduces_paper_table3_ratios(paper_tables):
    cond = paper_tables["table3_curet_parameters"]["conditions"]
    for row in paper_tables["table3_curet_parameters"]["rows"]:
        for key, corr in (("sigma_over_T_G", "gaussian"), ("sigma_over_T_E", "exponential")):
            e = rs.very_rough_brightness([cond["theta1_deg"], cond["theta2_deg"]], 0.0, 0.0,
                                         row[key], correlation=corr)
            assert e[0] / e[1] == pytest.approx(row["E1_over_E2"], rel=2e-4), row["name"]


@pytest.mark.parametrize("kwargs, pattern", [
    (dict(theta_i_deg=90.0), r"theta_i.*90"),
    (dict(theta_s_deg=float("nan")), r"theta_s.*nan"),
    (dict(phi_s_deg=float("inf")), r"phi_s.*inf"),
    (dict(sigma_over_T=-0.5), r"sigma_over_T.*-0\.5"),
    (dict(sigma_over_T=0.0), r"sigma_over_T"),
])
def test_very_rough_rejects_bad_scalars(kwargs, pattern):
    args = dict(theta_i_deg=30.0, theta_s_deg=20.0, phi_s_deg=10.0, sigma_over_T=0.5)
    args.update(kwargs)
    with pytest.raises(rs.InvalidArgument, match=pattern):
        rs.very_rough_brightness(**args)


@pytest.mark.parametrize("isa", available_isas())
def test_very_rough_reports_first_bad_element(isa, vector_isa):
    vector_isa(isa)
    n = 100_000  # large enough to be split over worker threads
    ti, ts, ps = random_geometries(n, seed=5)
    ti[90_000] = 95.0
    ts[70_001] = float("nan")
    ps[80_000] = float("inf")
    with pytest.raises(rs.InvalidArgument, match=r"^at index 70001: theta_s.*nan"):
        rs.very_rough_brightness(ti, ts, ps, 0.5)
    ts[70_001] = 10.0
    with pytest.raises(rs.InvalidArgument, match=r"^at index 80000: phi_s"):
        rs.very_rough_brightness(ti, ts, ps, 0.5)
    m = np.full(n, 0.5)
    m[3] = -1.0
    with pytest.raises(rs.InvalidArgument, match=r"^at index 3: sigma_over_T"):
        rs.very_rough_brightness(ti, ts, ps, m)


def test_very_rough_rejects_bad_names():
    with pytest.raises(rs.InvalidArgument, match="vh"):
        rs.very_rough_brightness(10.0, 10.0, 0.0, 0.5, factor="harvey")
    with pytest.raises(rs.InvalidArgument, match="gaussian"):
        rs.very_rough_brightness(10.0, 10.0, 0.0, 0.5, correlation="gauss")
    with pytest.raises(rs.InvalidArgument, match="radiance"):
        rs.very_rough_brightness(10.0, 10.0, 0.0, 0.5, radiometry="power")


# =============================================================================================
# Broadcasting and return types
# =============================================================================================

def test_scalars_give_floats_and_arrays_give_arrays():
    assert type(rs.lambert_brightness(30.0)) is float
    assert type(rs.lambert_brightness(np.float64(30.0))) is float
    assert type(rs.lambert_brightness(np.array(30.0))) is float
    out = rs.lambert_brightness([30.0])
    assert isinstance(out, np.ndarray) and out.shape == (1,)
    assert type(rs.very_rough_brightness(10.0, 20.0, 30.0, 0.5)) is float
    assert rs.lambert_brightness(np.array([], dtype=float)).shape == (0,)


def test_broadcasting_matches_elementwise_scalar_calls():
    ti = np.array([[0.0], [30.0], [60.0]])         # (3, 1)
    ts = np.array([0.0, 15.0, 45.0, 75.0])          # (4,)
    out = rs.very_rough_brightness(ti, ts, 180.0, 0.7, factor="beckmann")
    assert out.shape == (3, 4)
    for i in range(3):
        for j in range(4):
            assert out[i, j] == pytest.approx(
                rs.very_rough_brightness(ti[i, 0], ts[j], 180.0, 0.7, factor="beckmann"),
                rel=1e-12)
    on = rs.oren_nayar_radiance(ti, ts, 180.0, [[0.1, 0.3, 0.5, 0.7]], 0.8)
    assert on.shape == (3, 4)
    assert on[2, 3] == pytest.approx(rs.oren_nayar_radiance(60.0, 75.0, 180.0, 0.7, 0.8))
    # A non-contiguous, non-float64 view is converted.
    big = np.arange(0, 80, dtype=np.int32)[::4]
    np.testing.assert_allclose(rs.lambert_brightness(big), np.cos(np.radians(big)), rtol=1e-15)


def test_mean_scattered_power_returns_dict_of_arrays_or_scalars():
    p = rs.mean_scattered_power(30.0, 30.0, 0.0, 0.1, 1.0)
    assert set(p) == {"coherent", "diffuse", "total", "brightness", "g", "regime",
                      "roughness_class", "method", "relative_error_bound"}
    assert type(p["total"]) is float and type(p["regime"]) is str
    assert p["regime"] in rs.REGIMES and p["regime"] != "auto"
    assert p["total"] == pytest.approx(p["coherent"] + p["diffuse"], rel=1e-15)
    q = rs.mean_scattered_power([10.0, 20.0, 30.0], 30.0, 0.0, [[0.01], [2.0]], 1.0,
                                correlation="exponential", radiometry="intensity")
    assert q["total"].shape == (2, 3)
    assert q["regime"].shape == (2, 3) and q["regime"].dtype.kind == "U"
    assert list(q["roughness_class"][:, 0]) == ["slightly_rough", "very_rough"]
    # Intensity interpretation = radiance / cos θs.
    r = rs.mean_scattered_power([10.0, 20.0, 30.0], 30.0, 0.0, [[0.01], [2.0]], 1.0,
                                correlation="exponential", radiometry="radiance")
    np.testing.assert_allclose(q["brightness"], r["brightness"] / np.cos(np.radians(30.0)),
                               rtol=1e-14)


def test_parallel_loops_give_the_single_thread_results():
    from roughscope import _core

    ti, ts, ps = random_geometries(20_000, seed=13)
    sigma = np.random.default_rng(14).uniform(0.01, 2.0, ti.size)
    try:
        _core._set_max_threads(1)
        one = rs.mean_scattered_power(ti, ts, ps, sigma, 1.5)
        one_vr = rs.very_rough_brightness(ti, ts, ps, 0.4)
    finally:
        _core._set_max_threads(0)
    many = rs.mean_scattered_power(ti, ts, ps, sigma, 1.5)
    for key in ("coherent", "diffuse", "total", "brightness", "g"):
        np.testing.assert_array_equal(one[key], many[key])
    np.testing.assert_array_equal(one["regime"], many["regime"])
    np.testing.assert_array_equal(one_vr, rs.very_rough_brightness(ti, ts, ps, 0.4))
    with pytest.raises(rs.InvalidArgument):
        _core._set_max_threads(-1)


def test_mean_scattered_power_rejects_bad_input():
    with pytest.raises(rs.InvalidArgument, match=r"^at index 2: .*sigma"):
        rs.mean_scattered_power(30.0, 30.0, 0.0, [0.1, 0.2, -0.3], 1.0)
    with pytest.raises(rs.InvalidArgument, match=r"at index \(1, 0\)"):
        rs.mean_scattered_power([[10.0], [95.0]], 30.0, 0.0, 0.1, 1.0)
    with pytest.raises(rs.InvalidArgument, match="auto"):
        rs.mean_scattered_power(30.0, 30.0, 0.0, 0.1, 1.0, regime="exactish")
    with pytest.raises(rs.InvalidArgument, match="beckmann"):
        rs.mean_scattered_power(30.0, 30.0, 0.0, 0.1, 1.0, factor="bad")
    with pytest.raises(rs.InvalidArgument, match="wavelength"):
        rs.mean_scattered_power(30.0, 30.0, 0.0, 0.1, 1.0, wavelength_um=float("nan"))


def test_shapes_that_cannot_broadcast_are_rejected():
    with pytest.raises(rs.InvalidArgument, match=r"cannot be broadcast.*\(3,\).*\(4,\)"):
        rs.very_rough_brightness(np.zeros(3), np.zeros(4), 0.0, 0.5)
    # A wrong type is a TypeError naming the argument (test_python_inputs.py covers every
    # function and every kind of non-real input).
    with pytest.raises(TypeError, match="theta_i_deg must be a real number"):
        rs.lambert_brightness("thirty")
    with pytest.raises(TypeError, match="theta_i_deg .* not None"):
        rs.lambert_brightness(None)


# =============================================================================================
# Geometry (§2)
# =============================================================================================

def _frame_vectors(ti, ts, ps):
    a, b, c = np.radians(ti), np.radians(ts), np.radians(ps)
    L = np.stack([-np.sin(a), np.zeros_like(a), np.cos(a)], axis=-1)
    V = np.stack([np.sin(b) * np.cos(c), np.sin(b) * np.sin(c), np.cos(b)], axis=-1)
    return L, V


def _random_rotation(seed):
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def test_geometry_from_vectors_recovers_known_angles():
    ti = np.array([0.0, 10.0, 30.0, 45.0, 70.0, 85.0])
    ts = np.array([20.0, 0.0, 30.0, 60.0, 45.0, 5.0])
    ps = np.array([0.0, 0.0, 180.0, 90.0, 300.0, 135.0])
    L, V = _frame_vectors(ti, ts, ps)
    R = _random_rotation(1)
    N = R @ np.array([0.0, 0.0, 1.0])          # shape (3,), broadcast over the 6 rows
    got_i, got_s, got_p, visible = rs.geometry_from_vectors(N, L @ R.T, V @ R.T)
    assert visible.dtype == bool and visible.all()
    np.testing.assert_allclose(got_i, ti, atol=1e-9)
    np.testing.assert_allclose(got_s, ts, atol=1e-9)
    # φs is returned in [0, 180] (±φs are indistinguishable); undefined (0) when θ = 0.
    expected_p = np.where((ti == 0) | (ts == 0), 0.0, np.minimum(ps, 360.0 - ps))
    np.testing.assert_allclose(got_p, expected_p, atol=1e-7)


def test_geometry_from_vectors_below_horizon_is_invisible_not_an_error():
    N = [0.0, 0.0, 1.0]
    L = [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]]
    ti, ts, ps, visible = rs.geometry_from_vectors(N, L, [0.0, 0.0, 1.0])
    assert visible.tolist() == [True, False, False]
    assert ti[1:].tolist() == [0.0, 0.0] and ps[1:].tolist() == [0.0, 0.0]
    one = rs.geometry_from_vectors(N, N, N)
    assert one == (0.0, 0.0, 0.0, True)


def test_geometry_from_vectors_rejects_bad_vectors():
    N = [0.0, 0.0, 1.0]
    with pytest.raises(rs.InvalidArgument):
        rs.geometry_from_vectors(N, [0.0, 0.0, 2.0], N)      # not unit length
    with pytest.raises(rs.InvalidArgument, match="at index 1"):
        rs.geometry_from_vectors(N, [[0.0, 0.0, 1.0], [0.0, float("nan"), 1.0]], N)
    with pytest.raises(rs.InvalidArgument, match=r"shape \(\.\.\., 3\)"):
        rs.geometry_from_vectors(N, [0.0, 1.0], N)


def test_geometry_from_two_azimuths():
    ti, ts, ps = rs.geometry_from_two_azimuths([30.0, 30.0], [0.0, 90.0], 45.0, [0.0, 270.0])
    np.testing.assert_allclose(ti, 30.0)
    np.testing.assert_allclose(ts, 45.0)
    np.testing.assert_allclose(ps, [180.0, 0.0], atol=1e-12)   # same azimuth → retro half-plane
    with pytest.raises(rs.InvalidArgument):
        rs.geometry_from_two_azimuths(30.0, 0.0, 90.0, 0.0)


# =============================================================================================
# Validity (§3.1, §3.5) and comparison models (§5)
# =============================================================================================

def test_caron_quantities_reproduce_paper_table2(paper_tables):
    for row in paper_tables["table2_very_rough"]["rows"]:
        m = row["sigma_over_T_G"]
        assert round(rs.caron_theta_K_deg(m)) == row["theta_K_deg"], row["surface"]
        assert 100 * rs.caron_xi_K(m) == pytest.approx(row["xi_K_percent"], abs=0.051)


def test_validity_identities():
    m = np.array([0.1, 0.5, 1.0, 3.0])
    np.testing.assert_allclose(rs.rms_slope(m), np.sqrt(2) * m, rtol=1e-15)
    np.testing.assert_allclose(rs.caron_theta_K_deg(m), 90.0 - np.degrees(np.arctan(np.sqrt(2) * m)),
                               rtol=1e-14)
    np.testing.assert_allclose(rs.caron_xi_K(m), 1 - np.exp(-1 / (4 * m * m)), rtol=1e-14)
    assert rs.roughness_class(0.05) == "slightly_rough"
    assert rs.roughness_class(1.0) == "moderately_rough"
    assert rs.roughness_class(20.0) == "very_rough"
    assert rs.roughness_class([0.0, 0.5, 11.0]).tolist() == ["slightly_rough",
                                                             "moderately_rough", "very_rough"]


def test_validity_rejects_bad_input():
    for fn in (rs.rms_slope, rs.caron_theta_K_deg, rs.caron_xi_K):
        with pytest.raises(rs.InvalidArgument, match="sigma_over_T"):
            fn(-0.1)
        with pytest.raises(rs.InvalidArgument):
            fn(float("nan"))
    with pytest.raises(rs.InvalidArgument, match="g"):
        rs.roughness_class(-1.0)


def test_oren_nayar_with_smooth_facets_is_lambertian():
    ti, ts, ps = random_geometries(50, seed=9)
    for albedo in (0.3, 1.0):
        expected = albedo / np.pi * np.cos(np.radians(ti))
        np.testing.assert_allclose(rs.oren_nayar_radiance(ti, ts, ps, 0.0, albedo), expected,
                                   rtol=1e-14)
        np.testing.assert_allclose(rs.oren_nayar_qualitative_radiance(ti, ts, ps, 0.0, albedo),
                                   expected, rtol=1e-14)


def test_oren_nayar_rejects_bad_input():
    with pytest.raises(rs.InvalidArgument):
        rs.oren_nayar_radiance(30.0, 30.0, 0.0, -0.1, 0.5)
    with pytest.raises(rs.InvalidArgument, match="albedo"):
        rs.oren_nayar_radiance(30.0, 30.0, 0.0, 0.1, 1.5)
    with pytest.raises(rs.InvalidArgument):
        rs.oren_nayar_qualitative_radiance(90.0, 30.0, 0.0, 0.1, 0.5)


def test_lambert_and_lafortune():
    theta = np.array([0.0, 30.0, 60.0, 89.0])
    np.testing.assert_allclose(rs.lambert_brightness(theta), np.cos(np.radians(theta)),
                               rtol=1e-15)
    ti, ts, ps = random_geometries(40, seed=2)
    ci, cs = np.cos(np.radians(ti)), np.cos(np.radians(ts))
    n = 3.5
    np.testing.assert_allclose(rs.lafortune_diffuse_brightness(ti, ts, ps, n),
                               (ci * cs) ** n * ci, rtol=1e-13)
    # One lobe Cz = 1 is (Lz Vz)^n; lobes as dicts or as an (N, 5) array agree.
    lobe = {"Cx": 0.0, "Cy": 0.0, "Cz": 1.0, "n": n, "albedo": 1.0}
    np.testing.assert_allclose(rs.lafortune_brdf(ti, ts, ps, [lobe]), (ci * cs) ** n,
                               rtol=1e-13)
    lobes = [lobe, {"Cx": -0.8, "Cy": -0.8, "Cz": 0.6, "n": 12.0, "albedo": 0.5}]
    as_array = np.array([[0.0, 0.0, 1.0, n, 1.0], [-0.8, -0.8, 0.6, 12.0, 0.5]])
    np.testing.assert_allclose(rs.lafortune_brdf(ti, ts, ps, lobes, 0.2),
                               rs.lafortune_brdf(ti, ts, ps, as_array, 0.2), rtol=1e-15)


def test_lambert_and_lafortune_reject_bad_input():
    with pytest.raises(rs.InvalidArgument):
        rs.lambert_brightness(float("nan"))
    with pytest.raises(rs.InvalidArgument, match="n"):
        rs.lafortune_diffuse_brightness(30.0, 30.0, 0.0, -1.0)
    with pytest.raises(rs.InvalidArgument, match="shape"):
        rs.lafortune_brdf(30.0, 30.0, 0.0, np.zeros((2, 4)))
    with pytest.raises(rs.InvalidArgument, match="unknown key"):
        rs.lafortune_brdf(30.0, 30.0, 0.0, [{"Cq": 1.0}])
    with pytest.raises(rs.InvalidArgument, match="rho_d"):
        rs.lafortune_brdf(30.0, 30.0, 0.0, [{"n": 2.0}], -0.5)


# =============================================================================================
# Figures and report
# =============================================================================================

def test_figures_normalised_curves_start_at_one_and_bad_equation_rejected():
    from roughscope import figures

    for eq in (7, 8, 9, 10):
        curves = figures.normalised_retro_curves(eq, m_values=(0.71, 1.8))
        for values in curves.values():
            assert values[0] == pytest.approx(1.0, rel=1e-15)
            assert np.all(np.isfinite(values))
    # Fig. 4: larger σ/T gives a higher normalised radiance (§3.4).
    c = figures.normalised_retro_curves(9, m_values=(0.71, 1.8))
    assert np.all(c[1.8][1:] > c[0.71][1:])
    with pytest.raises(rs.InvalidArgument):
        figures.normalised_retro_curves(12)


def test_report_writes_index_and_figures(tmp_path, python_env):
    out = tmp_path / "report"
    proc = subprocess.run([sys.executable, "-m", "roughscope.report", "--out", str(out)],
                          env=python_env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    index = out / "index.html"
    assert proc.stdout.strip().endswith("index.html")
    assert pathlib.Path(proc.stdout.strip()).resolve() == index.resolve()
    html_text = index.read_text(encoding="utf-8")
    assert "<h2 id=\"models\">Models</h2>" in html_text and rs.__version__ in html_text
    assert "FAIL" not in html_text and "class=\"fail\"" not in html_text
    # The simulation section and both of its figures are there.
    assert "Ground truth: Monte Carlo Kirchhoff scattering" in html_text
    for name in ("fig3_bk_retro.png", "fig4_vh_retro.png", "simulation_validation.png",
                 "simulation_estimators.png"):
        png = out / name
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert f'src="{name}"' in html_text or f"src='{name}'" in html_text
    # Nothing temporary left beside the report.
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report"]


def test_report_failure_is_one_line_and_writes_nothing(tmp_path, python_env):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    proc = subprocess.run([sys.executable, "-m", "roughscope.report", "--out",
                           str(blocker / "report")], env=python_env, capture_output=True,
                          text=True, timeout=600)
    assert proc.returncode != 0
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("roughscope.report: error:")
    assert proc.stdout == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]
