"""Example 3 — least-squares fit of σ/T to a CSV of brightness measurements (paper §4) from
Python.

Writes a CSV in the layout of ``roughscope estimate fit --measurements`` (theta_i, phi_i,
theta_s, phi_s in degrees, brightness) for a very rough Gaussian surface, σ/T = 0.6, gain 250,
1 % noise; reads it back with NumPy; converts the two azimuths to the paper's frame; fits both
correlations with an unknown gain and compares them by AIC. The Gaussian must win and σ/T must
lie within 3 standard errors of the truth. Exits non-zero if a check fails.
"""
import sys
from pathlib import Path

import numpy as np

import roughscope as rs

true_sigma_over_T, gain = 0.6, 250.0
rng = np.random.default_rng(7)
theta_i, theta_s, phi_s = (a.ravel() for a in np.meshgrid(
    np.arange(5.0, 80.0, 10.0), [0.0, 30.0, 60.0], [90.0, 180.0], indexing="ij"))
phi_i = np.zeros_like(theta_i)
ti, ts, ps = rs.geometry_from_two_azimuths(theta_i, phi_i, theta_s, phi_s)
E = gain * rs.very_rough_brightness(ti, ts, ps, true_sigma_over_T)
E *= 1 + 0.01 * rng.standard_normal(E.shape)

csv = Path("example_03_measurements_py.csv")
np.savetxt(csv, np.column_stack([theta_i, phi_i, theta_s, phi_s, E]), delimiter=",",
           header="theta_i,phi_i,theta_s,phi_s,brightness", comments="", fmt="%.17g")

data = np.genfromtxt(csv, delimiter=",", names=True)
ti, ts, ps = rs.geometry_from_two_azimuths(data["theta_i"], data["phi_i"], data["theta_s"],
                                           data["phi_s"])
both = rs.compare_correlations(ti, ts, ps, data["brightness"])
fit = rs.fit_roughness(ti, ts, ps, data["brightness"])
print(f"{len(data)} measurements; sigma/T = {fit['sigma_over_T']:.4f} "
      f"+- {fit['sigma_over_T_stderr']:.4f} (true {true_sigma_over_T}); "
      f"preferred: {both['preferred_correlation']}, status {fit['status']}")
if fit["status"] != "converged" or both["preferred_correlation"] != "gaussian":
    sys.exit("unexpected fit status or correlation")
if abs(fit["sigma_over_T"] - true_sigma_over_T) > 3 * fit["sigma_over_T_stderr"]:
    sys.exit("sigma/T more than 3 standard errors from the truth")
