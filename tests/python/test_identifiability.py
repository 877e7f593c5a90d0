"""Fits the data cannot determine are never reported as results (docs/cli.md, docs/estimation.md).

A one-row BRDF table, or measurements all at one geometry, cannot determine σ/T (or σ and T) and
the gain: every fit path — `estimate fit`, `curet --table`, and their Python twins — reports
`not_identifiable` with the reason, no number for the undetermined parameters, no winner, and the
CLI exits 3 (no solution) instead of printing an arbitrary σ/T with exit 0. Each case is paired
with one that the data do determine.
"""

import json
import subprocess

import numpy as np
import pytest

import roughscope as rs

from conftest import cli_path

# Drives the CLI: also run against the sanitizer build (`make sanitize`, DEVELOPERS.md).
pytestmark = pytest.mark.cli

EXIT_NO_SOLUTION = 3
HEADER = "theta_i,phi_i,theta_s,phi_s,brightness\n"
TABLE_HEADER = "theta_i,phi_i,theta_s,phi_s,value\n"


def run(*args):
    return subprocess.run([cli_path(), *map(str, args)], capture_output=True, text=True,
                          timeout=300)


def assert_no_solution(proc, *needles):
    assert proc.returncode == EXIT_NO_SOLUTION, (proc.returncode, proc.stdout, proc.stderr)
    assert proc.stdout == ""
    lines = proc.stderr.strip("\n").split("\n")
    assert len(lines) == 1 and lines[0].startswith("roughscope: error: "), proc.stderr
    assert "not identifiable" in lines[0] or "no model is identifiable" in lines[0], lines[0]
    for n in needles:
        assert n in lines[0], (n, lines[0])


# ---------------------------------------------------------------------------------------------
# estimate fit

SAME_GEOMETRY = {
    "equal": HEADER + "30,180,0,0,1.0\n" * 3,
    "scattered": HEADER + "30,180,0,0,1.0\n30,180,0,0,1.1\n30,180,0,0,0.9\n",
}


@pytest.mark.parametrize("rows", sorted(SAME_GEOMETRY))
@pytest.mark.parametrize("correlation", ["gaussian", "exponential", "both"])
def test_estimate_fit_at_one_geometry_exits_3(tmp_path, rows, correlation):
    f = tmp_path / "same.csv"
    f.write_text(SAME_GEOMETRY[rows])
    assert_no_solution(run("estimate", "fit", "--measurements", f, "--correlation", correlation),
                       "3 measurements at 1 distinct geometry", "sigma_over_T")
    assert_no_solution(run("estimate", "fit", "--measurements", f, "--correlation", correlation,
                           "--json"), "at least 2 distinct geometries")


def test_estimate_fit_slightly_rough_needs_three_geometries(tmp_path):
    f = tmp_path / "two.csv"
    f.write_text(HEADER + "20,180,0,0,1.0\n40,180,0,0,0.8\n40,180,0,0,0.8\n")
    assert_no_solution(run("estimate", "fit", "--measurements", f, "--model", "slightly-rough",
                           "--correlation", "gaussian"),
                       "3 measurements at 2 distinct geometries", "the data do not determine",
                       "at least 3 distinct geometries")


def test_estimate_fit_with_fewer_rows_than_parameters_exits_3(tmp_path):
    f = tmp_path / "one.csv"
    f.write_text(HEADER + "30,180,0,0,1.0\n")
    for correlation in ("gaussian", "both"):
        assert_no_solution(run("estimate", "fit", "--measurements", f, "--correlation",
                               correlation), "1 measurement at 1 distinct geometry")
    f.write_text(HEADER + "20,180,0,0,1.0\n40,180,0,0,0.8\n")
    assert_no_solution(run("estimate", "fit", "--measurements", f, "--model", "slightly-rough",
                           "--correlation", "gaussian"), "2 measurements at 2 distinct geometries")


def test_estimate_fit_at_distinct_geometries_succeeds(tmp_path):
    ti = np.array([10.0, 30.0, 50.0, 70.0])
    b = rs.very_rough_brightness(ti, 0.0, 0.0, 0.4) * 3.0
    f = tmp_path / "good.csv"
    f.write_text(HEADER + "".join(f"{t},180,0,0,{v!r}\n" for t, v in zip(ti, b)))
    proc = run("estimate", "fit", "--measurements", f, "--correlation", "gaussian", "--json")
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(proc.stdout)
    assert doc["status"] == "converged"
    assert doc["sigma_over_T"] == pytest.approx(0.4, rel=1e-6)
    assert doc["not_identifiable"] == []


# ---------------------------------------------------------------------------------------------
# curet --table

ONE_GEOMETRY_TABLES = {
    "one-row": TABLE_HEADER + "30,180,0,0,0.1\n",
    "identical-rows": TABLE_HEADER + "30,180,0,0,0.1\n" * 3,
}


@pytest.mark.parametrize("table", sorted(ONE_GEOMETRY_TABLES))
@pytest.mark.parametrize("extra", [[], ["--json"], ["--no-fits"], ["--format", "csv"]])
def test_curet_table_at_one_geometry_exits_3(tmp_path, table, extra):
    f = tmp_path / "t.csv"
    f.write_text(ONE_GEOMETRY_TABLES[table])
    rows = 1 if table == "one-row" else 3
    assert_no_solution(run("curet", "--table", f, *extra),
                       f"{rows} measurement{'s' if rows > 1 else ''} at 1 distinct geometry")


def test_curet_table_at_distinct_geometries_names_a_winner(tmp_path):
    f = tmp_path / "t.csv"
    f.write_text(TABLE_HEADER + "30,180,0,0,0.1\n60,180,0,0,0.05\n45,180,20,30,0.08\n")
    proc = run("curet", "--table", f, "--json")
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["winner"] is not None


# ---------------------------------------------------------------------------------------------
# The Python twins

def test_python_fit_at_one_geometry_is_not_identifiable():
    ti, ts, ps = [30.0] * 3, [0.0] * 3, [0.0] * 3
    for b in ([1.0, 1.0, 1.0], [1.0, 1.1, 0.9]):
        for correlation in ("gaussian", "exponential"):
            r = rs.fit_roughness(ti, ts, ps, b, correlation=correlation)
            assert r["status"] == "not_identifiable", r["report"]
            assert r["sigma_over_T"] is None and r["gain"] is None
            assert r["theta_K_deg"] is None and r["rms_slope"] is None
            assert r["not_identifiable"] == ["sigma_over_T", "gain"]
            assert "3 measurements at 1 distinct geometry" in r["message"]
            assert all(p["value"] is None and not p["identified"] for p in r["parameter_table"])
        c = rs.compare_correlations(ti, ts, ps, b)
        assert c["sigma_over_T"] is None and c["delta_aic"] is None
        r = rs.fit_roughness(ti, ts, ps, b, model="slightly_rough")
        assert r["status"] == "not_identifiable"
        assert r["sigma_um"] is None and r["T_um"] is None and r["g"] is None


def test_python_fit_with_fewer_rows_than_parameters_is_not_identifiable():
    r = rs.fit_roughness([30.0], [0.0], [0.0], [1.0])
    assert r["status"] == "not_identifiable" and r["sigma_over_T"] is None
    assert "1 measurement at 1 distinct geometry" in r["message"]
    r = rs.fit_roughness([20.0, 40.0], [0.0, 0.0], [0.0, 0.0], [1.0, 0.8],
                         model="slightly_rough")
    assert r["status"] == "not_identifiable" and r["sigma_um"] is None


def test_python_fit_with_one_identifiable_correlation_prefers_it():
    # Two measurements at distinct geometries determine σ/T and K exactly (N = p).
    ti = np.array([10.0, 50.0])
    b = rs.very_rough_brightness(ti, 0.0, 0.0, 0.4)
    r = rs.fit_roughness(ti, [0.0, 0.0], [0.0, 0.0], b)
    assert r["status"] != "not_identifiable"
    assert r["sigma_over_T"] == pytest.approx(0.4, rel=1e-6)
    assert r["sigma_over_T_stderr"] is None  # no degrees of freedom


@pytest.mark.parametrize("rows", [1, 3])
def test_python_comparison_at_one_geometry_identifies_nothing(rows):
    c = rs.brdf_compare_arrays([30.0] * rows, [180.0] * rows, [0.0] * rows, [0.0] * rows,
                               [0.1] * rows)
    assert c["winner"] is None and c["winner_paper_metric"] is None
    for key, m in c["models"].items():
        if not m["available"]:
            continue
        assert m["fit_status"] == "not_identifiable", (key, m["fit_status"], m["fit_message"])
        assert "1 distinct geometry" in m["fit_message"], m["fit_message"]
        shape = {k: v for k, v in m["parameters"].items() if k != "gain" or key.endswith("_fit")}
        assert shape and all(v is None for v in shape.values()), (key, m["parameters"])
        assert m["standard_errors"] == {}


def test_python_comparison_at_two_geometries_identifies_the_one_parameter_models():
    c = rs.brdf_compare_arrays([30.0, 60.0], [180.0, 180.0], [0.0, 0.0], [0.0, 0.0], [0.1, 0.05])
    assert c["models"]["lafortune"]["fit_status"] != "not_identifiable"
    assert c["models"]["lafortune"]["parameters"]["n"] is not None
    assert c["winner"] is not None
