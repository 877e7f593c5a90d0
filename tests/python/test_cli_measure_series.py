"""`roughscope measure --json` carries the exact series (docs/uncertainty.md "Model error"):
with σ known, T given σ in the exact series for both correlations; with three geometries and σ
unknown, the joint fit of σ and T. Every number is finite (JSON null only for unknown)."""

import json
import math
import pathlib
import subprocess

import pytest

from conftest import cli_path


def run(path):
    proc = subprocess.run([cli_path(), "measure", str(path), "--json"], capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, f"exit {proc.returncode}: {proc.stderr}"
    return json.loads(proc.stdout)


@pytest.fixture(scope="module")
def linear_sample(tmp_path_factory):
    from roughscope import demo

    spec = demo.SAMPLES[1]
    return spec, demo.write_sample(spec, tmp_path_factory.mktemp("series"))


def edited(capture_file, name, change):
    doc = json.loads(pathlib.Path(capture_file).read_text())
    change(doc)
    path = pathlib.Path(capture_file).parent / name
    path.write_text(json.dumps(doc))
    return path


def finite(x):
    return isinstance(x, (int, float)) and math.isfinite(x)


def test_known_sigma_gives_the_exact_series_of_both_correlations(linear_sample):
    _, capture_file = linear_sample
    doc = run(edited(capture_file, "sigma.json",
                     lambda d: d.update(sigma_um=0.2, sigma_um_stderr=0.005)))
    series = doc["exact_series"]
    assert series["method"] == "t_given_sigma"
    assert series["method_description"] == "T given σ"
    assert series["captures"] == [1, 2]
    for corr in ("gaussian", "exponential"):
        e = series[corr]
        for key in ("sigma_um", "T_um", "sigma_over_T", "sigma_over_T_stderr",
                    "closed_form_sigma_over_T", "closed_form_deviation_rel"):
            assert finite(e[key]), (corr, key, e[key])
        low, high = e["sigma_over_T_interval95"]
        assert low < e["sigma_over_T"] < high
        assert e["sigma_over_T"] == pytest.approx(e["sigma_um"] / e["T_um"], rel=1e-9)
        assert e["closed_form_deviation_rel"] == pytest.approx(
            e["closed_form_sigma_over_T"] / e["sigma_over_T"] - 1.0, rel=1e-9)
        assert len(e["g"]) == 2 and all(finite(g) and g > 0 for g in e["g"])
        # The budget lists the series' sources under its own key, not as a headline.
        assert doc["uncertainty_budget"][f"sigma_over_T_series_{corr}"]
    assert "sigma_over_T_series_gaussian_uncertainty" not in doc


def test_a_pair_without_sigma_has_no_exact_series(linear_sample):
    _, capture_file = linear_sample
    assert run(capture_file)["exact_series"] is None


def test_three_geometries_fit_sigma_and_T(linear_sample):
    from roughscope import _core, demo

    spec, capture_file = linear_sample
    folder = pathlib.Path(capture_file).parent
    first = json.loads(pathlib.Path(capture_file).read_text())["captures"][0]
    (folder / "capture3").mkdir(exist_ok=True)
    _core.write_capture(str(folder / "capture3"), "tiff", scene="plane", width=demo.SIZE,
                        height=demo.SIZE, theta_i_deg=60.0, exposure_s=first["exposure_s"],
                        seed=99, **demo.surface_keywords(spec),
                        **demo.sample_camera(spec, electrons_per_unit_s=demo.lamp(spec)))
    doc = run(edited(capture_file, "three.json", lambda d: d["captures"].append(
        {"image": "capture3/capture.tiff", "theta_i_deg": 60.0,
         "exposure_s": first["exposure_s"]})))
    series = doc["exact_series"]
    assert series["method"] == "fit"
    assert series["method_description"] == "fit of 3 captures"
    assert "not propagated" in series["uncertainty_covers"]
    for corr in ("gaussian", "exponential"):
        e = series[corr]
        assert e["fit_status"] is not None
        if e["failure"] is None:
            assert finite(e["sigma_um"]) and finite(e["T_um"]) and finite(e["sigma_over_T"])
            assert e["sigma_over_T_stderr"] is None or finite(e["sigma_over_T_stderr"])


def test_the_text_report_has_the_exact_series_line(linear_sample):
    _, capture_file = linear_sample
    path = edited(capture_file, "sigma_text.json", lambda d: d.update(sigma_um=0.2))
    proc = subprocess.run([cli_path(), "measure", str(path)], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "sigma/T exact series (gaussian)" in proc.stdout
    assert "T given σ" in proc.stdout and "closed form" in proc.stdout
