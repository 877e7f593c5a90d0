"""Where Eq. 9 (V–H, Gaussian, very rough) leaves Kirchhoff scattering on a cylinder lit from the
camera (§5.2, Fig. 8), next to Caron's θK (docs/curved-objects.md, "Against Kirchhoff").

The Kirchhoff truth is the exact Gaussian series (Eq. 2) with the V–H factor: the Monte Carlo
Kirchhoff simulation on generated surfaces (docs/simulation.md) is checked against it at the
retro-reflection geometries of the cylinder first, then cylinders are rendered from it (14-bit
linear TIFF, shot and read noise) and measured. A cylinder rendered from Eq. 9 itself, with the
same camera and pipeline, is the control: there Eq. 9 never leaves the data.
"""

import json

import numpy as np
import pytest

import roughscope as rs
from roughscope import _core, demo

SIGMA_OVER_T = 0.4  # θK = 90° − atan(√2 · 0.4) = 60.5°
THETA_K_DEG = 90.0 - np.degrees(np.arctan(np.sqrt(2.0) * SIGMA_OVER_T))


def measure_cylinder(folder, **truth):
    """Renders a 400 × 200 cylinder (axis vertical, radius 80 px, L = V = +z) and measures it."""
    folder.mkdir(parents=True, exist_ok=True)
    scene = dict(scene="cylinder", width=400, height=200, theta_i_deg=0.0,
                 correlation="gaussian", factor="vh", sigma_over_T=SIGMA_OVER_T, **truth)
    exposure = demo.exposure_for_peak(demo.peak_brightness(**scene))
    _core.write_capture(str(folder), "tiff", exposure_s=exposure, seed=5, **scene,
                        **demo.object_camera())
    spec = {"format": "roughscope-measure", "black_level_dn": demo.OBJECT_BLACK_LEVEL,
            "object": {"shape": "cylinder",
                       "axis": {"point_px": [200, 100], "direction": [0, 1], "radius_px": 80}},
            "captures": [{"image": "capture.tiff", "light": [0, 0, 1], "view": [0, 0, 1]}]}
    (folder / "capture-file.json").write_text(json.dumps(spec))
    return rs.measure(str(folder / "capture-file.json"))["cylinder"]


@pytest.mark.parametrize("T_um", [1.25, 2.5])
def test_monte_carlo_kirchhoff_at_retro_geometries_is_the_series(T_um):
    # θi = θs, φs = 180°: what each pixel of a cylinder lit from the camera sees.
    theta = np.array([0.0, 20.0, 40.0, 55.0, 65.0])
    res = rs.simulate_scatter(theta, theta, 180.0, sigma_um=SIGMA_OVER_T * T_um, T_um=T_um,
                              factor="vh", realisations=200, seed=3)
    for row in res["results"]:
        z = (row["diffuse"] - row["series_diffuse"]) / row["diffuse_stderr"]
        assert abs(z) <= 3.0, (T_um, row["theta_i_deg"], row["g"], z)


@pytest.fixture(scope="module")
def cylinders(tmp_path_factory):
    base = tmp_path_factory.mktemp("kirchhoff_cylinders")
    out = {T: measure_cylinder(base / f"series-T{T}", model="mean_scattered_power", T_um=T)
           for T in (1.25, 2.5, 5.0)}
    out["eq9"] = measure_cylinder(base / "eq9", model="very_rough")
    return out


def test_eq9_never_leaves_a_cylinder_rendered_from_eq9(cylinders):
    # The control: same camera, pipeline and σ/T; the departure seen below is the physics.
    c = cylinders["eq9"]
    assert c["departure_angle_deg"]["vh_gaussian"] is None, c["departure_angle_deg"]
    assert abs(c["sigma_over_T_gaussian"] - SIGMA_OVER_T) <= 2.0 * c["sigma_over_T_gaussian_stderr"]
    assert c["theta_K_deg"] == pytest.approx(THETA_K_DEG, abs=0.1)


def test_eq9_leaves_kirchhoff_earlier_the_smaller_g(cylinders):
    # Eq. 4 is the g → ∞ limit of the series; at retro reflection g = (4πσ cos θ/λ)² falls with θ
    # and with σ. Same σ/T (same θK), σ = 0.5, 1, 2 µm (g at normal view 128, 513, 2051).
    dep = {T: cylinders[T]["departure_angle_deg"]["vh_gaussian"] for T in (1.25, 2.5, 5.0)}
    for T in (1.25, 2.5, 5.0):
        assert cylinders[T]["theta_K_deg"] == pytest.approx(THETA_K_DEG, abs=0.5)
    assert dep[1.25] is not None and dep[2.5] is not None, dep
    assert dep[1.25] < dep[2.5] < THETA_K_DEG, (dep, THETA_K_DEG)  # before θK, σ/T alone
    assert dep[5.0] is None or dep[5.0] > dep[2.5], dep
    # The fitted σ/T (θi ≤ 60°) carries the series' 1/g bias: small, larger the smaller g.
    bias = {T: cylinders[T]["sigma_over_T_gaussian"] / SIGMA_OVER_T - 1.0 for T in (1.25, 2.5)}
    assert abs(bias[2.5]) < abs(bias[1.25]) < 0.02, bias
