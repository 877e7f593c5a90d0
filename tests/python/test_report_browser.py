"""The HTML report of a measurement in a real browser (Debian's Chromium, headless).

A copy of the page gets a probe script first in <head>: it records console errors and failed
loads, and on `load` writes the number of images, the ones that did not decode and the errors
into an attribute of <body>, which `--dump-dom` prints. The companion test feeds the probe a page
with a broken image and a script error, so a probe that sees nothing cannot pass.
"""

import html
import json
import pathlib
import re
import shutil
import subprocess

import pytest

from conftest import cli_path

PROBE = """<script>
window.__probeErrors = [];
(function () {
  const original = console.error;
  console.error = function (...args) { window.__probeErrors.push(args.join(' ')); original.apply(console, args); };
  window.addEventListener('error', function (e) {
    window.__probeErrors.push('error: ' + (e.message || (e.target && (e.target.src || e.target.href)) || 'load'));
  }, true);
  window.addEventListener('load', function () {
    const images = Array.from(document.images);
    const bad = images.filter(function (i) { return !(i.complete && i.naturalWidth > 0); })
                      .map(function (i) { return i.alt || i.src.slice(0, 40); });
    document.body.setAttribute('data-probe', JSON.stringify(
      {images: images.length, bad: bad, errors: window.__probeErrors}));
  });
})();
</script>"""


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    pytest.fail("chromium not found: scripts/install-deps installs Debian's chromium")


def probe(page, tmp_path):
    """Load `page` (an HTML file) in headless Chromium; return the probe's findings."""
    text = pathlib.Path(page).read_text(encoding="utf-8")
    probed = tmp_path / "probe.html"
    probed.write_text(text.replace("<head>", "<head>" + PROBE, 1), encoding="utf-8")
    proc = subprocess.run(
        [chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
         "--no-first-run", "--disable-extensions", f"--user-data-dir={tmp_path / 'profile'}",
         "--virtual-time-budget=10000", "--dump-dom", probed.as_uri()],
        capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    match = re.search(r'data-probe="([^"]*)"', proc.stdout)
    assert match, f"the page did not finish loading: {proc.stdout[:500]} {proc.stderr[-1000:]}"
    return json.loads(html.unescape(match.group(1)))


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    from roughscope import demo

    folder = tmp_path_factory.mktemp("browser")
    capture_file = demo.write_sample(demo.SAMPLES[0], folder)
    out = folder / "report"
    proc = subprocess.run([cli_path(), "measure", str(capture_file), "--report", str(out)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return out / "index.html"


def test_measurement_report_loads_every_image_without_console_errors(report, tmp_path):
    found = probe(report, tmp_path)
    assert found["images"] == 3, found  # the two photographs and the uncertainty budget
    assert found["bad"] == [], found
    assert found["errors"] == [], found


def test_probe_sees_a_broken_image_and_a_script_error(tmp_path):
    page = tmp_path / "broken.html"
    page.write_text("<!DOCTYPE html><html><head><title>t</title></head><body>"
                    "<img alt='broken' src='data:image/png;base64,AAAA'>"
                    "<script>console.error('boom')</script></body></html>", encoding="utf-8")
    found = probe(page, tmp_path)
    assert found["images"] == 1
    assert found["bad"] == ["broken"]
    assert any("boom" in e for e in found["errors"])
