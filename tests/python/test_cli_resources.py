"""Size-like options checked against the memory they imply (docs/cli.md, "Memory limit").

The memory budget is set with ROUGHSCOPE_MEMORY_LIMIT_GB, so that what is refused does not depend
on the machine: a run above it exits 2 before allocating, with the estimate, the limit and what to
change in one line; a run within it succeeds. Worker threads beyond the hardware or the budget are
not started: the peak resident memory of a run asking for 64 threads stays that of a few.
"""

import os
import subprocess
import sys

import pytest

from conftest import cli_path

SANITIZED = os.environ.get("ROUGHSCOPE_SANITIZED") == "1"
EXIT_USAGE = 2

PEAK = """
import resource, subprocess, sys
p = subprocess.run(sys.argv[1:], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
sys.stderr.buffer.write(p.stderr)
print(p.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
"""


def run(*args, limit_gb=None, cwd=None):
    env = dict(os.environ)
    env.pop("ROUGHSCOPE_MEMORY_LIMIT_GB", None)
    if limit_gb is not None:
        env["ROUGHSCOPE_MEMORY_LIMIT_GB"] = str(limit_gb)
    return subprocess.run([cli_path(), *map(str, args)], capture_output=True, text=True,
                          timeout=300, env=env, cwd=cwd)


def refused(proc, *needles):
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == EXIT_USAGE, proc.stderr
    assert len(lines) == 1 and lines[0].startswith("roughscope: error: "), proc.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]
    assert proc.stdout == ""
    return lines[0]


SCATTER = ["simulate", "scatter", "--sigma-um", "0.05", "--T-um", "1", "--theta-i", "0",
           "--theta-s", "0", "--phi-s", "0"]


def test_scatter_nx_beyond_the_budget_is_refused_with_the_estimate():
    # One worker's surface of 4096 x 4096 points in its FFT buffer: 8 * 4096 * 4098 bytes.
    line = refused(run(*SCATTER, "--nx", "4096", "--dx-um", "0.01", "--realisations", "10",
                       limit_gb=0.1),
                   "nx up to 4096", "0.134 GB a worker thread",
                   "above the limit of 0.1 GB (ROUGHSCOPE_MEMORY_LIMIT_GB)", "give a smaller nx")
    assert "needs about 0.168 GB" in line, line


def test_scatter_within_the_budget_runs():
    proc = run(*SCATTER, "--nx", "64", "--dx-um", "0.05", "--realisations", "10", "--json",
               limit_gb=0.1)
    assert proc.returncode == 0, proc.stderr


def test_a_bad_memory_limit_is_named():
    proc = run(*SCATTER, "--nx", "64", "--dx-um", "0.05", "--realisations", "10",
               limit_gb="lots")
    assert proc.returncode == EXIT_USAGE, proc.stderr
    assert "ROUGHSCOPE_MEMORY_LIMIT_GB = 'lots'" in proc.stderr, proc.stderr


@pytest.mark.skipif(SANITIZED, reason="ASan's quarantine: peak memory says nothing")
def test_threads_beyond_the_budget_are_not_started():
    # 64 threads asked for; each would hold a 1024 x 1024 surface (8.4 MB) at once: 540 MB.
    # Within a 50 MB budget at most five workers fit (and no more than the hardware's cores run).
    env = dict(os.environ, ROUGHSCOPE_MEMORY_LIMIT_GB="0.05")
    p = subprocess.run([sys.executable, "-c", PEAK, cli_path(), *SCATTER, "--nx", "1024",
                        "--dx-um", "0.01", "--realisations", "64", "--threads", "64"],
                       capture_output=True, text=True, timeout=300, env=env)
    assert p.returncode == 0, p.stderr
    code, peak_kb = (int(v) for v in p.stdout.split())
    assert code == 0, p.stderr
    surface_kb = 8 * 1024 * 1026 / 1024
    assert peak_kb < 120 * 1024, f"peak {peak_kb / 1024:.0f} MB ({surface_kb / 1024:.1f} MB/worker)"


def test_surface_generate_counts_the_file_made_in_memory(tmp_path):
    # 2048 x 2048: 42 MB to generate; as raw float64 another 34 MB (76 MB: within 0.1 GB), as CSV
    # text about 20 bytes a height, 84 MB more (0.126 GB: refused before anything is generated).
    size = ["--nx", "2048", "--ny", "2048"]
    line = refused(run("surface", "generate", *size, "--out", "s.csv", limit_gb=0.1,
                       cwd=tmp_path),
                   "surface generate --nx 2048 --ny 2048 (a csv_matrix file of 4194304 heights)",
                   "needs about 0.126 GB", "give a smaller --nx or --ny")
    assert not (tmp_path / "s.csv").exists(), line
    proc = run("surface", "generate", *size, "--out", "s.raw", limit_gb=0.1, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "s.raw").stat().st_size == 8 * 2048 * 2048


def test_surface_generate_beyond_the_budget_is_refused_by_the_library_too(tmp_path):
    refused(run("surface", "generate", "--nx", "16384", "--ny", "16384", "--out", "s.raw",
                limit_gb=1, cwd=tmp_path),
            "16384", "needs about 4.83 GB", "above the limit of 1 GB")
    assert list(tmp_path.iterdir()) == []
