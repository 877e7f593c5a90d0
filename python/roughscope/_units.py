"""Unit helpers for the Python boundary (degrees and micrometres outside, radians inside).

These are plain NumPy conversions, kept here so that scripts never spell ``np.pi / 180`` by hand.
"""

import numpy as np


def deg_to_rad(angle_deg):
    """Degrees → radians (array-like in, float or array out)."""
    out = np.radians(np.asarray(angle_deg, dtype=float))
    return float(out) if out.ndim == 0 else out


def rad_to_deg(angle_rad):
    """Radians → degrees (array-like in, float or array out)."""
    out = np.degrees(np.asarray(angle_rad, dtype=float))
    return float(out) if out.ndim == 0 else out
