"""Peak memory of `roughscope measure` on a pair of large photographs.

Each capture is read, measured and released by one thread; on two or more cores both captures of
the pair are in flight at once (MeasureRequest::threads), so the peak is about two decoded images
and their flags, the region's mask and the two mapped files, not more. A 12-MP pair of 16-bit TIFFs is written with
`roughscope simulate capture`; the measurement runs from a fresh interpreter that reports the
peak resident set size of its child (getrusage(RUSAGE_CHILDREN).ru_maxrss). The limit: 6× one
decoded float image (12 MP × 4 bytes). Under ROUGHSCOPE_SANITIZED=1 (the ASan build, whose
allocator keeps freed memory in quarantine, so nothing could be asserted) the test is skipped.
"""

import json
import os
import subprocess
import sys

import pytest

from conftest import cli_path

SANITIZED = os.environ.get("ROUGHSCOPE_SANITIZED") == "1"
WIDTH, HEIGHT = 4240, 2832  # 12.0 MP

MEASURE = """
import resource, subprocess, sys
p = subprocess.run(sys.argv[1:], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
sys.stderr.buffer.write(p.stderr)
print(p.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
"""


pytestmark = pytest.mark.skipif(SANITIZED, reason="ASan's quarantine: peak memory says nothing")


@pytest.fixture(scope="module")
def large_pair(tmp_path_factory):
    folder = tmp_path_factory.mktemp("large")
    captures = []
    for k, theta in enumerate((30.0, 45.0)):
        out = folder / f"c{k}"
        subprocess.run([cli_path(), "simulate", "capture", "--width", str(WIDTH), "--height",
                        str(HEIGHT), "--theta-i", str(theta), "--bits", "16", "--format", "tiff",
                        "--gain", "1", "--seed", str(k + 1), "--out",
                        str(out)], check=True, capture_output=True, timeout=600)
        image = next(p for p in out.iterdir() if p.suffix == ".tiff")
        captures.append({"image": str(image), "theta_i_deg": theta, "exposure_s": 1.0})
    spec = {"response": "linear", "black_level_dn": 64,
            "roi": {"rect": [100, 100, WIDTH - 200, HEIGHT - 200]}, "captures": captures}
    path = folder / "capture-file.json"
    path.write_text(json.dumps(spec))
    return path


def test_measure_peak_memory_is_a_few_decoded_images(large_pair):
    p = subprocess.run([sys.executable, "-c", MEASURE, cli_path(), "measure", str(large_pair),
                        "--json"], capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stderr
    code, peak_kb = (int(v) for v in p.stdout.split())
    assert code == 0, p.stderr
    one_image_kb = WIDTH * HEIGHT * 4 / 1024
    print(f"peak RSS {peak_kb / 1024:.0f} MiB = {peak_kb / one_image_kb:.2f} x one decoded image")
    assert peak_kb <= 6 * one_image_kb, (
        f"peak RSS {peak_kb / 1024:.0f} MiB > 6 x {one_image_kb / 1024:.0f} MiB")


def test_the_tool_starts_small():
    """`roughscope --version` stays far below 40 MiB: the image topic links libpng, libtiff,
    libjpeg, LibRaw and OpenCV's core/imgproc/photo only. OpenCV's imgcodecs would load GDAL,
    HEIF, OpenEXR and ~100 other libraries into every command (55 MiB measured)."""
    p = subprocess.run([sys.executable, "-c", MEASURE, cli_path(), "--version"],
                       capture_output=True, text=True, timeout=60)
    code, peak_kb = (int(v) for v in p.stdout.split())
    assert code == 0, p.stderr
    assert peak_kb <= 40 * 1024, f"roughscope --version peak RSS {peak_kb / 1024:.0f} MiB"
