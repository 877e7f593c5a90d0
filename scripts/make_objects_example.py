#!/usr/bin/env python3
"""Writes docs/examples/measure/cylinder.json, map.json and their photographs: small synthetic
16-bit linear PNGs (the report's demo camera, roughscope.demo: 14-bit, shot and read
noise, black level 64 DN) of
  * a cylinder lit from the camera (L = V), V–H Gaussian σ/T = 0.71, 120 × 96 pixels, axis given;
  * a flat sample with three regions (σ/T 0.2, 1, 4: one per class), lit at 30° and 45°, camera
    on the normal, 96 × 96 pixels, for a map with 8-pixel tiles.

Run once with the built module (the files are committed):
    PYTHONPATH=build/python /usr/bin/python3 scripts/make_objects_example.py
"""

import json
import pathlib
import shutil
import tempfile

import numpy as np

from roughscope import _core, demo as ro

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "examples" / "measure"


def write(tmp, name, **scene):
    written = _core.write_capture(tmp, "png", name, **scene, **ro.object_camera())
    shutil.copy(written["image"], OUT / f"{name}.png")


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        scene = dict(scene="cylinder", width=120, height=96, theta_i_deg=0.0,
                     sigma_over_T=ro.CYLINDER_SIGMA_OVER_T, correlation="gaussian")
        write(tmp, "cylinder", exposure_s=ro.exposure_for_peak(ro.peak_brightness(**scene)),
              seed=41, **scene)
        size, half = 96, 48
        yy, xx = np.mgrid[0:size, 0:size]
        labels = np.where(yy >= half, 2, np.where(xx >= half, 1, 0)).astype(np.int32)
        ratios = [r for _, r in ro.MAP_REGIONS]
        captures = []
        for k, theta in enumerate((30.0, 45.0)):
            peak = max(ro.peak_brightness(scene="plane", theta_i_deg=theta, sigma_over_T=r,
                                correlation="gaussian") for r in ratios)
            exposure = float(f"{ro.exposure_for_peak(peak):.6g}")
            write(tmp, f"map{k + 1}", scene="plane", width=size, height=size, theta_i_deg=theta,
                  sigma_over_T=ratios, labels=labels, correlation="gaussian",
                  exposure_s=exposure, seed=51 + k)
            captures.append({"image": f"map{k + 1}.png", "theta_i_deg": theta,
                             "exposure_s": exposure})
    cylinder = {"black_level_dn": ro.OBJECT_BLACK_LEVEL, "response": "linear",
                "object": {"shape": "cylinder",
                           "axis": {"point_px": [60, 48], "direction": [0, 1],
                                    "radius_px": 38.4}},
                "captures": [{"image": "cylinder.png", "light": [0, 0, 1]}]}
    regions = [{"name": "top left", "rect": [8, 8, 32, 32]},
               {"name": "top right", "rect": [56, 8, 32, 32]},
               {"name": "bottom", "rect": [8, 56, 80, 32]}]
    flat = {"black_level_dn": ro.OBJECT_BLACK_LEVEL, "response": "linear",
            "maps": {"window_px": 8, "regions": regions}, "captures": captures}
    for name, doc in (("cylinder.json", cylinder), ("map.json", flat)):
        (OUT / name).write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")
    print(OUT)


if __name__ == "__main__":
    main()
