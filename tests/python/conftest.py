"""Shared pytest set-up for the roughscope Python tests.

ctest runs these with PYTHONPATH=<build>/python (the compiled module next to the package's .py
files). Importing roughscope here makes a wrong PYTHONPATH fail loudly at collection, with the
reason, instead of skipping anything.
"""

import json
import os
import pathlib
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
# the working directory and from the repository. None when absent.
PAPER_TABLES = roughscope._core.paper_tables_path([REPO_ROOT])


def need_shared(path, relative):
    """Skips when shared data are absent, or fails under ROUGHSCOPE_REQUIRE_SHARED_DATA=1."""
    if path is None:
        where = roughscope._core.shared_search_description(relative)
        if roughscope._core.shared_data_required():
            pytest.fail(f"ROUGHSCOPE_REQUIRE_SHARED_DATA=1 but {where} was not found")
        pytest.skip(f"shared data not found: {where} (not part of the repository)")
    return path


@pytest.fixture(scope="session")
def paper_tables():
    """The paper's Tables 1–4 (kept beside the repository, never inside it); skip if absent."""
    need_shared(PAPER_TABLES, "reference/paper-tables.json")
    with open(PAPER_TABLES, encoding="utf-8") as f:
        return json.load(f)


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
