"""What `roughscope measure` writes, and what it never touches (docs/measure.md "Outputs").

* `--report DIR` writes DIR/index.html and nothing else: files already in DIR (the photographs,
  the capture file, the maps of the same run, a symbolic link) stay as they were.
* One command, one commit: `--output`, `--maps` and `--report` of a run are all written or none is,
  also when the run is killed while the report is being made (the helper process dies with it).
* An output onto one of the run's own inputs is refused.
"""

import json
import os
import pathlib
import signal
import subprocess
import sys
import time

import pytest

from conftest import cli_path

pytestmark = pytest.mark.cli

EXIT_USAGE, EXIT_DATA = 2, 4


def run(*args, check=True, cwd=None, env=None):
    proc = subprocess.run([cli_path(), "measure", *map(str, args)], capture_output=True,
                          text=True, timeout=300, cwd=cwd, env=env)
    if check:
        assert proc.returncode == 0, f"exit {proc.returncode}: {proc.stderr}"
    return proc


def snapshot(folder):
    """{relative path: (kind, bytes or link target, mtime_ns)} of everything under `folder`."""
    folder = pathlib.Path(folder)
    state = {}
    for path in sorted(folder.rglob("*")):
        st = path.lstat()
        if path.is_symlink():
            state[str(path.relative_to(folder))] = ("link", os.readlink(path), st.st_mtime_ns)
        elif path.is_dir():
            state[str(path.relative_to(folder))] = ("dir", None, None)
        else:
            state[str(path.relative_to(folder))] = ("file", path.read_bytes(), st.st_mtime_ns)
    return state


@pytest.fixture()
def sample(tmp_path):
    from roughscope import demo

    spec = demo.SAMPLES[1]
    return demo.write_sample(spec, tmp_path / "photos")


@pytest.fixture(scope="module")
def flat_map(tmp_path_factory):
    from roughscope import demo

    return demo.write_map(tmp_path_factory.mktemp("map"))


def test_report_into_a_folder_of_the_users_touches_nothing_else(sample, tmp_path):
    folder = tmp_path / "mine"
    (folder / "sub").mkdir(parents=True)
    (folder / "notes.txt").write_text("keep me")
    (folder / "sub" / "data.csv").write_text("1,2,3\n")
    (folder / "link").symlink_to(folder / "notes.txt")
    (folder / "index.html.bak").write_text("an older page")
    before = snapshot(folder)
    proc = run(sample, "--report", folder)
    after = snapshot(folder)
    assert set(after) == set(before) | {"index.html"}, set(after) ^ set(before)
    for name, state in before.items():
        assert after[name] == state, name
    assert "E1/E2" in (folder / "index.html").read_text()
    assert "E1/E2" in proc.stdout
    # Run again: index.html is replaced, the rest still untouched.
    run(sample, "--report", folder)
    again = snapshot(folder)
    assert {k: v for k, v in again.items() if k != "index.html"} == before


def test_report_dot_from_the_photographs_folder_keeps_them(sample):
    photos = pathlib.Path(sample).parent
    before = snapshot(photos)
    assert len(before) >= 3  # the capture file and its two photographs
    run(pathlib.Path(sample).name, "--report", ".", cwd=photos)
    after = snapshot(photos)
    assert set(after) == set(before) | {"index.html"}
    for name, state in before.items():
        assert after[name] == state, name


def test_report_beside_the_maps_of_the_same_run_keeps_them(flat_map, tmp_path):
    rep = tmp_path / "rep"
    doc = json.loads(run(flat_map, "--json", "--maps", rep / "maps", "--report", rep).stdout)
    files = doc["map"]["files"]
    assert files and all((rep / "maps" / name).is_file() for name in files)
    assert (rep / "index.html").is_file()
    assert sorted(p.name for p in rep.iterdir()) == ["index.html", "maps"]


def test_a_symlinked_report_folder_is_written_through(sample, tmp_path):
    target = tmp_path / "real"
    target.mkdir()
    link = tmp_path / "link"
    link.symlink_to(target, target_is_directory=True)
    run(sample, "--report", link)
    assert link.is_symlink() and (target / "index.html").is_file()


def test_a_report_folder_that_is_a_file_is_a_named_error(sample, tmp_path):
    blocker = tmp_path / "report"
    blocker.write_text("keep")
    proc = run(sample, "--report", blocker, check=False)
    assert proc.returncode == EXIT_DATA, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and str(blocker) in lines[0] and "not a folder" in lines[0], lines
    assert "PosixPath" not in lines[0] and "Errno" not in lines[0]
    assert blocker.read_text() == "keep" and proc.stdout == ""


def test_a_failing_output_writes_no_map_and_no_report(flat_map, tmp_path):
    proc = run(flat_map, "--maps", tmp_path / "out" / "maps", "--report", tmp_path / "rep",
               "--output", tmp_path / "missing" / "result.txt", check=False)
    assert proc.returncode == EXIT_DATA, proc.stderr
    assert "missing" in proc.stderr
    # Nothing new: not the maps, not the report, not the folders made for them.
    assert sorted(p.name for p in tmp_path.iterdir()) == [], list(tmp_path.iterdir())


def test_a_failing_report_writes_no_map_and_no_output(flat_map, tmp_path):
    blocker = tmp_path / "rep"
    blocker.write_text("keep")
    proc = run(flat_map, "--maps", tmp_path / "maps", "--report", blocker,
               "--output", tmp_path / "result.txt", check=False)
    assert proc.returncode == EXIT_DATA, proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rep"]
    assert blocker.read_text() == "keep"


@pytest.mark.parametrize("which", ["capture file", "photograph"])
def test_output_onto_an_input_is_refused(sample, which):
    doc = json.loads(pathlib.Path(sample).read_text())
    target = (pathlib.Path(sample) if which == "capture file"
              else pathlib.Path(sample).parent / doc["captures"][0]["image"])
    before = target.read_bytes()
    proc = run(sample, "--output", target, check=False)
    assert proc.returncode == EXIT_USAGE, proc.stderr
    assert "--output" in proc.stderr and "input" in proc.stderr
    assert target.read_bytes() == before


def test_output_onto_an_input_through_a_symlink_is_refused(sample, tmp_path):
    link = tmp_path / "result.json"
    link.symlink_to(sample)
    before = pathlib.Path(sample).read_bytes()
    proc = run(sample, "--output", link, check=False)
    assert proc.returncode == EXIT_USAGE, proc.stderr
    assert pathlib.Path(sample).read_bytes() == before


def _process_gone(pid, timeout=10.0):
    """Whether `pid` has ended (reaped, or a zombie awaiting its new parent) within `timeout`."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        try:
            with open(f"/proc/{pid}/stat") as f:
                if f.read().split(") ")[-1].startswith("Z"):
                    return True
        except FileNotFoundError:
            return True
        time.sleep(0.05)
    return False


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_while_the_report_is_made_ends_the_helper_and_leaves_nothing(
        flat_map, tmp_path, sig):
    # A stand-in for the Python interpreter that records its pid and hangs, so that the signal
    # arrives while the report is being made.
    pid_file = tmp_path / "helper.pid"
    helper = tmp_path / "python"
    helper.write_text(f"#!/bin/sh\necho $$ > '{pid_file}.tmp'\nmv '{pid_file}.tmp' '{pid_file}'\n"
                      "exec sleep 120\n")
    helper.chmod(0o755)
    out = tmp_path / "out"
    out.mkdir()
    env = dict(os.environ, ROUGHSCOPE_PYTHON=str(helper))
    proc = subprocess.Popen([cli_path(), "measure", str(flat_map), "--maps", str(out / "maps"),
                             "--report", str(out / "rep"), "--output", str(out / "r.txt")],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)
    try:
        end = time.monotonic() + 120
        while not pid_file.exists():
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < end, "the report step never started"
            time.sleep(0.05)
        helper_pid = int(pid_file.read_text())
        proc.send_signal(sig)
        proc.wait(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == -sig
    assert _process_gone(helper_pid), "the report's helper process outlived the command"
    assert list(out.iterdir()) == [], list(out.iterdir())


def test_the_report_module_errors_are_one_line_naming_the_path(tmp_path, python_env):
    blocker = tmp_path / "file"
    blocker.write_text("keep")
    doc = {"captures": [], "warnings": []}
    proc = subprocess.run([sys.executable, "-m", "roughscope.report_measure", "--out",
                           str(blocker / "sub")], input=json.dumps(doc), capture_output=True,
                          text=True, timeout=120, env=python_env)
    assert proc.returncode == 1
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and str(blocker) in lines[0], lines
    assert "PosixPath" not in lines[0] and "Errno" not in lines[0], lines[0]


def test_the_main_report_refuses_a_folder_of_the_users(tmp_path, python_env):
    folder = tmp_path / "photos"
    folder.mkdir()
    (folder / "IMG_0001.CR2").write_bytes(b"raw")
    before = snapshot(folder)
    proc = subprocess.run([sys.executable, "-m", "roughscope.report", "--out", str(folder)],
                          capture_output=True, text=True, timeout=120, env=python_env)
    assert proc.returncode == 1
    assert "not a roughscope report" in proc.stderr and str(folder) in proc.stderr
    assert snapshot(folder) == before
