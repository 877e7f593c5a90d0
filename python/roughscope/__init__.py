"""roughscope: surface roughness from brightness with the modified Beckmann–Kirchhoff theory.

Implements Ragheb & Hancock, "The modified Beckmann–Kirchhoff scattering theory for rough surface
analysis" (Pattern Recognition, 2007). The numerical functions come from the compiled module
``roughscope._core``; see docs/python.md.

Conventions: angles in degrees (``_deg``), lengths in micrometres (``_um``); every numeric
argument is array-like and broadcast with NumPy's rules (scalars in → float out, arrays in →
arrays out); bad input raises :class:`roughscope.Error`, a :class:`ValueError`.

Plotting (``roughscope.figures``) and the HTML report (``python -m roughscope.report``) need
matplotlib, which is imported only when they are used.
"""

from ._core import *  # noqa: F401,F403  (the compiled API)
from ._core import Error, InvalidArgument, NoSolution, DataError  # noqa: F401
from ._core import __version__  # noqa: F401

from . import _units  # noqa: F401
from ._units import deg_to_rad, rad_to_deg  # noqa: F401


def __getattr__(name):
    # Lazy submodules: importing roughscope must not import matplotlib.
    if name in ("figures", "report", "report_estimation", "report_curet", "curet", "plot",
                "surface_figures", "report_surface", "simulation_figures", "report_simulation",
                "sweep", "demo", "report_measure", "report_objects"):
        import importlib

        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module 'roughscope' has no attribute {name!r}")
