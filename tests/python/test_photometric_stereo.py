"""roughscope.photometric_stereo (docs/photometric-stereo.md) on a Lambertian sphere rendered here
with numpy: the normals and albedo back from arrays (grey and channels-last colour), a mask, the
summary keys, and named errors for bad lights."""

import numpy as np
import pytest

import roughscope as rs

SIZE, CX, CY, R = 64, 32.2, 31.7, 28.0


def light(theta_deg, phi_deg):
    t, p = np.radians(theta_deg), np.radians(phi_deg)
    return [np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)]


LIGHTS = np.array([light(30, 0), light(40, 90), light(35, 180), light(45, 270)])


def angle_deg(a, b):
    """Angle between unit vectors along the last axis (atan2: accurate near 0)."""
    a = a.astype(float)
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, -1)))


def sphere():
    yy, xx = np.mgrid[0:SIZE, 0:SIZE] + 0.5
    nx, ny = (xx - CX) / R, -(yy - CY) / R
    inside = nx ** 2 + ny ** 2 < 0.95
    nz = np.sqrt(np.clip(1 - nx ** 2 - ny ** 2, 0, None))
    normals = np.stack([nx, ny, nz], axis=-1)
    albedo = 0.5 + 0.2 * nx
    images = [np.where(inside, albedo * np.clip(normals @ L, 0, None), 0.0) for L in LIGHTS]
    return normals, albedo, inside, images


def test_normals_and_albedo_from_grey_arrays():
    normals, albedo, inside, images = sphere()
    out = rs.photometric_stereo(images, LIGHTS)
    lit = out["valid"] & inside
    assert lit.sum() > 0.8 * inside.sum()
    err = angle_deg(out["normals"], normals)
    assert err[lit].max() < 0.01
    assert np.abs(out["albedo"][lit] / albedo[lit] - 1).max() < 1e-4
    assert np.isnan(out["normals"][~out["valid"]]).all()
    assert out["normals"].shape == (SIZE, SIZE, 3)
    assert out["pixels"]["object"] == SIZE * SIZE
    assert out["pixels"]["valid"] == int(out["valid"].sum())
    assert out["model"] == "lambert"
    assert out["median_residual"] < 1e-4


def test_colour_channels_last_and_mask():
    normals, _, inside, images = sphere()
    colour = [np.stack([im, 0.5 * im, 0.25 * im], axis=-1) for im in images]
    mask = np.zeros((SIZE, SIZE), dtype=np.uint8)
    mask[20:40, 20:40] = 1
    out = rs.photometric_stereo(colour, LIGHTS, mask=mask)
    assert out["pixels"]["object"] == 400
    assert not out["valid"][mask == 0].any()
    sel = out["valid"]
    err = angle_deg(out["normals"], normals)
    assert err[sel].max() < 0.01


def test_bad_lights_are_named():
    _, _, _, images = sphere()
    with pytest.raises(rs.InvalidArgument, match="coplanar"):
        rs.photometric_stereo(images[:3], [light(10, 0), light(20, 0), light(30, 0)])
    with pytest.raises(rs.InvalidArgument, match="points away from the camera"):
        bad = LIGHTS.copy()
        bad[1] = light(120, 0)
        rs.photometric_stereo(images, bad)
    with pytest.raises(rs.InvalidArgument, match="2 lights"):
        rs.photometric_stereo(images[:2], LIGHTS[:2])
    with pytest.raises(rs.InvalidArgument, match="3 images for 4 lights"):
        rs.photometric_stereo(images[:3], LIGHTS)
    with pytest.raises(TypeError, match="images"):
        rs.photometric_stereo("a.png", LIGHTS)
