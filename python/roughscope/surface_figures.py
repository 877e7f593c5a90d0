"""Figures of height data (paper §3.1): the height image, the autocorrelation with the fitted
Gaussian exp(−τ²/T²) and exponential exp(−|τ|/T) curves and the 1/e line that defines T, and the
power spectral density.

Input is the statistics document of ``roughscope surface stats --json`` with its ``curves`` and an
``image`` (``{"nx", "ny", "dx_um", "dy_um", "heights_um": rows}``) — what ``roughscope surface stats
FILE --plot OUT.png`` pipes into ``python3 -m roughscope.plot surface --out OUT.png`` — or, from
Python, :func:`document` built from heights and :func:`roughscope.surface_statistics`. Figures are
written atomically (temporary file, then rename). matplotlib is imported only here.
"""

import math

import numpy as np

from . import _core
from ._plotting import pyplot, save


def image_from_heights(heights_um, dx_um, dy_um=None, max_side=512):
    """The ``image`` entry of a document from a (ny, nx) array: subsampled by a whole stride so
    that neither side exceeds max_side; NaN (missing) becomes None."""
    z = np.asarray(heights_um, dtype=float)
    if z.ndim == 1:
        z = z[np.newaxis, :]
    if z.ndim != 2:
        raise ValueError(f"heights_um must be 1-D or 2-D, got {z.ndim} dimensions")
    dy_um = dx_um if dy_um is None else dy_um
    stride = max(1, math.ceil(max(z.shape) / max_side))
    sub = z[::stride, ::stride]
    rows = [[None if not np.isfinite(v) else float(v) for v in row] for row in sub]
    return {"nx": sub.shape[1], "ny": sub.shape[0], "dx_um": dx_um * stride,
            "dy_um": dy_um * stride, "stride": stride, "heights_um": rows}


def document(heights_um, dx_um, dy_um=None, **options):
    """The figure's document from heights: :func:`roughscope.surface_statistics` with curves and
    the heights as given (not levelled) as the image."""
    stats = _core.surface_statistics(heights_um, dx_um, dy_um, curves=True, **options)
    stats["image"] = image_from_heights(heights_um, dx_um, dy_um)
    return stats


def _curve(doc, name):
    c = (doc.get("curves") or {}).get(name) or {}
    x = c.get("lag_um", c.get("frequency_per_um")) or []
    y = c.get("acf", c.get("psd")) or []
    x = np.array([np.nan if v is None else v for v in x], dtype=float)
    y = np.array([np.nan if v is None else v for v in y], dtype=float)
    return x, y


def check_document(doc):
    """ValueError unless `doc` has what the figure draws."""
    if not isinstance(doc, dict):
        raise ValueError(f"expected a statistics object, got {type(doc).__name__}")
    if "curves" not in doc:
        raise ValueError("the statistics have no 'curves' (compute them with curves=True, or "
                         "use `roughscope surface stats FILE --plot OUT.png`)")
    if "image" not in doc:
        raise ValueError("the document has no 'image' (the heights to show)")


def stats_figure(doc, path):
    """Draw the three panels (height image, ACF with fits and 1/e line, PSD) into `path`."""
    check_document(doc)
    plt = pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(15.0, 4.6))
    try:
        # Height image.
        img = doc["image"]
        z = np.array([[np.nan if v is None else v for v in row] for row in img["heights_um"]],
                     dtype=float)
        ax = axes[0]
        extent = (0.0, img["nx"] * img["dx_um"], img["ny"] * img["dy_um"], 0.0)
        shown = ax.imshow(z, cmap="viridis", extent=extent, aspect="equal"
                          if img["ny"] > 1 else "auto", interpolation="nearest")
        fig.colorbar(shown, ax=ax, label="height (µm)")
        ax.set_xlabel("x (µm)")
        ax.set_ylabel("y (µm)")
        title = doc.get("file") or "heights"
        ax.set_title(f"{title}: σ = {doc['sigma_um']:.4g} µm" if doc.get("sigma_um") is not None
                     else str(title))

        # ACF with the fits and the 1/e line.
        ax = axes[1]
        tau, acf = _curve(doc, "acf_x")
        ax.plot(tau, acf, "k.-", ms=3, lw=1, label="ACF along x")
        ty, acfy = _curve(doc, "acf_y")
        if ty.size:
            ax.plot(ty, acfy, ".-", color="0.6", ms=2, lw=0.8, label="ACF along y")
        t = np.linspace(0.0, tau.max() if tau.size else 1.0, 400)
        tg, te = doc.get("T_fit_gaussian_um"), doc.get("T_fit_exponential_um")
        best = doc.get("correlation")
        for T_fit, correlation, name, colour in ((tg, "gaussian", "Gaussian", "C0"),
                                                 (te, "exponential", "exponential", "C3")):
            if T_fit:  # the model ACF of §3.1 with the fitted T
                chosen = best == correlation
                ax.plot(t, _core.acf_model(t, T_fit, correlation), colour, lw=2 if chosen else 1,
                        label=f"{name} fit, T = {T_fit:.4g} µm" + (" (AIC)" if chosen else ""))
        ax.axhline(math.exp(-1.0), color="C2", ls="--", lw=1, label="1/e")
        if doc.get("T_um"):
            ax.axvline(doc["T_um"], color="C2", ls=":", lw=1,
                       label=f"T (1/e) = {doc['T_um']:.4g} µm")
        # The ACF at lags near the map's length rests on few pairs (noisy): show ~6 T.
        scale = max([v for v in (doc.get("T_um"), tg, te) if v] or [0.0])
        if scale > 0 and tau.size and 6 * scale < np.nanmax(tau):
            ax.set_xlim(0.0, 6 * scale)
        ax.set_xlabel("lag τ (µm)")
        ax.set_ylabel("C(τ)")
        ax.set_title("autocorrelation")
        ax.legend(fontsize=8)

        # PSD.
        ax = axes[2]
        for name, style, label in (("psd_x", "k-", "1-D along x"),
                                   ("psd_radial", "C1-", "radial 2-D")):
            f, p = _curve(doc, name)
            keep = (f > 0) & (p > 0) if f.size else np.zeros(0, dtype=bool)
            if keep.any():
                ax.loglog(f[keep], p[keep], style, lw=1, label=label)
        ax.set_xlabel("spatial frequency (1/µm)")
        ax.set_ylabel("PSD")
        ax.set_title("power spectral density")
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=8)
        fig.tight_layout()
        save(fig, path)
    finally:
        plt.close(fig)
    return str(path)
