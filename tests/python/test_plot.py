"""The figure entry point `python3 -m roughscope.plot curet --out FILE` (JSON on stdin) and the
CLI's `roughscope curet --plot`, which pipes the comparison into it: success paths and failures
whose Python message reaches the user as one `roughscope: error: ...` line."""

import json
import subprocess
import sys

import numpy as np
import pytest

import roughscope as rs
from roughscope import curet, plot

from conftest import cli_path

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def table(tmp_path_factory):
    rng = np.random.default_rng(5)
    n = 30
    ti = rng.integers(0, 70, n).astype(float)
    ts = rng.integers(0, 70, n).astype(float)
    ps = rng.integers(0, 360, n).astype(float)
    f = rs.very_rough_brightness(ti, ts, ps, 0.5) / np.cos(np.radians(ti))
    path = tmp_path_factory.mktemp("plot") / "brdf.csv"
    rows = ["theta_i,phi_i,theta_s,phi_s,value"]
    rows += [f"{a!r},180,{c!r},{d!r},{e!r}" for a, c, d, e in zip(ti, ts, ps, f)]
    path.write_text("\n".join(rows) + "\n")
    return path


def _module(args, document, python_env):
    return subprocess.run([sys.executable, "-m", "roughscope.plot", *args],
                          input=json.dumps(document), capture_output=True, text=True,
                          env=python_env, timeout=300)


def test_module_draws_from_stdin(table, tmp_path, python_env):
    doc = curet.compare_table(table, pair=(1, 2), fits=False, series=True)
    p = _module(["curet", "--out", str(tmp_path / "f.png")], doc, python_env)
    assert p.returncode == 0, p.stderr
    assert p.stdout == "" and (tmp_path / "f.png").read_bytes()[:8] == PNG
    p = _module(["curet", "--out", str(tmp_path / "s.png")], [doc, doc], python_env)
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "s.png").read_bytes()[:8] == PNG


def test_module_errors_are_one_line(table, tmp_path, python_env):
    doc = curet.compare_table(table, pair=(1, 2), fits=False, series=False)
    p = _module(["curet", "--out", str(tmp_path / "f.png")], doc, python_env)
    assert p.returncode == 1 and not (tmp_path / "f.png").exists()
    assert p.stderr.count("\n") == 1 and "roughscope.plot: error:" in p.stderr
    assert "series" in p.stderr
    p = _module(["curet", "--out", str(tmp_path / "no" / "f.png")], {"series": {}}, python_env)
    assert p.returncode == 1 and "does not exist" in p.stderr
    bad = subprocess.run([sys.executable, "-m", "roughscope.plot", "curet", "--out",
                          str(tmp_path / "g.png")], input="not json", capture_output=True,
                         text=True, env=python_env, timeout=300)
    assert bad.returncode == 1 and "not a JSON document" in bad.stderr


def test_function_raises(table, tmp_path):
    doc = curet.compare_table(table, pair=(1, 2), fits=False, series=True)
    assert plot.curet(doc, tmp_path / "f.png") is not None
    assert (tmp_path / "f.png").read_bytes()[:8] == PNG
    with pytest.raises(ValueError, match="comparison object"):
        plot.curet(42, tmp_path / "x.png")
    with pytest.raises(OSError, match="does not exist"):
        plot.curet(doc, tmp_path / "missing" / "x.png")


def _cli_plot(table, out, env=None):
    return subprocess.run([cli_path(), "curet", "--table", str(table), "--pair", "1,2", "--no-fits",
                           "--plot", str(out)], capture_output=True, text=True, env=env,
                          timeout=300)


def test_cli_plot_success(table, tmp_path, python_env):
    p = _cli_plot(table, tmp_path / "fig.png", python_env)
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "fig.png").read_bytes()[:8] == PNG
    assert "Two-point estimate" in p.stdout  # the text report still goes to stdout


def test_cli_plot_unwritable_output(table, tmp_path, python_env):
    p = _cli_plot(table, tmp_path / "no-such-dir" / "fig.png", python_env)
    assert p.returncode == 4 and p.stdout == ""
    lines = p.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("roughscope: error: --plot: ")
    assert "does not exist" in lines[0]  # Python's own message


def test_cli_plot_missing_interpreter(table, tmp_path, python_env):
    env = dict(python_env, ROUGHSCOPE_PYTHON=str(tmp_path / "no-python3"))
    p = _cli_plot(table, tmp_path / "fig.png", env)
    assert p.returncode == 4 and p.stdout == "" and not (tmp_path / "fig.png").exists()
    lines = p.stderr.splitlines()
    assert len(lines) == 1 and "cannot run the Python interpreter" in lines[0], p.stderr
    assert "ROUGHSCOPE_PYTHON" in lines[0]
