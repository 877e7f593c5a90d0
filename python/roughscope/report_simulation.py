"""Report section: the closed forms against Monte Carlo Kirchhoff scattering (docs/simulation.md).

* Validation: the diffuse power simulated on generated surfaces (Gaussian and exponential
  correlation, three roughness levels g) against the exact series, with ±2 standard errors, and
  the paper's very-rough forms (Eq. 4, Eq. 5) for comparison.
* The moderately rough exponential regime (g ≈ 1), where neither one-term closed form holds.
* Finite patches: the fixed layout (a piece of an unbounded surface) against the series.
* The bias of the paper's estimators: brightness simulated at the paper's geometries (30°/45° and
  45.5°/67.5°, camera on the normal, V–H factor) for surfaces of known σ/T, inverted by Eq. 17
  and Eq. 19.

Every number comes from :func:`roughscope.simulate_scatter` with fixed seeds (the section is
reproducible); the realisations are kept small so that the report builds in about a minute.
"""

import numpy as np

from . import _core
from ._html import escape, fmt, linked_figure

LAMBDA_UM = 0.5
T_UM = 1.0
THETA_I = 30.0
SIGMAS = [("g ≈ 0.3", 0.023), ("g ≈ 2", 0.06), ("g ≈ 10", 0.135)]
REALISATIONS = 100


def _geometries():
    """θs across the plane of incidence at θi = 30°: the specular side and the light's side."""
    ts = [0, 10, 20, 30, 40, 55, 70]
    theta_s = ts + ts[1:]
    phi_s = [0] * len(ts) + [180] * (len(ts) - 1)
    return theta_s, phi_s


def _curve(correlation, sigma, regime):
    """D·A/T² on a dense signed θs grid (A cancels: any patch)."""
    dense = np.linspace(-70, 70, 141)
    phi = np.where(dense < 0, 180.0, 0.0)
    area = 4 * 500.0 * 500.0
    p = _core.mean_scattered_power(np.full_like(dense, THETA_I), np.abs(dense), phi, sigma, T_UM,
                                   correlation=correlation, factor="beckmann", regime=regime,
                                   wavelength_um=LAMBDA_UM)
    return dense, np.asarray(p["diffuse"]) * area / T_UM ** 2


def _validation(outdir):
    from . import simulation_figures

    theta_s, phi_s = _geometries()
    panels, table = [], []
    for correlation in ("gaussian", "exponential"):
        curves = []
        for k, (label, sigma) in enumerate(SIGMAS):
            doc = _core.simulate_scatter(THETA_I, theta_s, phi_s, correlation=correlation,
                                         sigma_um=sigma, T_um=T_UM, wavelength_um=LAMBDA_UM,
                                         realisations=REALISATIONS, seed=100 + k)
            dense, series = _curve(correlation, sigma, "series")
            paper = None
            if correlation == "exponential" and k == len(SIGMAS) - 1:
                paper = _curve(correlation, sigma, "very_rough")[1]
            curves.append(dict(label=label, document=doc, theta_deg=dense, series=series,
                               paper=paper))
            devs = [r["diffuse_deviation"] for r in doc["results"]]
            table.append((correlation, label, len(devs), max(abs(d) for d in devs),
                          float(np.sqrt(np.mean(np.square(devs))))))
        panels.append((f"{correlation} correlation, T = {T_UM} µm, λ = {LAMBDA_UM} µm", curves))
    name = "simulation_validation.png"
    figure = ""
    try:
        simulation_figures.validation_figure(panels, outdir / name)
        figure = linked_figure(
            name, "simulated against series",
            f"Diffuse power × A/T² at θi = {THETA_I:g}° across the plane of incidence: lines "
            "the exact series (Eq. 2; the exact exponential series), points the Monte Carlo "
            f"({REALISATIONS} surfaces per point, ±2 standard errors). Dashed: the paper's Eq. 5 "
            "at g ≈ 10, which the simulation does not follow.")
    except ImportError:
        pass
    rows = "".join(f"<tr><td class='l'>{escape(c)}</td><td class='l'>{escape(l)}</td><td>{n}</td>"
                   f"<td>{m:.2f}</td><td>{r:.2f}</td></tr>" for c, l, n, m, r in table)
    return figure + ("<table><tr><th class='l'>correlation</th><th class='l'>roughness</th>"
                     "<th>geometries</th><th>max |deviation| (s.e.)</th><th>RMS deviation "
                     f"(s.e.)</th></tr>{rows}</table>")


def _moderately_rough():
    """Exponential correlation at g ≈ 1: simulation against the series and the one-term forms."""
    sigma = 0.045
    theta_s = [0, 20, 40]
    doc = _core.simulate_scatter(THETA_I, theta_s, 0, correlation="exponential", sigma_um=sigma,
                                 T_um=T_UM, wavelength_um=LAMBDA_UM, realisations=200, seed=7)
    out = []
    for r in doc["results"]:
        half = r["patch_um"] / 2
        forms = {}
        for regime in ("slightly_rough", "very_rough", "very_rough_series_limit"):
            p = _core.mean_scattered_power(THETA_I, r["theta_s_deg"], 0, sigma, T_UM,
                                           correlation="exponential", factor="beckmann",
                                           regime=regime, wavelength_um=LAMBDA_UM,
                                           patch_x_um=half, patch_y_um=half)
            forms[regime] = float(np.asarray(p["diffuse"]))
        out.append((r, forms))
    rows = "".join(
        f"<tr><td>{r['theta_s_deg']:g}</td><td>{r['g']:.2f}</td>"
        f"<td>{fmt(r['diffuse'], r['diffuse_stderr'])}</td><td>{r['series_diffuse']:.4g}</td>"
        f"<td>{f['slightly_rough']:.4g}</td><td>{f['very_rough']:.4g}</td>"
        f"<td>{f['very_rough_series_limit']:.4g}</td></tr>" for r, f in out)
    return ("<table><tr><th>θs</th><th>g</th><th>simulated</th><th>exact series</th>"
            "<th>first term</th><th>Eq. 5</th><th>series limit</th></tr>" + rows + "</table>")


def _finite_patch():
    rows = []
    for L in (4, 8, 16, 32):
        cells = []
        for correlation in ("gaussian", "exponential"):
            for layout in ("lattice_aligned", "fixed"):
                r = _core.simulate_scatter(THETA_I, 0, 0, correlation=correlation,
                                           sigma_um=0.06, T_um=T_UM, wavelength_um=LAMBDA_UM,
                                           patch_over_T=L, layout=layout, realisations=150,
                                           seed=11)["results"][0]
                q = r["diffuse"] / r["series_diffuse"]
                e = r["diffuse_stderr"] / r["series_diffuse"]
                cells.append(f"<td>{fmt(q, e, decimals=3)}</td>")
        rows.append(f"<tr><td>{L}</td>{''.join(cells)}</tr>")
    return ("<table><tr><th>L/T</th><th>Gaussian, periodic lattice</th><th>Gaussian, finite "
            "patch</th><th>exponential, periodic lattice</th><th>exponential, finite patch</th>"
            "</tr>" + "".join(rows) + "</table>")


PAIRS = [("30°/45°", 30.0, 45.0), ("45.5°/67.5°", 45.5, 67.5)]
# True σ/T per correlation: the exponential kernel needs a grid that grows like g, so its sweep
# stops at g ≈ 8.
SLOPES = {"gaussian": [0.1, 0.2, 0.4, 0.8, 1.2], "exponential": [0.1, 0.2, 0.4, 0.6]}
T_ESTIMATOR_UM = 0.2
ESTIMATOR_REALISATIONS = 200


def estimator_rows(slopes=None, realisations=ESTIMATOR_REALISATIONS):
    """σ/T from the simulated ratio E1/E2 (camera on the normal, V–H factor, radiance) by Eq. 17
    (Gaussian) and Eq. 19 (exponential), for surfaces of known σ/T (T = 0.2 µm, λ = 0.5 µm).
    `slopes`: {correlation: [σ/T, ...]} (default SLOPES)."""
    slopes = SLOPES if slopes is None else slopes
    rows = []
    for correlation in ("gaussian", "exponential"):
        for k, s in enumerate(slopes[correlation]):
            sigma = s * T_ESTIMATOR_UM
            for label, t1, t2 in PAIRS:
                doc = _core.simulate_scatter([t1, t2], 0, 0, correlation=correlation,
                                             sigma_um=sigma, T_um=T_ESTIMATOR_UM,
                                             wavelength_um=LAMBDA_UM, factor="vh",
                                             realisations=realisations, seed=1000 + k)
                # Off the specular direction the coherent part is 0: the brightness is the
                # diffuse power (per unit area: A differs between the two geometries' grids).
                r1, r2 = doc["results"]
                e1 = r1["diffuse"] * r1["area_um2"]
                e2 = r2["diffuse"] * r2["area_um2"]
                noise = (r1["diffuse_stderr"] / r1["diffuse"], r2["diffuse_stderr"] / r2["diffuse"])
                estimate, stderr, series_estimate = None, None, None
                try:
                    est = _core.estimate_slope(e1 / e2, t1, t2, correlation=correlation,
                                               noise=noise)
                    estimate = est[f"sigma_over_T_{correlation}"]
                    stderr = est[f"sigma_over_T_{correlation}_stderr"]
                except _core.Error:
                    pass
                # The same inversion of the exact series' ratio: the bias without the noise.
                s1 = r1["series_diffuse"] * r1["area_um2"]
                s2 = r2["series_diffuse"] * r2["area_um2"]
                try:
                    series_estimate = _core.estimate_slope(
                        s1 / s2, t1, t2, correlation=correlation)[f"sigma_over_T_{correlation}"]
                except _core.Error:
                    pass
                rows.append(dict(correlation=correlation, pair=label, true=s, g1=r1["g"],
                                 estimate=estimate, stderr=stderr,
                                 series_estimate=series_estimate))
    return rows


def section(outdir):
    """The HTML fragment (figures are written into `outdir`)."""
    from . import simulation_figures

    validation = _validation(outdir)
    rows = estimator_rows()
    name = "simulation_estimators.png"
    figure = ""
    try:
        simulation_figures.estimator_figure(rows, outdir / name)
        figure = linked_figure(
            name, "estimated against true sigma/T",
            "σ/T from the simulated brightness ratio at the paper's two geometry pairs (camera "
            "on the normal), inverted by Eq. 17 (Gaussian) and Eq. 19 (exponential), against "
            f"the σ/T the surfaces were generated with (T = {T_ESTIMATOR_UM} µm, λ = "
            f"{LAMBDA_UM} µm; ±2 standard errors from the simulation's).")
    except ImportError:
        pass
    est_rows = "".join(
        f"<tr><td class='l'>{escape(r['correlation'])}</td><td class='l'>{escape(r['pair'])}</td>"
        f"<td>{r['true']:g}</td><td>{r['g1']:.3g}</td>"
        + (f"<td>{fmt(r['estimate'], r['stderr'], digits=3)}</td>"
           f"<td>{r['estimate'] / r['true'] - 1:+.0%}</td>" if r["estimate"] is not None
           else "<td>no solution</td><td>–</td>")
        + (f"<td>{r['series_estimate']:.3g}</td>" if r["series_estimate"] is not None
           else "<td>no solution</td>")
        + "</tr>" for r in rows)
    return f"""<h2>Ground truth: Monte Carlo Kirchhoff scattering</h2>
<p>The scalar Kirchhoff field ρ = (F/A)∫∫exp(i v·r) dx dy summed on generated surfaces
(docs/simulation.md) and averaged over realisations: the diffuse part ⟨|ρ − ⟨ρ⟩|²⟩ with its
standard error, against the closed forms at the same geometry. Beckmann's F, A the simulated
patch's area.</p>
{validation}
<h3>Moderately rough, exponential correlation (g ≈ 1)</h3>
<p>Neither one-term form holds here; the exact series does (θi = {THETA_I:g}°, φs = 0).</p>
{_moderately_rough()}
<h3>Finite patches</h3>
<p>Simulated over series at θi = {THETA_I:g}°, normal view, g ≈ 2 (T·v_xy = 2π, the lobe's tail):
on the periodic lattice (the infinite-patch integral) and on a finite patch cut from a larger
surface, where the window brings in power from the lobe's centre.</p>
{_finite_patch()}
<h3>Bias of the paper's estimators</h3>
{figure}
<table><tr><th class='l'>correlation</th><th class='l'>θ1/θ2</th><th>true σ/T</th>
<th>g at θ1</th><th>estimated σ/T</th><th>bias</th><th>from the exact series</th></tr>
{est_rows}</table>
<p>Eq. 17 and Eq. 19 assume the very-rough forms: where g at the geometries is small the
simulated ratio leaves their range (no solution) or the estimate is biased.</p>
"""
