"""Tests of `roughscope surface stats|generate|convert|predict`.

Each success test has a failure companion asserting the exit code and the one-line message.
Numbers are checked against the truth a generated surface was made with (σ, T), against the
library's scattering functions through the Python module (the same code, another front end), and
against the documented key list. The CLI is found by conftest.cli_path.
"""

import json
import math
import os
import re
import subprocess

import numpy as np
import pytest

import roughscope as rs
from conftest import cli_path

pytestmark = pytest.mark.cli

EXIT_USAGE, EXIT_DATA = 2, 4
NAN_RE = re.compile(r"\b(nan|inf|infinity)\b", re.IGNORECASE)

STATS_KEYS = ["file", "format", "nx", "ny", "dx_um", "dy_um", "leveling", "polynomial_order",
              "cutoff_um", "acf_estimator", "points", "sigma_um", "sigma_stderr_um", "Sa_um",
              "Ssk", "Sku", "Sp_um", "Sv_um", "Sz_um", "T_um", "T_y_um", "T_stderr_um",
              "T_fit_gaussian_um", "T_fit_exponential_um", "correlation", "T_extrapolated_um",
              "period_um", "period_y_um", "Sal_um", "Str", "Str_note", "rms_slope",
              "rms_slope_y", "Sdq", "m_from_T", "warnings"]


def run(*args, check=True, cwd=None):
    proc = subprocess.run([cli_path(), *map(str, args)], capture_output=True, text=True,
                          timeout=300, cwd=cwd)
    if check:
        assert proc.returncode == 0, f"exit {proc.returncode}: {proc.stderr}"
    assert not NAN_RE.search(proc.stdout), proc.stdout
    return proc


def assert_error(proc, code, *needles):
    assert proc.returncode == code, (proc.returncode, proc.stderr)
    assert proc.stdout == ""
    lines = proc.stderr.strip("\n").split("\n")
    assert len(lines) == 1 and lines[0].startswith("roughscope: error: "), proc.stderr
    for n in needles:
        assert n in lines[0], (n, lines[0])


def generate(path, correlation="gaussian", sigma=0.5, T=8.0, n=256, seed=3, extra=()):
    run("surface", "generate", "--correlation", correlation, "--sigma-um", sigma, "--T-um", T,
        "--nx", n, "--ny", n, "--dx-um", 1, "--seed", seed, "--out", path, *extra)
    return path


@pytest.fixture(scope="module")
def gaussian_x3p(tmp_path_factory):
    return generate(tmp_path_factory.mktemp("surf") / "g.x3p")


# ---- generate ------------------------------------------------------------------------------

def test_generate_writes_a_reproducible_surface(tmp_path):
    a = generate(tmp_path / "a.gsf", n=32, seed=7)
    b = generate(tmp_path / "b.gsf", n=32, seed=7)
    c = generate(tmp_path / "c.gsf", n=32, seed=8)
    za, zb, zc = (rs.read_height_map(str(p))["heights_um"] for p in (a, b, c))
    assert za.shape == (32, 32)
    assert np.array_equal(za, zb)
    assert not np.array_equal(za, zc)


def test_generate_json_summary(tmp_path):
    out = run("surface", "generate", "--nx", 16, "--ny", 8, "--dx-um", 0.5, "--T-um", 2, "--out",
              tmp_path / "s.gsf", "--json").stdout
    summary = json.loads(out)
    assert (summary["nx"], summary["ny"], summary["dx_um"], summary["dy_um"]) == (16, 8, 0.5, 0.5)
    assert summary["missing"] == 0


@pytest.mark.parametrize("args,code,needles", [
    (["--sigma-um", "0"], EXIT_USAGE, ["--sigma-um", "> 0"]),
    (["--T-um", "-3"], EXIT_USAGE, ["--T-um", "> 0"]),
    (["--nx", "0"], EXIT_USAGE, ["--nx", "[1,"]),
    (["--nx", "2.5"], EXIT_USAGE, ["--nx"]),
    (["--correlation", "lorentz"], EXIT_USAGE, ["--correlation", "gaussian"]),
    (["--seed", "-1"], EXIT_USAGE, ["--seed"]),
], ids=["sigma", "T", "nx", "nx-real", "correlation", "seed"])
def test_generate_rejects_bad_flags(tmp_path, args, code, needles):
    out = tmp_path / "x.gsf"
    proc = run("surface", "generate", "--nx", 8, "--ny", 8, "--out", out, *args, check=False)
    assert_error(proc, code, *needles)
    assert not out.exists()


def test_generate_needs_out_and_a_known_extension(tmp_path):
    assert_error(run("surface", "generate", check=False), EXIT_USAGE, "--out")
    proc = run("surface", "generate", "--nx", 8, "--ny", 8, "--out", tmp_path / "x.unknown",
               check=False)
    assert proc.returncode == EXIT_USAGE, proc.stderr
    assert not (tmp_path / "x.unknown").exists()


# ---- stats ---------------------------------------------------------------------------------

def test_stats_json_keys_and_round_trip_recovers_sigma_and_T(gaussian_x3p):
    doc = json.loads(run("surface", "stats", gaussian_x3p, "--json").stdout)
    assert list(doc) == ["roughscope_version", *STATS_KEYS]
    assert doc["format"] == "x3p" and doc["nx"] == 256 and doc["points"] == 256 * 256
    # Truth σ = 0.5 µm, T = 8 µm (L/T = 32: the 1/e T is biased low by a few per cent).
    assert abs(doc["sigma_um"] - 0.5) < 0.05
    assert abs(doc["T_um"] - 8.0) < 1.0
    assert abs(doc["T_fit_gaussian_um"] - 8.0) < 1.0
    assert doc["correlation"] == "gaussian"
    # m = σ√2/T and the finite-difference slope agree for Gaussian correlation (§4).
    assert doc["m_from_T"] == pytest.approx(doc["sigma_um"] * math.sqrt(2) / doc["T_um"])
    assert doc["rms_slope"] == pytest.approx(doc["m_from_T"], rel=0.1)


def test_stats_exponential_round_trip(tmp_path):
    path = generate(tmp_path / "e.x3p", correlation="exponential", sigma=0.3, T=6.0, n=256)
    doc = json.loads(run("surface", "stats", path, "--json").stdout)
    assert abs(doc["sigma_um"] - 0.3) < 0.04
    assert abs(doc["T_um"] - 6.0) < 1.2
    assert doc["correlation"] == "exponential"


def test_stats_text_labels_each_slope_for_what_it_is(tmp_path):
    # A sinusoid along x plus a weaker one along y, not levelled, sampled finely: Rdq along x and
    # along y and the areal Sdq of ISO 25178-2 = √(Rdq_x² + Rdq_y²) are three different numbers,
    # each printed on its own line under its own name (no longer Rdq labelled "Sdq").
    dx, lx, ly = 0.25, 64.0, 40.0
    x = np.arange(1024) * dx
    y = np.arange(640) * dx
    z = 0.8 * np.sin(2 * np.pi * x / lx)[None, :] + 0.5 * np.sin(2 * np.pi * y / ly)[:, None]
    path = tmp_path / "sines.gsf"
    rs.write_height_map(z, dx, path=str(path))
    doc = json.loads(run("surface", "stats", path, "--level", "none", "--json").stdout)
    kx, ky = 2 * np.pi / lx, 2 * np.pi / ly
    assert doc["rms_slope"] == pytest.approx(0.8 * kx / math.sqrt(2), rel=2e-3)
    assert doc["rms_slope_y"] == pytest.approx(0.5 * ky / math.sqrt(2), rel=2e-3)
    assert doc["Sdq"] == pytest.approx(math.hypot(0.8 * kx, 0.5 * ky) / math.sqrt(2), rel=2e-3)
    text = run("surface", "stats", path, "--level", "none").stdout
    lines = {line.split("  ")[0]: line.split()[-1] for line in text.splitlines() if "  " in line}
    assert float(lines["RMS slope along x (Rdq)"]) == pytest.approx(doc["rms_slope"], rel=1e-5)
    assert float(lines["RMS slope along y (Rdq)"]) == pytest.approx(doc["rms_slope_y"], rel=1e-5)
    assert float(lines["RMS gradient (Sdq)"]) == pytest.approx(doc["Sdq"], rel=1e-5)
    assert "RMS slope (Sdq)" not in text


def test_stats_periodic_surface_reports_its_period_and_why_str_is_missing(tmp_path):
    # Ridges along y with a 32 um period on a random surface: the period is found along x,
    # the text says so, Str is missing with its reason, and a warning says what was assumed.
    z = rs.generate_surface(sigma_um=1.0, T_um=8.0, nx=256, ny=256, dx_um=1.0, seed=5)
    z = z + 1.5 * np.sin(2 * np.pi * np.arange(256) / 32.0)[None, :]
    path = tmp_path / "lay.gsf"
    rs.write_height_map(z, 1.0, path=str(path))
    doc = json.loads(run("surface", "stats", path, "--json").stdout)
    assert doc["period_um"] == pytest.approx(32.0, rel=0.03)
    assert doc["period_y_um"] is None
    assert doc["Str"] is None and "stays above 0.2" in doc["Str_note"]
    assert any("periodic" in w for w in doc["warnings"])
    text = run("surface", "stats", path).stdout
    assert re.search(r"period \(ACF, x\)\s+32\.\d+ um", text), text
    assert re.search(r"Str\s+- \(the ACF stays above 0\.2", text), text


def test_stats_text_and_options(gaussian_x3p, tmp_path):
    text = run("surface", "stats", gaussian_x3p).stdout
    assert "sigma (Sq)" in text and "T (1/e, x)" in text
    doc = json.loads(run("surface", "stats", gaussian_x3p, "--level", "polynomial", "--order", 2,
                         "--cutoff-um", 80, "--acf", "biased", "--json").stdout)
    assert (doc["leveling"], doc["polynomial_order"], doc["cutoff_um"], doc["acf_estimator"]) == \
        ("polynomial", 2, 80, "biased")
    out = tmp_path / "s.json"
    assert run("surface", "stats", gaussian_x3p, "--json", "--output", out).stdout == ""
    assert json.loads(out.read_text())["nx"] == 256


@pytest.mark.parametrize("args,code,needles", [
    (["--level", "cubic"], EXIT_USAGE, ["--level"]),
    (["--order", "4", "--level", "polynomial"], EXIT_USAGE, ["--order", "[1, 3]"]),
    (["--order", "2"], EXIT_USAGE, ["--order", "--level polynomial"]),
    (["--cutoff-um", "0"], EXIT_USAGE, ["--cutoff-um", "> 0"]),
    (["--acf", "fast"], EXIT_USAGE, ["--acf"]),
    (["--format", "bmp"], EXIT_USAGE, ["--format"]),
], ids=["level", "order-range", "order-needs-polynomial", "cutoff", "acf", "format"])
def test_stats_rejects_bad_flags(gaussian_x3p, args, code, needles):
    assert_error(run("surface", "stats", gaussian_x3p, *args, check=False), code, *needles)


def test_stats_missing_or_malformed_file(tmp_path):
    assert_error(run("surface", "stats", "none.x3p", check=False, cwd=tmp_path), EXIT_DATA,
                 "none.x3p")
    (tmp_path / "bad.x3p").write_bytes(b"not a zip at all")
    assert_error(run("surface", "stats", "bad.x3p", check=False, cwd=tmp_path), EXIT_DATA,
                 "bad.x3p")


def test_stats_plot(gaussian_x3p, tmp_path):
    pytest.importorskip("matplotlib")
    out = tmp_path / "report.png"
    run("surface", "stats", gaussian_x3p, "--plot", out)
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_stats_plot_needs_png(gaussian_x3p, tmp_path):
    assert_error(run("surface", "stats", gaussian_x3p, "--plot", tmp_path / "r.pdf", check=False),
                 EXIT_USAGE, "--plot", ".png")
    assert not (tmp_path / "r.pdf").exists()


# ---- convert -------------------------------------------------------------------------------

@pytest.mark.parametrize("ext", ["x3p", "gsf", "csv"])
def test_convert_round_trip_is_bit_exact(tmp_path, ext):
    # A surface written in the format (gsf holds float32: its values survive every later step),
    # converted to x3p (doubles) and back.
    first = generate(tmp_path / f"first.{ext}", n=48)
    mid, back = tmp_path / "mid.x3p", tmp_path / f"back.{ext}"
    run("surface", "convert", first, mid)
    run("surface", "convert", mid, back)
    a = rs.read_height_map(str(first))
    b = rs.read_height_map(str(back))
    assert a["heights_um"].tobytes() == b["heights_um"].tobytes()
    assert (a["dx_um"], a["dy_um"]) == (b["dx_um"], b["dy_um"])


def test_convert_failures(gaussian_x3p, tmp_path):
    assert_error(run("surface", "convert", "none.gsf", "o.x3p", check=False, cwd=tmp_path),
                 EXIT_DATA, "none.gsf")
    assert_error(run("surface", "convert", gaussian_x3p, tmp_path / "o.gwy", check=False),
                 EXIT_USAGE, "gwy")
    assert not (tmp_path / "o.gwy").exists()
    assert_error(run("surface", "convert", gaussian_x3p, "no/o.gsf", check=False, cwd=tmp_path),
                 EXIT_DATA, "o.gsf")


def stale_checksum_copy(source, path):
    """`source` (an x3p) with one byte of bindata/data.bin changed and main.xml untouched: its
    MD5ChecksumPointData no longer matches, as in a file edited after it was written."""
    import zipfile
    with zipfile.ZipFile(source) as zin, zipfile.ZipFile(path, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename.endswith("data.bin"):
                data = data[:100] + bytes([data[100] ^ 0x01]) + data[101:]
            zout.writestr(item, data)
    return path


def test_a_stale_x3p_checksum_is_an_error_unless_not_verified(gaussian_x3p, tmp_path):
    stale = stale_checksum_copy(gaussian_x3p, tmp_path / "stale.x3p")
    for command in (["stats"], ["convert"], ["predict"]):
        extra = {"stats": [], "convert": [tmp_path / "o.gsf"],
                 "predict": ["--theta-i", 20, "--theta-s", 0, "--phi-s", 180]}[command[0]]
        assert_error(run("surface", *command, stale, *extra, check=False), EXIT_DATA,
                     "stale.x3p", "checksum mismatch", "MD5ChecksumPointData")
        run("surface", *command, stale, *extra, "--no-verify-checksums")
    assert (tmp_path / "o.gsf").exists()
    with pytest.raises(rs.DataError, match="checksum mismatch"):
        rs.read_height_map(str(stale))
    lax = rs.read_height_map(str(stale), verify_checksums=False)
    good = rs.read_height_map(str(gaussian_x3p))
    # One byte of one height differs; every other height is the file's.
    assert np.count_nonzero(lax["heights_um"] != good["heights_um"]) == 1


# ---- predict -------------------------------------------------------------------------------

def test_predict_given_matches_the_model():
    doc = json.loads(run("surface", "predict", "--sigma-um", 0.1, "--T-um", 2, "--theta-i",
                         "10,30", "--theta-s", 0, "--phi-s", 0, "--json").stdout)
    assert doc["source"] == "given" and doc["correlation"] == "gaussian"
    assert doc["g_normal"] == pytest.approx((4 * math.pi * 0.1 / 0.555) ** 2, rel=1e-12)
    assert doc["roughness_class"] == "moderately_rough"
    expected = rs.mean_scattered_power(np.array([10.0, 30.0]), 0.0, 0.0, 0.1, 2.0)
    got = [p["brightness"] for p in doc["points"]]
    assert got == pytest.approx(list(np.asarray(expected["brightness"])), rel=1e-15)


def test_predict_from_file_uses_its_statistics(gaussian_x3p):
    stats = json.loads(run("surface", "stats", gaussian_x3p, "--json").stdout)
    doc = json.loads(run("surface", "predict", gaussian_x3p, "--theta-i", 20, "--theta-s", 0,
                         "--phi-s", 0, "--wavelength-um", 10.6, "--json").stdout)
    assert doc["source"] == str(gaussian_x3p) and doc["T_source"] == "T_um"
    assert doc["sigma_um"] == stats["sigma_um"] and doc["T_um"] == stats["T_um"]
    assert doc["wavelength_um"] == 10.6
    assert doc["roughness_class"] == "moderately_rough"  # g = (4π·0.49/10.6)² ≈ 0.34
    text = run("surface", "predict", gaussian_x3p, "--theta-i", 20, "--theta-s", 0, "--phi-s",
               0).stdout
    assert "roughness class" in text and "very_rough" in text


@pytest.mark.parametrize("args,code,needles", [
    (["--sigma-um", "0.1", "--theta-i", "10", "--theta-s", "0", "--phi-s", "0"], EXIT_USAGE,
     ["--sigma-um", "--T-um"]),
    (["--sigma-um", "0.1", "--T-um", "2", "--theta-s", "0", "--phi-s", "0"], EXIT_USAGE,
     ["--theta-i"]),
    (["--sigma-um", "0.1", "--T-um", "2", "--theta-i", "95", "--theta-s", "0", "--phi-s", "0"],
     EXIT_USAGE, ["--theta-i", "[0, 90)"]),
    (["--sigma-um", "0.1", "--T-um", "2", "--theta-i", "10,20", "--theta-s", "0,1,2",
      "--phi-s", "0"], EXIT_USAGE, ["--theta-i", "2 values", "give 1 or 3"]),
    (["--sigma-um", "0.1", "--T-um", "2", "--theta-i", "10", "--theta-s", "0", "--phi-s", "0",
      "--wavelength-um", "0"], EXIT_USAGE, ["--wavelength-um"]),
], ids=["no-T", "no-theta-i", "theta-range", "lengths", "wavelength"])
def test_predict_rejects_bad_flags(args, code, needles):
    assert_error(run("surface", "predict", *args, check=False), code, *needles)


def test_predict_file_excludes_given_values(gaussian_x3p):
    assert_error(run("surface", "predict", gaussian_x3p, "--sigma-um", 1, "--T-um", 2,
                     "--theta-i", 10, "--theta-s", 0, "--phi-s", 0, check=False), EXIT_USAGE,
                 "FILE excludes")


def test_surface_needs_a_subcommand():
    proc = run("surface", check=False)
    assert proc.returncode == EXIT_USAGE


MEASURE = """
import resource, subprocess, sys
p = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
sys.stderr.buffer.write(p.stderr)
print(p.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
"""


@pytest.mark.skipif(os.environ.get("ROUGHSCOPE_SANITIZED") == "1",
                    reason="memory is not measured under AddressSanitizer")
def test_stats_peak_memory_is_at_most_six_copies_of_the_map(tmp_path):
    # 2048² float64 heights: one copy is 32 MiB; the 2-D ACF's padded array is ~4 copies and is
    # also where the ACF is left (no second array), and the map is levelled in place.
    import sys

    n = 2048
    path = tmp_path / "big.gsf"
    run("surface", "generate", "--sigma-um", "0.5", "--T-um", "8", "--nx", n, "--ny", n,
        "--dx-um", "1", "--seed", "2", "--out", path)
    baseline = subprocess.run([sys.executable, "-c", MEASURE, cli_path(), "--version"],
                              capture_output=True, text=True, timeout=60)
    base_kb = int(baseline.stdout.split()[1])
    p = subprocess.run([sys.executable, "-c", MEASURE, cli_path(), "surface", "stats", str(path),
                        "--json"], capture_output=True, text=True, timeout=600)
    code, peak_kb = (int(v) for v in p.stdout.split())
    assert code == 0, p.stderr
    copy_kb = n * n * 8 / 1024
    assert (peak_kb - base_kb) / copy_kb <= 6.0, \
        f"peak {peak_kb / 1024:.0f} MiB = {(peak_kb - base_kb) / copy_kb:.2f} copies"
