"""Hostile values at the Python boundary (docs/python.md, "Types" and "Limits").

A structure nested without end (a dict that contains itself, a list 100,000 deep), an integer
that overflows every C++ integer (seed=2**64), a path with an embedded NUL byte, a device or a FIFO
as a file, a size whose memory is beyond the machine: each raises TypeError, ValueError (the
library's errors are ValueError subclasses) or OSError — never a crash, never pybind's
RuntimeError. The deep structures run in a child interpreter, so that a stack overflow fails the
test instead of ending pytest. The properties (hypothesis) replace each argument of every known-good
call of test_python_inputs.GOOD_CALLS in turn by such values.
"""

import os
import pathlib
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import roughscope as rs
from roughscope import _core

from test_python_inputs import GOOD_CALLS, materialise, resolve

ALLOWED = (TypeError, ValueError, OSError, MemoryError)


# The folder holding this module's package, for a child interpreter started in another folder.
MODULE_PATH = str(pathlib.Path(_core.__file__).resolve().parents[1])


def child_env():
    return dict(os.environ, PYTHONPATH=os.pathsep.join(
        [MODULE_PATH] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))


def run_child(code, cwd=None):
    """Runs `code` in a fresh interpreter with the module's path; returns the process."""
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True,
                          text=True, timeout=120, env=child_env(), cwd=cwd)


CHILD_PRELUDE = """
import sys
import roughscope as rs
sys.setrecursionlimit(10 ** 6)  # (what a user's program may do; the module must not rely on it)

def expect(call, *types):
    try:
        call()
    except types as e:
        print(type(e).__name__, str(e)[:200])
        return
    except BaseException as e:
        print("WRONG", type(e).__name__, str(e)[:200])
        return
    print("WRONG no error")

def deep(n, leaf=1.0):
    x = leaf
    for _ in range(n):
        x = [x]
    return x
"""


@pytest.mark.parametrize("statement", [
    # A self-referencing dict and list as a region.
    "d = {}; d['rect'] = d; expect(lambda: rs.region_mask(d, 10, 10), ValueError)",
    "l = []; l.append(l); expect(lambda: rs.region_mask({'polygon': l}, 10, 10), ValueError)",
    # A list nested 100,000 deep as a region, a number, a geometry and a keyword option.
    "expect(lambda: rs.region_mask({'rect': deep(100000)}, 10, 10), ValueError)",
    "expect(lambda: rs.roughness_g(deep(100000), 30.0, 0.5), TypeError, ValueError)",
    "expect(lambda: rs.simulate_scatter(deep(100000), 0, 0, sigma_um=0.05, T_um=1.0), "
    "TypeError, ValueError)",
    "expect(lambda: rs.write_capture('out', 'png', scene=deep(100000)), TypeError, ValueError)",
    "d = {}; d['x'] = d; expect(lambda: rs.write_capture('out', 'png', roi=d), "
    "TypeError, ValueError)",
])
def test_nested_structures_raise_instead_of_crashing(statement, tmp_path):
    proc = run_child(CHILD_PRELUDE + statement, cwd=tmp_path)
    assert proc.returncode == 0, f"the interpreter died ({proc.returncode}): {proc.stderr[-500:]}"
    assert proc.stdout and not proc.stdout.startswith("WRONG"), proc.stdout + proc.stderr


@pytest.mark.parametrize("call", [
    lambda v: rs.generate_surface(sigma_um=0.1, T_um=1.0, nx=16, ny=16, seed=v),
    lambda v: rs.simulate_scatter(0, 0, 0, sigma_um=0.05, T_um=1.0, n=16, realisations=10,
                                  seed=v),
    lambda v: rs.render_capture(scene="plane", width=8, height=8, theta_i_deg=30, seed=v),
])
@pytest.mark.parametrize("value", [2 ** 64, -2 ** 64, 2 ** 200, 10 ** 5000],
                         ids=["2^64", "-2^64", "2^200", "10^5000"])
def test_an_integer_that_overflows_names_the_argument(call, value):
    with pytest.raises(ValueError, match="seed") as info:
        call(value)
    assert not isinstance(info.value, RuntimeError) or isinstance(info.value, rs.Error)


@pytest.mark.parametrize("value", [2 ** 64, 2 ** 200, -2 ** 70], ids=["2^64", "2^200", "-2^70"])
def test_integer_sizes_that_overflow_are_value_errors(value):
    for call in (lambda: rs.generate_surface(sigma_um=0.1, T_um=1.0, nx=value, ny=16),
                 lambda: rs.region_mask({"rect": [0, 0, 1, 1]}, value, 10),
                 lambda: rs.read_height_map("x.raw", nx=value, ny=4, dx_um=1.0)):
        with pytest.raises(ValueError):
            call()


def test_a_path_with_a_nul_byte_is_a_value_error_as_open_raises(tmp_path):
    with pytest.raises(ValueError, match="null"):
        open(str(tmp_path / "a\0b"))  # Python's own behaviour, the model
    bad = str(tmp_path / "real.csv") + "\0.png"
    (tmp_path / "real.csv").write_text("theta_i,phi_i,theta_s,phi_s,value\n30,0,0,0,0.1\n")
    calls = {
        "path": [lambda: rs.read_image(bad), lambda: rs.read_height_map(bad),
                 lambda: rs.brdf_read_csv(bad), lambda: rs.brdf_compare_csv(bad),
                 lambda: rs.write_height_map(np.zeros((4, 4)), 1.0, path=bad)],
        "capture_file": [lambda: rs.measure(bad)],
        "data_dir": [lambda: rs.curet_find_directory(bad), lambda: rs.curet_load(bad)],
        "out_dir": [lambda: rs.write_capture(bad, "png", scene="plane", width=8, height=8,
                                             theta_i_deg=30)],
    }
    for name, fs in calls.items():
        for f in fs:
            with pytest.raises(ValueError, match=f"{name}: embedded null byte"):
                f()
    assert not (tmp_path / "real.csv.png").exists()


@pytest.mark.parametrize("path", ["/dev/zero", "/dev/urandom"])
def test_a_device_as_a_file_is_a_data_error(path):
    for call in (lambda: rs.read_image(path), lambda: rs.read_height_map(path, format="csv_matrix"),
                 lambda: rs.brdf_read_csv(path), lambda: rs.measure(path)):
        with pytest.raises(rs.DataError, match="not a regular file"):
            call()


def test_a_fifo_as_a_file_is_a_data_error_without_waiting(tmp_path):
    fifo = tmp_path / "pipe.png"
    os.mkfifo(fifo)
    proc = run_child(f"""
        import roughscope as rs
        for f in (rs.read_image, rs.measure, rs.brdf_read_csv):
            try:
                f({str(fifo)!r})
                print("no error")
            except rs.DataError as e:
                print("DataError", e)
        """)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert len(lines) == 3 and all("not a regular file" in line for line in lines), proc.stdout


def test_a_surface_beyond_the_memory_budget_is_refused_before_allocating():
    proc = run_child("""
        import os
        os.environ["ROUGHSCOPE_MEMORY_LIMIT_GB"] = "0.05"
        import roughscope as rs
        try:
            rs.generate_surface(sigma_um=0.1, T_um=1.0, nx=4096, ny=4096)
            print("no error")
        except rs.InvalidArgument as e:
            print(e)
        """)
    assert proc.returncode == 0, proc.stderr
    assert "4096 x 4096 points needs about 0.168 GB" in proc.stdout, proc.stdout
    assert "ROUGHSCOPE_MEMORY_LIMIT_GB" in proc.stdout, proc.stdout


# ---------------------------------------------------------------------------------------------
# Properties: every argument of every known-good call replaced by a hostile value.

def _self_referencing(kind):
    if kind == "dict":
        d = {}
        d["rect"] = d
        return d
    lst = []
    lst.append(lst)
    return lst


HUGE_INTS = st.one_of(st.sampled_from([2 ** 64, -2 ** 64 - 1, 2 ** 100, -(2 ** 200)]),
                      st.builds(lambda: 10 ** 5000))  # (too long for repr(): built, not listed)
ODD_TEXT = st.text(alphabet=st.sampled_from(["\0", "\x1b", "\n", "\udcff", "\u202e", "a", "/",
                                             ".", "\u00e9", "\U0001f600"]), max_size=12)
SCALARS = st.one_of(HUGE_INTS, ODD_TEXT, st.floats(allow_nan=True, allow_infinity=True),
                    st.none(), st.booleans(), st.binary(max_size=8),
                    st.sampled_from(["/dev/zero", "/dev/urandom", "/", ""]))
NESTED = st.recursive(SCALARS, lambda children: st.one_of(
    st.lists(children, max_size=3), st.dictionaries(st.sampled_from(["rect", "circle", "polygon",
                                                                      "mask", "x"]),
                                                    children, max_size=3)), max_leaves=12)
HOSTILE = st.one_of(NESTED, st.sampled_from(["dict", "list"]).map(_self_referencing))

# Calls that take long on good input (a whole database, a measurement, a paper table): their
# argument handling is the same helpers' as the others'.
SLOW = {"curet_load", "measure", "recompute_paper_tables", "render_capture", "write_capture",
        "simulate_scatter", "check_simulate_scatter", "fit_roughness"}
CASES = [(name, where) for name, calls in sorted(GOOD_CALLS.items())
         if not name.startswith("CuretDatabase.") and name not in SLOW
         for where in list(range(len(calls[0][0]))) + sorted(calls[0][1])]


@pytest.mark.parametrize("name,where", CASES)
@settings(max_examples=15, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(value=HOSTILE)
def test_hostile_values_raise_only_type_value_or_os_errors(name, where, value, request,
                                                           tmp_path):
    function = resolve(name, None, request)
    args, kwargs = GOOD_CALLS[name][0]
    args = list(materialise(name, args, request))
    if isinstance(where, str):
        kwargs = dict(kwargs, **{where: value})
    else:
        args[where] = value
    cwd = os.getcwd()
    os.chdir(tmp_path)  # (a string value may be a path that is written)
    try:
        function(*args, **kwargs)
    except ALLOWED:
        pass
    finally:
        os.chdir(cwd)


def test_the_properties_cover_the_module():
    assert len(CASES) > 100
    assert {"region_mask", "generate_surface", "read_image", "read_height_map"} <= \
        {name for name, _ in CASES}
    assert _core.region_mask is rs.region_mask
