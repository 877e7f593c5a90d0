"""Figures of the Kirchhoff Monte Carlo (docs/simulation.md): simulated diffuse power with its
standard errors against the closed forms, and σ/T estimated from simulated brightness against
the truth. Inputs are the documents of :func:`roughscope.simulate_scatter` (``roughscope simulate
scatter --json``). Figures are written atomically; matplotlib is imported only here.
"""

import numpy as np

from ._plotting import pyplot, save


def signed_theta_s(result):
    """θs with the sign of the side: + in the specular half-plane (φs = 0), − towards the light
    (φs = 180°); other azimuths are drawn on the + side."""
    return -result["theta_s_deg"] if abs(result["phi_s_deg"] - 180.0) < 1e-9 else \
        result["theta_s_deg"]


def validation_figure(panels, out):
    """One panel per correlation: ``panels`` is a list of (title, curves) with curves a list of
    dicts {label, document, theta_deg (dense θs grid, signed), series (D·A/T² on that grid),
    paper (optional: the paper's very-rough form on that grid)}. Points: D·A/T² with ±2 standard
    errors from the document's results."""
    plt = pyplot()
    fig, axes = plt.subplots(1, len(panels), figsize=(6.2 * len(panels), 4.6), dpi=110,
                             squeeze=False)
    colours = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e"]
    for ax, (title, curves) in zip(axes[0], panels):
        for colour, c in zip(colours, curves):
            T2 = c["document"]["options"]["T_um"] ** 2
            results = c["document"]["results"]
            x = np.array([signed_theta_s(r) for r in results])
            y = np.array([r["diffuse"] * r["area_um2"] / T2 for r in results])
            e = np.array([2 * r["diffuse_stderr"] * r["area_um2"] / T2 for r in results])
            ax.plot(c["theta_deg"], c["series"], color=colour, lw=1.4,
                    label=f"{c['label']}: exact series")
            if c.get("paper") is not None:
                ax.plot(c["theta_deg"], c["paper"], color=colour, lw=1.0, ls="--",
                        label=f"{c['label']}: paper's very-rough form")
            ax.errorbar(x, y, yerr=e, fmt="o", ms=3.5, color=colour, capsize=2,
                        label=f"{c['label']}: simulated (±2 s.e.)")
        ax.set_yscale("log")
        ax.set_xlabel("θs (deg; < 0 towards the light), θi = 30°")
        ax.set_ylabel("diffuse power × A/T²")
        ax.set_title(title)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="lower center")
    fig.tight_layout()
    save(fig, out)
    plt.close(fig)


def estimator_figure(rows, out):
    """σ/T estimated from simulated brightness ratios against the true σ/T. ``rows``: dicts
    {correlation, pair (label), true, estimate (or None), stderr, series_estimate (or None)}."""
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4), dpi=110)
    markers = {"30°/45°": "o", "45.5°/67.5°": "s"}
    for ax, corr in zip(axes, ["gaussian", "exponential"]):
        sub = [r for r in rows if r["correlation"] == corr and r["estimate"] is not None]
        lo = min(r["true"] for r in rows) / 1.5
        hi = max([r["true"] for r in rows]) * 1.3
        ax.plot([lo, hi], [lo, hi], color="#555", lw=1, label="estimate = truth")
        for pair, marker in markers.items():
            exact = [r for r in rows if r["correlation"] == corr and r["pair"] == pair
                     and r.get("series_estimate") is not None]
            if exact:
                ax.plot([r["true"] for r in exact], [r["series_estimate"] for r in exact],
                        ls=":", marker=marker, mfc="none", color="#777", ms=5,
                        label=f"{pair}: from the exact series (no noise)")
            pts = [r for r in sub if r["pair"] == pair]
            if not pts:
                continue
            ax.errorbar([r["true"] for r in pts], [r["estimate"] for r in pts],
                        yerr=[2 * r["stderr"] for r in pts], fmt=marker, ms=4, capsize=2,
                        label=f"θ1/θ2 = {pair} (±2 s.e.)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("true σ/T")
        ax.set_ylabel(f"estimated σ/T ({'Eq. 17' if corr == 'gaussian' else 'Eq. 19'})")
        ax.set_title(f"{corr} correlation")
        ax.grid(True, alpha=0.3, which="both")
        ax.legend(fontsize=8)
    fig.tight_layout()
    save(fig, out)
    plt.close(fig)
