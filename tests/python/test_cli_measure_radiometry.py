"""`roughscope measure` never returns a confident wrong number from how the photographs were
recorded (docs/measure.md "The capture file", docs/image.md): a dark frame or flat field recorded
unlike the captures is refused; an 8-bit file declared linear and a linear file read with black
level 0 give a warning saying what was assumed; captures without exposure times are compared only
when the capture file says the exposures are equal; a RAW file that records no exposure time
reports it as unknown; a lossy DNG (processed 8-bit data) carries a warning.

The photographs are synthetic captures of known σ/T = 0.3 (the simulation topic's camera,
roughscope._core.write_capture, 64 x 64 pixels). The real RAW files are ../shared/data/raw (see
its README; skipped when absent, failing under ROUGHSCOPE_REQUIRE_SHARED_DATA=1).
"""

import json
import pathlib
import subprocess

import pytest

import roughscope._core as core
from conftest import REPO_ROOT, cli_path, need_shared

TRUTH = 0.30
FULL_WELL = 60000.0
# (bits, response, black level DN)
SRGB8 = (8, "srgb", 0.0)
LINEAR16 = (16, "linear", 64.0)


def camera(kind):
    bits, response, black = kind
    white = 2.0 ** bits - 1.0
    return dict(bits=bits, response=response, black_level=black, full_well_e=FULL_WELL,
                gain=1.05 * (white - black) / FULL_WELL, electrons_per_unit_s=20000.0)


def photograph(folder, name, kind, theta_i_deg=30.0, exposure_s=1.0, dark=False):
    """A synthetic photograph of the plane lit at θi (or, dark, of no light); its path."""
    sub = pathlib.Path(folder) / name
    sub.mkdir(parents=True, exist_ok=True)
    surface = (dict(brightness=[lambda *_: 0.0]) if dark else
               dict(sigma_over_T=TRUTH, correlation="gaussian"))
    core.write_capture(str(sub), "png", scene="plane", width=64, height=64,
                       theta_i_deg=theta_i_deg, exposure_s=exposure_s,
                       seed=int(theta_i_deg) + 7 * len(name), **surface, **camera(kind))
    return f"{name}/capture.png"


def pair(folder, kind, exposures=(1.0, 0.5)):
    return [photograph(folder, f"c{k}", kind, theta, t)
            for k, (theta, t) in enumerate(zip((30.0, 45.0), exposures))]


def capture_file(folder, images, name="capture-file.json", exposures=None, **keys):
    captures = []
    for k, (image, theta) in enumerate(zip(images, (30.0, 45.0))):
        c = {"image": image, "theta_i_deg": theta}
        if exposures is not None:
            c["exposure_s"] = exposures[k]
        captures.append(c)
    doc = {"roi": {"rect": [8, 8, 48, 48]}, "captures": captures, **keys}
    path = pathlib.Path(folder) / name
    path.write_text(json.dumps(doc))
    return path


def measure(path, *args):
    return subprocess.run([cli_path(), "measure", str(path), *args], capture_output=True,
                          text=True, timeout=120)


def measured(path):
    proc = measure(path, "--json")
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


def error_line(proc, code):
    assert proc.returncode == code, (proc.returncode, proc.stderr)
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("roughscope: error: "), proc.stderr
    return lines[0]


def near_truth(doc):
    value, err = doc["sigma_over_T_gaussian"], doc["sigma_over_T_gaussian_stderr"]
    return abs(value - TRUTH) <= max(4 * err, 0.01)


# ---- dark frames and flat fields recorded unlike the captures ----------------------------------

def test_a_16_bit_dark_frame_of_8_bit_captures_is_refused(tmp_path):
    # An 8-bit sRGB camera whose offset is 8 DN (of its linear signal, before the encoding).
    camera8 = (8, "srgb", 8.0)
    images = pair(tmp_path, camera8)
    # The offset recorded as a 16-bit linear dark frame (8 · 257 DN): the capture file's
    # "response": "srgb" would decode it as sRGB, far from the offset the captures hold.
    dark16 = photograph(tmp_path, "dark16", (16, "linear", 8 * 257.0), dark=True)
    path = capture_file(tmp_path, images, exposures=(1.0, 0.5), response="srgb",
                        dark_frame=dark16)
    line = error_line(measure(path), 4)
    assert f"{path}: dark_frame: " in line, line
    assert "16-bit srgb PNG" in line and "8-bit srgb PNG" in line, line
    # Recorded as the captures are: accepted, and the truth comes back.
    dark8 = photograph(tmp_path, "dark8", camera8, dark=True)
    doc = measured(capture_file(tmp_path, images, "ok.json", exposures=(1.0, 0.5),
                                response="srgb", dark_frame=dark8))
    assert near_truth(doc), doc["sigma_over_T_gaussian"]


def test_a_flat_field_of_another_response_is_refused(tmp_path):
    images = pair(tmp_path, LINEAR16)
    flat = photograph(tmp_path, "flat8", SRGB8, theta_i_deg=0.0)
    path = capture_file(tmp_path, images, exposures=(1.0, 0.5), black_level_dn=64,
                        flat_field=flat)
    line = error_line(measure(path), 4)
    assert f"{path}: flat_field: " in line and "8-bit" in line and "16-bit" in line, line


# ---- what was assumed about the response and the black level -----------------------------------

def test_an_8_bit_pair_declared_linear_warns(tmp_path):
    images = pair(tmp_path, SRGB8, exposures=(1.0, 1.0))
    doc = measured(capture_file(tmp_path, images, exposures=(1.0, 1.0), response="linear"))
    # The sRGB pair read as linear is far off the truth (0.44): the number alone cannot tell.
    assert doc["sigma_over_T_gaussian"] > TRUTH + 0.1
    warnings = [w for w in doc["warnings"] if "8-bit file read as linear" in w]
    assert len(warnings) == 2 and "\"srgb\"" in warnings[0], doc["warnings"]
    # Declared as recorded: the truth and no such warning.
    doc = measured(capture_file(tmp_path, images, "srgb.json", exposures=(1.0, 1.0),
                                response="srgb"))
    assert near_truth(doc) and not any("read as linear" in w for w in doc["warnings"])


def test_a_16_bit_pair_without_a_black_level_warns(tmp_path):
    images = pair(tmp_path, LINEAR16)
    doc = measured(capture_file(tmp_path, images, exposures=(1.0, 0.5)))
    warnings = [w for w in doc["warnings"] if "black level 0 assumed" in w]
    assert len(warnings) == 2 and "16-bit linear" in warnings[0], doc["warnings"]
    assert "black_level_dn" in warnings[0] and images[0] in warnings[0]
    # The camera's black level given: the truth, no warning.
    doc = measured(capture_file(tmp_path, images, "black.json", exposures=(1.0, 0.5),
                                black_level_dn=64))
    assert near_truth(doc) and not any("black level 0" in w for w in doc["warnings"])


# ---- exposure times ----------------------------------------------------------------------------

def test_captures_without_exposure_times_are_refused_unless_declared_equal(tmp_path):
    # Taken at 1 s and 0.5 s, no exposure given anywhere: the ratio would be off by 2.
    images = pair(tmp_path, LINEAR16)
    path = capture_file(tmp_path, images, black_level_dn=64)
    line = error_line(measure(path), 4)
    assert f"{path}: exposures_equal: " in line and "exposure_s" in line, line
    # The exposures given: the truth.
    assert near_truth(measured(capture_file(tmp_path, images, "t.json", exposures=(1.0, 0.5),
                                            black_level_dn=64)))
    # Equal exposures declared: compared as equal, and said so per capture.
    same = pair(tmp_path / "same", LINEAR16, exposures=(1.0, 1.0))
    doc = measured(capture_file(tmp_path / "same", same, exposures_equal=True,
                                black_level_dn=64))
    assert near_truth(doc)
    assert [c["exposure_source"] for c in doc["captures"]] == ["equal (exposures_equal)"] * 2
    # Declared equal, but the capture file gives different times: refused.
    path = capture_file(tmp_path, images, "both.json", exposures=(1.0, 0.5),
                        exposures_equal=True, black_level_dn=64)
    assert f"{path}: exposures_equal: " in error_line(measure(path), 4)


def test_a_raw_file_without_exposure_metadata_reports_it_unknown():
    # colorchart.dng records ExposureTime 0/1000000 and FNumber 0/10 (none); LibRaw falls back on
    # the APEX values 0, i.e. 1 s and f/1. IMG_5952.CR2: 1/400 s, f/22, ISO 640 (the README).
    raw = need_shared(core.find_shared("data/raw", [REPO_ROOT]), "data/raw")
    info = core.read_image(str(pathlib.Path(raw) / "colorchart.dng"))["info"]
    assert info["exposure_s"] is None and info["f_number"] is None and info["iso"] is None
    info = core.read_image(str(pathlib.Path(raw) / "IMG_5952.CR2"))["info"]
    assert info["exposure_s"] == pytest.approx(1 / 400, rel=1e-6)
    assert info["f_number"] == pytest.approx(22) and info["iso"] == pytest.approx(640)


# ---- camera files that are not sensor data -----------------------------------------------------

def test_a_lossy_dng_carries_a_warning_that_its_values_are_processed():
    raw = pathlib.Path(need_shared(core.find_shared("data/raw", [REPO_ROOT]), "data/raw"))
    info = core.read_image(str(raw / "canon_eos_6d.dng"))["info"]
    assert any("lossy DNG" in w and "not linear sensor counts" in w for w in info["warnings"])
    assert "processed" in info["file_response_evidence"]
    for real in ("colorchart.dng", "IMG_5952.CR2"):
        assert core.read_image(str(raw / real))["info"]["warnings"] == [], real
