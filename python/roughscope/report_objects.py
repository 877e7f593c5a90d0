"""Curved objects and roughness maps in the report (paper §5.2, Fig. 8; §5.1).

* :func:`objects_html` is the part of a measurement's page (``roughscope measure --report``)
  for a cylinder (the brightness profile against incidence angle with Lambert, Eq. 7, 9 and 10,
  the fitted σ/T, where each model leaves the data, Caron's θK), a sphere (its pixels as a BRDF
  table, every model compared) and a roughness map (σ/T and class maps, per-class and per-region
  statistics).
* :func:`section` is the report's section of ``make demo``: the measurements of a synthetic
  cylinder lit from the camera (L = V, as in §5.2), a synthetic sphere lit at 30° and a flat
  sample with three regions of known σ/T (one per class) that
  :func:`roughscope.demo.measure_objects` wrote, set against the truth.
"""

import io
import pathlib

from ._html import embedded_image, escape, fmt, within_two_sigma


# --------------------------------------------------------------------------------------------
# Cylinder (§5.2, Fig. 8)

_MODEL_STYLE = {
    "lambert": dict(linestyle=":", color="#555555"),
    "bk_gaussian": dict(linestyle="-.", color="#e76f51"),
    "vh_gaussian": dict(linestyle="-.", color="#2a9d8f"),
    "vh_exponential": dict(linestyle="--", color="#264653"),
}


def profile_figure_png(cylinder, title=None):
    """PNG bytes of a Fig. 8-style plot: normalised brightness (with ±2 s.e.) against incidence
    angle, the models normalised alike, θK and each model's departure angle marked."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = cylinder["profile"]
    theta = [r["theta_deg"] for r in rows]
    data = [r["brightness"] for r in rows]
    err = [2 * r["stderr"] for r in rows]
    fig, ax = plt.subplots(figsize=(5.2, 3.6), dpi=90)
    ax.errorbar(theta, data, yerr=err, color="black", fmt="o", markersize=3, elinewidth=0.8,
                label="data (±2 s.e.)", zorder=1)
    for m in cylinder["models"]:
        style = _MODEL_STYLE.get(m["model"], {})
        label = m["display_name"]
        if m["sigma_over_T"] is not None:
            label += f", σ/T = {m['sigma_over_T']:.3g}"
        ax.plot(theta, m["prediction"], label=label, zorder=2, **style)
        if m["departure_angle_deg"] is not None:
            ax.axvline(m["departure_angle_deg"], ymax=0.08, color=style.get("color", "grey"),
                       linewidth=2.5)
    if cylinder["theta_K_deg"] is not None:
        ax.axvline(cylinder["theta_K_deg"], color="#999999", linewidth=0.8)
        ax.text(cylinder["theta_K_deg"], 0.02, " θK", color="#777777", fontsize=8)
    ax.set_xlabel("incidence angle θi (°)")
    ax.set_ylabel("normalised brightness")
    ax.set_xlim(0, 90)
    ax.set_ylim(0, 1.15)
    ax.legend(fontsize=7, loc="lower left")
    if title:
        ax.set_title(title, fontsize=9)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    plt.close(fig)
    return buf.getvalue()


def cylinder_html(doc, truth=None):
    cyl = doc["cylinder"]
    axis = cyl["axis"]
    parts = [embedded_image(profile_figure_png(cyl), "brightness profile of the cylinder")]
    rows = []
    for key, label in (("sigma_over_T_gaussian", "σ/T fitted (V–H Gaussian)"),
                       ("sigma_over_T_exponential", "σ/T fitted (V–H exponential)")):
        value, err = cyl[key], cyl[key + "_stderr"]
        cells = f"<td class='l'>{escape(label)}</td><td>{escape(fmt(value, err))}</td>"
        if truth is not None:
            t = truth.get(key)
            cells += f"<td>{escape(fmt(t))}</td><td>{within_two_sigma(value, err, t)}</td>"
        rows.append(f"<tr>{cells}</tr>")
    head = "<tr><th class='l'>quantity</th><th>measured</th>"
    head += "<th>truth</th><th>within 2σ</th></tr>" if truth is not None else "</tr>"
    parts.append(f"<table>{head}{''.join(rows)}</table>")
    dep = ["<tr><th class='l'>model</th><th>σ/T</th><th>r.m.s. difference</th>"
           "<th>leaves the data at θi</th></tr>"]
    for m in cyl["models"]:
        d = m["departure_angle_deg"]
        dep.append(f"<tr><td class='l'>{escape(m['display_name'])}</td><td>{fmt(m['sigma_over_T'])}"
                   f"</td><td>{fmt(m['rms_difference'], digits=3)}</td>"
                   f"<td>{'—' if d is None else escape(fmt(d, digits=3) + '°')}</td></tr>")
    parts.append("<table>" + "".join(dep) + "</table>")
    parts.append(f"<p>Axis {escape(axis['source'])}: radius {axis['radius_px']:.4g} px; "
                 f"{len(cyl['profile'])} bins of {cyl['bin_width_deg']:.3g}° on the "
                 f"{escape(cyl['half'])} half; Caron's θK = "
                 f"{escape(fmt(cyl['theta_K_deg'], digits=3))}°."
                 " A model leaves the data where it differs by more than its departure rule "
                 "(docs/curved-objects.md).</p>")
    return "\n".join(parts)


# --------------------------------------------------------------------------------------------
# Sphere

def sphere_html(doc, truth=None):
    sph = doc["sphere"]
    comp = sph["comparison"]
    winner = comp.get("winner")
    rows = ["<tr><th class='l'>model</th><th>parameters</th><th>gain SSE</th>"
            "<th>r.m.s.</th></tr>"]
    for name, m in comp["models"].items():
        if not m["available"]:
            continue
        errs = m.get("standard_errors") or {}
        params = ", ".join(f"{k} = {fmt(v, errs.get(k))}"
                           for k, v in (m.get("parameters") or {}).items() if k != "gain")
        mark = " ★" if name == winner else ""
        rows.append(f"<tr><td class='l'>{escape(m['label'] + mark)}</td>"
                    f"<td class='l'>{escape(params)}"
                    f"</td><td>{fmt(m.get('sse_gain'), digits=3)}</td>"
                    f"<td>{fmt(m.get('rmse'), digits=3)}</td></tr>")
    circle = sph.get("circle") or {}
    text = (f"<p>Circle centre ({fmt(circle.get('centre_x_px'))}, "
            f"{fmt(circle.get('centre_y_px'))}) px, radius {fmt(circle.get('radius_px'))} px; "
            f"{sph['rows']} table rows from the lit and seen pixels; best model (lowest gain "
            f"SSE, ★): {escape(winner or '–')}.")
    if truth:
        text += f" Truth: {escape(truth)}."
    return text + "</p><table>" + "".join(rows) + "</table>"


# --------------------------------------------------------------------------------------------
# Maps

def map_figures(names, staged=None, maps_dir=None):
    """The embedded PNGs of the map files `names` that exist: `roughscope measure --maps DIR
    --report ...` hands them over before they are committed ("staged_files": name → temporary
    file), otherwise they are read from `maps_dir`."""
    staged = staged or {}
    figures = []
    for name in names:
        if name in staged:
            path = pathlib.Path(staged[name])
        elif maps_dir:
            path = pathlib.Path(maps_dir) / name
        else:
            continue
        if path.is_file():
            figures.append(embedded_image(path.read_bytes(), name))
    return figures


def map_html(doc, maps_dir=None, truth=None):
    m = doc["map"]
    parts = [f"<p>{m['width']} × {m['height']} map (window {m['window_px']} px, "
             f"{escape(m['method'])}): {m['valid']} valid, {m['missing']} missing, "
             f"{m['no_solution']} without a solution.</p>"]
    reg = m.get("registration")
    if reg:
        parts.append(f"<p>Registration of the pair (phase correlation): shift "
                     f"({reg['shift_x_px']:.3g}, {reg['shift_y_px']:.3g}) px, response "
                     f"{reg['response']:.3g}.</p>")
    # `roughscope measure --maps DIR --report ...` hands over the map files before they are
    # committed: "staged_files" maps each name to its temporary file.
    figures = map_figures(("sigma_over_T_gaussian.png", "roughness_class.png"),
                          m.get("staged_files"), maps_dir)
    if figures:
        parts.append("<figure>" + " ".join(figures) + "<figcaption>σ/T (Gaussian, Eq. 17) "
                     "per tile and the class map (slightly, moderately, very rough by σ/T, "
                     "docs/maps.md).</figcaption></figure>")
    rows = ["<tr><th class='l'>class</th><th>tiles</th><th>fraction</th><th>mean σ/T</th></tr>"]
    for c in m["classes"]:
        rows.append(f"<tr><td class='l'>{escape(c['roughness_class'].replace('_', ' '))}</td>"
                    f"<td>{c['count']}</td><td>{100 * c['fraction']:.1f} %</td>"
                    f"<td>{escape(fmt(c['mean_sigma_over_T'], c['mean_sigma_over_T_stderr']))}"
                    "</td></tr>")
    parts.append("<table>" + "".join(rows) + "</table>")
    if m["regions"]:
        head = "<tr><th class='l'>region</th><th>tiles</th><th>σ/T (Gaussian)</th>"
        head += "<th>truth</th><th>within 2σ</th></tr>" if truth else "</tr>"
        rows = [head]
        for r in m["regions"]:
            value, err = r["sigma_over_T_gaussian"], r["sigma_over_T_gaussian_stderr"]
            cells = (f"<td class='l'>{escape(r['name'])}</td><td>{r['count']}</td>"
                     f"<td>{escape(fmt(value, err))}</td>")
            if truth:
                t = truth.get(r["name"])
                cells += (f"<td>{escape(fmt(t))}</td>"
                          f"<td>{within_two_sigma(value, err, t)}</td>")
            rows.append(f"<tr>{cells}</tr>")
        parts.append("<table>" + "".join(rows) + "</table>")
    return "\n".join(parts)


def photometric_stereo_html(doc, maps_dir=None):
    """The photometric-stereo part: counts, lights, model comparison and, when the files were
    written (--maps), the normal map and the σ/T map (docs/photometric-stereo.md)."""
    ps = doc["photometric_stereo"]
    px = ps["pixels"]
    parts = [f"<p>Model <code>{escape(ps['model'])}</code>, {len(ps['lights'])} lights: "
             f"{px['valid']} of {px['object']} object pixels have a normal "
             f"({px['too_few_lights']} lit by fewer than 3 usable lights, {px['no_solution']} "
             f"without a solution); {ps['highlights_removed']} highlight values left out; "
             f"median residual {fmt(ps['median_residual'])} of the albedo.</p>"]
    comparison = ps.get("model_comparison")
    if comparison:
        parts.append(f"<p>Median σ/T {fmt(ps['median_sigma_over_T'])}. The rough model explains "
                     f"{comparison['rough_better_pixels']} of {comparison['compared_pixels']} "
                     f"pixels better than Lambert (median ΔAIC "
                     f"{fmt(comparison['median_delta_aic'])}).</p>")
    names = ["normals.png"] + [n for n in ps.get("files", [])
                               if n.endswith(".png") and n != "normals.png"]
    figures = map_figures(names, ps.get("staged_files"), maps_dir or ps.get("directory"))
    if figures:
        parts.append("<figure>" + " ".join(figures) + "<figcaption>The normals (colour "
                     "(n + 1)/2: x red, y green, z blue; grey where none) and, for a rough "
                     "model, σ/T and its class per pixel.</figcaption></figure>")
    return "\n".join(parts)


def objects_html(doc, maps_dir=None, truth=None):
    """The curved-object and map parts of one measurement document ('' when it has none)."""
    parts = []
    if doc.get("cylinder"):
        parts.append("<h4>Cylinder profile (§5.2)</h4>" + cylinder_html(doc, truth))
    if doc.get("sphere"):
        parts.append("<h4>Sphere: its pixels as a BRDF table</h4>" + sphere_html(doc, truth))
    if doc.get("map"):
        maps_dir = maps_dir or doc["map"].get("directory")
        parts.append("<h4>Roughness map (§5.1)</h4>" + map_html(doc, maps_dir, truth))
    if doc.get("photometric_stereo"):
        parts.append("<h4>Photometric stereo: the object's normals</h4>" +
                     photometric_stereo_html(doc, maps_dir))
    return "\n".join(parts)


def section(measured):
    """The report's section on curved objects and maps: `measured` is
    roughscope.demo.measure_objects' dict of {document, truth} per object."""
    parts = ["<h2>Curved objects and roughness maps</h2>",
             "<p>§5.2 of the paper measures brightness across a rough cylinder lit from the camera "
             "and compares it with Lambert and Eq. 7, 9, 10 (Fig. 8); §5.1 proposes classifying "
             "the parts of an object as slightly, moderately or very rough. Here each is run on "
             "synthetic photographs of known truth (docs/simulation-captures.md; 14-bit linear "
             "TIFF, shot and read noise) with <code>roughscope measure</code> "
             "(docs/curved-objects.md, docs/maps.md). The synthetic data follow the V–H model "
             "by construction, so the V–H curves should follow them; Lambert and the original "
             "B–K (Eq. 7) leave them at large angles.</p>"]
    cylinder, sphere, flat = measured["cylinder"], measured["sphere"], measured["map"]
    parts.append("<h3>A cylinder, L = V</h3>")
    parts.append(cylinder_html(cylinder["document"], cylinder["truth"]))
    parts.append("<h3>A sphere lit at 30°</h3>")
    parts.append(sphere_html(sphere["document"], sphere["truth"]))
    parts.append("<h3>A flat sample with three regions</h3>")
    parts.append(map_html(flat["document"], flat["maps_dir"], flat["truth"]))
    return "\n".join(parts)
