"""Inputs are regular files (docs/input-files.md, "Regular files only").

A device that never ends (/dev/zero, /dev/urandom) or a FIFO named as any input — an image, a
region mask, a dark frame, a height file, a CSV table, CUReT's files, the paper's JSON, a capture
file — is refused with exit code 4 and one line naming the file, before it is read: nothing grows
without bound, and a FIFO with no writer is not waited on (its type is looked at without opening
it). Height files are the exception for FIFOs (docs/height-files.md, "Pipes"): a pipe is read, but
never beyond the memory limit (ROUGHSCOPE_MEMORY_LIMIT_GB), so an endless writer is refused too. Each run has a timeout, and outside the sanitizer build an address-space limit, so that a
reader that did read the device fails the test instead of the machine.
"""

import contextlib
import json
import os
import pathlib
import resource
import subprocess
import threading

import pytest

from conftest import cli_path
from test_readers import _curet_brdf, _curet_table

SANITIZED = os.environ.get("ROUGHSCOPE_SANITIZED") == "1"
EXIT_DATA = 4
LIMIT_BYTES = 3 << 30  # far above what any of these commands needs on its good input


def _limit():
    if not SANITIZED:  # (ASan reserves terabytes of address space)
        resource.setrlimit(resource.RLIMIT_AS, (LIMIT_BYTES, LIMIT_BYTES))


def run(*args, cwd=None, env=None):
    return subprocess.run([cli_path(), *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=60, preexec_fn=_limit, env=env)


def special(kind, path):
    """Makes `path` the special file `kind` (a symlink to the device, or a FIFO)."""
    path = pathlib.Path(path)
    if path.exists() or path.is_symlink():
        path.unlink()
    if kind == "fifo":
        os.mkfifo(path)
    else:
        path.symlink_to(kind)
    return str(path)


KINDS = ["/dev/zero", "/dev/urandom", "fifo"]


def assert_refused(proc, path):
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == EXIT_DATA, proc.stderr
    assert len(lines) == 1 and lines[0].startswith("roughscope: error: "), proc.stderr
    # (A long path is shown by its first 64 bytes: core/text.hpp's quote_input.)
    assert "not a regular file" in lines[0] and str(path)[:60] in lines[0], lines[0]


def _curet_dir(tmp_path):
    d = tmp_path / "curet"
    d.mkdir()
    (d / "table.txt").write_text(_curet_table())
    (d / "abrdf.dat").write_text(_curet_brdf())
    return d


# name → (file to make special, under tmp_path; the command given its path)
READERS = {
    "model --csv": ("in.csv", lambda p: ["model", "--csv", p]),
    "estimate fit": ("in.csv", lambda p: ["estimate", "fit", "--measurements", p,
                                         "--correlation", "gaussian"]),
    "curet --table": ("in.csv", lambda p: ["curet", "--table", p, "--no-fits"]),
    "CUReT table.txt": ("curet/table.txt",
                        lambda p: ["curet", "--sample", "1", "--data", os.path.dirname(p),
                                   "--no-fits"]),
    "CUReT abrdf.dat": ("curet/abrdf.dat",
                        lambda p: ["curet", "--sample", "1", "--data", os.path.dirname(p),
                                   "--no-fits"]),
    "paper tables": ("tables.json", lambda p: ["paper", "tables", "--reference", p]),
    "simulate scatter --csv": ("angles.csv",
                               lambda p: ["simulate", "scatter", "--csv", p, "--sigma-um", "0.05",
                                          "--T-um", "1"]),
    "height csv": ("h.csv", lambda p: ["surface", "stats", p]),
    "height x3p": ("h.x3p", lambda p: ["surface", "stats", p]),
    "height png": ("h.png", lambda p: ["surface", "stats", p, "--z-scale-um", "0.01"]),
    "height raw": ("h.raw", lambda p: ["surface", "stats", p, "--nx", "4", "--ny", "4"]),
    "capture file": ("capture.json", lambda p: ["measure", p]),
}


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("reader", list(READERS))
def test_special_files_are_refused_by_every_reader(tmp_path, reader, kind):
    if kind == "fifo" and reader.startswith("height"):
        pytest.skip("height files read pipes up to the memory limit (the test below)")
    _curet_dir(tmp_path)
    file, command = READERS[reader]
    special(kind, tmp_path / file)
    assert_refused(run(*command(file), cwd=tmp_path), file)  # (relative: named in full)


@pytest.mark.parametrize("reader", [r for r in READERS if r.startswith("height")])
def test_an_endless_pipe_as_a_height_file_stops_at_the_memory_limit(tmp_path, reader):
    file, command = READERS[reader]
    path = tmp_path / file
    os.mkfifo(path)
    stop = threading.Event()

    def endless_writer():
        try:
            with open(path, "wb") as pipe:
                block = b"0" * (1 << 16)
                while not stop.is_set():
                    pipe.write(block)
        except (BrokenPipeError, OSError):
            pass

    writer = threading.Thread(target=endless_writer, daemon=True)
    writer.start()
    env = dict(os.environ, ROUGHSCOPE_MEMORY_LIMIT_GB="0.02")
    try:
        proc = run(*command(file), cwd=tmp_path, env=env)
    finally:
        stop.set()
        with contextlib.suppress(OSError):  # unblock a writer still waiting for a reader
            os.close(os.open(path, os.O_RDONLY | os.O_NONBLOCK))
        writer.join(timeout=10)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == EXIT_DATA, proc.stderr
    assert len(lines) == 1 and file in lines[0] and "memory limit" in lines[0], lines


@pytest.fixture(scope="module")
def capture_file(tmp_path_factory):
    from roughscope import demo

    spec = demo.SAMPLES[1]
    return demo.write_sample(spec, tmp_path_factory.mktemp("sample"))


# A file the capture file names: the first capture's image, the region's mask, the dark frame.
EDITS = {
    "image": lambda doc, p: doc["captures"][0].update(image=p),
    "mask": lambda doc, p: doc.update(roi={"mask": p}),
    "dark_frame": lambda doc, p: doc.update(dark_frame=p),
}


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("what", list(EDITS))
def test_special_files_named_by_a_capture_file_are_refused(capture_file, tmp_path, what, kind):
    path = special(kind, tmp_path / f"{what}.tiff")
    doc = json.loads(pathlib.Path(capture_file).read_text())
    base = pathlib.Path(capture_file).parent
    for c in doc["captures"]:  # absolute, so that the edited copy can live elsewhere
        c["image"] = str(base / c["image"])
    EDITS[what](doc, path)
    edited = tmp_path / "capture.json"
    edited.write_text(json.dumps(doc))
    assert_refused(run("measure", edited), path)


def test_the_good_capture_file_is_measured(capture_file):
    """The sample the edits start from is measured (the refusals above are the edits')."""
    proc = run("measure", capture_file, "--json")
    assert proc.returncode == 0, proc.stderr
