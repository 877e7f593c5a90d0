"""Report section: roughness estimation (paper §4, Tables 1–3).

Recomputes the paper's Tables 1, 2 and 3 from their printed inputs with the §4 estimators of the
compiled module and shows them next to the printed values (read from
../shared/reference/paper-tables.json, never copied into the repository). Each recomputed value is
marked "=" (same at the printed digits), "≈" (explained by the rounding of the printed inputs:
the printed value lies in the range the recomputation spans over the inputs' rounding intervals)
or "≠". A figure shows σ/T against E1/E2 for the Table 2 geometry with the valid ranges of Eq. 17
and Eq. 19 and the Table 2 surfaces.
"""

import json
from pathlib import Path

from . import _core
from ._html import escape, linked_figure


def find_paper_tables():
    """Path of paper-tables.json, or None (the library's locator, io/data_locator.hpp:
    $ROUGHSCOPE_SHARED_DIR, else ../shared upward from the working directory and from where this
    package lives)."""
    return _core.paper_tables_path([Path(__file__).resolve().parent])


_MARKS = {"exact": "=", "within_rounding": "≈", "differs": "≠"}


def _entry(check):
    """(printed, recomputed, mark, lo, hi) of one checked quantity of the library's document."""
    lo, hi = check["rounding_interval"]
    return (check["printed"], check["recomputed"], _MARKS[check["agreement"]], lo, hi)


def recompute_tables(tables):
    """The three tables recomputed by the library (``_core.recompute_paper_tables``, the same
    document as ``roughscope paper tables --json``): dict of lists of row dicts whose checked
    quantities are (printed, recomputed, mark, lo, hi) tuples (used by the report and tests)."""
    doc = _core.recompute_paper_tables(tables)
    out = {}
    for key in ("table1", "table2", "table3"):
        out[key] = [{k: (_entry(v) if isinstance(v, dict) else v) for k, v in row.items()}
                    for row in doc[key]["rows"]]
    return out


def _cell(entry, digits):
    printed, value, mark, _lo, _hi = entry
    cls = {"=": "ok", "≈": "near", "≠": "bad"}[mark]
    return (f"<td>{printed:.{digits}f}</td><td class='{cls}'>{value:.{digits + 1}f} "
            f"{escape(mark)}</td>")


def _figure(tables, outdir):
    """σ/T vs E1/E2 at the Table 2 geometry; returns the file name or None without matplotlib."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        import numpy as np
    except ImportError:
        return None
    t = tables["table2_very_rough"]
    t1, t2 = t["conditions"]["theta1_deg"], t["conditions"]["theta2_deg"]
    lo_g, _ = _core.ratio_range_gaussian(t1, t2)
    lo_e, hi_e = _core.ratio_range_exponential(t1, t2)
    r = np.linspace(lo_g * 1.002, 1.3, 400)
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.plot(r, _core.sigma_over_T_gaussian(r, t1, t2), label="Gaussian (Eq. 17)")
    ax.plot(r, _core.sigma_over_T_exponential(r, t1, t2), label="exponential (Eq. 19)")
    rows = t["rows"]
    ax.plot([x["E1_over_E2"] for x in rows], [x["sigma_over_T_G"] for x in rows], "o",
            color="C0", label="Table 2, σ/T_G (printed)")
    ax.plot([x["E1_over_E2"] for x in rows], [x["sigma_over_T_E"] for x in rows], "s",
            color="C1", label="Table 2, σ/T_E (printed)")
    ax.axvline(lo_g, color="0.5", ls=":", lw=1)
    ax.set_xlabel(f"E1/E2 (θ1 = {t1:g}°, θ2 = {t2:g}°, viewer on the normal, F_VH)")
    ax.set_ylabel("σ/T")
    ax.set_ylim(0, 4)
    ax.set_title(f"valid ratios: Eq. 17 > {lo_g:.4f}; Eq. 19 in ({lo_e:.4f}, {hi_e:.4f})",
                 fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    name = "estimation_slope_vs_ratio.png"
    fig.savefig(Path(outdir) / name, dpi=110)
    plt.close(fig)
    return name


def section(outdir):
    """Return the HTML fragment for the report (the figure is written into outdir)."""
    outdir = Path(outdir)
    head = "<h2>Roughness estimation (paper §4, Tables 1–3)</h2>\n"
    path = find_paper_tables()
    if path is None:
        return (head + "<p><em>Skipped: the paper's printed tables were not found "
                "(../shared/reference/paper-tables.json beside the project, or set "
                "ROUGHSCOPE_SHARED_DIR).</em></p>\n")
    with open(path, encoding="utf-8") as f:
        tables = json.load(f)
    rec = recompute_tables(tables)
    parts = [head,
             "<p>Each table is recomputed from the paper's printed inputs with the §4 estimators "
             "(Eq. 13, 15, 17, 19; λ = 0.555 µm, R0 = 1, F_VH) and shown next to the printed "
             "value: <b>=</b> same at the printed digits, <b>≈</b> explained by the rounding of "
             "the printed inputs, <b>≠</b> not explained. Command line: "
             "<code>roughscope paper tables</code>.</p>\n"]
    parts.append("<h3>Table 1 — slightly rough surfaces (σ from R_spec at 14°, T from the "
                 "printed σ and E1/E2 at 30°/45°)</h3>\n<table><tr><th>surface</th><th>R_spec</th>"
                 "<th>σ (µm)</th><th>recomputed</th><th>E1/E2</th><th>T (µm)</th>"
                 "<th>recomputed</th><th>σ/T</th><th>recomputed</th></tr>\n")
    for row in rec["table1"]:
        parts.append(f"<tr><td>{escape(row['surface'])}</td><td>{row['R_spec']:.3f}</td>"
                     f"{_cell(row['sigma_um'], 3)}<td>{row['E1_over_E2']:.3f}</td>"
                     f"{_cell(row['T_um'], 3)}{_cell(row['sigma_over_T'], 3)}</tr>\n")
    parts.append("</table>\n<p>Porcelain and plastic: σ from the printed R_spec = 0.003 and "
                 "0.002 is 0.1097 and 0.1135 µm; the printed 0.109 and 0.115 correspond to "
                 "R_spec ≈ 0.0032 and 0.0017, inside the rounding interval of the printed "
                 "R_spec. Note that g = σ²v_z² ≈ 3–4 at these geometries: the surfaces are "
                 "moderately rough by the g criterion, so Eq. 3 (g ≪ 1) is stretched.</p>\n")
    parts.append("<h3>Table 2 — very rough surfaces (E1/E2 at 30°/45°)</h3>\n<table><tr>"
                 "<th>surface</th><th>E1/E2</th><th>σ/T_G</th><th>recomputed</th><th>σ/T_E</th>"
                 "<th>recomputed</th><th>θK (°)</th><th>recomputed</th><th>ξK (%)</th>"
                 "<th>recomputed</th></tr>\n")
    for row in rec["table2"]:
        parts.append(f"<tr><td>{escape(row['surface'])}</td><td>{row['E1_over_E2']:.3f}</td>"
                     f"{_cell(row['sigma_over_T_G'], 4)}{_cell(row['sigma_over_T_E'], 4)}"
                     f"{_cell(row['theta_K_deg'], 0)}{_cell(row['xi_K_percent'], 1)}</tr>\n")
    parts.append("</table>\n<p>E1/E2 is printed to 3 decimals, which moves σ/T by up to ~0.03: "
                 "the printed slopes were computed from unrounded ratios. θK and ξK follow from "
                 "the printed σ/T_G to every printed digit.</p>\n")
    parts.append("<h3>Table 3 — CUReT samples (E1/E2 at 45°/67.5°)</h3>\n<table><tr>"
                 "<th>sample</th><th>E1/E2</th><th>σ/T_G</th><th>recomputed</th><th>σ/T_E</th>"
                 "<th>recomputed</th></tr>\n")
    for row in rec["table3"]:
        parts.append(f"<tr><td>{escape(row['sample'])}</td><td>{row['E1_over_E2']:.6f}</td>"
                     f"{_cell(row['sigma_over_T_G'], 4)}{_cell(row['sigma_over_T_E'], 4)}</tr>\n")
    parts.append("</table>\n<p>The text of §5.3 gives θ1 = 45.5° for CUReT measurement 81, but "
                 "the printed slopes are reproduced to all four digits only with θ1 = 45°.</p>\n")
    outdir.mkdir(parents=True, exist_ok=True)
    name = _figure(tables, outdir)
    if name:
        parts.append(linked_figure(name, "sigma/T against E1/E2",
                                   "σ/T from the brightness ratio (Eq. 17, 19) with the printed "
                                   "Table 2 values.") + "\n")
    return "".join(parts)
