"""Report section: height data (paper §3.1).

A surface of known statistics is generated (Gaussian heights, σ = 0.5 µm, Gaussian correlation
with T = 8 µm, 256 × 256 points 1 µm apart, seed 1) and measured back by the library's statistics:
the section shows the height image, the ACF with the fitted Gaussian and exponential curves and
the 1/e line, the PSD (:mod:`roughscope.surface_figures`), the recovered σ and T next to the truth,
and what the camera would see of it (g at normal view and the roughness class,
:func:`roughscope.predict_brightness`).
"""

import html

from . import _core

TRUTH = dict(correlation="gaussian", sigma_um=0.5, T_um=8.0, nx=256, ny=256, dx_um=1.0, seed=1)


def _e(text):
    return html.escape(str(text))


def _fmt(value, unit=""):
    if value is None:
        return "–"
    if isinstance(value, str):
        return _e(value)
    return f"{value:.4g}" + (f" {unit}" if unit else "")


def section(outdir):
    """The HTML fragment (the figure is written into `outdir`)."""
    from . import surface_figures

    heights = _core.generate_surface(**TRUTH)
    doc = surface_figures.document(heights, TRUTH["dx_um"], level="plane")
    name = "surface_stats.png"
    figure = ""
    try:
        surface_figures.stats_figure(doc, outdir / name)
        figure = (f"<figure><img src='{name}' alt='height image, ACF and PSD'><figcaption>"
                  "Left: the generated heights. Middle: the ACF along x and y with the fitted "
                  "Gaussian and exponential curves (the better by AIC drawn thicker) and the 1/e "
                  "line that defines T. Right: the 1-D and radially averaged PSD."
                  "</figcaption></figure>")
    except ImportError:  # no matplotlib: the table alone
        pass
    prediction = _core.predict_brightness(0.0, 0.0, 0.0, statistics=doc)
    rows = [("σ (Sq)", TRUTH["sigma_um"], doc["sigma_um"], "µm"),
            ("T (1/e, x)", TRUTH["T_um"], doc["T_um"], "µm"),
            ("T (1/e, y)", TRUTH["T_um"], doc["T_y_um"], "µm"),
            ("T (Gaussian fit)", TRUTH["T_um"], doc["T_fit_gaussian_um"], "µm"),
            ("correlation (AIC)", TRUTH["correlation"], doc["correlation"], ""),
            ("RMS slope", 2 ** 0.5 * TRUTH["sigma_um"] / TRUTH["T_um"], doc["rms_slope"], ""),
            ("m = σ√2/T", 2 ** 0.5 * TRUTH["sigma_um"] / TRUTH["T_um"], doc["m_from_T"], "")]
    table = "".join(f"<tr><td class='l'>{_e(n)}</td><td>{_fmt(t, u)}</td><td>{_fmt(m, u)}</td>"
                    f"</tr>" for n, t, m, u in rows)
    warnings = "".join(f"<li>{_e(w)}</li>" for w in doc["warnings"])
    return f"""<h2>Height data (§3.1)</h2>
<p>A random surface generated with σ = {TRUTH['sigma_um']} µm and Gaussian correlation of length
T = {TRUTH['T_um']} µm ({TRUTH['nx']} × {TRUTH['ny']} points, dx = {TRUTH['dx_um']} µm, seed
{TRUTH['seed']}), measured back after plane levelling. At λ = {prediction['wavelength_um']} µm a
camera sees it with g = {prediction['g_normal']:.4g} at normal view:
<b>{_e(prediction['roughness_class'].replace('_', ' '))}</b> (Caron's θK =
{prediction['theta_K_deg']:.3g}°).</p>
{figure}
<table><tr><th class='l'>quantity</th><th>truth</th><th>measured</th></tr>{table}</table>
{f"<ul>{warnings}</ul>" if warnings else ""}
"""
