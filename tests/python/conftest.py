"""Shared pytest set-up for the roughscope Python tests.

ctest runs these with PYTHONPATH=<build>/python (the compiled module next to the package's .py
files). Importing roughscope here makes a wrong PYTHONPATH fail loudly at collection, with the
reason, instead of skipping anything.
"""

import json
import os
import pathlib
import re
import subprocess
import sys

import pytest

try:
    import roughscope  # noqa: F401
    import roughscope._core
except ImportError as exc:  # pragma: no cover - a set-up error, reported verbatim
    raise ImportError(
        f"cannot import roughscope ({exc}); run the tests with PYTHONPATH=<build>/python "
        f"(ctest sets it), e.g. PYTHONPATH=build/python {sys.executable} -m pytest tests/python"
    ) from exc

REPO_ROOT = pathlib.Path(__file__).resolve().parents[2]
# The library's locator (io/data_locator.hpp): $ROUGHSCOPE_SHARED_DIR, else ../shared upward from
# the working directory and from the repository. None when absent. Tests reach these through the
# fixtures below (`paper_tables`, `paper_tables_path`, `curet_dir`) or `needs_curet`, which skip
# visibly when the data are missing and fail under ROUGHSCOPE_REQUIRE_SHARED_DATA=1.
PAPER_TABLES = roughscope._core.paper_tables_path([REPO_ROOT])
CURET_DIR = roughscope._core.curet_data_dir([REPO_ROOT])


def need_shared(path, relative):
    """Skips when shared data are absent, or fails under ROUGHSCOPE_REQUIRE_SHARED_DATA=1."""
    if path is None:
        where = roughscope._core.shared_search_description(relative)
        if roughscope._core.shared_data_required():
            pytest.fail(f"ROUGHSCOPE_REQUIRE_SHARED_DATA=1 but {where} was not found")
        pytest.skip(f"shared data not found: {where} (not part of the repository)")
    return path


@pytest.fixture(scope="session")
def paper_tables_path():
    """Path of the paper's printed tables (reference/paper-tables.json); skip (or fail) if absent."""
    return need_shared(PAPER_TABLES, "reference/paper-tables.json")


@pytest.fixture(scope="session")
def paper_tables(paper_tables_path):
    """The paper's Tables 1–4 (kept beside the repository, never inside it); skip if absent."""
    with open(paper_tables_path, encoding="utf-8") as f:
        return json.load(f)


@pytest.fixture(scope="session")
def curet_dir():
    """The CUReT directory (data/curet: table.txt, abrdf.dat); skip (or fail) if absent."""
    return need_shared(CURET_DIR, "data/curet")


# For tests that read CURET_DIR directly: the same skip-or-fail rule as the fixture.
needs_curet = pytest.mark.usefixtures("curet_dir")


def project_version():
    """The one version of the project: project(roughscope VERSION x.y.z) in CMakeLists.txt."""
    text = (REPO_ROOT / "CMakeLists.txt").read_text(encoding="utf-8")
    return re.search(r"project\(\s*roughscope\s+VERSION\s+(\d+\.\d+\.\d+)", text).group(1)


# ---------------------------------------------------------------------------------------------
# The command-line tool: $ROUGHSCOPE_CLI (ctest sets it), else <repo>/build/bin/roughscope.

def cli_path():
    """Path of the roughscope executable; fails the test when it is not built."""
    env = os.environ.get("ROUGHSCOPE_CLI")
    path = pathlib.Path(env) if env else REPO_ROOT / "build" / "bin" / "roughscope"
    if not path.is_file():
        pytest.fail(f"roughscope CLI not found at {path} (set ROUGHSCOPE_CLI or build build/)")
    return str(path.resolve())  # absolute: some tests run it from another directory


def cli_json(*args, timeout=600):
    """Runs `roughscope ARGS --json`, asserts exit 0 and returns the parsed document."""
    proc = subprocess.run([cli_path(), *map(str, args), "--json"], capture_output=True,
                          text=True, timeout=timeout)
    assert proc.returncode == 0, f"exit {proc.returncode}: {proc.stderr}"
    return json.loads(proc.stdout)


@pytest.fixture
def vector_isa():
    """Yields a setter for the array kernels' instruction set; restores the best one after."""
    from roughscope import _core

    yield _core._set_vector_isa
    _core._set_vector_isa("best")


@pytest.fixture
def python_env():
    """Environment for running `python -m roughscope...` in a subprocess (same sys.path)."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)
    env.setdefault("MPLBACKEND", "Agg")
    return env


# ---------------------------------------------------------------------------------------------
# Tests that drive only the command-line tool carry the marker `cli`: `make sanitize` runs them
# (`pytest -m cli`) against the AddressSanitizer + UBSan build of the executable. Every test in
# a file named test_cli_*.py has it; another file joins with `pytestmark = pytest.mark.cli`
# (or one test with @pytest.mark.cli). Such tests may use the Python module too (it is the
# release build's), but what they check must come from the executable.

def pytest_configure(config):
    config.addinivalue_line(
        "markers", "cli: drives only the roughscope executable (also run under ASan by "
                   "`make sanitize`)")


def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.path.name.startswith("test_cli_"):
            item.add_marker(pytest.mark.cli)


# Under `make sanitize`, sanitizer reports of the executable go to files in
# $ROUGHSCOPE_SANITIZER_LOG_DIR (ASAN_OPTIONS/UBSAN_OPTIONS log_path): a report written during a
# test fails it, whatever exit code the test expected.
SANITIZER_LOG_DIR = os.environ.get("ROUGHSCOPE_SANITIZER_LOG_DIR")


@pytest.fixture(autouse=True)
def no_sanitizer_report():
    if not SANITIZER_LOG_DIR:
        yield
        return
    log_dir = pathlib.Path(SANITIZER_LOG_DIR)
    before = set(log_dir.glob("report*"))
    yield
    new = sorted(set(log_dir.glob("report*")) - before)
    if new:
        text = "\n".join(f"--- {p}\n{p.read_text(errors='replace')[:20000]}" for p in new)
        pytest.fail(f"sanitizer report from the roughscope executable:\n{text}", pytrace=False)
