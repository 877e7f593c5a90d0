"""Tests of `roughscope simulate capture` (synthetic camera captures, docs/simulation-captures.md).

Each success test has a failure companion asserting the exit code and the one-line message. The
PNG is decoded here with zlib alone (an independent reader), and the pixel values are checked
against the camera formula at a known geometry (Lambert: brightness cos θi).
"""

import json
import math
import struct
import subprocess
import zlib

import pytest

from conftest import cli_path

pytestmark = pytest.mark.cli

EXIT_USAGE, EXIT_DATA = 2, 4


def run(*args, check=True):
    proc = subprocess.run([cli_path(), "simulate", "capture", *map(str, args)],
                          capture_output=True, text=True, timeout=300)
    if check:
        assert proc.returncode == 0, f"exit {proc.returncode}: {proc.stderr}"
    return proc


def fails(code, *args):
    proc = run(*args, check=False)
    assert proc.returncode == code, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("roughscope: error: "), proc.stderr
    return lines[0]


def read_png_grey(path):
    """Grey PNG (8 or 16 bit, no interlace) decoded with zlib: (width, height, bits, rows)."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, bits, colour, _, _, interlace = header
    assert colour == 0 and interlace == 0
    raw = zlib.decompress(idat)
    bpp = bits // 8
    stride = 1 + width * bpp
    rows, prev = [], bytearray(width * bpp)
    for r in range(height):
        filt, line = raw[r * stride], bytearray(raw[r * stride + 1:(r + 1) * stride])
        for i in range(len(line)):  # PNG filters 0..4 (libpng may pick any)
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], (prev[i - bpp] if i >= bpp else 0)
            if filt == 1:
                line[i] = (line[i] + a) & 255
            elif filt == 2:
                line[i] = (line[i] + b) & 255
            elif filt == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif filt == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[i] = (line[i] + pred) & 255
        prev = line
        rows.append([int.from_bytes(line[k * bpp:(k + 1) * bpp], "big") for k in range(width)])
    return width, height, bits, rows


def test_plane_png_holds_the_camera_formula(tmp_path):
    run("--scene", "plane", "--width", 12, "--height", 7, "--model", "lambert", "--theta-i", 30,
        "--no-shot-noise", "--read-noise-e", 0, "--bits", 16, "--gain", 0.25,
        "--black-level", 64, "--out", tmp_path)
    width, height, bits, rows = read_png_grey(tmp_path / "capture.png")
    assert (width, height, bits) == (12, 7, 16)
    # DN = round(gain · k · t · cos θi + black) with k = 20000 e per unit brightness per second.
    expected = math.floor(0.25 * 20000 * math.cos(math.radians(30)) + 64 + 0.5)
    assert all(v == expected for row in rows for v in row)
    side = json.loads((tmp_path / "capture.json").read_text())
    assert side["files"] == {"image": "capture.png", "format": "png", "sidecar": "capture.json"}
    assert side["scene"]["light"]["theta_deg"] == 30
    assert side["truth"]["regions"][0]["model"] == "lambert"
    assert side["statistics"]["object_pixels"] == 84


def test_plane_png_bad_bits_fails(tmp_path):
    line = fails(EXIT_USAGE, "--bits", 10, "--out", tmp_path / "x")
    assert "--bits" in line and "8,12,14,16" in line
    assert not (tmp_path / "x").exists()


def test_sphere_dng_and_sidecar(tmp_path):
    run("--scene", "sphere", "--width", 41, "--height", 31, "--format", "dng", "--bits", 12,
        "--out", tmp_path)
    data = (tmp_path / "capture.dng").read_bytes()
    assert data[:4] in (b"II*\x00", b"MM\x00*")
    side = json.loads((tmp_path / "capture.json").read_text())
    assert side["camera"]["white_level_dn"] == 4095
    assert side["scene"]["radius_um"] == pytest.approx(0.4 * 31 * 10)
    # The disc covers about π R² pixels.
    assert side["statistics"]["object_pixels"] == pytest.approx(math.pi * 12.4 ** 2, rel=0.05)


def test_sphere_dng_nonlinear_response_fails_and_writes_nothing(tmp_path):
    line = fails(EXIT_USAGE, "--scene", "sphere", "--format", "dng", "--response", "srgb",
                 "--out", tmp_path / "x")
    assert "--response" in line and "linear" in line
    assert not (tmp_path / "x").exists()


def test_same_seed_same_bytes(tmp_path):
    for name in ("a", "b", "c"):
        seed = 5 if name != "c" else 6
        run("--scene", "cylinder", "--width", 32, "--height", 16, "--format", "tiff",
            "--seed", seed, "--out", tmp_path / name)
    a = (tmp_path / "a" / "capture.tiff").read_bytes()
    assert a == (tmp_path / "b" / "capture.tiff").read_bytes()
    assert a != (tmp_path / "c" / "capture.tiff").read_bytes()


def test_bad_seed_fails(tmp_path):
    line = fails(EXIT_USAGE, "--seed", -1, "--out", tmp_path)
    assert "--seed" in line


def test_stripes_make_one_region_per_ratio(tmp_path):
    run("--width", 30, "--height", 4, "--sigma-over-T", "0.1,0.3,0.5", "--out", tmp_path)
    regions = json.loads((tmp_path / "capture.json").read_text())["truth"]["regions"]
    assert [r["sigma_over_T"] for r in regions] == pytest.approx([0.1, 0.3, 0.5])
    assert [r["bbox"] for r in regions] == [[0, 0, 9, 3], [10, 0, 19, 3], [20, 0, 29, 3]]


def test_stripes_bad_ratio_fails(tmp_path):
    line = fails(EXIT_USAGE, "--sigma-over-T", "0.1,0", "--out", tmp_path)
    assert "--sigma-over-T" in line


def test_out_is_a_file_fails(tmp_path):
    target = tmp_path / "file"
    target.write_text("keep")
    line = fails(EXIT_DATA, "--out", target)
    assert "not a directory" in line
    assert target.read_text() == "keep"


def test_numeric_flags_at_the_extremes(tmp_path):
    """Every numeric flag of `simulate capture` at the extremes of the double range: exit 0 or 2
    (naming the flag), never 1, no NaN (test_extreme_flags.sweep)."""
    from test_extreme_flags import sweep
    assert sweep(["simulate", "capture"], [
        ["--width", "16", "--height", "12", "--out", str(tmp_path / "a")],
        ["--scene", "sphere", "--width", "15", "--height", "11", "--model",
         "mean_scattered_power", "--format", "dng", "--out", str(tmp_path / "b")],
    ]) >= 40
