"""Tests of the CUReT comparison through the Python module and the `roughscope curet` command.

Real data: the shared data/curet; printed values: the shared reference/paper-tables.json. Both are
found by conftest.py (io/data_locator.hpp); tests needing them skip, saying so, when they are
absent, and fail under ROUGHSCOPE_REQUIRE_SHARED_DATA=1. Independent checks: the paper's
Tables 3 and 4, facts of the data README (43 non-positive values, measurements 81 and 112), and
synthetic tables generated here with numpy from Eq. 5 written out by hand.
"""

import json
import math
import os
import subprocess

import numpy as np
import pytest

import roughscope
import roughscope._core
from roughscope import curet

# The shared data through conftest.py (io/data_locator.hpp: $ROUGHSCOPE_SHARED_DIR, else ../shared
# upward): missing data skip visibly, or fail under ROUGHSCOPE_REQUIRE_SHARED_DATA=1.
from conftest import CURET_DIR, cli_path, needs_curet
from conftest import REPO_ROOT as REPO


@pytest.fixture(scope="module")
def db(curet_dir):
    return curet.load(curet_dir)


@pytest.fixture(scope="module")
def paper(paper_tables):
    return paper_tables


def run_cli(*args, cwd=None):
    return subprocess.run([cli_path(), "curet", *args], capture_output=True, text=True, cwd=cwd,
                          timeout=300)


# ---------------------------------------------------------------------------------------------
# Loader


@needs_curet
def test_loader_returns_numpy_arrays_as_the_readme_describes(db):
    assert db.brdf.shape == (61, 205) and db.brdf.dtype == np.float64
    assert db.samples.tolist() == list(range(1, 62))
    assert int((db.brdf <= 0).sum()) == 43  # README: 43 of 12,505 values are <= 0
    assert len(db.nonpositive()) == 43
    a = db.angles
    assert a["measurement"][80] == 81
    assert abs(a["theta_i_deg"][80] - 45.0) < 1e-4 and abs(a["theta_v_deg"][80]) < 1e-4
    assert abs(a["theta_i_deg"][111] - 67.5) < 1e-4
    # E = f cos(theta_i), and the paper frame: theta_s = theta_v, cos(phi_s) = -cos(phi_v - phi_i)
    assert np.allclose(db.brightness, db.brdf * np.cos(np.radians(a["theta_i_deg"])))
    assert np.allclose(a["theta_s_deg"], a["theta_v_deg"])
    assert np.allclose(np.cos(np.radians(a["phi_s_deg"])),
                       -np.cos(np.radians(a["phi_v_deg"] - a["phi_i_deg"])), atol=1e-12)
    assert db.overflow is None


def test_missing_directory_raises_a_value_error_naming_the_files(tmp_path):
    with pytest.raises(ValueError, match="table.txt"):
        curet.load(tmp_path / "nowhere")
    with pytest.raises(roughscope.DataError, match="abrdf.dat"):
        curet.load(tmp_path)  # exists but holds nothing
    assert curet.available(tmp_path) is False


@needs_curet
def test_bad_sample_and_channel_raise_value_error(db):
    with pytest.raises(ValueError, match="1..61"):
        db.compare(62)
    with pytest.raises(ValueError, match="channel"):
        curet.load(CURET_DIR, channel="purple")
    with pytest.raises(ValueError, match="rbrdf.dat"):
        curet.load(CURET_DIR, channel="red")
    with pytest.raises(ValueError, match="theta2_deg"):
        db.compare(25, theta1_deg=45.0)


# ---------------------------------------------------------------------------------------------
# Tables 3 and 4


@needs_curet
def test_table3_recomputed(db, paper):
    for row in paper["table3_curet_parameters"]["rows"]:
        r = db.compare(row["sample"], fits=False, series=False)
        assert f"{r['E1_over_E2']:.5g}" == f"{row['E1_over_E2']:.5g}"
        assert round(r["sigma_over_T_gaussian"], 4) == row["sigma_over_T_G"]
        assert round(r["sigma_over_T_exponential"], 4) == row["sigma_over_T_E"]
        nominal = db.compare(row["sample"], theta1_deg=45.0, theta2_deg=67.5, fits=False,
                             series=False)
        assert abs(nominal["E1_over_E2"] - row["E1_over_E2"]) < 5e-7
        on = r["models"]["oren_nayar"]["parameters"]
        assert (on["sigma_rad"], on["albedo"]) == (row["sigma_ON_rad"], row["rho_ON"])


@needs_curet
def test_table4_recomputed(db, paper):
    keys = ["bk_gaussian", "bk_exponential", "vh_gaussian", "vh_exponential"]
    for row in paper["table4_curet_errors"]["rows"]:
        r = db.compare(row["sample"], fits=False, series=False)
        for k, printed in zip(keys, row["values"][2:]):
            assert abs(r["sse"][k] / printed - 1) < 1e-3, (row["sample"], k, r["sse"][k])
        if row["sample"] in (25, 34):
            assert abs(r["sse"]["oren_nayar"] / row["values"][0] - 1) < 5e-3


@needs_curet
def test_table4_error_is_the_documented_sum_recomputed_with_numpy(db):
    # Independent of the library's error code: normalise the series and sum with numpy, and
    # evaluate Eq. 5 with F_VH (F^2 = cos theta_i) by hand at the paper-frame geometry.
    r = db.compare(34, fits=False)
    s = r["series"]
    ti, ts, ps = (np.radians(np.asarray(s[k])) for k in ("theta_i_deg", "theta_s_deg",
                                                          "phi_s_deg"))
    qx = np.sin(ti) - np.sin(ts) * np.cos(ps)
    qy = -np.sin(ts) * np.sin(ps)
    qz = -(np.cos(ti) + np.cos(ts))
    m = r["sigma_over_T_exponential"]
    model = np.cos(ti) / (qz**2 * (1 + (qx**2 + qy**2) / (m * m * qz**2)) ** 1.5)
    f = db.brdf[db.row(34)]
    data = f * np.cos(ti)
    expected = np.sum((model / model.max() - data / data.max()) ** 2)
    assert r["sse"]["vh_exponential"] == pytest.approx(expected, rel=1e-12)
    assert np.allclose(s["models"]["vh_exponential"], model / model.max(), rtol=1e-12)
    assert np.allclose(s["data"], data / data.max(), rtol=1e-12)
    # the gain-scaled series reproduces the SSE after the optimal gain
    gained = np.asarray(s["models_gain"]["vh_exponential"])
    assert np.sum((gained - np.asarray(s["data"])) ** 2) == pytest.approx(
        r["sse_gain"]["vh_exponential"], rel=1e-10)
    e = curet.error_measures(model, data)
    assert e["sse"] == pytest.approx(expected, rel=1e-12)
    assert e["rmse"] == pytest.approx(math.sqrt(expected / 205), rel=1e-12)


def test_error_measures_reject_bad_input():
    with pytest.raises(ValueError):
        curet.error_measures([1.0, 2.0], [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="max\\(data\\)"):
        curet.error_measures([1.0, 2.0], [-1.0, 0.0])


# ---------------------------------------------------------------------------------------------
# Whole database, sample 61


@needs_curet
def test_all_samples_processed_and_sample_61_explained(db):
    rows = db.compare_all(threads=2)
    assert [r["sample"] for r in rows] == list(range(1, 62))
    assert sum(r["E1_over_E2"] is not None for r in rows) == 60
    r61 = rows[-1]
    assert r61["E1_over_E2"] is None and r61["sigma_over_T_gaussian"] is None
    assert "measurement 81" in r61["two_point"]["reason"]
    assert "<= 0" in r61["two_point"]["reason"]
    excluded = [d["measurement"] for d in r61["data_issues"] if d["excluded_from"]]
    assert excluded == [81, 112]
    assert r61["sse"]["vh_exponential"] is None and r61["sse"]["vh_exponential_fit"] > 0
    assert sum(d["issue"] == "non_positive" for r in rows for d in r["data_issues"]) == 43
    md = db.compare_all_text("markdown", fits=False)
    assert md.count("\n") == 63
    csv = db.compare_all_text("csv", fits=False)
    assert csv.splitlines()[0].startswith("sample,name,channel,used,E1_over_E2")


# ---------------------------------------------------------------------------------------------
# Any BRDF table


def _synthetic_arrays(sigma_over_T=0.7, n=150, seed=3):
    rng = np.random.default_rng(seed)
    ti = np.concatenate([[45.0, 67.5], rng.uniform(0, 80, n)])
    tv = np.concatenate([[0.0, 0.0], rng.uniform(0, 80, n)])
    pi = rng.uniform(-180, 180, n + 2)
    pv = np.concatenate([pi[:2], rng.uniform(-180, 180, n)])
    # paper frame by hand: theta_s = theta_v, phi_s = phi_v - phi_i + 180
    t_i, t_s = np.radians(ti), np.radians(tv)
    p_s = np.radians(pv - pi + 180.0)
    qx = np.sin(t_i) - np.sin(t_s) * np.cos(p_s)
    qy = -np.sin(t_s) * np.sin(p_s)
    qz = -(np.cos(t_i) + np.cos(t_s))
    E = np.cos(t_i) / (qz**2 * (1 + (qx**2 + qy**2) / (sigma_over_T**2 * qz**2)) ** 1.5)
    return ti, pi, tv, pv, 2.5 * E / np.cos(t_i)


def test_compare_table_from_arrays_and_csv_recovers_the_slope(tmp_path):
    ti, pi, tv, pv, f = _synthetic_arrays()
    r = curet.compare_table(theta_i_deg=ti, phi_i_deg=pi, theta_s_deg=tv, phi_s_deg=pv, value=f,
                            pair=(1, 2))
    assert r["sigma_over_T_exponential"] == pytest.approx(0.7, rel=1e-9)
    assert r["sse"]["vh_exponential"] < 1e-18
    path = tmp_path / "table.csv"
    with open(path, "w") as out:
        out.write("theta_i,phi_i,theta_s,phi_s,value\n")
        for row in zip(ti, pi, tv, pv, f):
            out.write(",".join(repr(float(v)) for v in row) + "\n")
    t = curet.read_brdf_csv(path)
    assert t["value"].shape == (152,) and t["measurement"][0] == 1
    assert np.allclose(t["theta_s_deg"], tv)
    r2 = curet.compare_table(path, pair=(1, 2), fits=False)
    assert r2["sigma_over_T_exponential"] == pytest.approx(0.7, rel=1e-9)
    # and through the command line
    p = run_cli("--table", str(path), "--pair", "1,2", "--json", "--no-fits")
    assert p.returncode == 0, p.stderr
    assert json.loads(p.stdout)["sigma_over_T_exponential"] == pytest.approx(0.7, rel=1e-9)
    # --format names: the library's scheme (any case, "md" an alias of "markdown")
    md = run_cli("--table", str(path), "--pair", "1,2", "--no-fits", "--format", "MD")
    assert md.returncode == 0 and md.stdout == run_cli("--table", str(path), "--pair", "1,2",
                                                       "--no-fits", "--format", "markdown").stdout
    p = run_cli("--table", str(path), "--format", "xml")
    assert p.returncode == 2 and p.stdout == "" and "--format" in p.stderr
    assert "text, json, csv, markdown" in p.stderr


def test_bad_tables_raise_value_error(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("theta_i,phi_i,theta_s,value\n1,2,3,4\n")
    with pytest.raises(ValueError, match="bad.csv:1: missing column"):
        curet.read_brdf_csv(bad)
    with pytest.raises(ValueError, match="as long as value"):
        curet.compare_table(theta_i_deg=[1, 2], phi_i_deg=[0], theta_s_deg=[0, 0],
                            phi_s_deg=[0, 0], value=[0.1, 0.2])
    p = run_cli("--table", str(bad))
    assert p.returncode == 4 and p.stderr.count("\n") == 1 and "missing column" in p.stderr


# ---------------------------------------------------------------------------------------------
# Command line


@needs_curet
def test_cli_sample_json_has_the_documented_keys(tmp_path):
    p = run_cli("--sample", "25", "--json", "--data", str(CURET_DIR))
    assert p.returncode == 0, p.stderr
    j = json.loads(p.stdout)
    assert j["sample"] == 25 and round(j["sigma_over_T_gaussian"], 4) == 0.3957
    assert set(curet.PAPER_MODELS) <= set(j["sse"])
    assert "nan" not in p.stdout.lower()
    # the default directory: ../shared/data/curet relative to the working directory
    p2 = run_cli("--sample", "25", "--json", "--no-fits", cwd=REPO)
    assert p2.returncode == 0, p2.stderr
    assert json.loads(p2.stdout)["E1_over_E2"] == j["E1_over_E2"]


@needs_curet
def test_cli_all_formats_and_atomic_output(tmp_path):
    out = tmp_path / "all.csv"
    p = run_cli("--all", "--format", "csv", "--no-fits", "--data", str(CURET_DIR), "--output",
                str(out))
    assert p.returncode == 0, p.stderr
    assert len(out.read_text().splitlines()) == 62
    p = run_cli("--all", "--no-fits", "--data", str(CURET_DIR))
    assert p.returncode == 0 and p.stdout.startswith("| sample |")


def test_cli_errors_are_one_line_with_exit_codes(tmp_path):
    p = run_cli("--sample", "25", "--data", str(tmp_path / "none"))
    assert p.returncode == 4 and p.stderr.count("\n") == 1 and "CUReT" in p.stderr
    p = run_cli("--sample", "25", "--all")
    assert p.returncode == 2 and "exactly one" in p.stderr
    p = run_cli("--sample", "25", "--theta1", "45")
    assert p.returncode == 2 and "--theta2" in p.stderr
    p = run_cli("--sample", "25", "--theta1", "95", "--theta2", "60")
    assert p.returncode == 2
    p = run_cli("--sample", "25", "--on-albedo", "1.5", "--on-sigma", "0.3")
    assert p.returncode == 2
    # no database anywhere: a clear error, nothing on stdout
    env = {k: v for k, v in os.environ.items()
           if k not in ("ROUGHSCOPE_CURET", "ROUGHSCOPE_SHARED_DIR")}
    q = subprocess.run([cli_path(), "curet", "--sample", "25"], capture_output=True, text=True,
                       cwd=tmp_path, env=env, timeout=60)
    assert q.returncode == 4 and q.stdout == ""
    assert "ROUGHSCOPE_CURET" in q.stderr and "abrdf.dat" in q.stderr


@needs_curet
def test_cli_sample_out_of_range(tmp_path):
    p = run_cli("--sample", "99", "--data", str(CURET_DIR))
    assert p.returncode == 2 and "1..61" in p.stderr and p.stdout == ""


@needs_curet
def test_cli_plot_writes_a_png(tmp_path):
    png = tmp_path / "fig10.png"
    p = run_cli("--sample", "41", "--data", str(CURET_DIR), "--plot", str(png), "--no-fits")
    assert p.returncode == 0, p.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    p = run_cli("--sample", "41", "--data", str(CURET_DIR), "--plot", str(tmp_path / "x.pdf"))
    assert p.returncode == 2 and not (tmp_path / "x.pdf").exists()


# ---------------------------------------------------------------------------------------------
# Figures and the report


@needs_curet
def test_figures_are_written(db, tmp_path):
    from roughscope import curet_figures

    r = db.compare(25)
    curet_figures.fig10(r, tmp_path / "a.png")
    curet_figures.fig10_paper_layout([r, db.compare(61)], tmp_path / "b.png")
    curet_figures.summary(db.compare_all(fits=False), tmp_path / "c.png")
    for name in ("a.png", "b.png", "c.png"):
        assert (tmp_path / name).read_bytes()[:4] == b"\x89PNG"
    data, model = curet_figures.sorted_series(r, "vh_gaussian")
    assert np.all(np.diff(data) >= 0) and data[-1] == 1.0 and model.max() == 1.0
    with pytest.raises(ValueError, match="series"):
        curet_figures.sorted_series(db.compare(25, series=False), "vh_gaussian")


@needs_curet
def test_report_section_with_data(tmp_path, monkeypatch):
    from roughscope import report_curet

    monkeypatch.chdir(REPO)
    html = report_curet.section(tmp_path)
    assert "Table 3" in html and "Table 4" in html and "curet_fig10.png" in html
    assert "not reproduced" in html  # O–N for 41 and the LFTG column are flagged
    assert (tmp_path / "curet_fig10.png").is_file() and (tmp_path / "curet_summary.png").is_file()


def test_report_section_without_data(tmp_path, monkeypatch):
    from roughscope import report_curet

    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("ROUGHSCOPE_CURET", raising=False)
    monkeypatch.delenv("ROUGHSCOPE_SHARED_DIR", raising=False)
    html = report_curet.section(tmp_path / "out")
    assert "not found" in html and "<img" not in html
