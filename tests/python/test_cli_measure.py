"""Tests of `roughscope measure CAPTURE.json` (roughness from photographs, docs/measure.md).

The photographs are synthetic captures of known σ/T (roughscope.demo.write_sample:
the simulation topic's camera, written as 16-bit linear TIFF, 8-bit sRGB PNG or DNG). Each
success test has a failure companion asserting the exit code and the one-line message.
"""

import json
import os
import pathlib
import subprocess

import pytest

from conftest import cli_path

EXIT_USAGE, EXIT_NO_SOLUTION, EXIT_DATA = 2, 3, 4

HEADLINE = ["E1_over_E2", "sigma_over_T_gaussian", "sigma_over_T_exponential", "sigma_um",
            "T_um", "theta_K_deg", "xi_K"]


def run(*args, check=True, cwd=None):
    proc = subprocess.run([cli_path(), "measure", *map(str, args)], capture_output=True,
                          text=True, timeout=300, cwd=cwd)
    if check:
        assert proc.returncode == 0, f"exit {proc.returncode}: {proc.stderr}"
    return proc


def fails(code, *args, cwd=None):
    proc = run(*args, check=False, cwd=cwd)
    assert proc.returncode == code, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("roughscope: error: "), proc.stderr
    assert proc.stdout == ""
    return lines[0]


@pytest.fixture(scope="module", params=[0, 1, 2], ids=["srgb8-png", "linear16-tiff", "dng"])
def sample(request, tmp_path_factory):
    from roughscope import demo

    spec = demo.SAMPLES[request.param]
    folder = tmp_path_factory.mktemp(spec["name"])
    return spec, demo.write_sample(spec, folder)


@pytest.fixture(scope="module")
def linear_sample(tmp_path_factory):
    from roughscope import demo

    spec = demo.SAMPLES[1]
    return spec, demo.write_sample(spec, tmp_path_factory.mktemp("linear"))


def edited(capture_file, tmp_path, change):
    """A copy of the capture file (same folder, so relative image paths hold) after change(doc)."""
    doc = json.loads(pathlib.Path(capture_file).read_text())
    change(doc)
    path = pathlib.Path(capture_file).parent / f"edited-{tmp_path.name}.json"
    path.write_text(json.dumps(doc))
    return path


def test_json_recovers_the_truth_with_every_headline_key(sample):
    spec, capture_file = sample
    doc = json.loads(run(capture_file, "--json").stdout)
    for key in HEADLINE:
        assert key in doc and key + "_stderr" in doc, key
    assert doc["roughness_class"] == "very_rough" and doc["roughness_class_assumed"] is True
    key = f"sigma_over_T_{spec['correlation']}"
    value, err = doc[key], doc[key + "_stderr"]
    assert err > 0
    # 4σ: a single draw (the ≥ 90 % coverage at 2σ is tests/cpp/measure/test_measure.cpp's).
    assert abs(value - spec["sigma_over_T"]) <= 4 * err, (value, err)
    # σ unknown: no σ, no T.
    assert doc["sigma_um"] is None and doc["T_um"] is None
    assert len(doc["captures"]) == 2
    assert doc["captures"][1]["exposure_source"] == "capture file"
    assert doc["captures"][0]["region"]["pixels_used"] > 0


def test_text_output_names_the_values(linear_sample):
    _, capture_file = linear_sample
    out = run(capture_file).stdout
    assert "E1/E2" in out and "sigma/T (Gaussian)" in out and "±" in out
    assert "nan" not in out.lower()


def test_output_file_is_written_and_stdout_stays_empty(linear_sample, tmp_path):
    _, capture_file = linear_sample
    target = tmp_path / "result.json"
    proc = run(capture_file, "--json", "--output", target)
    assert proc.stdout == ""
    assert json.loads(target.read_text())["E1_over_E2"] > 1


def test_output_into_a_missing_folder_fails_and_writes_nothing(linear_sample, tmp_path):
    _, capture_file = linear_sample
    target = tmp_path / "no" / "such" / "result.json"
    fails(EXIT_DATA, capture_file, "--json", "--output", target)
    assert not target.exists()


def test_known_sigma_gives_T(linear_sample, tmp_path):
    spec, capture_file = linear_sample
    path = edited(capture_file, tmp_path,
                  lambda d: d.update(sigma_um=0.5, sigma_um_stderr=0.01, regime="very_rough",
                                     correlation=spec["correlation"]))
    doc = json.loads(run(path, "--json").stdout)
    assert doc["sigma_um"] == pytest.approx(0.5)
    assert doc["T_um"] > 0 and doc["T_um_stderr"] > 0
    # With the very-rough form for T, T = σ / (σ/T) of the same correlation.
    key = f"sigma_over_T_{spec['correlation']}"
    assert doc["T_um"] == pytest.approx(0.5 / doc[key], rel=1e-6)
    assert doc["roughness_class"] == "very_rough" and doc["roughness_class_assumed"] is False


def test_known_sigma_with_the_slightly_rough_form_warns_when_g_is_large(linear_sample, tmp_path):
    spec, capture_file = linear_sample
    path = edited(capture_file, tmp_path,
                  lambda d: d.update(sigma_um=0.5, correlation=spec["correlation"]))
    doc = json.loads(run(path, "--json").stdout)
    assert any("g" in w and "rough" in w for w in doc["warnings"]), doc["warnings"]


def test_a_missing_capture_file_is_a_data_error(tmp_path):
    line = fails(EXIT_DATA, tmp_path / "nope.json")
    assert "nope.json" in line


def test_a_missing_image_names_it(linear_sample, tmp_path):
    _, capture_file = linear_sample
    path = edited(capture_file, tmp_path,
                  lambda d: d["captures"][1].update(image="missing-image.tiff"))
    line = fails(EXIT_DATA, path)
    assert "missing-image.tiff" in line


def test_an_unknown_key_names_it_and_the_valid_ones(linear_sample, tmp_path):
    _, capture_file = linear_sample
    path = edited(capture_file, tmp_path, lambda d: d.update(exposure=1))
    line = fails(EXIT_DATA, path)
    assert "exposure" in line and "valid keys" in line


def test_an_angle_out_of_range_is_named(linear_sample, tmp_path):
    _, capture_file = linear_sample
    path = edited(capture_file, tmp_path, lambda d: d["captures"][0].update(theta_i_deg=91))
    line = fails(EXIT_DATA, path)
    assert "theta_i_deg" in line and "[0, 90)" in line


def test_a_region_outside_the_image_is_a_bad_value_of_the_capture_file(linear_sample, tmp_path):
    _, capture_file = linear_sample
    path = edited(capture_file, tmp_path, lambda d: d.update(roi={"rect": [100, 100, 500, 500]}))
    line = fails(EXIT_DATA, path)
    assert f"{path}: roi: " in line and "outside" in line


def test_captures_of_different_sizes_are_a_data_error(linear_sample, tmp_path):
    from roughscope import _core

    _, capture_file = linear_sample
    folder = pathlib.Path(capture_file).parent / "small"
    folder.mkdir(exist_ok=True)
    _core.write_capture(str(folder), "tiff", scene="plane", width=40, height=40, theta_i_deg=45,
                        bits=16, seed=3)
    path = edited(capture_file, tmp_path,
                  lambda d: d["captures"][1].update(image="small/capture.tiff"))
    line = fails(EXIT_DATA, path)
    assert "same size" in line


def test_a_ratio_without_solution_is_exit_3(linear_sample, tmp_path):
    _, capture_file = linear_sample
    # The photographs swapped (the 45° image said to be lit at 30°): E1/E2 < 1, which no
    # very-rough model produces.
    def swap(d):
        a, b = d["captures"]
        a["image"], b["image"] = b["image"], a["image"]
        a["exposure_s"], b["exposure_s"] = b["exposure_s"], a["exposure_s"]

    path = edited(capture_file, tmp_path, swap)
    fails(EXIT_NO_SOLUTION, path)


def test_report_is_self_contained(linear_sample, tmp_path):
    _, capture_file = linear_sample
    out = tmp_path / "report"
    proc = run(capture_file, "--report", out)
    index = out / "index.html"
    text = index.read_text()
    # both photographs with the region, and the uncertainty budget
    assert text.count("data:image/png;base64,") == 3
    assert "σ/T" in text and "E1/E2" in text
    assert "src=\"http" not in text and "href=\"http" not in text
    assert "E1/E2" in proc.stdout


def test_report_into_a_file_fails_and_leaves_it(linear_sample, tmp_path):
    _, capture_file = linear_sample
    blocker = tmp_path / "file"
    blocker.write_text("keep")
    proc = run(capture_file, "--report", blocker / "report", check=False)
    assert proc.returncode != 0
    assert blocker.read_text() == "keep"


def test_three_captures_are_fitted(linear_sample, tmp_path):
    from roughscope import _core, demo

    spec, capture_file = linear_sample
    folder = pathlib.Path(capture_file).parent
    first = json.loads(pathlib.Path(capture_file).read_text())["captures"][0]
    (folder / "capture3").mkdir(exist_ok=True)
    _core.write_capture(str(folder / "capture3"), "tiff", scene="plane", width=demo.SIZE,
                        height=demo.SIZE, theta_i_deg=60.0, exposure_s=first["exposure_s"],
                        seed=99, **demo.surface_keywords(spec),
                        **demo.sample_camera(spec, electrons_per_unit_s=demo.lamp(spec)))
    path = edited(capture_file, tmp_path, lambda d: d["captures"].append(
        {"image": "capture3/capture.tiff", "theta_i_deg": 60.0,
         "exposure_s": first["exposure_s"]}))
    doc = json.loads(run(path, "--json").stdout)
    assert doc["sigma_over_T_source"] == "fit"
    assert len(doc["captures"]) == 3 and doc["fit"] is not None
    value, err = doc["sigma_over_T_exponential"], doc["sigma_over_T_exponential_stderr"]
    assert err > 0 and abs(value - spec["sigma_over_T"]) <= 4 * err, (value, err)


def test_two_captures_use_the_pair(linear_sample):
    _, capture_file = linear_sample
    assert json.loads(run(capture_file, "--json").stdout)["sigma_over_T_source"] == "pair"
