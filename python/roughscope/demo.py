"""The synthetic samples of the report (``make demo``): photographs of known roughness written
as files with their capture files, and measured.

* Flat samples (:data:`SAMPLES`): the paper's 30°/45° pair (camera on the normal, the second
  capture with half the exposure) as 8-bit sRGB PNG, 16-bit linear TIFF, 14-bit DNG, and a
  slightly rough sample with a photograph of its specular highlight (σ from Eq. 13, T from
  Eq. 15) — :func:`write_sample`.
* Curved objects and a map: a cylinder lit from the camera (§5.2), a sphere lit at 30° and a flat
  sample with three regions of known σ/T (§5.1) — :func:`write_cylinder`, :func:`write_sphere`,
  :func:`write_map`.

Every photograph is rendered by the library (``_core.write_capture``: the very-rough brightness
Eq. 4/5 or the full B–K model, photon and read noise, black level, quantisation, the camera's
response; docs/simulation-captures.md). :func:`measure` runs ``roughscope measure`` on a capture
file; :func:`measure_samples` and :func:`measure_objects` write and measure everything the
report's first two sections show (:mod:`roughscope.report_measure`,
:mod:`roughscope.report_objects` render the documents).
"""

import json
import math
import os
import pathlib
import subprocess

from . import _core

# --------------------------------------------------------------------------------------------
# The camera

ELECTRONS_PER_UNIT_S = 20000.0  # photo-electrons per unit brightness and second
FULL_WELL = 60000.0             # electrons
WAVELENGTH_UM = 0.555


def black_level(bits):
    """Black level (DN): an 8-bit sRGB file has its black at 0 (as cameras write JPEGs); linear
    files keep 64 DN."""
    return 0.0 if bits == 8 else 64.0


def camera(bits, response, electrons_per_unit_s=ELECTRONS_PER_UNIT_S):
    """The write_capture keywords of the demo camera: the full well 5 % above the white level
    (as in most cameras)."""
    black = black_level(bits)
    gain = 1.05 * (2.0 ** bits - 1.0 - black) / FULL_WELL  # DN per electron
    return dict(bits=bits, response=response, electrons_per_unit_s=electrons_per_unit_s,
                full_well_e=FULL_WELL, black_level=black, gain=gain, keep_geometry=False)


def write_capture_file(folder, spec):
    """Write `spec` (a capture-file document) as folder/capture-file.json; return its path."""
    path = pathlib.Path(folder) / "capture-file.json"
    path.write_text(json.dumps(spec, indent=2) + "\n", encoding="utf-8")
    return path


# --------------------------------------------------------------------------------------------
# Flat samples of known truth

# (name, description, truth, capture settings). Camera on the normal, light at θi = 30° and 45°
# (the paper's pair, §4.2), the second capture with half the exposure. Sample D is slightly rough
# (the glossy paper of Table 1): a specular photograph at 14° gives σ (Eq. 13), the pair T
# (Eq. 15); its pair is rendered with the full B–K model (mean scattered power, Eq. 1–2).
SAMPLES = [
    dict(name="A-srgb8", description="8-bit sRGB PNG (a phone or JPEG-like camera)",
         sigma_over_T=0.30, correlation="gaussian", fmt="png", bits=8, response="srgb",
         seed=11),
    dict(name="B-linear16", description="16-bit linear TIFF (a machine-vision camera)",
         sigma_over_T=0.20, correlation="exponential", fmt="tiff", bits=16, response="linear",
         seed=12),
    dict(name="C-dng", description="DNG camera RAW, 14-bit (a raw photograph)",
         sigma_over_T=0.50, correlation="gaussian", fmt="dng", bits=14, response="linear",
         seed=13),
    dict(name="D-specular", description="slightly rough (glossy paper of Table 1): a specular "
         "photograph and a pair, 16-bit linear PNG", sigma_um=0.094, T_um=0.195,
         sigma_over_T=0.094 / 0.195, correlation="gaussian", fmt="png", bits=16,
         response="linear", seed=14, specular_theta_deg=14.0),
]
THETA_I_DEG = (30.0, 45.0)
EXPOSURE_FACTORS = (1.0, 0.5)
SIZE = 160
BASE_EXPOSURE_S = 0.02  # the first capture of each pair: 1/50 s
HIGHLIGHT_RADIUS_PX = 12


def sample_camera(sample, electrons_per_unit_s=ELECTRONS_PER_UNIT_S):
    """The camera of a flat sample (its bits and response)."""
    return camera(sample["bits"], sample["response"], electrons_per_unit_s)


def surface_keywords(sample):
    """The write_capture keywords of the sample's surface (very rough, or the full B–K model)."""
    if "sigma_um" in sample:
        return dict(model="mean_scattered_power", sigma_over_T=sample["sigma_over_T"],
                    T_um=sample["T_um"], correlation=sample["correlation"],
                    wavelength_um=WAVELENGTH_UM)
    return dict(sigma_over_T=sample["sigma_over_T"], correlation=sample["correlation"])


def _mean_brightness(sample, theta_i_deg):
    """The model brightness of the plane at θi (camera on the normal), from a tiny render."""
    out = _core.render_capture(scene="plane", width=2, height=2, theta_i_deg=theta_i_deg,
                               **surface_keywords(sample))
    return float(out["radiance"].mean())


def specular_brightness(sample):
    """(Ẽ_dif, Ẽ_tot) of the specular photograph at θ = θi = θs: the highlight exceeds its
    surround by the coherent fraction R_spec = 1 − Ẽ_dif/Ẽ_tot = exp(−g) (Eq. 1 with ρ0 = 1,
    the forward form of Eq. 13 with R0 = 1), g from the sample's σ."""
    theta = sample["specular_theta_deg"]
    g = _core.roughness_g(theta, theta, sample["sigma_um"], WAVELENGTH_UM)
    e_tot = 1.0
    return e_tot * (1.0 - _core.coherent_power(1.0, g)), e_tot


def _write_specular(sample, folder, ext):
    """A photograph in the mirror direction at θ: the reflection of the (extended) source is a
    disc brighter than its surround (specular_brightness)."""
    import numpy as np

    theta = sample["specular_theta_deg"]
    e_dif, e_tot = specular_brightness(sample)
    yy, xx = np.mgrid[0:SIZE, 0:SIZE] + 0.5
    centre = SIZE / 2 + 3.0
    labels = ((xx - centre) ** 2 + (yy - centre + 6.0) ** 2
              <= HIGHLIGHT_RADIUS_PX ** 2).astype(np.int32)
    exposure = 0.5 * FULL_WELL / (ELECTRONS_PER_UNIT_S * e_tot)
    sub = folder / "specular"
    sub.mkdir(parents=True, exist_ok=True)
    _core.write_capture(str(sub), sample["fmt"], scene="plane", width=SIZE, height=SIZE,
                        theta_i_deg=theta, theta_v_deg=theta, phi_v_deg=0.0, labels=labels,
                        brightness=[lambda *_: e_dif, lambda *_: e_tot],
                        exposure_s=exposure, seed=sample["seed"] * 10 + 9,
                        **sample_camera(sample))
    return {"image": f"specular/capture.{ext}", "theta_i_deg": theta, "theta_s_deg": theta,
            "phi_s_deg": 0.0, "role": "specular"}


def lamp(sample, brightness=None):
    """Electrons per unit brightness and second of the sample's diffuse captures: the lamp that
    puts the first capture's mean at 40 % of the full well in BASE_EXPOSURE_S (a dim, slightly
    rough sample gets a brighter lamp, not an exposure of years)."""
    if brightness is None:
        brightness = [_mean_brightness(sample, t) for t in THETA_I_DEG]
    return 0.4 * FULL_WELL / (BASE_EXPOSURE_S * max(brightness))


def write_sample(sample, folder):
    """Write the captures and the capture file of one flat sample; return the file's path."""
    folder = pathlib.Path(folder)
    ext = "dng" if sample["fmt"] == "dng" else ("tiff" if sample["fmt"] == "tiff" else "png")
    electrons = lamp(sample)
    captures = []
    if "specular_theta_deg" in sample:
        captures.append(_write_specular(sample, folder, ext))
    for k, (theta, factor) in enumerate(zip(THETA_I_DEG, EXPOSURE_FACTORS)):
        sub = folder / f"capture{k + 1}"
        sub.mkdir(parents=True, exist_ok=True)
        exposure = BASE_EXPOSURE_S * factor
        _core.write_capture(str(sub), sample["fmt"], scene="plane", width=SIZE, height=SIZE,
                            theta_i_deg=theta, exposure_s=exposure,
                            seed=sample["seed"] * 10 + k, **surface_keywords(sample),
                            **sample_camera(sample, electrons_per_unit_s=electrons))
        captures.append({"image": f"capture{k + 1}/capture.{ext}", "theta_i_deg": theta,
                         "theta_s_deg": 0.0, "phi_s_deg": 0.0, "exposure_s": exposure,
                         "role": "diffuse"})
    margin = SIZE // 8
    spec = {"format": "roughscope-measure",
            "description": sample["description"],
            "response": sample["response"],
            "roi": {"rect": [margin, margin, SIZE - 2 * margin, SIZE - 2 * margin]},
            "captures": captures}
    if "sigma_um" in sample:
        # T given σ from the exact series (the pair is rendered with it; at this sample's
        # g ≈ 4 the paper's Eq. 15, "regime": "slightly_rough", reads T about 25 % high).
        spec["wavelength_um"] = WAVELENGTH_UM
        spec["correlation"] = sample["correlation"]
        spec["regime"] = "series"
    if sample["fmt"] != "dng":  # a RAW file carries its own black level
        spec["black_level_dn"] = black_level(sample["bits"])
    return write_capture_file(folder, spec)


def truth(sample):
    """The true values the report compares with (σ and T for the slightly rough sample)."""
    if "sigma_um" in sample:
        return {"sigma_um": sample["sigma_um"], "T_um": sample["T_um"]}
    return {f"sigma_over_T_{sample['correlation']}": sample["sigma_over_T"]}


# --------------------------------------------------------------------------------------------
# Curved objects and a map (14-bit linear TIFF)

OBJECT_BITS = 14
OBJECT_BLACK_LEVEL = black_level(OBJECT_BITS)
CYLINDER_SIGMA_OVER_T = 0.71   # a sandpaper of Table 2 (V–H Gaussian)
SPHERE_SIGMA_OVER_T = 0.5
MAP_REGIONS = (("slightly rough", 0.2), ("moderately rough", 1.0), ("very rough", 4.0))
MAP_SIZE = 256
MAP_WINDOW_PX = 16


def object_camera():
    """The camera of the objects and the map: 14-bit linear, black level 64 DN."""
    return camera(OBJECT_BITS, "linear")


def exposure_for_peak(peak_brightness, fill=0.6):
    """The exposure (s) that puts `peak_brightness` at `fill` of the full well."""
    return fill * FULL_WELL / (ELECTRONS_PER_UNIT_S * peak_brightness)


def peak_brightness(**scene):
    """The brightest model pixel of a scene (write_capture keywords), from a small render."""
    scene = dict(scene, width=64, height=64)
    out = _core.render_capture(shot_noise=False, **scene)
    return float(out["radiance"].max())


def write_cylinder(folder):
    """A cylinder lit from the camera (L = V = +z), V–H Gaussian truth; its capture file."""
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    scene = dict(scene="cylinder", width=200, height=160, theta_i_deg=0.0,
                 sigma_over_T=CYLINDER_SIGMA_OVER_T, correlation="gaussian")
    _core.write_capture(str(folder), "tiff", exposure_s=exposure_for_peak(peak_brightness(**scene)),
                        seed=21, **scene, **object_camera())
    spec = {"format": "roughscope-measure",
            "description": "synthetic cylinder, L = V (§5.2)",
            "black_level_dn": OBJECT_BLACK_LEVEL,
            # The known geometry, as in §5.2 (the renderer's axis: the vertical centre line,
            # radius 0.4 · 160 px). Found from the silhouette instead, the radius of a very
            # rough cylinder lit from the camera comes out short: its limb is dark.
            "object": {"shape": "cylinder",
                       "axis": {"point_px": [100, 80], "direction": [0, 1], "radius_px": 64}},
            "captures": [{"image": "capture.tiff", "light": [0, 0, 1], "view": [0, 0, 1]}]}
    return write_capture_file(folder, spec)


def write_sphere(folder):
    """A sphere lit at 30° from the camera, V–H Gaussian truth; its capture file."""
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    scene = dict(scene="sphere", width=160, height=160, theta_i_deg=30.0,
                 sigma_over_T=SPHERE_SIGMA_OVER_T, correlation="gaussian")
    _core.write_capture(str(folder), "tiff", exposure_s=exposure_for_peak(peak_brightness(**scene)),
                        seed=22, **scene, **object_camera())
    light = [-math.sin(math.radians(30.0)), 0.0, math.cos(math.radians(30.0))]
    spec = {"format": "roughscope-measure",
            "description": "synthetic sphere, light at 30°",
            "black_level_dn": OBJECT_BLACK_LEVEL,
            # The known circle (centred, radius 0.4 · 160 px): beyond the terminator the sphere
            # is dark and its outline cannot be seen.
            "object": {"shape": "sphere", "circle": [80, 80, 64]},
            "captures": [{"image": "capture.tiff", "light": light, "view": [0, 0, 1]}]}
    return write_capture_file(folder, spec)


def map_labels(shift_px=0):
    """The map's three regions: the top left quarter (slightly rough), the top right quarter
    (moderately rough) and the bottom half (very rough) — borders in both directions, so that
    the pair's registration is determined — optionally moved `shift_px` columns to the right."""
    import numpy as np

    half = MAP_SIZE // 2
    yy, xx = np.mgrid[0:MAP_SIZE, 0:MAP_SIZE]
    xx = xx - shift_px
    labels = np.where(yy >= half, 2, np.where(xx >= half, 1, 0))
    return labels.astype(np.int32)


def map_regions():
    """The named regions of the map, one window inside each region's borders."""
    half, w = MAP_SIZE // 2, MAP_WINDOW_PX
    rects = ([w, w, half - 2 * w, half - 2 * w], [half + w, w, half - 2 * w, half - 2 * w],
             [w, half + w, MAP_SIZE - 2 * w, half - 2 * w])
    return [{"name": name, "rect": rect} for (name, _), rect in zip(MAP_REGIONS, rects)]


def write_map_capture(folder, k, theta, exposure, shift_px=0, seed=None):
    """Capture k (0 or 1) of the map's pair, lit at θi = `theta`."""
    _core.write_capture(str(folder), "tiff", scene="plane", width=MAP_SIZE, height=MAP_SIZE,
                        theta_i_deg=theta, sigma_over_T=[r for _, r in MAP_REGIONS],
                        labels=map_labels(shift_px), correlation="gaussian",
                        exposure_s=exposure, seed=31 + k if seed is None else seed,
                        **object_camera())


def write_map(folder):
    """A flat sample with three regions of known σ/T (one per class), lit at 30° and 45°; its
    capture file with the regions named for the map's statistics."""
    folder = pathlib.Path(folder)
    captures = []
    for k, theta in enumerate((30.0, 45.0)):
        sub = folder / f"capture{k + 1}"
        sub.mkdir(parents=True, exist_ok=True)
        peak = max(peak_brightness(scene="plane", theta_i_deg=theta, sigma_over_T=r,
                                   correlation="gaussian") for _, r in MAP_REGIONS)
        exposure = exposure_for_peak(peak)
        write_map_capture(sub, k, theta, exposure)
        captures.append({"image": f"capture{k + 1}/capture.tiff", "theta_i_deg": theta,
                         "exposure_s": exposure})
    spec = {"format": "roughscope-measure",
            "description": "synthetic flat sample, three regions",
            "black_level_dn": OBJECT_BLACK_LEVEL,
            "maps": {"window_px": MAP_WINDOW_PX, "regions": map_regions()},
            "captures": captures}
    return write_capture_file(folder, spec)


# --------------------------------------------------------------------------------------------
# Measuring them

def measure(capture_file, maps_dir=None):
    """``roughscope measure CAPTURE --json [--maps DIR]`` when $ROUGHSCOPE_CLI names the tool
    (make demo sets it), else the same measurement through the module (one library behind both;
    the map files are then not written)."""
    cli = os.environ.get("ROUGHSCOPE_CLI")
    if not cli:
        return _core.measure(str(capture_file))
    args = [cli, "measure", str(capture_file), "--json"]
    if maps_dir is not None:
        args += ["--maps", str(maps_dir)]
    proc = subprocess.run(args, capture_output=True, text=True, timeout=600)
    if proc.returncode != 0:
        raise RuntimeError(f"roughscope measure {capture_file}: {proc.stderr.strip()}")
    return json.loads(proc.stdout)


def measure_samples(outdir):
    """Every flat sample written into outdir/captures/NAME and measured: a list of dicts
    {sample, capture_file, document, truth}."""
    out = []
    for sample in SAMPLES:
        capture_file = write_sample(sample, pathlib.Path(outdir) / "captures" / sample["name"])
        out.append(dict(sample=sample, capture_file=capture_file,
                        document=measure(capture_file), truth=truth(sample)))
    return out


def measure_objects(outdir):
    """The cylinder, the sphere and the map written into outdir/captures/objects and measured:
    a dict of {document, truth} per object (and the map's folder of layers, maps_dir)."""
    base = pathlib.Path(outdir) / "captures" / "objects"
    cylinder = measure(write_cylinder(base / "cylinder"))
    sphere = measure(write_sphere(base / "sphere"))
    maps_dir = base / "map" / "maps"
    flat = measure(write_map(base / "map"), maps_dir)
    return {"cylinder": dict(document=cylinder,
                             truth={"sigma_over_T_gaussian": CYLINDER_SIGMA_OVER_T}),
            "sphere": dict(document=sphere,
                           truth=f"V–H Gaussian, σ/T = {SPHERE_SIGMA_OVER_T}"),
            "map": dict(document=flat, truth=dict(MAP_REGIONS), maps_dir=maps_dir)}
