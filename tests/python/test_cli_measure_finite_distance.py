"""`roughscope measure` with a lamp and a camera at a finite distance (docs/measure.md "A lamp and
a camera at a finite distance"): a capture file whose lights are positions measures, and the JSON
says per capture how far the lamp was, the geometry's spread and the correction factors.

The photographs are roughscope.demo's linear 16-bit pair (a collimated light): with the lamp
10⁷ mm away the positions must give what the directions give; at 500 mm they must not.
"""

import json
import math
import pathlib
import subprocess

import pytest

from conftest import cli_path

EXIT_DATA = 4


def run(capture_file, check=True):
    proc = subprocess.run([cli_path(), "measure", "--json", str(capture_file)],
                          capture_output=True, text=True, timeout=300)
    if check:
        assert proc.returncode == 0, f"exit {proc.returncode}: {proc.stderr}"
    return proc


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    from roughscope import demo

    spec = demo.SAMPLES[1]
    return demo.write_sample(spec, tmp_path_factory.mktemp("finite_distance"))


def with_positions(capture_file, name, lamp_mm, pixel_size_mm=0.5, camera_mm=None):
    doc = json.loads(pathlib.Path(capture_file).read_text())
    doc["sample_plane"] = {"pixel_size_mm": pixel_size_mm}
    for c in doc["captures"]:
        t = math.radians(c.pop("theta_i_deg"))
        c.pop("theta_s_deg", None)
        c.pop("phi_s_deg", None)
        c["light"] = {"position_mm": [-lamp_mm * math.sin(t), 0.0, lamp_mm * math.cos(t)]}
        c["view"] = {"position_mm": [0.0, 0.0, camera_mm]} if camera_mm else [0, 0, 1]
    path = pathlib.Path(capture_file).parent / name
    path.write_text(json.dumps(doc))
    return path


def test_positions_measure_and_the_json_says_how(pair):
    nominal = json.loads(run(pair).stdout)
    far = json.loads(run(with_positions(pair, "far.json", 1e7)).stdout)
    near = json.loads(run(with_positions(pair, "near.json", 500.0, camera_mm=400.0)).stdout)
    assert "finite_distance" not in nominal["captures"][0]
    s = nominal["sigma_over_T_gaussian"]
    assert far["sigma_over_T_gaussian"] == pytest.approx(s, rel=1e-6)
    # The demo's photographs are lit by a collimated light: read as a lamp at 500 mm, corrected.
    assert abs(near["sigma_over_T_gaussian"] / s - 1) > 1e-3
    for result, lamp in ((far, 1e7), (near, 500.0)):
        for c in result["captures"]:
            fd = c["finite_distance"]
            assert fd["lamp_distance_mm"] == pytest.approx(lamp, rel=1e-6)
            assert fd["correction_sigma_over_T_gaussian"] > 0
            assert fd["correction_sigma_over_T_exponential"] > 0
            assert fd["correction_T"] is None
            assert fd["theta_i_deg_range"][0] <= c["theta_i_deg"] <= fd["theta_i_deg_range"][1]
            assert fd["sample_points"] > 0
    assert near["captures"][0]["finite_distance"]["camera_distance_mm"] == pytest.approx(400.0)
    assert far["captures"][0]["finite_distance"]["camera_distance_mm"] is None


def test_a_position_without_the_sample_plane_names_the_key(pair):
    doc = json.loads(with_positions(pair, "plane.json", 500.0).read_text())
    del doc["sample_plane"]
    path = pathlib.Path(pair).parent / "no_plane.json"
    path.write_text(json.dumps(doc))
    proc = run(path, check=False)
    assert proc.returncode == EXIT_DATA, proc.stderr
    assert "captures[0].light.position_mm" in proc.stderr and "sample_plane" in proc.stderr
