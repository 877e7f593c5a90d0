"""Planning a capture: roughscope.plan_capture and `roughscope plan` (docs/uncertainty.md,
"Planning a capture").

The predicted u(sigma/T) is checked against a first-order propagation written here from the
paper's very-rough Gaussian brightness (Eq. 4 with the Vernold-Harvey factor F^2 = cos(theta_i),
radiance, camera possibly tilted in the plane of incidence), inverted by bisection: independent
of the library's solvers and of its propagation engine.
"""

import json
import math
import subprocess

import numpy as np
import pytest

import roughscope
from conftest import cli_path


def log_brightness(theta_i, theta_s, s):
    """ln of Eq. 4 (Gaussian, very rough) in the plane of incidence, phi_s = 0 (theta_s signed)."""
    vx = math.sin(theta_i) - math.sin(theta_s)
    vz = math.cos(theta_i) + math.cos(theta_s)
    return math.log(math.cos(theta_i) / vz ** 2) - vx ** 2 / (4 * s ** 2 * vz ** 2)


def invert(ratio, t1, t2, tilt):
    """sigma/T whose model ratio at (t1, t2, tilt) is `ratio` (bisection in ln s)."""
    def f(log_s):
        s = math.exp(log_s)
        return log_brightness(t1, tilt, s) - log_brightness(t2, tilt, s) - math.log(ratio)
    lo, hi = math.log(1e-3), math.log(1e3)
    assert f(lo) * f(hi) < 0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if f(lo) * f(mid) <= 0:
            hi = mid
        else:
            lo = mid
    return math.exp(0.5 * (lo + hi))


def predicted_u(s, theta1_deg, theta2_deg, angle_deg, exposure_rel, noise_rel):
    """First order (central differences over +- u) of sigma/T measured at theta1/theta2, each
    capture exposed to the same fill (the black level cancels)."""
    t1, t2 = math.radians(theta1_deg), math.radians(theta2_deg)
    ratio = math.exp(log_brightness(t1, 0.0, s) - log_brightness(t2, 0.0, s))
    ua = math.radians(angle_deg)
    x0 = np.array([t1, t2, 0.0, 0.0, 0.0, 0.0, 0.0])
    u = np.array([ua, ua, ua, exposure_rel, exposure_rel, noise_rel, noise_rel])

    def model(x):
        r = ratio * (1 + x[5]) / (1 + x[3]) / ((1 + x[6]) / (1 + x[4]))
        return invert(r, x[0], x[1], x[2])

    var = 0.0
    for i in range(len(x0)):
        xp, xm = x0.copy(), x0.copy()
        xp[i] += u[i]
        xm[i] -= u[i]
        var += ((model(xp) - model(xm)) / 2) ** 2
    return math.sqrt(var), ratio


@pytest.mark.parametrize("s", [0.3, 0.5])
def test_the_prediction_is_a_first_order_propagation_of_the_model(s):
    d = roughscope.plan_capture(s, tolerances={"angle_deg": 0.5, "exposure_rel": 0.01},
                                black_level_rel=0.001, noise_rel=0.002, theta_step_deg=5,
                                method="first_order")
    for pair in (d["paper_30_45"], d["recommended"]):
        u, ratio = predicted_u(s, pair["theta1_deg"], pair["theta2_deg"], 0.5, 0.01, 0.002)
        assert pair["E1_over_E2"] == pytest.approx(ratio, rel=1e-9)
        assert pair["sigma_over_T_uncertainty"] == pytest.approx(u, rel=0.02), pair
        assert pair["sigma_over_T_interval95"][0] == pytest.approx(s - 1.96 * u, rel=0.02)
    assert d["recommended"]["sigma_over_T_uncertainty"] <= \
        d["paper_30_45"]["sigma_over_T_uncertainty"]
    assert d["assumed"] == []
    assert d["tolerances"] == {"angle_deg": 0.5, "exposure_rel": 0.01, "black_level_rel": 0.001}
    # Every pair of the 5 degree grid from 5 to 75 degrees at least 5 degrees apart.
    assert d["grid"]["pairs"] == 14 * 15 // 2
    # The budget's fractions add up to 1, the largest first.
    fractions = [line["fraction"] for line in d["recommended"]["budget"]]
    assert sum(fractions) == pytest.approx(1.0)
    assert fractions == sorted(fractions, reverse=True)


def test_the_command_prints_the_same_document():
    kwargs = dict(sigma_over_T=0.8, sigma_over_T_max=1.2, correlation="exponential",
                  tolerances={"angle_deg": 0.3}, theta_step_deg=2, top=3)
    d = roughscope.plan_capture(**kwargs)
    proc = subprocess.run([cli_path(), "plan", "--sigma-over-T", "0.8", "--sigma-over-T-max",
                           "1.2", "--correlation", "exponential", "--angle-deg", "0.3",
                           "--theta-step", "2", "--top", "3", "--json"],
                          capture_output=True, text=True, timeout=300, check=True)
    cli = json.loads(proc.stdout)
    assert cli.pop("roughscope_version") == roughscope.__version__
    assert cli == d
    assert len(d["top"]) == 3
    assert d["sigma_over_T_points"] == pytest.approx([0.8, 0.9, 1.0, 1.1, 1.2])
    assert sorted(d["assumed"]) == ["black_level_rel = 0.002", "exposure_rel = 0.01"]
    text = subprocess.run([cli_path(), "plan", "--sigma-over-T", "0.8"], capture_output=True,
                          text=True, timeout=300, check=True).stdout
    assert "recommended" in text and "paper 30° / 45°" in text and "largest source" in text


@pytest.mark.parametrize("kwargs, field", [
    (dict(sigma_over_T=0.0), "sigma_over_T"),
    (dict(sigma_over_T=-0.5), "sigma_over_T"),
    (dict(sigma_over_T=0.5, theta_min_deg=40, theta_max_deg=40), "angle grid"),
    (dict(sigma_over_T=0.5, tolerances={"angle": 1}), "angle"),
    (dict(sigma_over_T=0.5, tolerances={"black_level_dn": 40}), "full_scale_dn"),
    (dict(sigma_over_T=0.5, noise_rel=-1), "noise_rel"),
    (dict(sigma_over_T=0.5, exposure="sometimes"), "sometimes"),
])
def test_a_bad_request_names_its_field(kwargs, field):
    with pytest.raises(roughscope.InvalidArgument, match=field):
        roughscope.plan_capture(**kwargs)


def test_a_bad_command_line_exits_2_naming_the_flag():
    proc = subprocess.run([cli_path(), "plan", "--sigma-over-T", "0"], capture_output=True,
                          text=True, timeout=60)
    assert proc.returncode == 2
    assert "--sigma-over-T" in proc.stderr
