"""Parity of the two front ends: every `roughscope ... --json` subcommand with a matching Python
function gives the same document for the same inputs, because both print what the library's
serializer (roughscope/serialize) builds. Same keys (recursively, in any order), numbers equal to
1e-12 relative, strings and booleans equal, null ↔ None.

CUReT cases need the shared data/curet and the paper-tables cases reference/paper-tables.json,
found by conftest.py's locator (io/data_locator.hpp: $ROUGHSCOPE_SHARED_DIR, else ../shared
searched upward); they skip, saying so, without them, and fail under
ROUGHSCOPE_REQUIRE_SHARED_DATA=1.
`roughscope model` has no Python counterpart and is not compared.
"""

import json
import math
import pathlib
import subprocess

import numpy as np
import pytest

import roughscope as rs
from roughscope import curet

from conftest import CURET_DIR, cli_json, cli_path, needs_curet


def assert_same(cli, py, path="$"):
    """Recursive comparison; the message names the first differing path. A CLI document carries
    the version that wrote it (serialize::versioned), which the Python dicts do not (they have
    roughscope.__version__): it must be that version, and is then left out of the comparison."""
    if isinstance(cli, dict) and "roughscope_version" in cli and "roughscope_version" not in py:
        assert cli["roughscope_version"] == rs.__version__, f"{path}.roughscope_version"
        cli = {k: v for k, v in cli.items() if k != "roughscope_version"}
    if isinstance(cli, dict):
        assert isinstance(py, dict), f"{path}: CLI has an object, Python {type(py).__name__}"
        assert set(cli) == set(py), (f"{path}: keys differ: only CLI {sorted(set(cli) - set(py))}, "
                                     f"only Python {sorted(set(py) - set(cli))}")
        for k in cli:
            assert_same(cli[k], py[k], f"{path}.{k}")
    elif isinstance(cli, list):
        assert isinstance(py, list), f"{path}: CLI has a list, Python {type(py).__name__}"
        assert len(cli) == len(py), f"{path}: lengths {len(cli)} != {len(py)}"
        for k, (a, b) in enumerate(zip(cli, py)):
            assert_same(a, b, f"{path}[{k}]")
    elif isinstance(cli, bool) or cli is None or isinstance(cli, str):
        assert cli == py and type(cli) is type(py), f"{path}: {cli!r} != {py!r}"
    else:
        assert isinstance(py, (int, float)) and not isinstance(py, bool), f"{path}: {py!r}"
        assert math.isclose(cli, py, rel_tol=1e-12, abs_tol=0.0 if cli else 1e-300), \
            f"{path}: {cli!r} != {py!r}"


def test_assert_same_detects_differences():
    assert_same({"a": [1.0, None, "x"]}, {"a": [1.0 + 1e-15, None, "x"]})
    for py in ({"a": [1.0, None, "x"], "b": 1}, {"a": [1.1, None, "x"]},
               {"a": [1.0, 0.0, "x"]}, {"a": [1.0, None, "y"]}):
        with pytest.raises(AssertionError):
            assert_same({"a": [1.0, None, "x"]}, py)


# ---- estimate specular ---------------------------------------------------------------------------

@pytest.mark.parametrize("cli_args, kwargs", [
    (["--r-spec", "0.014", "--theta", "14"], dict(R_spec=0.014, theta_deg=14)),
    (["--e-tot", "100", "--e-dif", "98.6", "--theta", "14", "--noise", "0.01"],
     dict(E_tot=100.0, E_dif=98.6, theta_deg=14, noise=0.01)),
    (["--r-spec", "0.2", "--theta", "30", "--wavelength", "0.6", "--r0", "0.9"],
     dict(R_spec=0.2, theta_deg=30, wavelength_um=0.6, R0=0.9)),
])
def test_estimate_specular(cli_args, kwargs):
    assert_same(cli_json("estimate", "specular", *cli_args), rs.estimate_sigma_specular(**kwargs))


# ---- estimate correlation-length -----------------------------------------------------------------

BASE_T = ["--sigma", "0.094", "--ratio", "1.043", "--theta1", "30", "--theta2", "45"]


@pytest.mark.parametrize("cli_args, kwargs", [
    ([], {}),
    (["--noise", "0.005", "--sigma-stderr", "0.01"], dict(noise=0.005, sigma_um_stderr=0.01)),
    (["--sigma-stderr", "0.01"], dict(sigma_um_stderr=0.01)),
    (["--correlation", "exponential", "--regime", "series"],
     dict(correlation="exponential", regime="series")),
    (["--theta-s1", "20", "--phi-s1", "90", "--factor", "beckmann"],
     dict(theta_s1_deg=20, phi_s1_deg=90, factor="beckmann")),
])
def test_estimate_correlation_length(cli_args, kwargs):
    assert_same(cli_json("estimate", "correlation-length", *BASE_T, *cli_args),
                rs.estimate_correlation_length(1.043, 0.094, 30, 45, **kwargs))


# ---- estimate slope ------------------------------------------------------------------------------

@pytest.mark.parametrize("cli_args, args, kwargs", [
    (["--ratio", "1.880176", "--theta1", "45", "--theta2", "67.5"], (1.880176, 45, 67.5),
     dict(correlation="both")),
    (["--ratio", "1.880176", "--theta1", "45", "--theta2", "67.5", "--correlation", "gaussian",
      "--noise", "0.01"], (1.880176, 45, 67.5), dict(correlation="gaussian", noise=0.01)),
    (["--ratio", "1.091", "--theta1", "30", "--theta2", "45", "--sigma", "5"], (1.091, 30, 45),
     dict(correlation="both", sigma_um=5.0)),
    (["--ratio", "1.3", "--theta1", "30", "--theta2", "45", "--correlation", "exponential",
      "--radiometry", "intensity"], (1.3, 30, 45),
     dict(correlation="exponential", radiometry="intensity")),
    (["--e1", "130", "--e2", "110", "--theta1", "30", "--theta2", "45", "--theta-s1", "20",
      "--phi-s1", "90", "--correlation", "gaussian"], (130.0 / 110.0, 30, 45),
     dict(correlation="gaussian", theta_s1_deg=20, phi_s1_deg=90)),
])
def test_estimate_slope(cli_args, args, kwargs):
    assert_same(cli_json("estimate", "slope", *cli_args), rs.estimate_slope(*args, **kwargs))


# ---- estimate fit --------------------------------------------------------------------------------

def _measurements(tmp_path, correlation, n=20, seed=7, noise=0.01):
    """A CSV in the paper's frame (phi_i = 180, so the CSV's phi_s is the paper's φs) and the same
    measurements as arrays. Integer angles keep both front ends on the same doubles."""
    rng = np.random.default_rng(seed)
    ti = rng.integers(0, 70, n).astype(float)
    ts = rng.integers(0, 70, n).astype(float)
    ps = rng.integers(90, 271, n).astype(float)  # φv − 180° + 180° is exact in radians here
    b = 3.0 * rs.very_rough_brightness(ti, ts, ps, 0.5, correlation=correlation)
    b = b * (1 + noise * rng.standard_normal(n))
    path = tmp_path / f"m_{correlation}_{seed}.csv"
    rows = ["theta_i,phi_i,theta_s,phi_s,brightness"]
    rows += [f"{a!r},180,{c!r},{d!r},{e!r}" for a, c, d, e in zip(ti, ts, ps, b)]
    path.write_text("\n".join(rows) + "\n")
    return path, (ti, ts, ps, np.array([float(repr(x)) for x in b]))


@pytest.mark.parametrize("correlation", ["gaussian", "exponential"])
def test_fit_one_correlation(tmp_path, correlation):
    path, arrays = _measurements(tmp_path, correlation)
    assert_same(cli_json("estimate", "fit", "--measurements", path, "--correlation", correlation,
                         "--residuals"),
                rs.fit_roughness(*arrays, correlation=correlation, residuals=True))
    assert_same(cli_json("estimate", "fit", "--measurements", path, "--correlation", correlation,
                         "--loss", "huber", "--residual", "log"),
                rs.fit_roughness(*arrays, correlation=correlation, loss="huber", residual="log",
                                 residuals=False))


def test_fit_both_correlations(tmp_path):
    path, arrays = _measurements(tmp_path, "exponential", n=30, seed=3)
    assert_same(cli_json("estimate", "fit", "--measurements", path),
                rs.compare_correlations(*arrays, residuals=False))


# ---- curet ---------------------------------------------------------------------------------------

def _table(tmp_path):
    rng = np.random.default_rng(11)
    n = 40
    ti = rng.integers(0, 70, n).astype(float)
    ts = rng.integers(0, 70, n).astype(float)
    ps = rng.integers(0, 360, n).astype(float)
    f = rs.very_rough_brightness(ti, ts, ps, 0.7, correlation="exponential") / np.cos(
        np.radians(ti))
    path = tmp_path / "brdf.csv"
    rows = ["theta_i,phi_i,theta_s,phi_s,value"]
    rows += [f"{a!r},180,{c!r},{d!r},{e!r}" for a, c, d, e in zip(ti, ts, ps, f)]
    path.write_text("\n".join(rows) + "\n")
    return path


def test_curet_table(tmp_path):
    path = _table(tmp_path)
    assert_same(cli_json("curet", "--table", path, "--pair", "1,2", "--no-fits"),
                curet.compare_table(path, pair=(1, 2), fits=False, series=False))
    assert_same(cli_json("curet", "--table", path, "--pair", "1,2", "--series"),
                curet.compare_table(path, pair=[1, 2], series=True))


@needs_curet
@pytest.mark.parametrize("sample, cli_args, kwargs", [
    (25, ["--no-fits"], dict(fits=False, series=False)),
    (41, ["--no-fits", "--series", "--radiometry", "intensity"],
     dict(fits=False, series=True, radiometry="intensity")),
    (61, ["--on-sigma", "0.3", "--on-albedo", "0.8", "--no-fits"],
     dict(fits=False, series=False, on_sigma_rad=0.3, on_albedo=0.8)),
    (34, [], dict(series=False)),
])
def test_curet_sample(sample, cli_args, kwargs):
    assert_same(cli_json("curet", "--sample", sample, "--data", CURET_DIR, *cli_args),
                curet.compare(sample, data_dir=CURET_DIR, **kwargs))


# ---- paper tables --------------------------------------------------------------------------------

def test_paper_tables(paper_tables, tmp_path):
    ref = tmp_path / "paper-tables.json"
    ref.write_text(json.dumps(paper_tables), encoding="utf-8")
    cli = cli_json("paper", "tables", "--reference", ref)
    assert cli.pop("reference") == str(ref)
    assert_same(cli, rs.recompute_paper_tables(paper_tables))


def test_paper_tables_bad_reference_fails_in_both(paper_tables, tmp_path):
    broken = {k: v for k, v in paper_tables.items() if k != "table2_very_rough"}
    ref = tmp_path / "broken.json"
    ref.write_text(json.dumps(broken), encoding="utf-8")
    proc = subprocess.run([cli_path(), "paper", "tables", "--reference", str(ref)],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 4 and "missing key 'table2_very_rough'" in proc.stderr
    with pytest.raises(rs.DataError, match="missing key 'table2_very_rough'"):
        rs.recompute_paper_tables(broken)


@pytest.mark.parametrize("index", [0, 1, 2], ids=["srgb8-png", "linear16-tiff", "dng"])
def test_image_info_is_one_schema(tmp_path, index):
    """A photograph's ImageInfo has one conversion (serialize/measure.hpp): the `info` of each
    capture of `measure --json` and the `info` of Python's read_image are the same document for
    the same image and options, and the capture's metadata keys repeat its values."""
    from roughscope import _core, demo

    spec = demo.SAMPLES[index]
    capture_file = demo.write_sample(spec, tmp_path)
    doc = json.loads(pathlib.Path(capture_file).read_text(encoding="utf-8"))
    result = cli_json("measure", capture_file)
    for spec_capture, capture in zip(doc["captures"], result["captures"]):
        path = tmp_path / spec_capture["image"]
        py = _core.read_image(str(path), response=doc["response"],
                              black_level_dn=doc.get("black_level_dn"))["info"]
        cli = dict(capture["info"])
        assert set(cli) == set(py)
        assert pathlib.Path(cli.pop("source")).name == pathlib.Path(py.pop("source")).name
        assert_same(cli, py)
        for key in ("format", "bits_per_sample", "response", "file_response",
                    "file_response_evidence"):
            assert capture[key] == py[key], key
        for key in ("exposure_s", "iso", "f_number"):
            assert capture[f"{key}_metadata"] == py[key], key
