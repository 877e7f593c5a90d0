"""Report section: height data (paper §3.1).

A surface of known statistics is generated (Gaussian heights, σ = 0.5 µm, Gaussian correlation
with T = 8 µm, 256 × 256 points 1 µm apart, seed 1) and measured back by the library's statistics:
the section shows the height image, the ACF with the fitted Gaussian and exponential curves and
the 1/e line, the PSD (:mod:`roughscope.surface_figures`), the recovered σ and T next to the truth,
and what the camera would see of it (g at normal view and the roughness class,
:func:`roughscope.predict_brightness`).
"""

from . import _core
from ._html import escape, linked_figure, quantity

TRUTH = dict(correlation="gaussian", sigma_um=0.5, T_um=8.0, nx=256, ny=256, dx_um=1.0, seed=1)


def section(outdir):
    """The HTML fragment (the figure is written into `outdir`)."""
    from . import surface_figures

    heights = _core.generate_surface(**TRUTH)
    doc = surface_figures.document(heights, TRUTH["dx_um"], level="plane")
    name = "surface_stats.png"
    figure = ""
    try:
        surface_figures.stats_figure(doc, outdir / name)
        figure = linked_figure(
            name, "height image, ACF and PSD",
            "Left: the generated heights. Middle: the ACF along x and y with the fitted "
            "Gaussian and exponential curves (the better by AIC drawn thicker) and the 1/e "
            "line that defines T. Right: the 1-D and radially averaged PSD.")
    except ImportError:  # no matplotlib: the table alone
        pass
    prediction = _core.predict_brightness(0.0, 0.0, 0.0, statistics=doc)
    true_slope = float(_core.rms_slope(TRUTH["sigma_um"] / TRUTH["T_um"]))
    rows = [("σ (Sq)", TRUTH["sigma_um"], doc["sigma_um"], "µm"),
            ("T (1/e, x)", TRUTH["T_um"], doc["T_um"], "µm"),
            ("T (1/e, y)", TRUTH["T_um"], doc["T_y_um"], "µm"),
            ("T (Gaussian fit)", TRUTH["T_um"], doc["T_fit_gaussian_um"], "µm"),
            ("correlation (AIC)", TRUTH["correlation"], doc["correlation"], ""),
            ("RMS slope", true_slope, doc["rms_slope"], ""),
            ("m = σ√2/T", true_slope, doc["m_from_T"], "")]
    table = "".join(f"<tr><td class='l'>{escape(n)}</td><td>{quantity(t, u)}</td>"
                    f"<td>{quantity(m, u)}</td></tr>" for n, t, m, u in rows)
    warnings = "".join(f"<li>{escape(w)}</li>" for w in doc["warnings"])
    return f"""<h2>Height data (§3.1)</h2>
<p>A random surface generated with σ = {TRUTH['sigma_um']} µm and Gaussian correlation of length
T = {TRUTH['T_um']} µm ({TRUTH['nx']} × {TRUTH['ny']} points, dx = {TRUTH['dx_um']} µm, seed
{TRUTH['seed']}), measured back after plane levelling. At λ = {prediction['wavelength_um']} µm a
camera sees it with g = {prediction['g_normal']:.4g} at normal view:
<b>{escape(prediction['roughness_class'].replace('_', ' '))}</b> (Caron's θK =
{prediction['theta_K_deg']:.3g}°).</p>
{figure}
<table><tr><th class='l'>quantity</th><th>truth</th><th>measured</th></tr>{table}</table>
{f"<ul>{warnings}</ul>" if warnings else ""}
"""
