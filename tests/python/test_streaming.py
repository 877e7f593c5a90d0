"""Streaming inputs and outputs: 1e6-row files through the CLI in bounded memory.

Each command runs from a fresh Python interpreter that reports the peak resident set size of its
child (getrusage(RUSAGE_CHILDREN).ru_maxrss), so the test process's own memory does not count.
The outputs are checked by their row counts and their first and last rows, which must be the
bytes the same command writes for those rows alone. Under ROUGHSCOPE_SANITIZED=1 (the ASan
build) the memory limits are not asserted and the files have 1e5 rows.
"""

import json
import os
import subprocess
import sys

import pytest

from conftest import cli_path

# Drives the CLI: also run against the sanitizer build (`make sanitize`, DEVELOPERS.md).
pytestmark = pytest.mark.cli

SANITIZED = os.environ.get("ROUGHSCOPE_SANITIZED") == "1"
ROWS = 100_000 if SANITIZED else 1_000_000  # the same code path; ASan is ~5x slower
LIMIT_KB = 200 * 1024

# Runs argv[1:] and prints the peak RSS (KiB) of that child; its stdout goes to the file argv[1].
MEASURE = """
import resource, subprocess, sys
with open(sys.argv[1], "wb") as out:
    p = subprocess.run(sys.argv[2:], stdout=out, stderr=subprocess.PIPE)
sys.stderr.buffer.write(p.stderr)
print(p.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
"""


def run_measured(tmp, *args):
    """(exit code, peak RSS in KiB, stdout bytes file) of `roughscope ARGS`."""
    stdout_file = tmp / "stdout.bin"
    p = subprocess.run([sys.executable, "-c", MEASURE, str(stdout_file), cli_path(), *args],
                       capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stderr
    code, peak_kb = (int(v) for v in p.stdout.split())
    assert code == 0, p.stderr
    return code, peak_kb, stdout_file


def check_memory(peak_kb, what):
    if SANITIZED:
        return
    assert peak_kb <= LIMIT_KB, f"{what}: peak RSS {peak_kb / 1024:.0f} MiB > 200 MiB"


def geometry(k):
    return k * 7 % 800 / 10, k * 13 % 800 / 10, k * 17 % 3600 / 10


@pytest.fixture(scope="module")
def big(tmp_path_factory):
    """1e6-row inputs of `model --csv` and `estimate fit`, and the first and last rows of each as
    small files (the `curet --table` input is the fit's with the BRDF column named value)."""
    d = tmp_path_factory.mktemp("streaming")
    angles = [geometry(k) for k in range(ROWS)]
    files = {}
    for name, header, lines in [
        ("model", "theta_i,theta_s,phi_s", [f"{ti},{ts},{ps}" for ti, ts, ps in angles]),
        ("fit", "theta_i,phi_i,theta_s,phi_s,brightness",
         [f"{ti},180,{ts},{ps},{0.5 + k % 97 / 100}" for k, (ti, ts, ps) in enumerate(angles)]),
    ]:
        (d / f"{name}.csv").write_text(header + "\n" + "\n".join(lines) + "\n")
        (d / f"{name}_ends.csv").write_text(f"{header}\n{lines[0]}\n{lines[-1]}\n")
        files[name] = d / f"{name}.csv"
        files[name + "_ends"] = d / f"{name}_ends.csv"
    return files


def test_model_csv_streams_1e6_rows(big, tmp_path):
    out = tmp_path / "out.csv"
    _, peak_kb, _ = run_measured(tmp_path, "model", "--csv", str(big["model"]), "--sigma", "1",
                                 "--T", "2", "--output", str(out))
    check_memory(peak_kb, "model --csv")
    ends = subprocess.run([cli_path(), "model", "--csv", str(big["model_ends"]), "--sigma", "1",
                           "--T", "2"], capture_output=True, check=True).stdout.splitlines()
    data = out.read_bytes()
    assert data.count(b"\n") == ROWS + 1
    head = data[:4096].split(b"\n")
    assert head[0] == ends[0] and head[1] == ends[1]
    assert data.rstrip(b"\n").rsplit(b"\n", 1)[1] == ends[2]


def test_model_json_streams_1e6_rows_as_one_array(big, tmp_path):
    _, peak_kb, stdout_file = run_measured(tmp_path, "model", "--csv", str(big["model"]),
                                           "--sigma", "1", "--T", "2", "--json")
    check_memory(peak_kb, "model --csv --json")
    ends = subprocess.run([cli_path(), "model", "--csv", str(big["model_ends"]), "--sigma", "1",
                           "--T", "2", "--json"], capture_output=True, check=True).stdout
    first, last = ends[2:-3].split(b"\n  },\n  {\n")  # "[\n" first,last "\n]\n"
    first, last = first + b"\n  }", b"  {\n" + last
    data = stdout_file.read_bytes()
    assert data.startswith(b"[\n" + first + b",\n")
    assert data.endswith(b",\n" + last + b"\n]\n")
    assert data.count(b"\n  {\n") == ROWS
    assert json.loads(ends)[1] == json.loads(last)


@pytest.fixture(scope="module")
def fit_run(big, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("fit")
    _, peak_kb, stdout_file = run_measured(tmp, "estimate", "fit", "--measurements",
                                           str(big["fit"]), "--correlation", "gaussian", "--json")
    return peak_kb, json.loads(stdout_file.read_bytes())


def test_estimate_fit_reads_1e6_measurements(fit_run):
    _, result = fit_run
    assert result["measurements"] == ROWS and result["n"] == ROWS
    assert result["status"] == "converged"


def test_estimate_fit_peak_memory_1e6(fit_run):
    # The reader keeps 40 B per row; the engine's rank test and covariance work on the p×p factor
    # of the Jacobian, not on copies of the N×p Jacobian.
    if SANITIZED:
        pytest.skip("no memory limits under the sanitizers")
    check_memory(fit_run[0], "estimate fit")


def test_curet_table_streams_1e6_rows(big, tmp_path):
    # The table is held whole (the fits need every row), but each model family's precomputed
    # terms exist only while its models and fit run, and the engine keeps no N-sized copies
    # beside Ceres' working set.
    table = tmp_path / "table.csv"
    table.write_text(big["fit"].read_text().replace("brightness", "value", 1))
    _, peak_kb, stdout_file = run_measured(tmp_path, "curet", "--table", str(table), "--json")
    check_memory(peak_kb, "curet --table")
    assert json.loads(stdout_file.read_bytes())["measurements"] == ROWS
