"""The light's direction from a mirror sphere: `roughscope calibrate light` and
roughscope.calibrate_light (docs/calibration.md) against spheres rendered here with a known light.

The renderer is independent of the library: for each pixel (3 x 3 samples) the normal of an
orthographic sphere, the mirror direction of the view V = +z, a narrow lobe exp(-a^2 / 2 w^2)
around the light plus a dim Lambertian term, noise, quantised to 16 bits and written as a
16-bit PNG (no colour chunk: read as linear).
"""

import json
import struct
import subprocess
import zlib

import numpy as np
import pytest

import roughscope
from conftest import cli_path

SIZE, CX, CY, R = 200, 101.3, 98.6, 90.0
EXIT_USAGE, EXIT_DATA = 2, 4


def light_from(theta_deg, phi_deg):
    t, p = np.radians(theta_deg), np.radians(phi_deg)
    return np.array([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)])


def render(light, lobe_deg=1.5, peak=2.0, noise=0.003, seed=0):
    """(SIZE, SIZE) linear image of a mirror sphere lit from `light` (camera frame, y up)."""
    offsets = (np.arange(3) * 2 + 1) / 6.0
    img = np.zeros((SIZE, SIZE))
    for oy in offsets:
        for ox in offsets:
            x = np.arange(SIZE)[None, :] + ox - CX
            y = np.arange(SIZE)[:, None] + oy - CY
            nx, ny = x / R, -y / R
            rho2 = nx ** 2 + ny ** 2
            inside = rho2 < 1
            nz = np.sqrt(np.clip(1 - rho2, 0, 1))
            mirror = np.stack([2 * nz * nx, 2 * nz * ny, 2 * nz * nz - 1])
            cos_a = np.clip(np.tensordot(light, mirror, axes=1), -1, 1)
            a = np.degrees(np.arccos(cos_a))
            lambert = np.clip(light[0] * nx + light[1] * ny + light[2] * nz, 0, None)
            value = peak * np.exp(-a ** 2 / (2 * lobe_deg ** 2)) + 0.08 * lambert
            img += np.where(inside, value, 0.01) / 9
    img += noise * np.random.default_rng(seed).standard_normal(img.shape)
    return np.round(np.clip(img, 0, 1) * 65535) / 65535


def write_png16(path, img):
    """A 16-bit greyscale PNG of img (values in [0, 1])."""
    codes = np.round(img * 65535).astype(">u2")
    raw = b"".join(b"\x00" + row.tobytes() for row in codes)

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))

    header = struct.pack(">IIBBBBB", img.shape[1], img.shape[0], 16, 0, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header)
                     + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))
    return path


def angle_deg(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b)), np.dot(a, b)))


def run(*args):
    return subprocess.run([cli_path(), "calibrate", "light", *map(str, args)],
                          capture_output=True, text=True, timeout=120)


@pytest.fixture(scope="module")
def sphere_png(tmp_path_factory):
    light = light_from(40.0, 120.0)
    return write_png16(tmp_path_factory.mktemp("mirror") / "sphere.png", render(light)), light


@pytest.mark.parametrize("theta,phi", [(0, 0), (20, 300), (45, 30), (60, 200)])
def test_python_recovers_the_light_from_an_array(theta, phi):
    light = light_from(theta, phi)
    doc = roughscope.calibrate_light(render(light, seed=theta), circle=(CX, CY, R))
    assert angle_deg(doc["light"], light) < 0.3
    assert doc["theta_deg"] == pytest.approx(theta, abs=0.3)
    if theta:
        assert (doc["phi_deg"] - phi + 180) % 360 - 180 == pytest.approx(0, abs=0.5)
    assert 0 < doc["angle_uncertainty_deg"] < 2
    assert doc["method"] == "mirror_sphere" and doc["blobs"] == 1 and doc["warnings"] == []
    # An array has no flags: the clipped core is not marked saturated (a PNG's is, below).
    assert doc["pixels"]["saturated"] == 0 and 3 < doc["pixels"]["highlight"] < 100


def test_light_at_the_camera_puts_the_highlight_at_the_centre():
    # Off the pixel grid, the clipped core's edge sampled by pixels: within a tenth of a pixel
    # (the centroid's uncertainty floor).
    doc = roughscope.calibrate_light(render(light_from(0, 0), noise=0), circle=(CX, CY, R))
    assert doc["highlight"]["x_px"] == pytest.approx(CX, abs=0.1)
    assert doc["highlight"]["y_px"] == pytest.approx(CY, abs=0.1)
    assert doc["highlight"]["rho"] < 1e-3


def test_cli_json_is_the_python_dict(sphere_png):
    path, light = sphere_png
    proc = run(path, "--sphere", f"{CX},{CY},{R}", "--json")
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(proc.stdout)
    assert angle_deg(doc["light"], light) < 0.3
    assert doc["pixels"]["saturated"] > 0  # the PNG's clipped core: flagged, and used
    py = roughscope.calibrate_light(str(path), circle=(CX, CY, R))
    doc.pop("roughscope_version")
    assert doc == py
    # A path-like object and read_image's dict give the same.
    import pathlib
    assert roughscope.calibrate_light(pathlib.Path(path), (CX, CY, R)) == py
    assert roughscope.calibrate_light(roughscope.read_image(str(path)), (CX, CY, R)) == py


def test_cli_text(sphere_png):
    path, light = sphere_png
    proc = run(path, "--sphere", f"{CX},{CY},{R}")
    assert proc.returncode == 0, proc.stderr
    text = proc.stdout
    assert "light (x, y, z)" in text and "theta" in text and "phi" in text
    assert "± " in text and " deg" in text
    theta = float(text.split("theta")[1].split()[0])
    assert theta == pytest.approx(40.0, abs=0.3)


def test_mask_gives_the_circle_and_restricts_the_search(tmp_path, sphere_png):
    path, light = sphere_png
    yy, xx = np.mgrid[0:SIZE, 0:SIZE] + 0.5
    mask = ((xx - CX) ** 2 + (yy - CY) ** 2 < R ** 2).astype(float)
    mask_png = write_png16(tmp_path / "mask.png", mask)
    proc = run(path, "--mask", mask_png, "--json")
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(proc.stdout)
    assert doc["circle"]["radius_px"] == pytest.approx(R, abs=0.1)
    assert angle_deg(doc["light"], light) < 0.3
    py = roughscope.calibrate_light(str(path), mask=mask)
    assert angle_deg(py["light"], light) < 0.3


def fails(code, *args):
    proc = run(*args)
    assert proc.returncode == code, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("roughscope: error: "), proc.stderr
    assert proc.stdout == ""
    return lines[0]


def test_cli_refuses_bad_input(tmp_path, sphere_png):
    path, _ = sphere_png
    msg = fails(EXIT_USAGE, path, "--sphere", f"{CX},{CY},150")
    assert "centre x" in msg and "valid range" in msg
    assert "radius = 3 px" in fails(EXIT_USAGE, path, "--sphere", f"{CX},{CY},3")
    assert "--sphere" in fails(EXIT_USAGE, path, "--sphere", "1,2")
    assert "--sphere" in fails(EXIT_USAGE, path)
    assert "no highlight" in fails(
        EXIT_DATA, write_png16(tmp_path / "matte.png", np.full((SIZE, SIZE), 0.3)),
        "--sphere", f"{CX},{CY},{R}")
    fails(EXIT_DATA, tmp_path / "missing.png", "--sphere", f"{CX},{CY},{R}")
    mask = write_png16(tmp_path / "small.png", np.ones((10, 10)))
    assert "--mask" in fails(EXIT_USAGE, path, "--mask", mask)


def test_python_refuses_bad_input():
    img = render(light_from(30, 0))
    with pytest.raises(roughscope.InvalidArgument, match="radius"):
        roughscope.calibrate_light(img, circle=(CX, CY, 2))
    with pytest.raises(roughscope.InvalidArgument, match="circle"):
        roughscope.calibrate_light(img, circle=(CX, CY))
    with pytest.raises(roughscope.InvalidArgument):
        roughscope.calibrate_light(img)
    with pytest.raises(TypeError):
        roughscope.calibrate_light(img, circle=("a", 1, 2))
    with pytest.raises(roughscope.DataError, match="no highlight"):
        roughscope.calibrate_light(np.full((SIZE, SIZE), 0.3), circle=(CX, CY, R))
