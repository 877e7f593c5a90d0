"""`roughscope simulate scatter` and roughscope.simulate_scatter: the Kirchhoff Monte Carlo.

Each success test has a failure companion (exit code, one-line message naming the flag). The
numbers are checked against the exact series the library evaluates independently
(roughscope.model / the document's series_diffuse) within the simulation's standard errors, the
CLI against the Python module (same seeds, same numbers), and the memory of a 1024² run.
"""

import json
import math
import os
import re
import subprocess
import sys

import pytest

import roughscope as rs
from conftest import cli_path

pytestmark = pytest.mark.cli

EXIT_USAGE, EXIT_DATA = 2, 4
SANITIZED = os.environ.get("ROUGHSCOPE_SANITIZED") == "1"
NAN_RE = re.compile(r"\b(nan|inf|infinity)\b", re.IGNORECASE)
RESULT_KEYS = ["theta_i_deg", "theta_s_deg", "phi_s_deg", "g", "T_vxy", "F2", "diffuse",
               "diffuse_stderr", "coherent", "coherent_stderr", "series_diffuse",
               "series_coherent", "diffuse_deviation", "n", "dx_um", "patch_um", "area_um2",
               "realisations", "layout", "lattice_index"]
BASE = ["simulate", "scatter", "--sigma-um", "0.04", "--T-um", "1", "--wavelength-um", "0.5"]


def run(*args, check=True):
    proc = subprocess.run([cli_path(), *map(str, args)], capture_output=True, text=True,
                          timeout=300)
    if check:
        assert proc.returncode == 0, f"exit {proc.returncode}: {proc.stderr}"
    assert not NAN_RE.search(proc.stdout), proc.stdout
    return proc


def fails(code, *args, mentions=()):
    proc = run(*args, check=False)
    assert proc.returncode == code, (proc.returncode, proc.stdout, proc.stderr)
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("roughscope: error: "), proc.stderr
    for word in mentions:
        assert word in lines[0], lines[0]
    assert proc.stdout == ""
    return lines[0]


def test_json_has_the_documented_keys_and_agrees_with_the_series():
    doc = json.loads(run(*BASE, "--theta-i", "30,45", "--theta-s", "0,20", "--phi-s", "0,90",
                         "--realisations", "80", "--json").stdout)
    assert list(doc) == ["roughscope_version", "options", "results"]
    assert doc["options"]["realisations"] == 80 and doc["options"]["n"] is None
    assert len(doc["results"]) == 2
    for r in doc["results"]:
        assert list(r) == RESULT_KEYS
        assert abs(r["diffuse"] - r["series_diffuse"]) <= 3 * r["diffuse_stderr"]
        assert r["diffuse_deviation"] == pytest.approx(
            (r["diffuse"] - r["series_diffuse"]) / r["diffuse_stderr"])
        # series_diffuse is Eq. 2 with the simulated patch's area: the model subcommand's
        # exact series with Beckmann's F and X = Y = patch/2 gives the same number.
        half = r["patch_um"] / 2
        model = json.loads(run("model", "--theta-i", r["theta_i_deg"], "--theta-s",
                               r["theta_s_deg"], "--phi-s", r["phi_s_deg"], "--sigma", 0.04,
                               "--T", 1, "--wavelength", 0.5, "--factor", "beckmann",
                               "--regime", "series", "--patch-x", half, "--patch-y", half,
                               "--json").stdout)
        assert r["series_diffuse"] == pytest.approx(model["diffuse"], rel=1e-9)
        assert r["g"] == pytest.approx(model["g"], rel=1e-12)


def test_json_failure_on_a_negative_sigma():
    fails(EXIT_USAGE, *BASE[:2], "--sigma-um", "-1", "--T-um", "1", "--theta-i", "30",
          "--theta-s", "0", "--phi-s", "0", "--json", mentions=["--sigma-um"])


def test_text_table_names_every_column():
    out = run(*BASE, "--theta-i", "30", "--theta-s", "10", "--phi-s", "45",
              "--realisations", "10").stdout
    assert "theta_i" in out and "diffuse" in out and "series" in out and "coherent" in out


def test_text_failure_on_a_missing_angle():
    fails(EXIT_USAGE, *BASE, "--theta-i", "30", "--phi-s", "0", mentions=["--theta-s"])


def test_csv_geometries_and_csv_output(tmp_path):
    geoms = tmp_path / "geoms.csv"
    geoms.write_text("theta_i,theta_s,phi_s\n30,0,0\n# a comment\n60,40,0\n")
    out = tmp_path / "out.csv"
    run(*BASE, "--csv", geoms, "--realisations", "20", "--output", out)
    lines = out.read_text().splitlines()
    assert lines[0].split(",") == RESULT_KEYS
    assert len(lines) == 3
    assert [float(lines[k].split(",")[0]) for k in (1, 2)] == [30, 60]


def test_csv_failures_name_the_file_and_line(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("theta_i,theta_s,phi_s\n30,0,0\n95,0,0\n")
    out = tmp_path / "out.csv"
    message = fails(EXIT_DATA, *BASE, "--csv", bad, "--output", out,
                    mentions=["bad.csv:3", "theta_i"])
    assert "[0" in message or "90" in message
    assert not out.exists()
    fails(EXIT_USAGE, *BASE, "--csv", bad, "--theta-i", "30", mentions=["--csv"])
    fails(EXIT_DATA, *BASE, "--csv", tmp_path / "missing.csv")


def test_cli_and_python_give_the_same_numbers():
    args = dict(sigma_um=0.04, T_um=1.0, wavelength_um=0.5, realisations=12, seed=99,
                correlation="exponential")
    doc = json.loads(run("simulate", "scatter", "--sigma-um", 0.04, "--T-um", 1,
                         "--wavelength-um", 0.5, "--realisations", 12, "--seed", 99,
                         "--correlation", "exponential", "--theta-i", "20,50",
                         "--theta-s", "10", "--phi-s", "0,120", "--json").stdout)
    py = rs.simulate_scatter([20, 50], 10, [0, 120], **args)
    assert doc.pop("roughscope_version") == rs.__version__  # the CLI's documents carry it
    assert py == doc


def test_python_failures_raise_the_library_errors():
    with pytest.raises(rs.InvalidArgument, match="realisations"):
        rs.simulate_scatter(30, 0, 0, sigma_um=0.04, T_um=1, realisations=1)
    with pytest.raises(TypeError):
        rs.simulate_scatter(30, 0, 0, sigma=0.04, T_um=1)
    with pytest.raises(TypeError, match="sigma_um"):
        rs.simulate_scatter(30, 0, 0, sigma_um="0.04", T_um=1)
    with pytest.raises(rs.InvalidArgument, match="theta_i"):
        rs.simulate_scatter(95, 0, 0, sigma_um=0.04, T_um=1)
    with pytest.raises(TypeError):
        rs.simulate_scatter(30, 0, 0, sigma_um=0.04, T_um=1, progress=3)


def test_python_progress_reports_and_can_stop_the_run():
    seen = []
    rs.simulate_scatter(30, 0, 0, sigma_um=0.04, T_um=1, realisations=10,
                        progress=lambda done, total: seen.append((done, total)))
    assert seen[-1] == (10, 10) and all(t == 10 for _, t in seen)

    class Stop(Exception):
        pass

    def stop(done, total):
        raise Stop()

    with pytest.raises(Stop):
        rs.simulate_scatter(30, 0, 0, sigma_um=0.04, T_um=1, realisations=50, progress=stop)


def test_lattice_and_direct_integrals_agree():
    z = rs.generate_surface(nx=32, ny=24, dx_um=0.25, T_um=1.0, sigma_um=0.1, seed=3)
    lat = rs.scattering_integral_lattice(z, 0.25, -10.0)
    assert lat["values"].shape == (24, 32)
    for i, j in [(0, 0), (1, 0), (3, 5), (31, 23)]:
        vx = lat["dvx_per_um"] * (i if i <= 16 else i - 32)
        vy = lat["dvy_per_um"] * (j if j <= 12 else j - 24)
        direct = rs.scattering_integral_at(z, 0.25, vx, vy, -10.0)
        assert abs(lat["values"][j, i] - direct) < 1e-13
    # A flat plate: 1 in the specular direction, 0 elsewhere on the lattice.
    flat = rs.scattering_integral_lattice([[0.0] * 8] * 8, 1.0, -3.0)["values"]
    assert abs(flat[0, 0] - 1) < 1e-15 and abs(flat).sum() - 1 < 1e-13
    with pytest.raises(rs.InvalidArgument, match="missing"):
        rs.scattering_integral_at([[0.0, math.nan]], 1.0, 0, 0, 1.0)


MEASURE = """
import resource, subprocess, sys
p = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
sys.stderr.buffer.write(p.stderr)
print(p.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
"""


@pytest.mark.skipif(SANITIZED, reason="memory is not measured under AddressSanitizer")
def test_a_1024_squared_ensemble_stays_below_200_mb():
    p = subprocess.run([sys.executable, "-c", MEASURE, cli_path(), *BASE, "--theta-i", "30",
                        "--theta-s", "0", "--phi-s", "0", "--nx", "1024", "--dx-um", "0.05",
                        "--realisations", "10", "--threads", "2"],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    code, peak_kb = (int(v) for v in p.stdout.split())
    assert code == 0, p.stderr
    assert peak_kb <= 200 * 1024, f"peak RSS {peak_kb / 1024:.0f} MiB"
