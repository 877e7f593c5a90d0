"""Every bad value of a capture file exits 4 with one line naming the file and the key
(docs/cli.md "Exit codes and errors", docs/measure.md "Errors"): the examples below, and a
property test that puts random JSON values under the keys of a valid capture file — the run
either succeeds (or finds no solution, exit 3) or exits 4 naming the key; never exit 1 or 2, a
crash or a traceback.
"""

import json
import os
import pathlib
import subprocess

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import roughscope._core as core
from conftest import cli_path


def photographs(folder):
    """Two 8-bit sRGB photographs (32 x 32) lit at 30° and 45°, a bigger one, a 16-bit one."""
    folder = pathlib.Path(folder)
    for name, theta, width, bits in (("a", 30.0, 32, 8), ("b", 45.0, 32, 8), ("big", 30.0, 40, 8),
                                     ("deep", 30.0, 32, 16)):
        core.write_capture(str(folder), "png", stem=name, scene="plane", width=width, height=32,
                           theta_i_deg=theta, sigma_over_T=0.3, bits=bits,
                           response="srgb" if bits == 8 else "linear",
                           black_level=0.0 if bits == 8 else 64.0,
                           gain=1.05 * (2.0 ** bits - 1) / 60000, full_well_e=60000.0)


BASE = {
    "response": "srgb",
    "roi": {"rect": [4, 4, 24, 24]},
    "captures": [{"image": "a.png", "theta_i_deg": 30, "exposure_s": 1},
                 {"image": "b.png", "theta_i_deg": 45, "exposure_s": 1}],
}


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    f = tmp_path_factory.mktemp("capture-file")
    photographs(f)
    return f


def run(folder, doc, name="c.json"):
    path = pathlib.Path(folder) / name
    path.write_text(json.dumps(doc, allow_nan=False))
    proc = subprocess.run([cli_path(), "measure", str(path), "--json"], capture_output=True,
                          text=True, timeout=120)
    return path, proc


def one_line(proc):
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("roughscope: error: "), proc.stderr
    return lines[0]


def changed(change):
    doc = json.loads(json.dumps(BASE))
    change(doc)
    return doc


def with_light(doc, light):
    c = doc["captures"][0]
    del c["theta_i_deg"]
    c.update(light=light, view=[0, 0, 1])


def with_bracket(doc):
    c = doc["captures"][0]
    del c["image"], c["exposure_s"]
    c["bracket"] = [{"image": "a.png", "exposure_s": 1}, {"image": "big.png", "exposure_s": 2}]


EXAMPLES = [
    ("maps.min_used_fraction", lambda d: d.update(maps={"min_used_fraction": 5})),
    ("maps.very_rough_min_sigma_over_T",
     lambda d: d.update(maps={"very_rough_min_sigma_over_T": 0.01})),
    ("sigma_um", lambda d: d.update(sigma_um=1e308)),
    ("sigma_um_stderr", lambda d: d.update(sigma_um_stderr=1e308)),
    ("wavelength_um", lambda d: d.update(wavelength_um=1e308)),
    ("captures[0].exposure_s", lambda d: d["captures"][0].update(exposure_s=1e-320)),
    ("captures[1].exposure_s", lambda d: d["captures"][1].update(exposure_s=1e308)),
    ("captures[0].light", lambda d: with_light(d, [1e308, 0, 1])),
    ("captures[0].light", lambda d: with_light(d, [1, 0, 1e-300])),
    ("captures[0].bracket[1].image", with_bracket),
    ("captures[0].theta_i_deg", lambda d: d["captures"][0].update(theta_i_deg=90)),
    ("captures[0].role", lambda d: d["captures"][0].update(role="specular", theta_s_deg=31)),
    ("roi", lambda d: d.update(roi={"rect": [1e308, 0, 4, 4]})),
    ("roi", lambda d: d.update(roi={"circle": [16, 16, 1e308]})),
    ("black_level_dn", lambda d: d.update(black_level_dn=1e308)),
    ("black_level_dn", lambda d: d.update(black_level_dn=[1, 2, 3])),
    ("highlight", lambda d: (d["captures"][0].update(role="specular", theta_s_deg=30),
                             d.update(highlight={"core_radius_px": 1e308}))),
    ("captures[1].image", lambda d: d["captures"][1].update(image="big.png")),
    ("dark_frame", lambda d: d.update(dark_frame="deep.png")),
    ("exposures_equal", lambda d: (d.update(exposures_equal=True),
                                   d["captures"][1].update(exposure_s=2))),
]


@pytest.mark.parametrize("key,change", EXAMPLES, ids=[f"{k}-{i}" for i, (k, _) in
                                                       enumerate(EXAMPLES)])
def test_a_bad_value_exits_4_naming_the_file_and_the_key(folder, key, change):
    path, proc = run(folder, changed(change))
    assert proc.returncode == 4, (proc.returncode, proc.stderr)
    line = one_line(proc)
    assert f"{path}: {key}" in line, line


def test_the_angles_are_echoed_as_typed(folder):
    # 30° through radians and back is 29.999999999999996°.
    _, proc = run(folder, changed(lambda d: d["captures"][0].update(
        role="specular", theta_s_deg=31, phi_s_deg=0.1)))
    line = one_line(proc)
    assert "theta_i = 30°, theta_s = 31°, phi_s = 0.1°" in line, line
    assert "29.99" not in line


# ---- the property: random values under every key -----------------------------------------------

# Every key of the capture file (docs/measure.md), as a path into the document.
KEYS = [
    ("format",), ("version",), ("description",), ("wavelength_um",), ("channel_wavelengths_um",),
    ("response",), ("response", "gamma"), ("black_level_dn",), ("dark_frame",), ("flat_field",),
    ("roi",), ("roi", "rect"), ("roi", "circle"), ("roi", "polygon"), ("roi", "mask"),
    ("captures",), ("correlation",), ("sigma_um",), ("sigma_um_stderr",), ("R0",), ("factor",),
    ("radiometry",), ("regime",), ("highlight",), ("highlight", "core_radius_px"),
    ("highlight", "annulus_inner_px"), ("highlight", "annulus_outer_px"),
    ("highlight", "smoothing_sigma_px"), ("highlight", "centre_px"), ("statistics",),
    ("statistics", "tile_size_px"), ("statistics", "max_excluded_fraction"), ("white_balance",),
    ("object",), ("object", "shape"), ("maps",), ("maps", "window_px"),
    ("maps", "min_used_fraction"), ("maps", "max_shift_px"), ("maps", "allow_misregistration"),
    ("maps", "slightly_rough_max_sigma_over_T"), ("maps", "very_rough_min_sigma_over_T"),
    ("maps", "regions"), ("exposures_equal",),
    ("captures", 0), ("captures", 0, "image"), ("captures", 0, "theta_i_deg"),
    ("captures", 0, "theta_s_deg"), ("captures", 0, "phi_s_deg"), ("captures", 0, "light"),
    ("captures", 0, "view"), ("captures", 0, "exposure_s"), ("captures", 0, "role"),
    ("captures", 0, "bracket"), ("captures", 1, "exposure_s"), ("captures", 1, "theta_i_deg"),
]

NUMBERS = st.one_of(
    st.integers(min_value=-2**70, max_value=2**70),
    st.floats(allow_nan=False, allow_infinity=False),
    st.sampled_from([0, -0.0, 5e-324, 1e-320, 1e-300, 1e300, 1.7976931348623157e308, 0.5, 1,
                     30, 89.99999999999999, 90, 1e6, 4096, 65535]))
SCALARS = st.one_of(st.none(), st.booleans(), NUMBERS,
                    st.sampled_from(["", "a.png", "big.png", "deep.png", "linear", "srgb",
                                     "gaussian", "specular", "plane", "cylinder", "sphere",
                                     "normal_map", "../nowhere.png", "\x1b[31m"]),
                    st.text(max_size=8))
VALUES = st.recursive(SCALARS, lambda children: st.one_of(
    st.lists(children, max_size=5), st.dictionaries(
        st.sampled_from(["rect", "circle", "gamma", "image", "exposure_s", "shape", "name",
                         "core_radius_px", "x"]), children, max_size=3)), max_leaves=12)


def put(doc, path, value):
    """doc with `value` at `path` (objects and lists on the way made as needed)."""
    node = doc
    for k, step in enumerate(path[:-1]):
        nxt = path[k + 1]
        empty = [] if isinstance(nxt, int) else {}
        if isinstance(node, list):
            while len(node) <= step:
                node.append({})
            if not isinstance(node[step], (dict, list)):
                node[step] = empty
            node = node[step]
        else:
            if not isinstance(node.get(step), (dict, list)):
                node[step] = empty
            node = node[step]
    last = path[-1]
    if isinstance(node, list):
        while len(node) <= last:
            node.append({})
    node[last] = value
    return doc


def key_text(path):
    """How the parser names the key: captures[0].theta_i_deg, maps.window_px, ..."""
    out = ""
    for step in path:
        out += f"[{step}]" if isinstance(step, int) else (f".{step}" if out else step)
    return out


EXAMPLES_PER_RUN = 60 if os.environ.get("ROUGHSCOPE_SANITIZED") == "1" else 250


@settings(max_examples=EXAMPLES_PER_RUN, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(path=st.sampled_from(KEYS), value=VALUES)
def test_random_values_under_every_key_exit_4_naming_it_or_succeed(folder, path, value):
    doc = put(json.loads(json.dumps(BASE)), path, value)
    file, proc = run(folder, doc, "random.json")
    assert proc.returncode in (0, 3, 4), (proc.returncode, proc.stderr, doc)
    assert "Traceback" not in proc.stderr
    if proc.returncode == 0:
        json.loads(proc.stdout)
        return
    line = one_line(proc)
    if proc.returncode == 4:
        # "<file>: <key>: ...": the key changed, or the one holding it, or (a combination that
        # cannot be measured: a dark frame that leaves the region black, a capture of another
        # size) the other key it clashes with.
        prefix = f"roughscope: error: {file}: "
        assert line.startswith(prefix), (line, path, value)
        named = line[len(prefix):].split(":")[0].split(" ")[0]
        assert named.split(".")[0].split("[")[0] in TOP_KEYS, (line, path, value)


TOP_KEYS = {path[0] for path in KEYS}
