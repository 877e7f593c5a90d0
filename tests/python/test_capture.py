"""roughscope.render_capture / write_capture (synthetic captures, docs/simulation-captures.md).

Checked against independent facts: the plane's pixels against the camera formula at a known
Lambert brightness, the sphere's centre geometry, the photon-transfer relation, a Python
brightness callback, and the written files against the returned arrays.
"""

import json
import math

import numpy as np
import pytest

import roughscope as rs


def test_plane_render_matches_the_camera_formula():
    out = rs.render_capture(scene="plane", width=8, height=5, model="lambert", theta_i_deg=60,
                            shot_noise=False, read_noise_e=0, bits=16, gain=0.5, black_level=10)
    assert out["dn"].shape == (5, 8) and out["dn"].dtype == np.uint16
    assert np.all(out["radiance"] == np.float32(0.5))
    assert np.all(out["dn"] == math.floor(0.5 * 20000 * 0.5 + 10 + 0.5))
    assert np.allclose(out["theta_i_deg"], 60, atol=1e-4)
    assert out["sidecar"]["files"] is None
    assert out["sidecar"]["camera"]["bit_depth"] == 16


def test_plane_render_rejects_bad_values():
    with pytest.raises(ValueError, match="bit_depth = 10"):
        rs.render_capture(bits=10)
    with pytest.raises(ValueError, match="theta_i_deg"):
        rs.render_capture(theta_i_deg=90)
    with pytest.raises(TypeError, match="unexpected keyword"):
        rs.render_capture(colour="red")


def test_sphere_centre_geometry_and_photon_transfer():
    out = rs.render_capture(scene="sphere", width=51, height=51, theta_v_deg=15, theta_i_deg=25,
                            model="lambert")
    assert out["theta_i_deg"][25, 25] == pytest.approx(40, abs=1e-4)
    assert out["theta_s_deg"][25, 25] == pytest.approx(0, abs=1e-4)
    assert out["label"][0, 0] == -1 and math.isnan(out["theta_i_deg"][0, 0])
    flat = rs.render_capture(width=150, height=150, theta_i_deg=0, model="lambert",
                             electrons_per_unit_s=2000, gain=0.5, read_noise_e=2, bits=16,
                             black_level=32, seed=3)["dn"].astype(float)
    var_expected = 0.5 * (flat.mean() - 32) + 0.25 * 4 + 1 / 12
    assert flat.mean() == pytest.approx(1032, abs=4 * math.sqrt(var_expected / flat.size))
    assert flat.var(ddof=1) == pytest.approx(var_expected,
                                             abs=4 * var_expected * math.sqrt(2 / flat.size))


def test_brightness_callback_and_labels():
    labels = np.zeros((4, 6), dtype=np.int32)
    labels[:, 3:] = 1
    out = rs.render_capture(width=6, height=4, theta_i_deg=20, sigma_over_T=[0.2, 0.4],
                            labels=labels, shot_noise=False, read_noise_e=0)
    left, right = out["radiance"][0, 0], out["radiance"][0, 5]
    assert left != right
    assert [r["pixels"] for r in out["sidecar"]["truth"]["regions"]] == [12, 12]
    cb = rs.render_capture(width=3, height=3, theta_i_deg=20,
                           brightness=lambda ti, ts, ps: ti / 100.0)
    assert np.allclose(cb["radiance"], 0.2)
    with pytest.raises(ValueError, match="labels"):
        rs.render_capture(width=6, height=4, sigma_over_T=[0.2, 0.4])


def test_write_capture_files_match_the_render(tmp_path):
    kw = dict(scene="cylinder", width=20, height=10, bits=12, seed=9)
    paths = rs.write_capture(str(tmp_path), "tiff", **kw)
    side = json.loads(open(paths["sidecar"]).read())
    assert side["files"]["image"] == "capture.tiff"
    again = rs.render_capture(**kw)
    assert side["statistics"]["saturated_pixels"] == int(again["saturated"].sum())
    # Uncompressed, one strip per few rows: the DN are the last width·height·2 bytes before the IFD
    # or after the header; find them in the file.
    data = open(paths["image"], "rb").read()
    assert again["dn"].astype("<u2").tobytes() in data
    with pytest.raises(ValueError, match="response"):
        rs.write_capture(str(tmp_path / "none"), "dng", response="srgb")
