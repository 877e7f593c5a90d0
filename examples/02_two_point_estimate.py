"""Example 2 — σ/T from two photographs (paper §4.2, Eq. 16–19) from Python.

Brightness at θ1 = 45° and θ2 = 67.5° with the camera on the normal, generated from a known
σ/T; the estimate must give it back, with a standard error from 1 % brightness noise. A ratio
with no solution raises ``roughscope.NoSolution`` naming the valid range.
"""
import sys

import roughscope as rs

true_sigma_over_T = 0.35
for correlation in ("gaussian", "exponential"):
    E1 = rs.very_rough_brightness(45.0, 0.0, 0.0, true_sigma_over_T, correlation=correlation)
    E2 = rs.very_rough_brightness(67.5, 0.0, 0.0, true_sigma_over_T, correlation=correlation)
    est = rs.estimate_slope(E1 / E2, 45.0, 67.5, correlation=correlation, noise=0.01)
    print(f"{correlation:11s} E1/E2 = {E1 / E2:.5f}  sigma/T = {est['sigma_over_T']:.6f} "
          f"+- {est['sigma_over_T_stderr']:.4f}  theta_K = {est['theta_K_deg']:.1f} deg")
    if abs(est["sigma_over_T"] - true_sigma_over_T) > 1e-9 * true_sigma_over_T:
        sys.exit(f"expected sigma/T = {true_sigma_over_T}")

try:
    rs.estimate_slope(0.5, 45.0, 67.5)
    sys.exit("E1/E2 = 0.5 should have no solution")
except rs.NoSolution as err:
    print(f"E1/E2 = 0.5: {err}")
