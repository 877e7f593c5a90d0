"""Numbers `roughscope measure` must not state with confidence it does not have (docs/measure.md):
a standard error the captures cannot give is null (JSON) and None (Python), with a warning; T
given σ says which form it used; an exponential σ/T carries its note on Eq. 5.

The photographs are synthetic captures (roughscope.write_capture, docs/simulation-captures.md).
"""

import json
import subprocess

import pytest

import roughscope
from conftest import cli_path

pytestmark = pytest.mark.cli


def run_json(capture_file):
    proc = subprocess.run([cli_path(), "measure", str(capture_file), "--json"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


def pair(tmp_path, size, roi, extra=None):
    """Two 16-bit linear TIFFs of a very rough plane (σ/T = 0.4) lit at 30° and 45°."""
    captures = []
    for k, theta in enumerate((30.0, 45.0)):
        sub = tmp_path / f"c{k}"
        sub.mkdir()
        roughscope.write_capture(str(sub), "tiff", scene="plane", width=size, height=size,
                                 theta_i_deg=theta, sigma_over_T=0.4, bits=16,
                                 response="linear", black_level=0, exposure_s=1.0,
                                 electrons_per_unit_s=20000.0, seed=7 + k,
                                 keep_geometry=False)
        captures.append({"image": f"c{k}/capture.tiff", "theta_i_deg": theta, "exposure_s": 1.0})
    doc = {"roi": {"rect": roi}, "captures": captures, **(extra or {})}
    path = tmp_path / "capture.json"
    path.write_text(json.dumps(doc))
    return path


def test_a_one_pixel_region_has_null_standard_errors(tmp_path):
    capture_file = pair(tmp_path, 1, [0, 0, 1, 1], {"sigma_um": 2.0})
    for doc in (run_json(capture_file), roughscope.measure(str(capture_file))):
        for key in ("E1_over_E2", "sigma_over_T_gaussian", "sigma_over_T_exponential", "T_um"):
            assert doc[key] is not None and doc[key] > 0, key
            assert doc[key + "_stderr"] is None, key
        assert sum("no measurable noise" in w for w in doc["warnings"]) == 2


def test_a_larger_region_keeps_its_standard_errors_and_notes_eq5(tmp_path):
    capture_file = pair(tmp_path, 24, [2, 2, 20, 20])
    doc = run_json(capture_file)
    assert doc["sigma_over_T_gaussian_stderr"] > 0
    assert not any("no measurable noise" in w for w in doc["warnings"])
    # The exponential σ/T is Eq. 19's: the note says what it rests on.
    assert doc["sigma_over_T_exponential"] is not None
    assert any("Eq. 5" in w and "exact Kirchhoff series" in w for w in doc["warnings"])


@pytest.mark.parametrize("writer", ["write_cylinder", "write_map"])
def test_a_cylinder_profile_and_a_map_with_an_exponential_value_note_eq5(tmp_path, writer):
    from roughscope import demo

    doc = run_json(getattr(demo, writer)(tmp_path))
    assert doc["sigma_over_T_exponential"] is not None or doc["map"] is not None
    assert sum("exact Kirchhoff series" in w for w in doc["warnings"]) == 1
