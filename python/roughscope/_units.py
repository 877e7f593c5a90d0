"""Unit helpers for the Python boundary (degrees and micrometres outside, radians inside).

These are plain NumPy conversions, kept here so that scripts never spell ``np.pi / 180`` by hand.
They accept what every numeric argument of roughscope accepts (docs/python.md, "Types"): int and
float, NumPy integer and floating scalars and arrays, and sequences of them; anything else (bool,
str, bytes, complex, datetime64, timedelta64, object arrays, None) raises TypeError.
"""

import numpy as np

_REAL_KINDS = "iuf"  # NumPy dtype kinds: signed, unsigned integer, floating point


def _real_array(name, value):
    """``value`` as a NumPy array of a real dtype; TypeError naming ``name`` otherwise."""
    if isinstance(value, np.ndarray):
        array = value
    elif value is None or isinstance(value, (bool, str, bytes, complex)):
        raise TypeError(f"{name} must be a real number or an array-like of real numbers (int or "
                        f"float, or a NumPy array of integer or floating dtype), not "
                        f"{type(value).__name__}")
    else:
        array = np.asarray(value)
    if array.dtype.kind not in _REAL_KINDS:
        raise TypeError(f"{name} must be a real number or an array-like of real numbers (int or "
                        f"float, or a NumPy array of integer or floating dtype), not an array of "
                        f"dtype {array.dtype}")
    return array


def deg_to_rad(angle_deg):
    """Degrees → radians (array-like in, float or array out)."""
    out = np.radians(_real_array("angle_deg", angle_deg).astype(float, copy=False))
    return float(out) if out.ndim == 0 else out


def rad_to_deg(angle_rad):
    """Radians → degrees (array-like in, float or array out)."""
    out = np.degrees(_real_array("angle_rad", angle_rad).astype(float, copy=False))
    return float(out) if out.ndim == 0 else out
