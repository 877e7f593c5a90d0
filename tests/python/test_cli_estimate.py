"""Tests of `roughscope estimate ...` and `roughscope paper tables`.

Numbers are checked against the paper's tables (the shared reference/paper-tables.json, through
conftest.py's `paper_tables_path` fixture) or the paper's equations evaluated here with Python's
math module. Every success test has bad-input companions asserting the exit code and a one-line
message. The CLI is found by conftest.cli_path: ROUGHSCOPE_CLI (ctest sets it), else
build/bin/roughscope.
"""

import csv
import json
import math
import random
import re
import subprocess

import pytest

from conftest import REPO_ROOT as REPO
from conftest import cli_path

EXIT_USAGE, EXIT_NO_SOLUTION, EXIT_DATA = 2, 3, 4
NAN_RE = re.compile(r"\b(nan|inf|infinity)\b", re.IGNORECASE)


def run(*args, check=True, cwd=None):
    proc = subprocess.run([cli_path(), *map(str, args)], capture_output=True, text=True, timeout=300,
                          cwd=cwd)
    if check:
        assert proc.returncode == 0, f"exit {proc.returncode}: {proc.stderr}"
    # never a NaN or an infinity printed as a number
    assert not NAN_RE.search(proc.stdout.replace('"inf"', "")), proc.stdout
    return proc


def run_json(*args):
    return json.loads(run(*args, "--json").stdout)


def assert_error(proc, code, *needles):
    assert proc.returncode == code, (proc.returncode, proc.stderr)
    assert proc.stdout == ""
    lines = proc.stderr.strip("\n").split("\n")
    assert len(lines) == 1 and lines[0].startswith("roughscope: error: "), proc.stderr
    for n in needles:
        assert n in lines[0], (n, lines[0])


def eq17(r, t1, t2):
    a = lambda t: math.tan(math.radians(t) / 2) ** 2
    w = lambda t: math.cos(math.radians(t)) / (1 + math.cos(math.radians(t))) ** 2
    return 0.5 * math.sqrt((a(t2) - a(t1)) / math.log(r * w(t2) / w(t1)))


# ---- estimate slope ------------------------------------------------------------------------------

def test_slope_table3_json_keys():
    out = run_json("estimate", "slope", "--ratio", "1.880176", "--theta1", "45", "--theta2", "67.5",
                   "--noise", "0.01")
    assert round(out["sigma_over_T_gaussian"], 4) == 0.3957
    assert round(out["sigma_over_T_exponential"], 4) == 0.7982
    assert out["sigma_over_T"] == out["sigma_over_T_gaussian"]
    for key in ("sigma_over_T_stderr", "sigma_over_T_gaussian_stderr",
                "sigma_over_T_exponential_stderr", "theta_K_deg", "xi_K", "rms_slope",
                "roughness_class", "g", "warnings", "theta_K_deg_stderr"):
        assert key in out, key
    assert out["theta_K_deg"] == pytest.approx(90 - math.degrees(math.atan(math.sqrt(2) * out["sigma_over_T"])), rel=1e-9)
    assert any("theta_K" in w for w in out["warnings"])  # 67.5 deg > theta_K = 60.8 deg
    # --e1/--e2 is the same as --ratio
    out2 = run_json("estimate", "slope", "--e1", "1.880176", "--e2", "1", "--theta1", "45",
                    "--theta2", "67.5", "--correlation", "gaussian")
    assert out2["sigma_over_T"] == pytest.approx(eq17(1.880176, 45, 67.5), rel=1e-9)
    assert out2["sigma_over_T_exponential"] is None


def test_slope_general_geometry_and_text_output():
    out = run_json("estimate", "slope", "--ratio", "1.1", "--theta1", "30", "--theta2", "45",
                   "--theta-s1", "20", "--phi-s1", "90")
    assert "solver" in out["estimator"] and out["sigma_over_T"] > 0
    text = run("estimate", "slope", "--ratio", "1.091", "--theta1", "30", "--theta2", "45").stdout
    assert "sigma_over_T_gaussian" in text and "0.63233" in text


def test_slope_errors():
    p = run("estimate", "slope", "--ratio", "1.0", "--theta1", "30", "--theta2", "45", check=False)
    assert_error(p, EXIT_NO_SOLUTION, "E1/E2 = 1", "must be > 1.025019")
    p = run("estimate", "slope", "--ratio", "4", "--theta1", "30", "--theta2", "45",
            "--correlation", "exponential", check=False)
    assert_error(p, EXIT_NO_SOLUTION, "(1.025019, 3.786583)")
    p = run("estimate", "slope", "--ratio", "1.1", "--theta1", "90", "--theta2", "45", check=False)
    assert_error(p, EXIT_USAGE, "--theta1")
    p = run("estimate", "slope", "--ratio", "1.1", "--theta1", "30", "--theta2", "30", check=False)
    assert_error(p, EXIT_USAGE, "theta1 = theta2")
    p = run("estimate", "slope", "--e1", "0", "--e2", "1", "--theta1", "30", "--theta2", "45",
            check=False)
    assert_error(p, EXIT_USAGE, "--e1")
    p = run("estimate", "slope", "--ratio", "nan", "--theta1", "30", "--theta2", "45", check=False)
    assert_error(p, EXIT_USAGE, "--ratio")
    p = run("estimate", "slope", "--ratio", "1.1", "--e1", "1", "--theta1", "30", "--theta2", "45",
            check=False)
    assert_error(p, EXIT_USAGE, "--ratio excludes")
    p = run("estimate", "slope", "--ratio", "1.1", "--theta1", "30", check=False)
    assert_error(p, EXIT_USAGE, "--theta2")
    p = run("estimate", "slope", "--ratio", "1.1", "--theta1", "30", "--theta2", "45",
            "--correlation", "lorentzian", check=False)
    assert_error(p, EXIT_USAGE, "--correlation", "lorentzian", "gaussian, exponential, both")


def test_correlation_names_are_case_insensitive():
    # the library's name scheme (core/names.hpp): any case, '-' == '_'
    base = ("estimate", "slope", "--ratio", "1.091", "--theta1", "30", "--theta2", "45")
    assert run_json(*base, "--correlation", "BOTH") == run_json(*base)
    one = run_json(*base, "--correlation", "Exponential")
    assert one["sigma_over_T_gaussian"] is None and one["sigma_over_T_exponential"] > 0


# ---- estimate specular / correlation-length ------------------------------------------------------

def test_specular_table1_glossy_paper():
    out = run_json("estimate", "specular", "--r-spec", "0.014", "--theta", "14")
    expected = 0.555 / (4 * math.pi * math.cos(math.radians(14))) * math.sqrt(math.log(1 / 0.014))
    assert out["sigma_um"] == pytest.approx(expected, rel=1e-9)
    assert round(out["sigma_um"], 3) == 0.094
    assert out["g"] == [pytest.approx(math.log(1 / 0.014), rel=1e-9)]
    assert "sigma_um_stderr" not in out  # no --noise given: no uncertainty keys
    out = run_json("estimate", "specular", "--e-tot", "100", "--e-dif", "98.6", "--theta", "14",
                   "--noise", "0.01")
    assert out["R_spec"] == pytest.approx(0.014) and out["sigma_um_stderr"] > 0


def test_specular_errors():
    p = run("estimate", "specular", "--r-spec", "1", "--theta", "14", check=False)
    assert_error(p, EXIT_USAGE, "R_spec = 1", "R0 = 1")
    p = run("estimate", "specular", "--r-spec", "0.5", "--theta", "14", "--r0", "0.4", check=False)
    assert_error(p, EXIT_USAGE, "R_spec")
    p = run("estimate", "specular", "--e-tot", "1", "--e-dif", "2", "--theta", "14", check=False)
    assert_error(p, EXIT_USAGE, "E_dif")
    p = run("estimate", "specular", "--r-spec", "0.01", "--theta", "95", check=False)
    assert_error(p, EXIT_USAGE, "--theta")
    p = run("estimate", "specular", "--r-spec", "0.01", check=False)
    assert_error(p, EXIT_USAGE, "--theta")


def test_correlation_length_table1():
    out = run_json("estimate", "correlation-length", "--sigma", "0.094", "--ratio", "1.043",
                   "--theta1", "30", "--theta2", "45", "--noise", "0.005")
    assert round(out["T_um"], 3) == 0.195 and round(out["sigma_over_T"], 3) == 0.482
    for key in ("T_um_stderr", "sigma_over_T_stderr", "theta_K_deg", "xi_K", "rms_slope", "g",
                "roughness_class", "warnings"):
        assert key in out
    assert len(out["g"]) == 2 and out["roughness_class"] == "moderately_rough"
    out = run_json("estimate", "correlation-length", "--sigma", "0.08", "--ratio", "1.5",
                   "--theta1", "30", "--theta2", "50", "--correlation", "exponential",
                   "--regime", "series")
    assert out["T_um"] > 0 and "solver" in out["estimator"]


def test_correlation_length_errors():
    p = run("estimate", "correlation-length", "--sigma", "0.094", "--ratio", "0.5", "--theta1",
            "30", "--theta2", "45", check=False)
    assert_error(p, EXIT_NO_SOLUTION, "Eq. 15", "must be > 0.769")
    p = run("estimate", "correlation-length", "--ratio", "1.04", "--theta1", "30", "--theta2", "45",
            check=False)
    assert_error(p, EXIT_USAGE, "--sigma")
    p = run("estimate", "correlation-length", "--sigma", "-1", "--ratio", "1.04", "--theta1", "30",
            "--theta2", "45", check=False)
    assert_error(p, EXIT_USAGE, "--sigma")


# ---- estimate fit --------------------------------------------------------------------------------

def _write_measurements(path, s=0.4, n=30, noise=0.01, seed=7, weight=False):
    rnd = random.Random(seed)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["theta_i", "phi_i", "theta_s", "phi_s", "brightness"] + (["weight"] if weight else []))
        for _ in range(n):
            ti, ts, ps = rnd.uniform(0, 70), rnd.uniform(0, 70), rnd.uniform(0, 360)
            a, b, c = map(math.radians, (ti, ts, ps))
            qx = math.sin(a) - math.sin(b) * math.cos(c)
            qy = -math.sin(b) * math.sin(c)
            qz2 = (math.cos(a) + math.cos(b)) ** 2
            E = 50 * math.cos(a) / qz2 * math.exp(-(qx * qx + qy * qy) / (4 * s * s * qz2))
            # the light at phi_i = 180 (paper frame): phi_s is the paper's azimuth
            w.writerow([ti, 180, ts, ps, E * (1 + noise * rnd.gauss(0, 1))] + ([1.0] if weight else []))


def test_fit_csv(tmp_path):
    f = tmp_path / "m.csv"
    _write_measurements(f)
    out = run_json("estimate", "fit", "--measurements", f)
    assert out["preferred_correlation"] == "gaussian"
    assert abs(out["sigma_over_T_gaussian"] - 0.4) < 3 * out["sigma_over_T_gaussian_stderr"]
    for key in ("sigma_over_T", "sigma_over_T_stderr", "sigma_over_T_exponential", "delta_aic",
                "theta_K_deg", "xi_K", "rms_slope", "roughness_class", "warnings"):
        assert key in out
    assert out["gaussian"]["status"] == "converged" and len(out["gaussian"]["covariance"]) == 2
    one = run_json("estimate", "fit", "--measurements", f, "--correlation", "gaussian",
                   "--residuals", "--loss", "huber")
    assert len(one["residuals"]) == 30 and one["aic"] == pytest.approx(
        30 * math.log(one["sse"] / 30) + 4, rel=1e-6)
    # the same data in the CUReT-like frame (light at phi_i = 0) give the same fit
    g = tmp_path / "m2.csv"
    rows = list(csv.reader(open(f)))
    with open(g, "w", newline="") as h:
        w = csv.writer(h)
        w.writerow(rows[0])
        for r in rows[1:]:
            w.writerow([r[0], 0, r[2], float(r[3]) - 180, r[4]])
    two = run_json("estimate", "fit", "--measurements", g, "--correlation", "gaussian")
    assert two["sigma_over_T"] == pytest.approx(run_json("estimate", "fit", "--measurements", f,
                                                         "--correlation", "gaussian")["sigma_over_T"], rel=1e-9)


def test_fit_errors(tmp_path):
    f = tmp_path / "bad.csv"
    f.write_text("theta_i,phi_i,theta_s,phi_s,brightness\n10,180,0,0,1\n20,180,0,0,abc\n30,180,0,0,2\n")
    assert_error(run("estimate", "fit", "--measurements", f, check=False), EXIT_DATA, ":3:", "brightness")
    f.write_text("theta_i,phi_i,theta_s,phi_s,brightness\n10,180,0,0,1\n20,180,0,0,-2\n30,180,0,0,2\n")
    assert_error(run("estimate", "fit", "--measurements", f, check=False), EXIT_DATA, ":3:", "> 0")
    f.write_text("theta_i,phi_i,theta_s,phi_s,brightness\n10,180,0,0,1\n95,180,0,0,2\n30,180,0,0,2\n")
    assert_error(run("estimate", "fit", "--measurements", f, check=False), EXIT_DATA, ":3:", "theta_i")
    f.write_text("theta_i,theta_s,phi_s,brightness\n10,0,0,1\n")
    assert_error(run("estimate", "fit", "--measurements", f, check=False), EXIT_DATA, "phi_i")
    f.write_text("theta_i,phi_i,theta_s,phi_s,brightness\n10,180,0,0,1\n")
    assert_error(run("estimate", "fit", "--measurements", f, check=False), EXIT_NO_SOLUTION,
                 "1 measurement at 1 distinct geometry")
    assert_error(run("estimate", "fit", "--measurements", tmp_path / "missing.csv", check=False), EXIT_DATA)
    assert_error(run("estimate", "fit", check=False), EXIT_USAGE, "--measurements")


def test_output_file_is_atomic(tmp_path):
    out = tmp_path / "r.json"
    run("estimate", "slope", "--ratio", "1.091", "--theta1", "30", "--theta2", "45", "--json",
        "--output", out)
    assert json.loads(out.read_text())["sigma_over_T"] == pytest.approx(eq17(1.091, 30, 45))
    bad = tmp_path / "never.json"
    p = run("estimate", "slope", "--ratio", "0.9", "--theta1", "30", "--theta2", "45", "--json",
            "--output", bad, check=False)
    assert p.returncode == EXIT_NO_SOLUTION and not bad.exists()
    assert list(tmp_path.iterdir()) == [out]


# ---- paper tables --------------------------------------------------------------------------------

def test_paper_tables(paper_tables_path):
    out = run_json("paper", "tables", "--reference", paper_tables_path)
    for row in out["table3"]["rows"]:
        assert row["sigma_over_T_G"]["agreement"] == "exact"
        assert row["sigma_over_T_E"]["agreement"] == "exact"
    for row in out["table2"]["rows"]:
        for k in ("sigma_over_T_G", "sigma_over_T_E", "theta_K_deg", "xi_K_percent"):
            assert row[k]["agreement"] in ("exact", "within_rounding"), (row["surface"], k)
        assert row["theta_K_deg"]["agreement"] == "exact"
    for row in out["table1"]["rows"]:
        for k in ("sigma_um", "T_um", "sigma_over_T"):
            assert row[k]["agreement"] in ("exact", "within_rounding"), (row["surface"], k)
    text = run("paper", "tables", "--reference", paper_tables_path).stdout
    assert "Table 1" in text and "Table 3" in text and "DIFFERS" not in text.split("*")[0]
    # default path: ../shared/reference/paper-tables.json relative to the working directory
    assert run("paper", "tables", cwd=REPO).returncode == 0


def test_paper_tables_missing_reference(tmp_path):
    p = run("paper", "tables", "--reference", tmp_path / "nope.json", check=False)
    assert_error(p, EXIT_DATA, "paper tables not found", "--reference")
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    assert_error(run("paper", "tables", "--reference", bad, check=False), EXIT_DATA, "not valid JSON")
    p = run("paper", "tables", cwd=tmp_path, check=False)
    assert_error(p, EXIT_DATA, "../shared/reference/paper-tables.json")
