"""The uncertainty budget through the CLI, the Python module and the report (docs/uncertainty.md).

The numbers themselves (coverage on perturbed benches, first order against Monte Carlo) are
tested in tests/cpp/measure/test_budget.cpp; here: the keys, the text line, the same document from
Python, the report's figure, and the errors of a bad `uncertainty` object.
"""

import json
import math
import pathlib
import re
import shutil
import subprocess

import pytest

from conftest import cli_path

pytestmark = pytest.mark.cli

EXAMPLE = pathlib.Path(__file__).resolve().parents[2] / "docs" / "examples" / "measure"
QUANTITIES = ("E1_over_E2", "sigma_over_T_gaussian", "sigma_over_T_exponential")


def run(*args):
    return subprocess.run([cli_path(), "measure", *map(str, args)], capture_output=True,
                          text=True, timeout=300)


@pytest.fixture()
def example(tmp_path):
    for f in ("capture-file.json", "capture1.png", "capture2.png"):
        shutil.copy(EXAMPLE / f, tmp_path / f)
    return tmp_path / "capture-file.json"


def edit(path, **changes):
    doc = json.loads(path.read_text(encoding="utf-8"))
    doc.update(changes)
    path.write_text(json.dumps(doc), encoding="utf-8")


def test_the_json_carries_each_quantitys_budget(example):
    proc = run(example, "--json")
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(proc.stdout)
    assert doc["uncertainty_method"] == "first_order"
    assert doc["uncertainty_assumed"] == []  # the example declares every source it has
    for q in QUANTITIES:
        value, u = doc[q], doc[q + "_uncertainty"]
        low, high = doc[q + "_interval95"]
        assert low < value < high
        assert math.isclose(high - low, 2 * 1.959963984540054 * u, rel_tol=1e-9)
        # The combined u holds the statistical part and more (the setup's tolerances).
        assert u > doc[q + "_stderr"]
        lines = doc["uncertainty_budget"][q]
        assert [line["contribution"] for line in lines] == \
            sorted((line["contribution"] for line in lines), reverse=True)
        assert math.isclose(sum(line["fraction"] for line in lines), 1.0, rel_tol=1e-9)
        assert math.isclose(math.sqrt(sum(line["contribution"] ** 2 for line in lines)), u,
                            rel_tol=1e-9)
        for line in lines:
            assert set(line) == {"source", "u_input", "sensitivity", "contribution", "fraction"}
    # No σ (no specular capture, none given): its keys are null.
    assert doc["sigma_um_uncertainty"] is None and doc["T_um_interval95"] is None


def test_the_text_gives_the_interval_and_the_largest_source(example):
    proc = run(example)
    assert proc.returncode == 0, proc.stderr
    line = next(x for x in proc.stdout.splitlines() if x.startswith("sigma/T (Gaussian)"))
    assert re.search(r"\d\.\d+ ± \d\.\d+ \(k=1, 95 % \[\d\.\d+, \d\.\d+\]\); largest: .+ "
                     r"\(\d+ %\)$", line), line
    assert "uncertainty: first order" in proc.stdout


def test_assumed_tolerances_are_said(example):
    edit(example, uncertainty={})
    doc = json.loads(run(example, "--json").stdout)
    assert "angle_deg = 0.5°" in doc["uncertainty_assumed"]
    assert any("assumed tolerances" in w for w in doc["warnings"])


def test_monte_carlo_on_request_is_seeded(example):
    edit(example, uncertainty={"angle_deg": 0.5, "method": "monte_carlo", "seed": 5})
    a = json.loads(run(example, "--json").stdout)
    b = json.loads(run(example, "--json").stdout)
    assert a["uncertainty_method"] == "monte_carlo" and a["uncertainty_trials"] >= 20000
    assert a["sigma_over_T_gaussian_interval95"] == b["sigma_over_T_gaussian_interval95"]
    assert "Monte Carlo" in run(example).stdout


@pytest.mark.parametrize("uncertainty,key", [
    ({"angle_deg": -1}, "uncertainty.angle_deg"),
    ({"angle": 1}, "uncertainty.angle"),
    ({"method": "bootstrap"}, "uncertainty.method"),
])
def test_a_bad_uncertainty_object_is_refused_naming_the_key(example, uncertainty, key):
    edit(example, uncertainty=uncertainty)
    proc = run(example, "--json")
    assert proc.returncode != 0 and proc.stdout == ""
    assert key in proc.stderr, proc.stderr


def test_python_and_report_show_the_budget(example):
    import roughscope
    from roughscope import report_measure

    doc = roughscope.measure(str(example))
    cli = json.loads(run(example, "--json").stdout)
    for q in QUANTITIES:
        assert doc[q + "_uncertainty"] == cli[q + "_uncertainty"]
    html = report_measure.measurement_html(doc)
    assert "Uncertainty budget" in html and "data:image/png;base64," in html
    assert "combined u" in html
