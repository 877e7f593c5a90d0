"""Figures of the paper reproduced with roughscope (matplotlib, Agg backend, PNG).

* :func:`figure3` — Fig. 3: normalised retro-scattered radiance of the original B–K model
  (F = F_Beck) against θ for several m = σ/T: (a) Gaussian correlation, Eq. 7;
  (b) exponential correlation, Eq. 8. Lambert's cos θ dashed.
* :func:`figure4` — Fig. 4: the same for the V–H modified model (F² = cos θi): Eq. 9 and Eq. 10.

"Normalised" means divided by the value at θ = 0 (every curve and Lambert's law start at 1),
as in the paper. Every function returns the path of the PNG it wrote; the file is written to a
temporary name in the same folder and renamed, so a failed call leaves nothing half-written.

matplotlib is imported only here (and only through its object-oriented API, so the caller's
pyplot state and backend are untouched): ``import roughscope`` works without it.
"""

import pathlib

import numpy as np

from . import _core
from ._plotting import save

#: The σ/T values plotted (the paper mentions 0.71 and 1.8 in §3.4).
M_VALUES = (0.2, 0.4, 0.71, 1.0, 1.8)

#: Incidence angles plotted, degrees (the closed forms need θ < 90°).
THETA_DEG = np.linspace(0.0, 89.0, 357)


def _new_figure(width_in=10.0, height_in=4.2):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width_in, height_in), dpi=110)
    FigureCanvasAgg(fig)
    return fig


def _save(fig, path):
    """Save `fig` as PNG at `path` atomically (its folder created when missing); return the
    path."""
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    save(fig, path)
    return path


def normalised_retro_curves(equation, m_values=M_VALUES, theta_deg=THETA_DEG):
    """Normalised retro-scattered radiance for each m, as a dict m → array over `theta_deg`.

    equation: 7, 8, 9 or 10 (the paper's retro-scattering closed forms).
    """
    fn = {
        7: _core.retro_beckmann_gaussian_very_rough,
        8: _core.retro_beckmann_exponential_very_rough,
        9: _core.retro_vh_gaussian_very_rough,
        10: _core.retro_vh_exponential_very_rough,
    }.get(equation)
    if fn is None:
        raise _core.InvalidArgument(f"equation = {equation!r} is not one of 7, 8, 9, 10")
    theta_deg = np.asarray(theta_deg, dtype=float)
    curves = {}
    for m in m_values:
        values = np.asarray(fn(theta_deg, m), dtype=float)
        curves[m] = values / float(fn(0.0, m))
    return curves


def _retro_panel(ax, equation, title, log_scale):
    theta = THETA_DEG
    for m, values in normalised_retro_curves(equation).items():
        ax.plot(theta, values, lw=1.6, label=f"σ/T = {m:g}")
    ax.plot(theta, _core.lambert_brightness(theta), "k--", lw=1.2, label="Lambert cos θ")
    ax.set_xlim(0.0, 90.0)
    ax.set_xlabel("θ = θi = θs (degrees), retro-scattering φs = 180°")
    ax.set_ylabel("normalised radiance")
    ax.set_title(title, fontsize=10)
    if log_scale:
        ax.set_yscale("log")
        ax.set_ylim(1e-3, 1e5)
    else:
        ax.set_ylim(0.0, None)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")


def figure3(outdir, filename="fig3_bk_retro.png"):
    """Fig. 3: original B–K model (F = F_Beck), (a) Eq. 7 Gaussian, (b) Eq. 8 exponential.

    The y axis is logarithmic: the 1/cos⁶θ factor makes these curves span many decades
    (Eq. 8 diverges as θ → 90°, the paper's point). Returns the PNG's path.
    """
    fig = _new_figure()
    ax_a, ax_b = fig.subplots(1, 2)
    _retro_panel(ax_a, 7, "(a) original B–K, Gaussian correlation (Eq. 7)", log_scale=True)
    _retro_panel(ax_b, 8, "(b) original B–K, exponential correlation (Eq. 8)", log_scale=True)
    fig.suptitle("Fig. 3 — normalised retro-scattered radiance, F = F_Beck", fontsize=11)
    fig.tight_layout()
    return _save(fig, pathlib.Path(outdir) / filename)


def figure4(outdir, filename="fig4_vh_retro.png"):
    """Fig. 4: V–H modified B–K model (F² = cos θi), (a) Eq. 9 Gaussian, (b) Eq. 10 exponential.

    Returns the PNG's path.
    """
    fig = _new_figure()
    ax_a, ax_b = fig.subplots(1, 2)
    _retro_panel(ax_a, 9, "(a) V–H modified B–K, Gaussian correlation (Eq. 9)", log_scale=False)
    _retro_panel(ax_b, 10, "(b) V–H modified B–K, exponential correlation (Eq. 10)",
                 log_scale=False)
    fig.suptitle("Fig. 4 — normalised retro-scattered radiance, F² = F_VH² = cos θi",
                 fontsize=11)
    fig.tight_layout()
    return _save(fig, pathlib.Path(outdir) / filename)
