"""Curved objects and roughness maps in the report (paper §5.2, Fig. 8; §5.1).

* :func:`objects_html` is the part of a measurement's page (``roughscope measure --report``)
  for a cylinder (the brightness profile against incidence angle with Lambert, Eq. 7, 9 and 10,
  the fitted σ/T, where each model leaves the data, Caron's θK), a sphere (its pixels as a BRDF
  table, every model compared) and a roughness map (σ/T and class maps, per-class and per-region
  statistics).
* :func:`section` is the report's section of ``make demo``: a synthetic cylinder lit from the
  camera (L = V, as in §5.2), a synthetic sphere lit at 30° and a flat sample with three regions
  of known σ/T (one per class), each written as photographs, measured with ``roughscope measure``
  and set against the truth.
"""

import io
import json
import math
import os
import pathlib
import subprocess

from . import _core
from .report_measure import _e, _fmt, _img_tag


def _pass(good):
    return f"<span class='{'pass' if good else 'fail'}'>{'yes' if good else 'no'}</span>"


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
    parts = [_img_tag(profile_figure_png(cyl), "brightness profile of the cylinder")]
    rows = []
    for key, label in (("sigma_over_T_gaussian", "σ/T fitted (V–H Gaussian)"),
                       ("sigma_over_T_exponential", "σ/T fitted (V–H exponential)")):
        value, err = cyl[key], cyl[key + "_stderr"]
        cells = f"<td class='l'>{_e(label)}</td><td>{_e(_fmt(value, err))}</td>"
        if truth is not None:
            t = truth.get(key)
            ok = _pass(abs(value - t) <= 2 * err) if (t is not None and value is not None
                                                     and err) else ""
            cells += f"<td>{_e(_fmt(t))}</td><td>{ok}</td>"
        rows.append(f"<tr>{cells}</tr>")
    head = "<tr><th class='l'>quantity</th><th>measured</th>"
    head += "<th>truth</th><th>within 2σ</th></tr>" if truth is not None else "</tr>"
    parts.append(f"<table>{head}{''.join(rows)}</table>")
    dep = ["<tr><th class='l'>model</th><th>σ/T</th><th>r.m.s. difference</th>"
           "<th>leaves the data at θi</th></tr>"]
    for m in cyl["models"]:
        d = m["departure_angle_deg"]
        dep.append(f"<tr><td class='l'>{_e(m['display_name'])}</td><td>{_fmt(m['sigma_over_T'])}"
                   f"</td><td>{_fmt(m['rms_difference'], digits=3)}</td>"
                   f"<td>{'—' if d is None else _e(_fmt(d, digits=3) + '°')}</td></tr>")
    parts.append("<table>" + "".join(dep) + "</table>")
    parts.append(f"<p>Axis {_e(axis['source'])}: radius {axis['radius_px']:.4g} px; "
                 f"{len(cyl['profile'])} bins of {cyl['bin_width_deg']:.3g}° on the "
                 f"{_e(cyl['half'])} half; Caron's θK = {_e(_fmt(cyl['theta_K_deg'], digits=3))}°."
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
        params = ", ".join(f"{k} = {_fmt(v, errs.get(k))}"
                           for k, v in (m.get("parameters") or {}).items() if k != "gain")
        mark = " ★" if name == winner else ""
        rows.append(f"<tr><td class='l'>{_e(m['label'] + mark)}</td><td class='l'>{_e(params)}"
                    f"</td><td>{_fmt(m.get('sse_gain'), digits=3)}</td>"
                    f"<td>{_fmt(m.get('rmse'), digits=3)}</td></tr>")
    circle = sph.get("circle") or {}
    text = (f"<p>Circle centre ({_fmt(circle.get('centre_x_px'))}, "
            f"{_fmt(circle.get('centre_y_px'))}) px, radius {_fmt(circle.get('radius_px'))} px; "
            f"{sph['rows']} table rows from the lit and seen pixels; best model (lowest gain "
            f"SSE, ★): {_e(winner or '–')}.")
    if truth:
        text += f" Truth: {_e(truth)}."
    return text + "</p><table>" + "".join(rows) + "</table>"


# --------------------------------------------------------------------------------------------
# Maps

def map_html(doc, maps_dir=None, truth=None):
    m = doc["map"]
    parts = [f"<p>{m['width']} × {m['height']} map (window {m['window_px']} px, "
             f"{_e(m['method'])}): {m['valid']} valid, {m['missing']} missing, "
             f"{m['no_solution']} without a solution.</p>"]
    reg = m.get("registration")
    if reg:
        parts.append(f"<p>Registration of the pair (phase correlation): shift "
                     f"({reg['shift_x_px']:.3g}, {reg['shift_y_px']:.3g}) px, response "
                     f"{reg['response']:.3g}.</p>")
    # `roughscope measure --maps DIR --report ...` hands over the map files before they are
    # committed: "staged_files" maps each name to its temporary file.
    staged = m.get("staged_files") or {}
    if maps_dir or staged:
        figures = []
        for name in ("sigma_over_T_gaussian.png", "roughness_class.png"):
            path = pathlib.Path(staged[name]) if name in staged else pathlib.Path(maps_dir) / name
            if path.is_file():
                figures.append(_img_tag(path.read_bytes(), name))
        if figures:
            parts.append("<figure>" + " ".join(figures) + "<figcaption>σ/T (Gaussian, Eq. 17) "
                         "per tile and the class map (slightly, moderately, very rough by σ/T, "
                         "docs/maps.md).</figcaption></figure>")
    rows = ["<tr><th class='l'>class</th><th>tiles</th><th>fraction</th><th>mean σ/T</th></tr>"]
    for c in m["classes"]:
        rows.append(f"<tr><td class='l'>{_e(c['roughness_class'].replace('_', ' '))}</td>"
                    f"<td>{c['count']}</td><td>{100 * c['fraction']:.1f} %</td>"
                    f"<td>{_e(_fmt(c['mean_sigma_over_T'], c['mean_sigma_over_T_stderr']))}</td></tr>")
    parts.append("<table>" + "".join(rows) + "</table>")
    if m["regions"]:
        head = "<tr><th class='l'>region</th><th>tiles</th><th>σ/T (Gaussian)</th>"
        head += "<th>truth</th><th>within 2σ</th></tr>" if truth else "</tr>"
        rows = [head]
        for r in m["regions"]:
            value, err = r["sigma_over_T_gaussian"], r["sigma_over_T_gaussian_stderr"]
            cells = (f"<td class='l'>{_e(r['name'])}</td><td>{r['count']}</td>"
                     f"<td>{_e(_fmt(value, err))}</td>")
            if truth:
                t = truth.get(r["name"])
                ok = _pass(abs(value - t) <= 2 * err) if (t is not None and value is not None
                                                         and err) else ""
                cells += f"<td>{_e(_fmt(t))}</td><td>{ok}</td>"
            rows.append(f"<tr>{cells}</tr>")
        parts.append("<table>" + "".join(rows) + "</table>")
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
    return "\n".join(parts)


# --------------------------------------------------------------------------------------------
# The demo

DEMO_ELECTRONS = 20000.0
DEMO_FULL_WELL = 60000.0
DEMO_BITS = 14
DEMO_BLACK = 64.0
CYLINDER_SIGMA_OVER_T = 0.71   # a sandpaper of Table 2 (V–H Gaussian)
SPHERE_SIGMA_OVER_T = 0.5
MAP_REGIONS = (("slightly rough", 0.2), ("moderately rough", 1.0), ("very rough", 4.0))
MAP_SIZE = 256
MAP_WINDOW_PX = 16


def _camera():
    gain = 1.05 * (2.0 ** DEMO_BITS - 1.0 - DEMO_BLACK) / DEMO_FULL_WELL
    return dict(bits=DEMO_BITS, response="linear", electrons_per_unit_s=DEMO_ELECTRONS,
                full_well_e=DEMO_FULL_WELL, black_level=DEMO_BLACK, gain=gain,
                keep_geometry=False)


def _exposure(peak_brightness, fill=0.6):
    return fill * DEMO_FULL_WELL / (DEMO_ELECTRONS * peak_brightness)


def _peak(**scene):
    scene = dict(scene, width=64, height=64)
    out = _core.render_capture(shot_noise=False, **scene)
    return float(out["radiance"].max())


def run_cli(capture_file, maps_dir=None):
    """``roughscope measure CAPTURE --json [--maps DIR]`` with $ROUGHSCOPE_CLI (make demo sets
    it), else the module (one library behind both; the map files are then not written)."""
    cli = os.environ.get("ROUGHSCOPE_CLI")
    if not cli:
        return _core.measure(str(capture_file))
    args = [cli, "measure", str(capture_file), "--json"]
    if maps_dir is not None:
        args += ["--maps", str(maps_dir)]
    proc = subprocess.run(args, capture_output=True, text=True, timeout=600)
    if proc.returncode != 0:
        raise RuntimeError(f"roughscope measure {capture_file}: {proc.stderr.strip()}")
    return json.loads(proc.stdout)


def write_cylinder_demo(folder):
    """A cylinder lit from the camera (L = V = +z), V–H Gaussian truth; its capture file."""
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    scene = dict(scene="cylinder", width=200, height=160, theta_i_deg=0.0,
                 sigma_over_T=CYLINDER_SIGMA_OVER_T, correlation="gaussian")
    _core.write_capture(str(folder), "tiff", exposure_s=_exposure(_peak(**scene)), seed=21,
                        **scene, **_camera())
    spec = {"format": "roughscope-measure",
            "description": "synthetic cylinder, L = V (§5.2)",
            "black_level_dn": DEMO_BLACK,
            # The known geometry, as in §5.2 (the renderer's axis: the vertical centre line,
            # radius 0.4 · 160 px). Found from the silhouette instead, the radius of a very
            # rough cylinder lit from the camera comes out short: its limb is dark.
            "object": {"shape": "cylinder",
                       "axis": {"point_px": [100, 80], "direction": [0, 1], "radius_px": 64}},
            "captures": [{"image": "capture.tiff", "light": [0, 0, 1], "view": [0, 0, 1]}]}
    path = folder / "capture-file.json"
    path.write_text(json.dumps(spec, indent=2) + "\n", encoding="utf-8")
    return path


def write_sphere_demo(folder):
    """A sphere lit at 30° from the camera, V–H Gaussian truth; its capture file."""
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    scene = dict(scene="sphere", width=160, height=160, theta_i_deg=30.0,
                 sigma_over_T=SPHERE_SIGMA_OVER_T, correlation="gaussian")
    _core.write_capture(str(folder), "tiff", exposure_s=_exposure(_peak(**scene)), seed=22,
                        **scene, **_camera())
    light = [-math.sin(math.radians(30.0)), 0.0, math.cos(math.radians(30.0))]
    spec = {"format": "roughscope-measure",
            "description": "synthetic sphere, light at 30°",
            "black_level_dn": DEMO_BLACK,
            # The known circle (centred, radius 0.4 · 160 px): beyond the terminator the sphere
            # is dark and its outline cannot be seen.
            "object": {"shape": "sphere", "circle": [80, 80, 64]},
            "captures": [{"image": "capture.tiff", "light": light, "view": [0, 0, 1]}]}
    path = folder / "capture-file.json"
    path.write_text(json.dumps(spec, indent=2) + "\n", encoding="utf-8")
    return path


def map_demo_labels(shift_px=0):
    """The demo's three regions: the top left quarter (slightly rough), the top right quarter
    (moderately rough) and the bottom half (very rough) — borders in both directions, so that
    the pair's registration is determined — optionally moved `shift_px` columns to the right."""
    import numpy as np

    half = MAP_SIZE // 2
    yy, xx = np.mgrid[0:MAP_SIZE, 0:MAP_SIZE]
    xx = xx - shift_px
    labels = np.where(yy >= half, 2, np.where(xx >= half, 1, 0))
    return labels.astype(np.int32)


def map_demo_regions():
    """The named regions of the map demo, one window inside each region's borders."""
    half, w = MAP_SIZE // 2, MAP_WINDOW_PX
    rects = ([w, w, half - 2 * w, half - 2 * w], [half + w, w, half - 2 * w, half - 2 * w],
             [w, half + w, MAP_SIZE - 2 * w, half - 2 * w])
    return [{"name": name, "rect": rect} for (name, _), rect in zip(MAP_REGIONS, rects)]


def write_map_capture(folder, k, theta, exposure, shift_px=0, seed=None):
    _core.write_capture(str(folder), "tiff", scene="plane", width=MAP_SIZE, height=MAP_SIZE,
                        theta_i_deg=theta, sigma_over_T=[r for _, r in MAP_REGIONS],
                        labels=map_demo_labels(shift_px), correlation="gaussian",
                        exposure_s=exposure, seed=31 + k if seed is None else seed, **_camera())


def write_map_demo(folder):
    """A flat sample with three regions of known σ/T (one per class), lit at 30° and 45°; its
    capture file with the regions named for the map's statistics."""
    folder = pathlib.Path(folder)
    captures = []
    for k, theta in enumerate((30.0, 45.0)):
        sub = folder / f"capture{k + 1}"
        sub.mkdir(parents=True, exist_ok=True)
        peak = max(_peak(scene="plane", theta_i_deg=theta, sigma_over_T=r,
                         correlation="gaussian") for _, r in MAP_REGIONS)
        exposure = _exposure(peak)
        write_map_capture(sub, k, theta, exposure)
        captures.append({"image": f"capture{k + 1}/capture.tiff", "theta_i_deg": theta,
                         "exposure_s": exposure})
    spec = {"format": "roughscope-measure",
            "description": "synthetic flat sample, three regions",
            "black_level_dn": DEMO_BLACK,
            "maps": {"window_px": MAP_WINDOW_PX, "regions": map_demo_regions()},
            "captures": captures}
    path = folder / "capture-file.json"
    path.write_text(json.dumps(spec, indent=2) + "\n", encoding="utf-8")
    return path


def section(outdir):
    """The report's section on curved objects and maps (synthetic, known truth)."""
    outdir = pathlib.Path(outdir)
    base = outdir / "captures" / "objects"
    parts = ["<h2>Curved objects and roughness maps</h2>",
             "<p>§5.2 of the paper measures brightness across a rough cylinder lit from the camera "
             "and compares it with Lambert and Eq. 7, 9, 10 (Fig. 8); §5.1 proposes classifying "
             "the parts of an object as slightly, moderately or very rough. Here each is run on "
             "synthetic photographs of known truth (docs/simulation-captures.md; 14-bit linear "
             "TIFF, shot and read noise) with <code>roughscope measure</code> "
             "(docs/curved-objects.md, docs/maps.md). The synthetic data follow the V–H model "
             "by construction, so the V–H curves should follow them; Lambert and the original "
             "B–K (Eq. 7) leave them at large angles.</p>"]
    cyl_file = write_cylinder_demo(base / "cylinder")
    doc = run_cli(cyl_file)
    parts.append("<h3>A cylinder, L = V</h3>")
    parts.append(cylinder_html(doc, {"sigma_over_T_gaussian": CYLINDER_SIGMA_OVER_T}))
    sph_file = write_sphere_demo(base / "sphere")
    doc = run_cli(sph_file)
    parts.append("<h3>A sphere lit at 30°</h3>")
    parts.append(sphere_html(doc, f"V–H Gaussian, σ/T = {SPHERE_SIGMA_OVER_T}"))
    map_file = write_map_demo(base / "map")
    maps_dir = base / "map" / "maps"
    doc = run_cli(map_file, maps_dir)
    parts.append("<h3>A flat sample with three regions</h3>")
    parts.append(map_html(doc, maps_dir, {name: r for name, r in MAP_REGIONS}))
    return "\n".join(parts)
