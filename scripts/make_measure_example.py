#!/usr/bin/env python3
"""Writes docs/examples/measure/: the capture file of the README's "Measure your own sample" and
its two photographs — small synthetic 8-bit sRGB PNGs (64 × 64) of a flat sample of σ/T = 0.3
(Gaussian correlation) lit at 30° and 45°, camera on the normal, the second at half the exposure
(roughscope.simulate capture's camera: shot and read noise, sRGB encoding).

Run once with the built module (the files are committed):
    PYTHONPATH=build/python /usr/bin/python3 scripts/make_measure_example.py
"""

import json
import pathlib
import shutil
import tempfile

from roughscope import _core

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "examples" / "measure"
SIZE = 64
SIGMA_OVER_T = 0.3
FULL_WELL = 60000.0


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    brightness = [float(_core.very_rough_brightness(t, 0.0, 0.0, SIGMA_OVER_T,
                                                    correlation="gaussian")) for t in (30.0, 45.0)]
    # Exposures 0.02 s and 0.01 s; the camera's sensitivity puts the first at 40 % of the well.
    base = 0.02
    electrons = 0.4 * FULL_WELL / (base * brightness[0])
    captures = []
    with tempfile.TemporaryDirectory() as tmp:
        for k, (theta, factor) in enumerate(((30.0, 1.0), (45.0, 0.5))):
            exposure = base * factor
            written = _core.write_capture(tmp, "png", f"capture{k + 1}", scene="plane",
                                          width=SIZE, height=SIZE, theta_i_deg=theta,
                                          sigma_over_T=SIGMA_OVER_T, correlation="gaussian",
                                          bits=8, response="srgb", exposure_s=exposure,
                                          electrons_per_unit_s=electrons, full_well_e=FULL_WELL,
                                          gain=1.05 * 255 / FULL_WELL, black_level=0,
                                          keep_geometry=False, seed=31 + k)
            shutil.copy(written["image"], OUT / f"capture{k + 1}.png")
            captures.append({"image": f"capture{k + 1}.png", "theta_i_deg": theta,
                             "exposure_s": exposure})
    spec = {"response": "srgb", "roi": {"rect": [8, 8, 48, 48]}, "captures": captures}
    (OUT / "capture-file.json").write_text(json.dumps(spec, indent=2) + "\n", encoding="utf-8")
    print(OUT)


if __name__ == "__main__":
    main()
