"""Example 1 — the forward model (paper §2–3) from Python.

The Python module is vectorised: every argument is array-like and broadcast with NumPy's rules,
angles are in degrees (``_deg``) and lengths in micrometres (``_um``).

  1. the geometry from unit vectors N, L, V (§2);
  2. Eq. 1 for a slightly rough surface of known σ and T, regime chosen from g = σ²v_z²;
  3. the very-rough shape Eq. 4 over a whole range of viewing angles in one call, and the
     retro-scattering closed form Eq. 9 against the general form at θi = θs, φs = 180°.
Exits non-zero if a check fails, so the test suite runs it.
"""
import sys

import numpy as np

import roughscope as rs

# 1. Light 45° from the normal on one side, camera 30° on the other side.
N = np.array([0.0, 0.0, 1.0])
L = np.array([-np.sin(np.radians(45)), 0.0, np.cos(np.radians(45))])
V = np.array([np.sin(np.radians(30)), 0.0, np.cos(np.radians(30))])
theta_i, theta_s, phi_s, visible = rs.geometry_from_vectors(N, L, V)
print(f"theta_i = {theta_i:.1f} deg, theta_s = {theta_s:.1f} deg, phi_s = {phi_s:.1f} deg")

# 2. σ = 0.01 µm, T = 1 µm in green light: slightly rough, mostly coherent.
p = rs.mean_scattered_power(theta_i, theta_s, phi_s, sigma_um=0.01, T_um=1.0)
print(f"g = {p['g']:.4f} ({p['roughness_class']}): coherent {p['coherent']:.4g}, "
      f"diffuse {p['diffuse']:.4g}")

# 3. σ/T = 0.5, lit from 45°, viewer anywhere in the plane of incidence (one call).
theta_s_deg = np.arange(0.0, 90.0, 15.0)
E = rs.very_rough_brightness(45.0, theta_s_deg, 0.0, 0.5)
for t, e in zip(theta_s_deg, E):
    print(f"{t:5.0f}  {e:.6g}")

theta = np.array([10.0, 40.0, 70.0])
closed = rs.retro_vh_gaussian_very_rough(theta, 0.5)
general = 4 * rs.very_rough_brightness(theta, theta, 180.0, 0.5)
if not np.allclose(closed, general, rtol=1e-12, atol=0):
    sys.exit(f"Eq. 9 disagrees with Eq. 4: {closed} vs {general}")
print("Eq. 9 = Eq. 4 at the retro geometry: ok")
