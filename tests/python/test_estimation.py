"""Tests of the §4 estimators and fits through the Python module (mirrors tests/cpp/test_estimation.cpp
and tests/cpp/test_fit.cpp).

Expected values come from the paper's tables (../shared/reference/paper-tables.json; skipped when
absent) or from the paper's equations re-implemented here with NumPy (Eq. 4, 5, 13, 15, 17, 19),
never from the library itself. Each success test is paired with a bad-input test.
"""

import math

import numpy as np
import pytest

import roughscope as rs

LAMBDA = 0.555


# ---- Independent NumPy implementations of the paper's equations ---------------------------------

def _q(ti, ts, ps):
    """Scattering direction v/k in the paper's frame (§3.1), angles in degrees."""
    ti, ts, ps = np.radians(ti), np.radians(ts), np.radians(ps)
    qx = np.sin(ti) - np.sin(ts) * np.cos(ps)
    qy = -np.sin(ts) * np.sin(ps)
    qz = -(np.cos(ti) + np.cos(ts))
    return qx**2 + qy**2, qz**2


def very_rough_vh(ti, ts, ps, s, correlation):
    """Eq. 4 (Gaussian) / Eq. 5 (exponential) with F_VH^2 = cos(theta_i), constants dropped."""
    qxy2, qz2 = _q(ti, ts, ps)
    F2 = np.cos(np.radians(ti))
    if correlation == "gaussian":
        return F2 / qz2 * np.exp(-qxy2 / (4 * s * s * qz2))
    return F2 / (qz2 * (1 + qxy2 / (s * s * qz2)) ** 1.5)


def eq17(r, t1, t2):
    a = lambda t: np.tan(np.radians(t) / 2) ** 2  # v_xy^2/v_z^2 at normal view
    w = lambda t: np.cos(np.radians(t)) / (1 + np.cos(np.radians(t))) ** 2  # F_VH^2/v_z^2
    kappa = r * w(t2) / w(t1)
    return 0.5 * np.sqrt((a(t2) - a(t1)) / np.log(kappa))


def eq19(r, t1, t2):
    a = lambda t: np.tan(np.radians(t) / 2) ** 2
    w = lambda t: np.cos(np.radians(t)) / (1 + np.cos(np.radians(t))) ** 2
    k23 = (r * w(t2) / w(t1)) ** (2 / 3)
    return np.sqrt((a(t2) - k23 * a(t1)) / (k23 - 1))


def eq13(R, theta, lam=LAMBDA, R0=1.0):
    return lam / (4 * math.pi * math.cos(math.radians(theta))) * math.sqrt(math.log(R0 / R))


def eq15(r, sigma, t1, t2, lam=LAMBDA):
    k = 2 * math.pi / lam
    g = lambda t: (sigma * k * (1 + math.cos(math.radians(t)))) ** 2
    F2 = lambda t: math.cos(math.radians(t))
    vxy2 = lambda t: (k * math.sin(math.radians(t))) ** 2
    zeta = g(t2) * F2(t2) * r / (g(t1) * F2(t1))
    return 2 * math.sqrt((g(t1) - g(t2) + math.log(zeta)) / (vxy2(t2) - vxy2(t1)))


# ---- Paper tables --------------------------------------------------------------------------------

def test_table3_all_four_digits(paper_tables):
    t = paper_tables["table3_curet_parameters"]
    t1, t2 = t["conditions"]["theta1_deg"], t["conditions"]["theta2_deg"]
    ratios = np.array([row["E1_over_E2"] for row in t["rows"]])
    sG = rs.sigma_over_T_gaussian(ratios, t1, t2)
    sE = rs.sigma_over_T_exponential(ratios, t1, t2)
    assert isinstance(sG, np.ndarray) and sG.shape == (3,)
    for row, g, e in zip(t["rows"], sG, sE):
        assert round(g, 4) == row["sigma_over_T_G"], row["name"]
        assert round(e, 4) == row["sigma_over_T_E"], row["name"]


def test_table2_within_rounding_of_printed_ratio(paper_tables):
    t = paper_tables["table2_very_rough"]
    t1, t2 = t["conditions"]["theta1_deg"], t["conditions"]["theta2_deg"]
    for row in t["rows"]:
        r = row["E1_over_E2"]
        box = np.array([r - 5e-4, r + 5e-4])  # E1/E2 printed to 3 decimals
        g = rs.sigma_over_T_gaussian(box, t1, t2)
        e = rs.sigma_over_T_exponential(box, t1, t2)
        assert g.min() - 5e-5 <= row["sigma_over_T_G"] <= g.max() + 5e-5, row["surface"]
        assert e.min() - 5e-5 <= row["sigma_over_T_E"] <= e.max() + 5e-5, row["surface"]
        # theta_K, xi_K from the printed slope, to the printed digits (Caron, §3.5)
        s = row["sigma_over_T_G"]
        est = rs.estimate_slope(r, t1, t2)
        assert est["theta_K_deg"] == pytest.approx(90 - math.degrees(math.atan(math.sqrt(2) * est["sigma_over_T"])))
        assert round(90 - math.degrees(math.atan(math.sqrt(2) * s))) == row["theta_K_deg"]
        assert round(100 * (1 - math.exp(-1 / (4 * s * s))), 1) == row["xi_K_percent"]


def test_table1_within_rounding(paper_tables):
    t = paper_tables["table1_slightly_rough"]
    c = t["conditions"]
    for row in t["rows"]:
        sig = rs.sigma_from_specular(np.array([row["R_spec"] - 5e-4, row["R_spec"] + 5e-4]),
                                     c["specular_theta_deg"], c["lambda_um"])
        assert sig.min() - 5e-4 <= row["sigma_um"] <= sig.max() + 5e-4, row["surface"]
        T = rs.correlation_length_from_ratio(row["E1_over_E2"], row["sigma_um"], c["theta1_deg"],
                                             c["theta2_deg"], c["lambda_um"])
        assert T == pytest.approx(eq15(row["E1_over_E2"], row["sigma_um"], 30, 45), rel=1e-12)
        assert abs(T - row["T_um"]) < 1.5e-3, row["surface"]
        assert round(row["sigma_um"] / T, 3) == row["sigma_over_T"], row["surface"]


# ---- Closed forms against independent implementations --------------------------------------------

def test_closed_forms_match_numpy_equations_and_broadcast():
    r = np.array([[1.06, 1.1, 1.3], [1.5, 2.0, 2.5]])
    t2 = np.array([45.0, 50.0, 60.0])
    g = rs.sigma_over_T_gaussian(r, 30.0, t2)
    e = rs.sigma_over_T_exponential(r, 30.0, t2)
    assert g.shape == (2, 3)
    np.testing.assert_allclose(g, eq17(r, 30.0, t2), rtol=1e-12)
    np.testing.assert_allclose(e, eq19(r, 30.0, t2), rtol=1e-12)
    assert isinstance(rs.sigma_over_T_gaussian(1.1, 30, 45), float)
    assert rs.sigma_from_specular(0.014, 14) == pytest.approx(eq13(0.014, 14), rel=1e-14)
    assert rs.sigma_from_specular(0.014, 14) == pytest.approx(0.094, abs=5e-4)
    assert rs.specular_reflectance_from_brightness(200.0, 50.0) == 0.75
    lo, hi = rs.ratio_range_exponential(30, 45)
    assert lo == pytest.approx(eq19_limit_lower := (math.cos(math.radians(30)) / (1 + math.cos(math.radians(30))) ** 2)
                               / (math.cos(math.radians(45)) / (1 + math.cos(math.radians(45))) ** 2))
    assert hi == pytest.approx(eq19_limit_lower * (math.tan(math.radians(22.5)) ** 2 / math.tan(math.radians(15)) ** 2) ** 1.5)
    assert math.isinf(rs.ratio_range_gaussian(30, 45)[1])


def test_closed_forms_bad_input():
    with pytest.raises(rs.NoSolution, match=r"at index 1: .*must be > 1\.025019 "):
        rs.sigma_over_T_gaussian([1.1, 1.0], 30, 45)
    with pytest.raises(rs.NoSolution, match=r"Eq\. 19.*\(1\.025019, 3\.786583\)"):
        rs.sigma_over_T_exponential(4.0, 30, 45)
    with pytest.raises(rs.NoSolution, match="Eq. 15"):
        rs.correlation_length_from_ratio(0.5, 0.094, 30, 45)
    with pytest.raises(rs.InvalidArgument, match="theta1 = theta2"):
        rs.sigma_over_T_gaussian(1.1, 30, 30)
    with pytest.raises(rs.InvalidArgument, match="theta2"):
        rs.sigma_over_T_gaussian(1.1, 30, 90)
    with pytest.raises(rs.InvalidArgument, match="E1/E2"):
        rs.sigma_over_T_exponential(-1.0, 30, 45)
    with pytest.raises(rs.InvalidArgument, match="E1/E2"):
        rs.sigma_over_T_gaussian(float("nan"), 30, 45)
    with pytest.raises(rs.InvalidArgument, match="R_spec"):
        rs.sigma_from_specular(1.0, 14)
    with pytest.raises(rs.InvalidArgument, match="E_dif"):
        rs.specular_reflectance_from_brightness(1.0, 2.0)
    with pytest.raises(ValueError, match="factor"):
        rs.sigma_over_T_gaussian(1.1, 30, 45, factor="nope")
    with pytest.raises(ValueError, match="broadcast"):
        rs.sigma_over_T_gaussian([1.1, 1.2], 30, [45, 50, 60])


# ---- General two-geometry solver -----------------------------------------------------------------

@pytest.mark.parametrize("correlation", ["gaussian", "exponential"])
def test_two_geometry_solver_inverts_the_forward_model(correlation):
    s_true = np.array([0.05, 0.3, 1.0, 4.0])
    g1, g2 = (20.0, 35.0, 120.0), (55.0, 10.0, 40.0)
    r = very_rough_vh(*g1, s_true, correlation) / very_rough_vh(*g2, s_true, correlation)
    s = rs.sigma_over_T_two_geometries(r, *g1, *g2, correlation=correlation)
    np.testing.assert_allclose(s, s_true, rtol=1e-9)
    # normal view: same as the closed forms
    closed = (rs.sigma_over_T_gaussian if correlation == "gaussian" else rs.sigma_over_T_exponential)(1.2, 30, 60)
    assert rs.sigma_over_T_two_geometries(1.2, 30, 0, 0, 60, 0, 0, correlation=correlation) == \
        pytest.approx(closed, rel=1e-10)


def test_two_geometry_solver_bad_input():
    # Eq. 16's range at normal view: E1/E2 > C (ratio_range_gaussian)
    C = rs.ratio_range_gaussian(30, 45)[0]
    with pytest.raises(rs.NoSolution, match=f"must be > {C:.7g}"):
        rs.sigma_over_T_two_geometries(0.5, 30, 0, 0, 45, 0, 0)
    with pytest.raises(rs.InvalidArgument, match="same v_xy"):
        rs.sigma_over_T_two_geometries(1.1, 30, 0, 0, 30, 0, 0)
    with pytest.raises(rs.InvalidArgument, match="theta_s"):
        rs.sigma_over_T_two_geometries(1.1, 30, 95, 0, 45, 0, 0)
    with pytest.raises(rs.InvalidArgument, match="sigma"):
        rs.correlation_length_two_geometries(1.04, -0.1, 30, 0, 0, 45, 0, 0)


def test_correlation_length_two_geometries_matches_eq15():
    T = rs.correlation_length_two_geometries(1.043, 0.094, 30, 0, 0, 45, 0, 0)
    assert T == pytest.approx(eq15(1.043, 0.094, 30, 45), rel=1e-10)


# ---- Uncertainty and derived quantities ----------------------------------------------------------

def test_estimate_slope_uncertainty_matches_monte_carlo():
    rng = np.random.default_rng(12)
    E1, E2 = very_rough_vh(30, 0, 0, 0.5, "gaussian"), very_rough_vh(60, 0, 0, 0.5, "gaussian")
    est = rs.estimate_slope(E1 / E2, 30, 60, noise=0.01)
    assert est["sigma_over_T"] == pytest.approx(0.5, rel=1e-9)
    r = E1 * (1 + 0.01 * rng.standard_normal(20000)) / (E2 * (1 + 0.01 * rng.standard_normal(20000)))
    sd = np.std(eq17(r, 30, 60))
    assert est["sigma_over_T_stderr"] == pytest.approx(sd, rel=0.1)
    assert est["rms_slope_stderr"] == pytest.approx(math.sqrt(2) * est["sigma_over_T_stderr"])
    assert est["roughness_class"] == "very_rough" and est["roughness_class_assumed"]
    assert est["g"] is None


def test_estimate_warnings_and_known_sigma():
    est = rs.estimate_slope(1.880176, 45, 67.5)
    assert any("theta_K" in w and "measurement 2" in w for w in est["warnings"])
    est = rs.estimate_slope(1.091, 30, 45, sigma_um=5.0)
    assert est["T_um"] == pytest.approx(5.0 / est["sigma_over_T"])
    assert len(est["g"]) == 2 and est["roughness_class"] == "very_rough"
    assert est["warnings"] == []
    with pytest.raises(rs.InvalidArgument, match="noise"):
        rs.estimate_slope(1.1, 30, 45, noise=-0.1)
    with pytest.raises(rs.InvalidArgument, match="sigma"):
        rs.estimate_slope(1.1, 30, 45, sigma_um=0.0)


def test_estimate_slope_correlation_names():
    # the library's name scheme, as the CLI's --correlation: any case; "both" side by side
    both = rs.estimate_slope(1.091, 30, 45, correlation="both")
    assert rs.estimate_slope(1.091, 30, 45, correlation="BOTH") == both
    assert both["sigma_over_T_gaussian"] > 0 and both["sigma_over_T_exponential"] > 0
    g = rs.estimate_slope(1.091, 30, 45, correlation="Gaussian")
    assert g["sigma_over_T_exponential"] is None
    with pytest.raises(rs.InvalidArgument, match="gaussian, exponential, both"):
        rs.estimate_slope(1.091, 30, 45, correlation="lorentzian")


def test_estimate_specular_and_correlation_length():
    e = rs.estimate_sigma_specular(E_tot=100.0, E_dif=98.6, theta_deg=14, noise=0.01)
    assert e["sigma_um"] == pytest.approx(eq13(0.014, 14))
    assert e["g"][0] == pytest.approx(math.log(1 / 0.014))  # Eq. 12: g = ln(R0/R_spec)
    assert e["sigma_um_stderr"] > 0
    t = rs.estimate_correlation_length(1.043, 0.094, 30, 45, noise=0.005)
    assert t["T_um"] == pytest.approx(eq15(1.043, 0.094, 30, 45))
    assert t["roughness_class"] == "moderately_rough"
    assert any("slightly-rough" in w for w in t["warnings"])
    with pytest.raises(rs.InvalidArgument, match="R_spec"):
        rs.estimate_sigma_specular(R_spec=2.0, theta_deg=14)
    with pytest.raises(rs.InvalidArgument, match="not both"):
        rs.estimate_sigma_specular(R_spec=0.1, E_tot=1.0, E_dif=0.5, theta_deg=14)
    with pytest.raises(rs.InvalidArgument, match="theta"):
        rs.estimate_sigma_specular(R_spec=0.1, theta_deg=90)


# ---- Fits ----------------------------------------------------------------------------------------

def _geoms(n, rng):
    return rng.uniform(0, 70, n), rng.uniform(0, 70, n), rng.uniform(0, 360, n)


@pytest.mark.parametrize("correlation", ["gaussian", "exponential"])
def test_fit_recovers_parameters(correlation):
    rng = np.random.default_rng(3)
    ti, ts, ps = _geoms(25, rng)
    b = 42.0 * very_rough_vh(ti, ts, ps, 0.6, correlation)
    fit = rs.fit_roughness(ti, ts, ps, b, correlation=correlation)
    assert fit["status"] == "converged"
    assert fit["sigma_over_T"] == pytest.approx(0.6, rel=1e-7)
    assert fit["gain"] == pytest.approx(42.0, rel=1e-6)
    assert len(fit["residuals"]) == 25 and np.shape(fit["covariance"]) == (2, 2)
    # 1 % noise: the reported standard error is of the right size
    noisy = b * (1 + 0.01 * rng.standard_normal(25))
    fit = rs.fit_roughness(ti, ts, ps, noisy, correlation=correlation)
    assert abs(fit["sigma_over_T"] - 0.6) < 4 * fit["sigma_over_T_stderr"]
    assert fit["aic"] == pytest.approx(25 * math.log(fit["sse"] / 25) + 4)


def test_compare_correlations_prefers_the_truth():
    rng = np.random.default_rng(4)
    ti, ts, ps = _geoms(40, rng)
    b = very_rough_vh(ti, ts, ps, 0.5, "exponential") * (1 + 0.01 * rng.standard_normal(40))
    cmp = rs.compare_correlations(ti, ts, ps, b)
    assert cmp["preferred_correlation"] == "exponential" and cmp["delta_aic"] > 10


def test_fit_bad_input():
    rng = np.random.default_rng(5)
    ti, ts, ps = _geoms(5, rng)
    b = very_rough_vh(ti, ts, ps, 0.5, "gaussian")
    with pytest.raises(rs.InvalidArgument, match="none given"):
        rs.fit_roughness([], [], [], [])
    bad = b.copy()
    bad[1] = -1
    with pytest.raises(rs.InvalidArgument, match="measurement 2 brightness"):
        rs.fit_roughness(ti, ts, ps, bad)
    with pytest.raises(rs.InvalidArgument, match="measurement 1 theta_i"):
        rs.fit_roughness(np.r_[95.0, ti[1:]], ts, ps, b)
    with pytest.raises(rs.InvalidArgument, match="theta_s_deg has 3 values"):
        rs.fit_roughness(ti, ts[:3], ps, b)
    with pytest.raises(ValueError, match="loss"):
        rs.fit_roughness(ti, ts, ps, b, loss="l1")
    with pytest.raises(rs.InvalidArgument, match="bounds"):
        rs.fit_roughness(ti, ts, ps, b, sigma_over_T_bounds=(2.0, 1.0))


# ---- Report section ------------------------------------------------------------------------------

def test_report_section_recomputes_tables(paper_tables, tmp_path):
    from roughscope import report_estimation

    rec = report_estimation.recompute_tables(paper_tables)
    assert [r["sigma_over_T_G"][2] for r in rec["table3"]] == ["=", "=", "="]
    assert [r["sigma_over_T_E"][2] for r in rec["table3"]] == ["=", "=", "="]
    assert all(r["theta_K_deg"][2] == "=" for r in rec["table2"])
    assert all(r[k][2] in ("=", "≈") for r in rec["table1"] for k in ("sigma_um", "T_um", "sigma_over_T"))
    html = report_estimation.section(tmp_path)
    assert "Table 1" in html and "Table 3" in html and "class='bad'" not in html
    assert (tmp_path / "estimation_slope_vs_ratio.png").is_file()


def test_report_section_without_tables(tmp_path, monkeypatch):
    from roughscope import report_estimation

    monkeypatch.setattr(report_estimation, "find_paper_tables", lambda: None)
    assert "Skipped" in report_estimation.section(tmp_path)
