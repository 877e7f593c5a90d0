"""Measurements from photographs in the report, and the report of ``roughscope measure --report``.

* ``python -m roughscope.report_measure --out DIR`` reads the JSON document of
  ``roughscope measure --json`` on standard input and writes DIR/index.html: a self-contained page
  (images embedded as data URIs) with the photographs and the measured regions overlaid, the
  values with their standard errors, and the checks (warnings, saturation, channel agreement).
* :func:`section` is the first section of the main report (``make demo``): the measurements of
  the synthetic samples of known roughness that :func:`roughscope.demo.measure_samples` wrote
  (8-bit sRGB PNG, 16-bit linear TIFF, DNG; the paper's 30°/45° pair, different exposures), the
  recovered values set against the truth.
"""

import argparse
import io
import json
import pathlib
import sys

from . import _core
from ._html import (embedded_image, escape, one_line_error, page_html, prepare_folder,
                    fmt, verdict, within_two_sigma, write_page)
from .report_objects import objects_html


# --------------------------------------------------------------------------------------------
# Figures: a photograph with the measured region (and the highlight's rings) drawn over it.

def _display(values):
    """Average channel, scaled so that the 99.5th percentile (or twice the median, for a nearly
    uniform photograph, which then shows mid-grey) is white, sRGB-encoded for the screen."""
    import numpy as np

    grey = values.mean(axis=0)
    top = max(float(np.percentile(grey, 99.5)), 2.0 * float(np.median(grey))) or 1.0
    return _core.srgb_encode(np.clip(grey / top, 0.0, 1.0))


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


def _combined(doc, key):
    """'± u (k=1), 95 % [low, high]' of the budget (docs/uncertainty.md), or '–'."""
    value, u = doc.get(key), doc.get(key + "_uncertainty")
    interval = doc.get(key + "_interval95")
    if value is None or u is None or not interval:
        return "–"
    low, high = (_core.format_uncertain(x, u).split(" ± ")[0] for x in interval)
    return f"{_core.format_uncertain(value, u)}, 95 % [{low}, {high}]"


def values_table(doc, truth=None):
    """The headline values with their standard errors: the statistical one (pixel noise) and
    the combined one of the uncertainty budget (and the truth, when known)."""
    budget = doc.get("uncertainty_method") is not None
    head = "<tr><th class='l'>quantity</th><th>measured ± s.e. (pixel noise)</th>"
    if budget:
        head += "<th>± combined u (setup and noise, k=1)</th>"
    head += "<th>truth</th><th>within 2σ</th></tr>" if truth else "</tr>"
    rows = []
    for key, label, unit in HEADLINE:
        value, err = doc.get(key), doc.get(key + "_stderr")
        if value is None and not (truth and key in truth):
            continue
        cells = f"<td class='l'>{escape(label)}{(' (' + unit + ')') if unit else ''}</td>"
        cells += f"<td>{escape(fmt(value, err))}</td>"
        if budget:
            cells += f"<td>{escape(_combined(doc, key))}</td>"
        if truth:
            t = truth.get(key)
            cells += (f"<td>{escape(fmt(t))}</td>"
                      f"<td>{within_two_sigma(value, err, t)}</td>")
        rows.append(f"<tr>{cells}</tr>")
    rows.extend(_exact_series_rows(doc, 1 + (1 if budget else 0) + (2 if truth else 0)))
    cls = doc.get("roughness_class")
    if cls:
        assumed = " (assumed by the estimator)" if doc.get("roughness_class_assumed") else ""
        span = (4 if truth else 2) + (1 if budget else 0)
        rows.append(f"<tr><td class='l'>roughness class</td>"
                    f"<td colspan='{span - 1}'>{escape(cls.replace('_', ' ') + assumed)}</td></tr>")
    return f"<table>{head}{''.join(rows)}</table>"


def _exact_series_rows(doc, span):
    """σ/T of the exact series per correlation (docs/uncertainty.md "Model error"): value ± u,
    its 95 % interval, how it was found and how far the closed form is from it."""
    series = doc.get("exact_series")
    if not series:
        return []
    rows = []
    for corr in ("gaussian", "exponential"):
        e = series.get(corr) or {}
        value, u = e.get("sigma_over_T"), e.get("sigma_over_T_stderr")
        if value is None:
            continue
        text = fmt(value, u)
        interval = e.get("sigma_over_T_interval95")
        if interval:
            text += f", 95 % [{fmt(interval[0])}, {fmt(interval[1])}]"
        deviation = e.get("closed_form_deviation_rel")
        if deviation is not None:
            text += f"; closed form {100.0 * deviation:+.0f} %"
        label = f"σ/T exact series ({corr}; {series.get('method_description', '')})"
        rows.append(f"<tr><td class='l'>{escape(label)}</td>"
                    f"<td colspan='{span}'>{escape(text)}</td></tr>")
    return rows


BUDGET_LABELS = {"E1_over_E2": "E1/E2", "sigma_over_T_gaussian": "σ/T (Gaussian)",
                 "sigma_over_T_exponential": "σ/T (exponential)", "sigma_um": "σ",
                 "T_um": "T"}


def budget_png(doc, top=6):
    """PNG bytes of the uncertainty budget: per quantity, the share (u_i(y)²/u(y)², %) of its
    largest sources as horizontal bars; None without a budget."""
    budget = doc.get("uncertainty_budget") or {}
    quantities = [q for q in BUDGET_LABELS if budget.get(q)]
    if not quantities:
        return None
    from ._plotting import pyplot

    plt = pyplot()
    fig, axes = plt.subplots(len(quantities), 1, figsize=(6.4, 1.0 + 1.5 * len(quantities)),
                             dpi=90, squeeze=False)
    for ax, q in zip(axes[:, 0], quantities):
        lines = [line for line in budget[q] if line["fraction"] > 0][:top][::-1]
        ax.barh([line["source"] for line in lines],
                [100.0 * line["fraction"] for line in lines], color="#3a86ff")
        ax.set_xlim(0, 100)
        ax.set_title(f"{BUDGET_LABELS[q]} = "
                     f"{_core.format_uncertain(doc[q], doc[q + '_uncertainty'])} (k=1)",
                     fontsize=10)
        ax.tick_params(labelsize=9)
    axes[-1, 0].set_xlabel("share of u(y)² (%)", fontsize=9)
    fig.tight_layout()
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png")
    plt.close(fig)
    return buffer.getvalue()


def budget_html(doc):
    """The budget's figure and its method, or '' without a budget."""
    png = budget_png(doc)
    if png is None:
        return ""
    method = doc.get("uncertainty_method")
    how = ("Monte Carlo (JCGM 101), " + str(doc.get("uncertainty_trials")) + " trials"
           if method == "monte_carlo" else "first order (GUM, JCGM 100 §5.1)")
    assumed = doc.get("uncertainty_assumed") or []
    note = (" Assumed, not declared: " + ", ".join(assumed) + "." if assumed else "")
    return ("<figure>" + embedded_image(png, "uncertainty budget") +
            f"<figcaption>Uncertainty budget: each source's share of the combined variance, "
            f"propagated by {escape(how)} (docs/uncertainty.md).{escape(note)}</figcaption>"
            "</figure>")


def captures_table(doc):
    rows = []
    for c in doc["captures"]:
        region = c["region"]
        avg = region["average"]
        rows.append(
            "<tr>" + "".join(f"<td>{escape(x)}</td>" for x in (
                pathlib.Path(c["image"]).name, c["role"], c["format"], c["response"],
                fmt(c["theta_i_deg"]), fmt(c["theta_s_deg"]),
                fmt(c["phi_s_deg"]),
                f"{fmt(c['exposure_scale'])} ({c['exposure_source']})",
                fmt(c["brightness"],
                    (c["brightness"] or 0) * (c["brightness_relative_stderr"] or 0)),
                fmt(avg["stderr_pixel"], digits=2), fmt(avg["stderr_tiles"], digits=2),
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
        items.append(f"<li>σ per channel agrees (χ² = {chi2:.3g}, 2 d.o.f., limit 9.21): "
                     f"{verdict(chi2 <= 9.21)}</li>")
    for c in doc["captures"]:
        if c["file_response"] and c["file_response"] != c["response"]:
            items.append(f"<li class='fail'>{escape(pathlib.Path(c['image']).name)}: declared "
                         f"{escape(c['response'])}, the file says {escape(c['file_response'])} "
                         f"({escape(c['file_response_evidence'])})</li>")
    for w in doc["warnings"]:
        items.append(f"<li>warning: {escape(w)}</li>")
    if not items:
        items.append("<li class='pass'>no warnings</li>")
    return "<ul>" + "".join(items) + "</ul>"


def measurement_html(doc, capture_file=None, truth=None, title=None):
    """An HTML fragment for one measurement document (roughscope.measure / measure --json)."""
    parts = []
    if title:
        parts.append(f"<h3>{escape(title)}</h3>")
    parts.append(values_table(doc, truth))
    budget = budget_html(doc)
    if budget:
        parts.append(budget)
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
                figures.append(f"<p>(no figure for {escape(c['image'])}: {escape(exc)})</p>")
                continue
            figures.append(embedded_image(png, pathlib.Path(c["image"]).name))
    if figures:
        parts.append("<figure>" + " ".join(figures) + "<figcaption>The photographs (grey: "
                     "channel average, sRGB for display) with the measured region (orange), "
                     "saturated pixels (red) and, for a specular capture, the highlight's core "
                     "and annulus.</figcaption></figure>")
    objects = objects_html(doc)
    if objects:
        parts.append(objects)
    if (doc.get("region") or {}).get("description"):
        parts.append(captures_table(doc))
    parts.append("<h4>Checks</h4>" + checks_html(doc))
    return "\n".join(parts)


def page(body, title):
    """The complete, self-contained page of one measurement (figures embedded as data URIs)."""
    return page_html(body, title, f"roughscope {escape(_core.__version__)}")


SUMMARY_LABELS = {"sigma_um": "σ (µm)", "T_um": "T (µm)",
                  "sigma_over_T_gaussian": "σ/T (Gaussian)",
                  "sigma_over_T_exponential": "σ/T (exponential)"}


def section(measured):
    """The report's first section: `measured` is roughscope.demo.measure_samples' list of
    {sample, capture_file, document, truth}."""
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
    for m in measured:
        sample, doc = m["sample"], m["document"]
        for key, true_value in m["truth"].items():
            value, err = doc[key], doc[key + "_stderr"]
            good = value is not None and err is not None and abs(value - true_value) <= 2 * err
            summary.append(
                f"<tr><td class='l'>{escape(sample['name'])}</td><td class='l'>"
                f"{escape(sample['description'])}</td><td class='l'>"
                f"{escape(SUMMARY_LABELS[key])}</td><td>{fmt(true_value)}</td>"
                f"<td>{escape(fmt(value, err))}</td><td>{verdict(good)}</td></tr>")
        fragments.append(measurement_html(doc, m["capture_file"], m["truth"],
                                          title=f"Sample {sample['name']}: "
                                                f"{sample['description']}"))
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
            sys.stdout.write(page(body, "roughscope measurement"))
            sys.stdout.flush()
            return 0
        index = write_page(args.out, page(body, "roughscope measurement"))
    except Exception as exc:  # one line, no traceback: this is a command-line tool
        print(f"roughscope.report_measure: error: {one_line_error(exc)}", file=sys.stderr)
        return 1
    print(index)
    return 0


if __name__ == "__main__":
    sys.exit(main())
