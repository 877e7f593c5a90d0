"""Measurements from photographs in the report, and the report of ``roughscope measure --report``.

* ``python -m roughscope.report_measure --out DIR`` reads the JSON document of
  ``roughscope measure --json`` on standard input and writes DIR/index.html: a self-contained page
  (images embedded as data URIs) with the photographs and the measured regions overlaid, the
  values with their standard errors, and the checks (warnings, saturation, channel agreement).
* :func:`section` is the first section of the main report (``make demo``): synthetic captures of
  samples of known roughness (8-bit sRGB PNG, 16-bit linear TIFF, DNG; the paper's 30°/45° pair,
  different exposures) are written, measured with :func:`roughscope.measure` and the recovered
  values set against the truth.
"""

import argparse
import base64
import contextlib
import html
import io
import json
import math
import os
import pathlib
import sys
import tempfile

from . import _core


def _e(text):
    return html.escape(str(text))


def _fmt(value, err=None, digits=4):
    if value is None:
        return "–"
    text = f"{value:.{digits}g}"
    if err is not None and err > 0:
        text += f" ± {err:.2g}"
    return text


# --------------------------------------------------------------------------------------------
# Figures: a photograph with the measured region (and the highlight's rings) drawn over it.

def _display(values):
    """Average channel, scaled so that the 99.5th percentile (or twice the median, for a nearly
    uniform photograph, which then shows mid-grey) is white, sRGB-encoded for the screen."""
    import numpy as np

    grey = values.mean(axis=0)
    top = max(float(np.percentile(grey, 99.5)), 2.0 * float(np.median(grey))) or 1.0
    u = np.clip(grey / top, 0.0, 1.0)
    return np.where(u <= 0.0031308, 12.92 * u, 1.055 * np.power(u, 1 / 2.4) - 0.055)


def overlay_png(image_path, roi, response=None, gamma=2.2, highlight=None, title=None):
    """PNG bytes of the photograph (grey) with the region's outline; None if it cannot be read."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    image = _core.read_image(str(image_path), response=response, gamma=gamma)
    values = image["values"]
    _, height, width = values.shape
    mask = _core.region_mask(roi, width, height)
    aspect = height / width
    fig, ax = plt.subplots(figsize=(4.0, max(1.5, 4.0 * aspect)), dpi=90)
    ax.imshow(_display(values), cmap="gray", vmin=0, vmax=1, interpolation="nearest")
    ax.contour(mask.astype(float), levels=[0.5], colors=["#ff9f1c"], linewidths=1.2)
    saturated = (image["flags"] & 1) != 0
    if saturated.any():
        ys, xs = np.nonzero(saturated)
        ax.plot(xs, ys, ",", color="#e71d36")
    if highlight is not None:
        cx, cy = highlight["centre_px"]
        for radius, colour in ((highlight["core_radius_px"], "#2ec4b6"),
                               (highlight["annulus_inner_px"], "#cbf3f0"),
                               (highlight["annulus_outer_px"], "#cbf3f0")):
            ax.add_patch(plt.Circle((cx - 0.5, cy - 0.5), radius, fill=False, color=colour))
    ax.set_xticks([])
    ax.set_yticks([])
    if title:
        ax.set_title(title, fontsize=8)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    plt.close(fig)
    return buf.getvalue()


def _img_tag(png, alt):
    data = base64.b64encode(png).decode("ascii")
    return f'<img src="data:image/png;base64,{data}" alt="{_e(alt)}">'


# --------------------------------------------------------------------------------------------
# One measurement as HTML.

HEADLINE = [
    ("E1_over_E2", "E1/E2", ""),
    ("sigma_over_T_gaussian", "σ/T (Gaussian, Eq. 17)", ""),
    ("sigma_over_T_exponential", "σ/T (exponential, Eq. 19)", ""),
    ("sigma_um", "σ", "µm"),
    ("T_um", "T", "µm"),
    ("theta_K_deg", "Caron's θK", "°"),
    ("xi_K", "Caron's ξK", ""),
]


def values_table(doc, truth=None):
    """The headline values with their standard errors (and the truth, when known)."""
    head = "<tr><th class='l'>quantity</th><th>measured</th>"
    head += "<th>truth</th><th>within 2σ</th></tr>" if truth else "</tr>"
    rows = []
    for key, label, unit in HEADLINE:
        value, err = doc.get(key), doc.get(key + "_stderr")
        if value is None and not (truth and key in truth):
            continue
        cells = f"<td class='l'>{_e(label)}{(' (' + unit + ')') if unit else ''}</td>"
        cells += f"<td>{_e(_fmt(value, err))}</td>"
        if truth:
            t = truth.get(key)
            ok = ""
            if t is not None and value is not None and err:
                good = abs(value - t) <= 2 * err
                ok = f"<span class='{'pass' if good else 'fail'}'>{'yes' if good else 'no'}</span>"
            cells += f"<td>{_e(_fmt(t))}</td><td>{ok}</td>"
        rows.append(f"<tr>{cells}</tr>")
    cls = doc.get("roughness_class")
    if cls:
        assumed = " (assumed by the estimator)" if doc.get("roughness_class_assumed") else ""
        span = 4 if truth else 2
        rows.append(f"<tr><td class='l'>roughness class</td>"
                    f"<td colspan='{span - 1}'>{_e(cls.replace('_', ' ') + assumed)}</td></tr>")
    return f"<table>{head}{''.join(rows)}</table>"


def captures_table(doc):
    rows = []
    for c in doc["captures"]:
        region = c["region"]
        avg = region["average"]
        rows.append(
            "<tr>" + "".join(f"<td>{_e(x)}</td>" for x in (
                pathlib.Path(c["image"]).name, c["role"], c["format"], c["response"],
                _fmt(c["theta_i_deg"]), _fmt(c["theta_s_deg"]), _fmt(c["phi_s_deg"]),
                f"{_fmt(c['exposure_scale'])} ({c['exposure_source']})",
                _fmt(c["brightness"], (c["brightness"] or 0) * (c["brightness_relative_stderr"] or 0)),
                _fmt(avg["stderr_pixel"], digits=2), _fmt(avg["stderr_tiles"], digits=2),
                f"{region['pixels_used']} / {region['pixels_in_region']}",
                region["pixels_saturated"])) + "</tr>")
    head = ("<tr><th>image</th><th>role</th><th>format</th><th>response</th><th>θi</th>"
            "<th>θs</th><th>φs</th><th>exposure scale</th><th>brightness Ẽ</th>"
            "<th>s.e. (pixels)</th><th>s.e. (tiles)</th><th>pixels used</th>"
            "<th>saturated</th></tr>")
    return f"<table>{head}{''.join(rows)}</table>"


def checks_html(doc):
    items = []
    spec = doc.get("specular")
    if spec and spec.get("channel_chi2") is not None:
        chi2 = spec["channel_chi2"]
        ok = chi2 <= 9.21
        items.append(f"<li>σ per channel agrees (χ² = {chi2:.3g}, 2 d.o.f., limit 9.21): "
                     f"<span class='{'pass' if ok else 'fail'}'>{'yes' if ok else 'no'}</span>"
                     "</li>")
    for c in doc["captures"]:
        if c["file_response"] and c["file_response"] != c["response"]:
            items.append(f"<li class='fail'>{_e(pathlib.Path(c['image']).name)}: declared "
                         f"{_e(c['response'])}, the file says {_e(c['file_response'])} "
                         f"({_e(c['file_response_evidence'])})</li>")
    for w in doc["warnings"]:
        items.append(f"<li>warning: {_e(w)}</li>")
    if not items:
        items.append("<li class='pass'>no warnings</li>")
    return "<ul>" + "".join(items) + "</ul>"


def measurement_html(doc, capture_file=None, truth=None, title=None):
    """An HTML fragment for one measurement document (roughscope.measure / measure --json)."""
    parts = []
    if title:
        parts.append(f"<h3>{_e(title)}</h3>")
    parts.append(values_table(doc, truth))
    capture_file = capture_file or doc.get("capture_file")
    figures = []
    if capture_file and pathlib.Path(capture_file).is_file():
        spec = json.loads(pathlib.Path(capture_file).read_text(encoding="utf-8"))
        response = spec.get("response")
        gamma = 2.2
        if isinstance(response, dict):
            gamma, response = response["gamma"], "gamma"
        for c in doc["captures"]:
            if "roi" not in spec:  # a curved object or a map: the figures below show it
                break
            try:
                png = overlay_png(c["image"], spec["roi"], response, gamma, c.get("highlight"),
                                  title=f"{pathlib.Path(c['image']).name}: θi = "
                                        f"{c['theta_i_deg']:g}°, {c['role']}")
            except Exception as exc:  # a figure must not hide the numbers
                figures.append(f"<p>(no figure for {_e(c['image'])}: {_e(exc)})</p>")
                continue
            figures.append(_img_tag(png, pathlib.Path(c["image"]).name))
    if figures:
        parts.append("<figure>" + " ".join(figures) + "<figcaption>The photographs (grey: "
                     "channel average, sRGB for display) with the measured region (orange), "
                     "saturated pixels (red) and, for a specular capture, the highlight's core "
                     "and annulus.</figcaption></figure>")
    from .report_objects import objects_html

    objects = objects_html(doc)
    if objects:
        parts.append(objects)
    if (doc.get("region") or {}).get("description"):
        parts.append(captures_table(doc))
    parts.append("<h4>Checks</h4>" + checks_html(doc))
    return "\n".join(parts)


_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title}</title><style>{css}</style></head>
<body><h1>{title}</h1><p class="meta">roughscope {version}</p>
{body}
</body></html>
"""


def page_html(body, title):
    """The complete, self-contained page (figures embedded as data URIs)."""
    from .report import _CSS

    return _PAGE.format(title=_e(title), css=_CSS, version=_e(_core.__version__), body=body)


def prepare_folder(out):
    """`out` as a folder for index.html: created when missing (with its parents); an error
    naming the path when it exists and is not a folder."""
    out = pathlib.Path(out)
    if out.exists() and not out.is_dir():
        raise NotADirectoryError(f"cannot write the report to {out}: it is not a folder")
    out.mkdir(parents=True, exist_ok=True)
    return out


def write_page(out, body, title):
    """Write out/index.html atomically and nothing else: a temporary file in `out` renamed over
    index.html. Nothing already in `out` is removed or changed; `out` (or a symbolic link to a
    folder) is created when missing. A path that exists and is not a folder is an error."""
    out = prepare_folder(out)
    index = out / "index.html"
    fd, tmp = tempfile.mkstemp(prefix=".index.html.tmp-", dir=out)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(page_html(body, title))
        os.chmod(tmp, 0o644)
        os.replace(tmp, index)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return index


def one_line_error(exc):
    """A one-line message for `exc`: an OSError as "<path>: <reason>" (no Python reprs)."""
    if isinstance(exc, OSError) and exc.strerror and exc.filename is not None:
        reason = exc.strerror[0].lower() + exc.strerror[1:]
        return f"{os.fsdecode(exc.filename)}: {reason}"
    return " ".join(str(exc).split()) or type(exc).__name__


# --------------------------------------------------------------------------------------------
# The demo: synthetic captures of known truth, measured.

# (name, description, truth, capture settings). Camera on the normal, light at θi = 30° and 45°
# (the paper's pair, §4.2), the second capture with half the exposure. Sample D is slightly rough
# (the glossy paper of Table 1): a specular photograph at 14° gives σ (Eq. 13), the pair T
# (Eq. 15); its pair is rendered with the full B–K model (mean scattered power, Eq. 1–2).
DEMO_SAMPLES = [
    dict(name="A-srgb8", description="8-bit sRGB PNG (a phone or JPEG-like camera)",
         sigma_over_T=0.30, correlation="gaussian", fmt="png", bits=8, response="srgb",
         seed=11),
    dict(name="B-linear16", description="16-bit linear TIFF (a machine-vision camera)",
         sigma_over_T=0.20, correlation="exponential", fmt="tiff", bits=16, response="linear",
         seed=12),
    dict(name="C-dng", description="DNG camera RAW, 14-bit (a raw photograph)",
         sigma_over_T=0.50, correlation="gaussian", fmt="dng", bits=14, response="linear",
         seed=13),
    dict(name="D-specular", description="slightly rough (glossy paper of Table 1): a specular "
         "photograph and a pair, 16-bit linear PNG", sigma_um=0.094, T_um=0.195,
         sigma_over_T=0.094 / 0.195, correlation="gaussian", fmt="png", bits=16,
         response="linear", seed=14, specular_theta_deg=14.0),
]
DEMO_THETA_I_DEG = (30.0, 45.0)
DEMO_EXPOSURE_FACTORS = (1.0, 0.5)
DEMO_SIZE = 160
DEMO_ELECTRONS = 20000.0
DEMO_FULL_WELL = 60000.0
DEMO_BASE_EXPOSURE_S = 0.02  # the first capture of each pair: 1/50 s
DEMO_WAVELENGTH_UM = 0.555
DEMO_HIGHLIGHT_RADIUS_PX = 12


def _demo_black_level(sample):
    # An 8-bit sRGB file has its black at 0 (as cameras write JPEGs); linear files keep 64 DN.
    return 0.0 if sample["bits"] == 8 else 64.0


def _demo_gain(sample):
    # DN per electron: the full well lies 5 % above the white level (as in most cameras).
    white = 2.0 ** sample["bits"] - 1.0
    return 1.05 * (white - _demo_black_level(sample)) / DEMO_FULL_WELL


def _camera(sample, electrons_per_unit_s=DEMO_ELECTRONS):
    return dict(bits=sample["bits"], response=sample["response"],
                electrons_per_unit_s=electrons_per_unit_s, full_well_e=DEMO_FULL_WELL,
                black_level=_demo_black_level(sample), gain=_demo_gain(sample),
                keep_geometry=False)


def _surface(sample):
    """The write_capture keywords of the sample's surface (very rough, or the full B–K model)."""
    if "sigma_um" in sample:
        return dict(model="mean_scattered_power", sigma_over_T=sample["sigma_over_T"],
                    T_um=sample["T_um"], correlation=sample["correlation"],
                    wavelength_um=DEMO_WAVELENGTH_UM)
    return dict(sigma_over_T=sample["sigma_over_T"], correlation=sample["correlation"])


def _mean_brightness(sample, theta_i_deg):
    """The model brightness of the plane at θi (camera on the normal), from a tiny render."""
    out = _core.render_capture(scene="plane", width=2, height=2, theta_i_deg=theta_i_deg,
                               **_surface(sample))
    return float(out["radiance"].mean())


def _write_specular(sample, folder, ext):
    """A photograph in the mirror direction at θ: the reflection of the (extended) source is a
    disc whose brightness exceeds its surround by the coherent fraction, R_spec = 1 − Ẽ_dif/Ẽ_tot
    = exp(−g), g = (4πσ cos θ/λ)² (Eq. 13 with R0 = 1)."""
    import numpy as np

    theta = sample["specular_theta_deg"]
    g = (4 * math.pi * sample["sigma_um"] * math.cos(math.radians(theta)) / DEMO_WAVELENGTH_UM) ** 2
    e_tot = 1.0
    e_dif = e_tot * (1.0 - math.exp(-g))
    yy, xx = np.mgrid[0:DEMO_SIZE, 0:DEMO_SIZE] + 0.5
    centre = DEMO_SIZE / 2 + 3.0
    labels = ((xx - centre) ** 2 + (yy - centre + 6.0) ** 2
              <= DEMO_HIGHLIGHT_RADIUS_PX ** 2).astype(np.int32)
    exposure = 0.5 * DEMO_FULL_WELL / (DEMO_ELECTRONS * e_tot)
    sub = folder / "specular"
    sub.mkdir(parents=True, exist_ok=True)
    _core.write_capture(str(sub), sample["fmt"], scene="plane", width=DEMO_SIZE,
                        height=DEMO_SIZE, theta_i_deg=theta, theta_v_deg=theta, phi_v_deg=0.0,
                        labels=labels,
                        brightness=[lambda *_: e_dif, lambda *_: e_tot],
                        exposure_s=exposure, seed=sample["seed"] * 10 + 9, **_camera(sample))
    return {"image": f"specular/capture.{ext}", "theta_i_deg": theta, "theta_s_deg": theta,
            "phi_s_deg": 0.0, "role": "specular"}


def demo_lamp(sample, brightness=None):
    """Electrons per unit brightness and second of the sample's diffuse captures: the lamp that
    puts the first capture's mean at 40 % of the full well in DEMO_BASE_EXPOSURE_S (a dim,
    slightly rough sample gets a brighter lamp, not an exposure of years)."""
    if brightness is None:
        brightness = [_mean_brightness(sample, t) for t in DEMO_THETA_I_DEG]
    return 0.4 * DEMO_FULL_WELL / (DEMO_BASE_EXPOSURE_S * max(brightness))


def write_demo_sample(sample, folder):
    """Write the captures and the capture file of one demo sample; return its path."""
    folder = pathlib.Path(folder)
    ext = "dng" if sample["fmt"] == "dng" else ("tiff" if sample["fmt"] == "tiff" else "png")
    brightness = [_mean_brightness(sample, t) for t in DEMO_THETA_I_DEG]
    base_exposure = DEMO_BASE_EXPOSURE_S
    lamp = demo_lamp(sample, brightness)
    captures = []
    if "specular_theta_deg" in sample:
        captures.append(_write_specular(sample, folder, ext))
    for k, (theta, factor) in enumerate(zip(DEMO_THETA_I_DEG, DEMO_EXPOSURE_FACTORS)):
        sub = folder / f"capture{k + 1}"
        sub.mkdir(parents=True, exist_ok=True)
        exposure = base_exposure * factor
        _core.write_capture(str(sub), sample["fmt"], scene="plane", width=DEMO_SIZE,
                            height=DEMO_SIZE, theta_i_deg=theta, exposure_s=exposure,
                            seed=sample["seed"] * 10 + k, **_surface(sample),
                            **_camera(sample, electrons_per_unit_s=lamp))
        captures.append({"image": f"capture{k + 1}/capture.{ext}", "theta_i_deg": theta,
                         "theta_s_deg": 0.0, "phi_s_deg": 0.0, "exposure_s": exposure,
                         "role": "diffuse"})
    margin = DEMO_SIZE // 8
    spec = {"format": "roughscope-measure",
            "description": sample["description"],
            "response": sample["response"],
            "roi": {"rect": [margin, margin, DEMO_SIZE - 2 * margin, DEMO_SIZE - 2 * margin]},
            "captures": captures}
    if "sigma_um" in sample:
        # T given σ from the exact series (the pair is rendered with it; at this sample's
        # g ≈ 4 the paper's Eq. 15, "regime": "slightly_rough", reads T about 25 % high).
        spec["wavelength_um"] = DEMO_WAVELENGTH_UM
        spec["correlation"] = sample["correlation"]
        spec["regime"] = "series"
    if sample["fmt"] != "dng":  # a RAW file carries its own black level
        spec["black_level_dn"] = _demo_black_level(sample)
    path = folder / "capture-file.json"
    path.write_text(json.dumps(spec, indent=2) + "\n", encoding="utf-8")
    return path


def measure_with_cli(capture_file):
    """``roughscope measure CAPTURE --json`` when $ROUGHSCOPE_CLI names the tool (make demo sets
    it), else the same measurement through the module (one library behind both)."""
    import subprocess

    cli = os.environ.get("ROUGHSCOPE_CLI")
    if not cli:
        return _core.measure(str(capture_file))
    proc = subprocess.run([cli, "measure", str(capture_file), "--json"], capture_output=True,
                          text=True, timeout=600)
    if proc.returncode != 0:
        raise RuntimeError(f"roughscope measure {capture_file}: {proc.stderr.strip()}")
    return json.loads(proc.stdout)


def demo_truth(sample):
    """The true values the demo compares with (σ and T for the slightly rough sample)."""
    if "sigma_um" in sample:
        return {"sigma_um": sample["sigma_um"], "T_um": sample["T_um"]}
    return {f"sigma_over_T_{sample['correlation']}": sample["sigma_over_T"]}


def section(outdir):
    """The report's first section: the demo samples written, measured and checked."""
    outdir = pathlib.Path(outdir)
    parts = ["<h2>Measuring a sample from its photographs</h2>",
             "<p>The main job of roughscope (<code>roughscope measure CAPTURE.json</code>, "
             "docs/measure.md): photographs of a flat sample lit from two directions give "
             "E1/E2, and Eq. 17 / 19 give σ/T (§4.2). Here the photographs are synthetic "
             "captures of samples of known roughness (docs/simulation-captures.md: very-rough "
             "brightness Eq. 4/5 with V–H factor, photon shot noise, read noise, black level, "
             "quantisation and the camera's response), taken with the paper's geometry — camera "
             "on the normal, light at 30° and 45° — the second with half the exposure. Sample D "
             "is slightly rough: a photograph of the specular highlight at 14° gives σ (Eq. 13) "
             "and the pair, rendered with the full B–K model, gives T (Eq. 15). The captures and "
             "their capture files are in <code>captures/</code> beside this page.</p>"]
    summary = []
    fragments = []
    labels = {"sigma_um": "σ (µm)", "T_um": "T (µm)", "sigma_over_T_gaussian": "σ/T (Gaussian)",
              "sigma_over_T_exponential": "σ/T (exponential)"}
    for sample in DEMO_SAMPLES:
        folder = outdir / "captures" / sample["name"]
        capture_file = write_demo_sample(sample, folder)
        doc = measure_with_cli(capture_file)
        truth = demo_truth(sample)
        for key, true_value in truth.items():
            value, err = doc[key], doc[key + "_stderr"]
            good = value is not None and err is not None and abs(value - true_value) <= 2 * err
            summary.append(
                f"<tr><td class='l'>{_e(sample['name'])}</td><td class='l'>"
                f"{_e(sample['description'])}</td><td class='l'>{_e(labels[key])}</td>"
                f"<td>{_fmt(true_value)}</td><td>{_e(_fmt(value, err))}</td>"
                f"<td><span class='{'pass' if good else 'fail'}'>{'yes' if good else 'no'}"
                "</span></td></tr>")
        fragments.append(measurement_html(doc, capture_file, truth,
                                          title=f"Sample {sample['name']}: {sample['description']}"))
    parts.append("<table><tr><th class='l'>sample</th><th class='l'>photographs</th>"
                 "<th class='l'>quantity</th><th>truth</th><th>measured ± s.e.</th>"
                 "<th>within 2σ</th></tr>" + "".join(summary) + "</table>")
    parts.extend(fragments)
    return "\n".join(parts)


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python -m roughscope.report_measure",
        description="Write the HTML report of one measurement (the JSON of roughscope measure "
                    "--json on standard input).")
    parser.add_argument("--out", required=True,
                        help="folder for index.html (nothing else in it is touched), or - for "
                             "the page on standard output")
    args = parser.parse_args(argv)
    try:
        if args.out != "-":
            prepare_folder(args.out)
        doc = json.load(sys.stdin)
        body = measurement_html(doc)
        if args.out == "-":
            sys.stdout.write(page_html(body, "roughscope measurement"))
            sys.stdout.flush()
            return 0
        index = write_page(args.out, body, "roughscope measurement")
    except Exception as exc:  # one line, no traceback: this is a command-line tool
        print(f"roughscope.report_measure: error: {one_line_error(exc)}", file=sys.stderr)
        return 1
    print(index)
    return 0


if __name__ == "__main__":
    sys.exit(main())
