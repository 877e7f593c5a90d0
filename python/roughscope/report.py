"""The roughscope HTML report: ``python -m roughscope.report --out DIR`` (default out/report).

Writes DIR/index.html — a self-contained page (inline CSS, figures as PNG files beside it,
linked relatively) — with:

* a header (library version, date);
* first, the main job — :mod:`roughscope.report_measure`: synthetic photographs of samples of known
  roughness written and measured (``roughscope measure``) by :mod:`roughscope.demo`, the
  recovered values set against the truth; then :mod:`roughscope.report_objects`: a cylinder
  (Fig. 8), a sphere and a roughness map of synthetic photographs;
* "Models": the paper's Figs. 3 and 4 (retro-scattering, B–K and V–H) and a table checking the
  closed forms Eq. 7–11 against the library's general forms at the retro geometry;
* the sections of :mod:`roughscope.report_estimation`, :mod:`roughscope.report_curet`,
  :mod:`roughscope.report_surface` and :mod:`roughscope.report_simulation`
  (each ``section(outdir)`` returns an HTML fragment, or None to be left out).

Everything is written to a temporary folder beside DIR and renamed at the end, so DIR is either
the previous report or the complete new one. DIR is replaced only when it is new, empty or a
report written before (it holds the marker file ``.roughscope-report``); a folder holding other
files is refused, never emptied. On success the path of index.html is printed; on
failure a one-line error goes to stderr and the exit status is 1.
"""

import argparse
import datetime
import os
import pathlib
import shutil
import sys
import tempfile

import numpy as np

from . import _core
from ._html import escape, one_line_error, page_html

# Relative agreement required of a closed form and the general form it simplifies.
CLOSED_FORM_TOLERANCE = 1e-12


def closed_form_rows(theta_deg=(0.0, 20.0, 40.0, 60.0, 80.0), sigma_over_T=0.71,
                     sigma_um=0.02, T_um=1.5, wavelength_um=0.555):
    """Rows comparing each retro closed form with the general form it simplifies.

    Eq. 7–10 = 4 × very_rough_brightness(θ, θ, 180°, σ/T) (Eq. 4/5 shapes at the retro geometry:
    q_z² = 4 cos²θ absorbs the 4); Eq. 11 = Eq. 3 (F_VH) × A/(4πT²σ²k²).
    Each row: (equation, description, θ, closed form, general form, relative difference).
    """
    theta = np.asarray(theta_deg, dtype=float)
    phi = np.full_like(theta, 180.0)
    rows = []
    very_rough = [
        (7, "B–K, Gaussian", _core.retro_beckmann_gaussian_very_rough, "gaussian", "beckmann"),
        (8, "B–K, exponential", _core.retro_beckmann_exponential_very_rough, "exponential",
         "beckmann"),
        (9, "V–H, Gaussian", _core.retro_vh_gaussian_very_rough, "gaussian", "vh"),
        (10, "V–H, exponential", _core.retro_vh_exponential_very_rough, "exponential", "vh"),
    ]
    for eq, label, closed, corr, factor in very_rough:
        c = np.asarray(closed(theta, sigma_over_T))
        g = 4.0 * np.asarray(_core.very_rough_brightness(theta, theta, phi, sigma_over_T,
                                                         correlation=corr, factor=factor))
        for t, cv, gv in zip(theta, c, g):
            rows.append((eq, f"{label}, very rough, σ/T = {sigma_over_T:g}", t, cv, gv,
                         abs(cv - gv) / abs(cv)))
    # Eq. 11 against Eq. 3 (the slightly-rough Gaussian regime of mean_scattered_power).
    area_um2 = 4.0 * 500.0 * 500.0
    k = 2.0 * np.pi / wavelength_um
    c = np.asarray(_core.retro_vh_gaussian_slightly_rough(theta, sigma_um, T_um, wavelength_um))
    p = _core.mean_scattered_power(theta, theta, phi, sigma_um, T_um, correlation="gaussian",
                                   factor="vh", regime="slightly_rough",
                                   wavelength_um=wavelength_um)
    g = np.asarray(p["diffuse"]) * area_um2 / (4.0 * np.pi * T_um ** 2 * sigma_um ** 2 * k ** 2)
    for t, cv, gv in zip(theta, c, g):
        rows.append((11, f"V–H, Gaussian, slightly rough, σ = {sigma_um:g} µm, T = {T_um:g} µm",
                     t, cv, gv, abs(cv - gv) / abs(cv)))
    return rows


def _closed_form_table(rows):
    out = ['<table>', '<tr><th>Eq.</th><th class="l">model</th><th>θ (°)</th>'
           '<th>closed form</th><th>general form</th><th>relative difference</th>'
           '<th>check</th></tr>']
    for eq, label, t, cv, gv, rel in rows:
        ok = rel <= CLOSED_FORM_TOLERANCE
        out.append(
            f'<tr><td>{eq}</td><td class="l">{escape(label)}</td><td>{t:g}</td>'
            f'<td>{cv:.10g}</td><td>{gv:.10g}</td><td>{rel:.2e}</td>'
            f'<td class="{"pass" if ok else "fail"}">{"pass" if ok else "FAIL"}</td></tr>')
    out.append('</table>')
    return "\n".join(out)


def models_section(outdir):
    """The "Models" section: Figs. 3 and 4 written into `outdir`, and the closed-form table."""
    from . import figures

    fig3 = figures.figure3(outdir)
    fig4 = figures.figure4(outdir)
    rows = closed_form_rows()
    n_fail = sum(1 for r in rows if not r[5] <= CLOSED_FORM_TOLERANCE)
    verdict = (f'<p class="pass">All {len(rows)} closed-form values agree with the general '
               f'forms to {CLOSED_FORM_TOLERANCE:g} relative.</p>' if n_fail == 0 else
               f'<p class="fail">{n_fail} of {len(rows)} closed-form values disagree with the '
               f'general forms.</p>')
    m_list = ", ".join(f"{m:g}" for m in figures.M_VALUES)
    return f"""
<h2 id="models">Models</h2>
<p>Retro-scattering (L = V: θi = θs = θ, φs = 180°) for very rough surfaces, paper §3.4. Each
curve is divided by its value at θ = 0; σ/T = {m_list}; the dashed curve is Lambert's law.</p>
<figure><img src="{escape(fig3.name)}" alt="Figure 3">
<figcaption>Fig. 3 — original Beckmann–Kirchhoff model (F = F_Beck): (a) Gaussian correlation,
Eq. 7; (b) exponential correlation, Eq. 8 (logarithmic axis). The 1/cos⁶θ factor makes the
radiance peak at grazing angles for large σ/T, and Eq. 8 diverges as θ → 90°.</figcaption>
</figure>
<figure><img src="{escape(fig4.name)}" alt="Figure 4">
<figcaption>Fig. 4 — Vernold–Harvey modified model (F² = cos θi): (a) Eq. 9; (b) Eq. 10. The
1/cos θ behaviour stays bounded and tends to 0 at grazing angles; larger σ/T gives a higher
normalised radiance.</figcaption>
</figure>
<h3>Closed forms against the general model</h3>
<p>Eq. 7–10 are the very-rough forms Eq. 4/5 at the retro geometry
(<code>4 × very_rough_brightness(θ, θ, 180°, σ/T)</code>); Eq. 11 is Eq. 3 with F_VH
(<code>mean_scattered_power(..., regime="slightly_rough")</code> × A/(4πT²σ²k²)).</p>
{verdict}
{_closed_form_table(rows)}
"""


def build_report(outdir):
    """Write the full report into `outdir` (an existing, empty folder); return index.html's path."""
    from . import (demo, report_curet, report_estimation, report_measure, report_objects,
                   report_simulation, report_surface)

    outdir = pathlib.Path(outdir)
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    sections = [report_measure.section(demo.measure_samples(outdir)),
                report_objects.section(demo.measure_objects(outdir)),
                models_section(outdir)]
    for module in (report_estimation, report_curet, report_surface, report_simulation):
        fragment = module.section(outdir)
        if fragment is not None:
            sections.append(str(fragment))
    meta = (f"roughscope {escape(_core.__version__)} · generated {now} · Ragheb &amp;\n"
            "Hancock, “The modified Beckmann–Kirchhoff scattering theory for rough surface "
            "analysis”,\nPattern Recognition (2007)")
    index = outdir / "index.html"
    index.write_text(page_html("\n".join(sections), "roughscope report", meta), encoding="utf-8")
    return index


# The file that marks a folder as a report this module wrote (and may replace as a whole).
MARKER = ".roughscope-report"


def _is_previous_report(folder):
    """Whether `folder` holds a report written by this module (its marker, or, from versions
    before the marker, an index.html with this report's title)."""
    if (folder / MARKER).is_file():
        return True
    index = folder / "index.html"
    try:
        with open(index, encoding="utf-8", errors="replace") as f:
            return "<title>roughscope report</title>" in f.read(4096)
    except OSError:
        return False


def write_report(out):
    """Build the report in a temporary folder beside `out`, then move it into place.

    `out` is replaced as a whole only when it is missing, empty or a report written before (it
    holds MARKER); a folder holding anything else is refused, so that no file of the user's is
    ever removed. A symbolic link to a folder is followed. Returns the final path of index.html.
    """
    out = pathlib.Path(os.path.realpath(out))
    if out.exists():
        if not out.is_dir():
            raise NotADirectoryError(f"cannot write the report to {out}: it is not a folder")
        if any(out.iterdir()) and not _is_previous_report(out):
            raise FileExistsError(
                f"cannot write the report to {out}: the folder holds files that are not a "
                "roughscope report (it would be replaced as a whole); choose a new or empty folder")
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = pathlib.Path(tempfile.mkdtemp(prefix=f".{out.name}-tmp-", dir=out.parent))
    old = None
    try:
        build_report(tmp)
        (tmp / MARKER).write_text("written by python -m roughscope.report\n", encoding="utf-8")
        os.chmod(tmp, 0o755)
        if out.exists():
            old = pathlib.Path(tempfile.mkdtemp(prefix=f".{out.name}-old-", dir=out.parent))
            os.rmdir(old)
            os.replace(out, old)
        os.replace(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        if old is not None and old.exists() and not out.exists():
            os.replace(old, out)  # put the previous report back
        raise
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)
    return out / "index.html"


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python -m roughscope.report",
        description="Write the roughscope HTML report (figures and checks of the paper).")
    parser.add_argument("--out", default="out/report",
                        help="output folder (default: out/report); replaced as a whole when it "
                             "is new, empty or a previous report, refused otherwise")
    args = parser.parse_args(argv)
    try:
        index = write_report(args.out)
    except Exception as exc:  # one line, no traceback: this is a command-line tool
        print(f"roughscope.report: error: {one_line_error(exc)}", file=sys.stderr)
        return 1
    print(index)
    return 0


if __name__ == "__main__":
    sys.exit(main())
