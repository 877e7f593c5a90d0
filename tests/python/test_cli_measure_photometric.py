"""`roughscope measure` on an object of unknown shape (docs/photometric-stereo.md): a capture file
with "object": {"shape": "photometric_stereo"} and one capture per light. The photographs are
`roughscope simulate capture --scene sphere` renders (16-bit TIFF, no noise) under lights 35° from
the camera axis at four or five azimuths; the truth is the sphere's normal (x right, y up, z
towards the camera) and, for the very-rough render, its σ/T."""

import json
import math
import subprocess

import numpy as np
import pytest

from conftest import cli_path

SIZE = 96
EXIT_DATA = 4


def light(phi_deg, theta_deg=35.0):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return [math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)]


def render(folder, azimuths, model="lambert", sigma_over_T=0.3, noise=False, zeniths=None):
    captures = []
    for k, phi in enumerate(azimuths):
        theta = 35.0 if zeniths is None else zeniths[k % len(zeniths)]
        out = folder / f"c{k}"
        camera = (["--seed", str(k + 1)] if noise else
                  ["--read-noise-e", "0", "--no-shot-noise"])
        subprocess.run([cli_path(), "simulate", "capture", "--scene", "sphere", "--model", model,
                        "--sigma-over-T", str(sigma_over_T), "--theta-i", str(theta), "--phi-i",
                        str(phi), "--width", str(SIZE), "--height", str(SIZE), "--bits", "16",
                        "--black-level", "0", *camera, "--format", "tiff", "--out", str(out)],
                       check=True, capture_output=True)
        captures.append({"image": f"c{k}/capture.tiff", "light": light(phi, theta),
                         "exposure_s": 1})
    return captures


def capture_file(folder, captures, **object_keys):
    path = folder / "ps.json"
    doc = {"response": "linear", "black_level_dn": 0,
           "object": {"shape": "photometric_stereo", **object_keys}, "captures": captures}
    path.write_text(json.dumps(doc))
    return path


def true_normals():
    r = 0.4 * SIZE
    yy, xx = np.mgrid[0:SIZE, 0:SIZE] + 0.5
    nx, ny = (xx - SIZE / 2) / r, -(yy - SIZE / 2) / r
    inside = nx ** 2 + ny ** 2 < 0.8
    nz = np.sqrt(np.clip(1 - nx ** 2 - ny ** 2, 0, None))
    return np.stack([nx, ny, nz], axis=-1), inside


def angle_deg(a, b):
    a = a.astype(float)
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, -1)))


def measure(path, maps):
    proc = subprocess.run([cli_path(), "measure", str(path), "--json", "--maps", str(maps)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


def test_lambertian_sphere_normals_and_files(tmp_path):
    path = capture_file(tmp_path, render(tmp_path, [0, 90, 180, 270]))
    doc = measure(path, tmp_path / "maps")
    ps = doc["photometric_stereo"]
    assert ps["model"] == "lambert"
    assert len(ps["lights"]) == 4
    assert sorted(ps["files"]) == ["albedo.npy", "normals.npy", "normals.png", "residual.npy"]
    normals = np.load(tmp_path / "maps" / "normals.npy")
    assert normals.shape == (SIZE, SIZE, 3)
    truth, inside = true_normals()
    valid = np.isfinite(normals[..., 0])
    assert ps["pixels"]["valid"] == int(valid.sum())
    sel = valid & inside
    assert sel.sum() > 0.9 * inside.sum()
    err = angle_deg(normals[sel], truth[sel])
    assert np.median(err) < 0.05 and err.max() < 0.5
    assert ps["median_residual"] < 1e-3


def test_rough_sphere_gives_sigma_over_T(tmp_path):
    path = capture_file(tmp_path, render(tmp_path, [0, 72, 144, 216, 288], model="very_rough",
                                         sigma_over_T=0.4), model="vh_gaussian")
    doc = measure(path, tmp_path / "maps")
    ps = doc["photometric_stereo"]
    assert ps["model"] == "vh_gaussian"
    assert ps["median_sigma_over_T"] == pytest.approx(0.4, rel=0.01)
    assert ps["model_comparison"]["rough_better_pixels"] > \
        0.9 * ps["model_comparison"]["compared_pixels"]
    slope = np.load(tmp_path / "maps" / "sigma_over_T_gaussian.npy")
    assert np.nanmedian(slope) == pytest.approx(0.4, rel=0.01)
    normals = np.load(tmp_path / "maps" / "normals.npy")
    truth, inside = true_normals()
    sel = np.isfinite(normals[..., 0]) & inside
    assert np.median(angle_deg(normals[sel], truth[sel])) < 0.1


def test_bad_photometric_stereo_files_are_named(tmp_path):
    captures = render(tmp_path, [0, 120, 240])
    for change, words in [
        (lambda c: c[:2], "at least 3 captures"),
        (lambda c: [c[0], c[1], {k: v for k, v in c[2].items() if k != "light"}],
         "light"),
    ]:
        path = capture_file(tmp_path, change(captures))
        proc = subprocess.run([cli_path(), "measure", str(path), "--json"], capture_output=True,
                              text=True)
        assert proc.returncode == EXIT_DATA, proc.stderr
        assert words in proc.stderr and "ps.json" in proc.stderr
    path = capture_file(tmp_path, captures, model="vh_gaussian")
    proc = subprocess.run([cli_path(), "measure", str(path)], capture_output=True, text=True)
    assert proc.returncode == EXIT_DATA and "at least 4 captures" in proc.stderr
    path = capture_file(tmp_path, captures, model="phong")
    proc = subprocess.run([cli_path(), "measure", str(path)], capture_output=True, text=True)
    assert proc.returncode == EXIT_DATA and "vh_gaussian" in proc.stderr


def test_report_shows_the_normals(tmp_path):
    path = capture_file(tmp_path, render(tmp_path, [0, 90, 180, 270]))
    proc = subprocess.run([cli_path(), "measure", str(path), "--maps", str(tmp_path / "maps"),
                           "--report", str(tmp_path / "report")], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr
    html = (tmp_path / "report" / "index.html").read_text(encoding="utf-8")
    assert "Photometric stereo: the object's normals" in html
    assert "4 lights" in html and "data:image/png" in html


REGIONS = {"regions": [{"name": "left", "rect": [0, 0, 44, SIZE]},
                       {"name": "right", "rect": [52, 0, 44, SIZE]}]}


def regions_of(tmp_path, stripes):
    """The statue experiment on a sphere whose left and right halves have the σ/T `stripes`."""
    captures = render(tmp_path, [45 * k for k in range(8)], model="very_rough",
                      sigma_over_T=stripes, noise=True, zeniths=[20, 40])
    path = tmp_path / "ps.json"
    # The object's pixels away from the limb (the roi): the background holds noise only, and
    # near the limb every light is grazing.
    path.write_text(json.dumps({"response": "linear", "black_level_dn": 0,
                                "object": {"shape": "photometric_stereo", "model": "vh_gaussian"},
                                "roi": {"circle": [SIZE / 2, SIZE / 2, 0.6 * 0.4 * SIZE]},
                                "maps": REGIONS, "captures": captures}))
    return measure(path, tmp_path / "maps")["photometric_stereo"]


def test_regions_of_different_roughness_differ(tmp_path):
    ps = regions_of(tmp_path, "0.25,0.6")
    left, right = ps["regions"]
    assert left["name"] == "left" and right["name"] == "right"
    for region, truth in ((left, 0.25), (right, 0.6)):
        assert region["with_slope"] > 250
        assert abs(region["sigma_over_T"] - truth) < max(3 * region["sigma_over_T_stderr"],
                                                         0.03 * truth), region
    assert left["roughness_class"] == "slightly_rough"
    assert right["roughness_class"] == "moderately_rough"
    (c,) = ps["comparisons"]
    assert c["differ"] and c["p_value"] < 1e-6 and not c["same_class"]
    classes = np.load(tmp_path / "maps" / "roughness_class.npy")
    assert classes.shape == (SIZE, SIZE)


def test_regions_of_one_roughness_do_not_differ(tmp_path):
    ps = regions_of(tmp_path, "0.4,0.4")
    (c,) = ps["comparisons"]
    assert c["same_class"]
    assert not c["differ"], c
