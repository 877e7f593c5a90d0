"""Report section: roughness estimation (paper §4, Tables 1–3).

Recomputes the paper's Tables 1, 2 and 3 from their printed inputs with the §4 estimators of the
compiled module and shows them next to the printed values (read from
../shared/reference/paper-tables.json, never copied into the repository). Each recomputed value is
marked "=" (same at the printed digits), "≈" (explained by the rounding of the printed inputs:
the printed value lies in the range the recomputation spans over the inputs' rounding intervals)
or "≠". A figure shows σ/T against E1/E2 for the Table 2 geometry with the valid ranges of Eq. 17
and Eq. 19 and the Table 2 surfaces.
"""

import html
import itertools
import json
import math
from pathlib import Path

from . import _core


def _e(text):
    return html.escape(str(text))


def find_paper_tables():
    """Path of paper-tables.json, or None (the library's locator, io/data_locator.hpp:
    $ROUGHSCOPE_SHARED_DIR, else ../shared upward from the working directory and from where this
    package lives)."""
    return _core.paper_tables_path([Path(__file__).resolve().parent])


def _check(printed, decimals, inputs, input_decimals, f):
    """(recomputed, mark, lo, hi): f at the printed inputs and over their rounding box."""
    value = f(*inputs)
    lo = hi = value
    for signs in itertools.product((-1.0, 1.0), repeat=len(inputs)):
        x = [v + s * 0.5 * 10.0 ** -d for v, s, d in zip(inputs, signs, input_decimals)]
        try:
            y = f(*x)
        except ValueError:
            continue
        lo, hi = min(lo, y), max(hi, y)
    h = 0.5 * 10.0 ** -decimals
    if round(value * 10**decimals) == round(printed * 10**decimals):
        mark = "="
    elif lo - h <= printed <= hi + h:
        mark = "≈"
    else:
        mark = "≠"
    return value, mark, lo, hi


def recompute_tables(tables):
    """The three tables recomputed: dict of lists of row dicts (used by the report and tests)."""
    out = {"table1": [], "table2": [], "table3": []}
    t = tables["table1_slightly_rough"]
    c = t["conditions"]
    th, t1, t2, lam = c["specular_theta_deg"], c["theta1_deg"], c["theta2_deg"], c["lambda_um"]

    def T_of(s, r):
        return _core.correlation_length_from_ratio(r, s, t1, t2, lam)

    for row in t["rows"]:
        s, r = row["sigma_um"], row["E1_over_E2"]
        out["table1"].append({
            "surface": row["surface"], "R_spec": row["R_spec"], "E1_over_E2": r,
            "sigma_um": (row["sigma_um"], *_check(row["sigma_um"], 3, [row["R_spec"]], [3],
                                                  lambda R: _core.sigma_from_specular(R, th, lam))),
            "T_um": (row["T_um"], *_check(row["T_um"], 3, [s, r], [3, 3], T_of)),
            "sigma_over_T": (row["sigma_over_T"],
                             *_check(row["sigma_over_T"], 3, [s, r], [3, 3],
                                     lambda a, b: a / T_of(a, b))),
        })
    t = tables["table2_very_rough"]
    t1, t2 = t["conditions"]["theta1_deg"], t["conditions"]["theta2_deg"]
    for row in t["rows"]:
        r, sG = row["E1_over_E2"], row["sigma_over_T_G"]
        out["table2"].append({
            "surface": row["surface"], "E1_over_E2": r,
            "sigma_over_T_G": (sG, *_check(sG, 4, [r], [3],
                                           lambda x: _core.sigma_over_T_gaussian(x, t1, t2))),
            "sigma_over_T_E": (row["sigma_over_T_E"],
                               *_check(row["sigma_over_T_E"], 4, [r], [3],
                                       lambda x: _core.sigma_over_T_exponential(x, t1, t2))),
            "theta_K_deg": (row["theta_K_deg"],
                            *_check(row["theta_K_deg"], 0, [sG], [4],
                                    lambda s: 90 - math.degrees(math.atan(math.sqrt(2) * s)))),
            "xi_K_percent": (row["xi_K_percent"],
                             *_check(row["xi_K_percent"], 1, [sG], [4],
                                     lambda s: 100 * (1 - math.exp(-1 / (4 * s * s))))),
        })
    t = tables["table3_curet_parameters"]
    t1, t2 = t["conditions"]["theta1_deg"], t["conditions"]["theta2_deg"]
    for row in t["rows"]:
        r = row["E1_over_E2"]
        out["table3"].append({
            "sample": f'{row["name"]} ({row["sample"]})', "E1_over_E2": r,
            "sigma_over_T_G": (row["sigma_over_T_G"],
                               *_check(row["sigma_over_T_G"], 4, [r], [6],
                                       lambda x: _core.sigma_over_T_gaussian(x, t1, t2))),
            "sigma_over_T_E": (row["sigma_over_T_E"],
                               *_check(row["sigma_over_T_E"], 4, [r], [6],
                                       lambda x: _core.sigma_over_T_exponential(x, t1, t2))),
        })
    return out


def _cell(entry, digits):
    printed, value, mark, _lo, _hi = entry
    cls = {"=": "ok", "≈": "near", "≠": "bad"}[mark]
    return (f"<td>{printed:.{digits}f}</td><td class='{cls}'>{value:.{digits + 1}f} "
            f"{_e(mark)}</td>")


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
        parts.append(f"<tr><td>{_e(row['surface'])}</td><td>{row['R_spec']:.3f}</td>"
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
        parts.append(f"<tr><td>{_e(row['surface'])}</td><td>{row['E1_over_E2']:.3f}</td>"
                     f"{_cell(row['sigma_over_T_G'], 4)}{_cell(row['sigma_over_T_E'], 4)}"
                     f"{_cell(row['theta_K_deg'], 0)}{_cell(row['xi_K_percent'], 1)}</tr>\n")
    parts.append("</table>\n<p>E1/E2 is printed to 3 decimals, which moves σ/T by up to ~0.03: "
                 "the printed slopes were computed from unrounded ratios. θK and ξK follow from "
                 "the printed σ/T_G to every printed digit.</p>\n")
    parts.append("<h3>Table 3 — CUReT samples (E1/E2 at 45°/67.5°)</h3>\n<table><tr>"
                 "<th>sample</th><th>E1/E2</th><th>σ/T_G</th><th>recomputed</th><th>σ/T_E</th>"
                 "<th>recomputed</th></tr>\n")
    for row in rec["table3"]:
        parts.append(f"<tr><td>{_e(row['sample'])}</td><td>{row['E1_over_E2']:.6f}</td>"
                     f"{_cell(row['sigma_over_T_G'], 4)}{_cell(row['sigma_over_T_E'], 4)}</tr>\n")
    parts.append("</table>\n<p>The text of §5.3 gives θ1 = 45.5° for CUReT measurement 81, but "
                 "the printed slopes are reproduced to all four digits only with θ1 = 45°.</p>\n")
    outdir.mkdir(parents=True, exist_ok=True)
    name = _figure(tables, outdir)
    if name:
        parts.append(f"<figure><img src='{_e(name)}' alt='sigma/T against E1/E2'>"
                     "<figcaption>σ/T from the brightness ratio (Eq. 17, 19) with the printed "
                     "Table 2 values.</figcaption></figure>\n")
    return "".join(parts)
