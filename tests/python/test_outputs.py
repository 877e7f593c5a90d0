"""Output files of the CLI (io::OutputFile): what `--output PATH` does to each kind of PATH.

Regular files are replaced atomically with their mode kept; symlinks are written through;
devices, FIFOs and `-` are written directly; a file the user may not write is refused (exit 4,
unchanged); a failure half-way or a SIGTERM leaves the old output byte-identical and no
temporary file behind.
"""

import os
import pathlib
import shutil
import signal
import stat
import subprocess
import tempfile
import threading
import time

import pytest

from conftest import cli_path

# Drives the CLI: also run against the sanitizer build (`make sanitize`, DEVELOPERS.md).
pytestmark = pytest.mark.cli

# One geometry, printed as CSV when --output is given.
ONE_POINT = ["model", "--theta-i", "30", "--theta-s", "20", "--phi-s", "0", "--sigma", "1",
             "--T", "2"]


def run(*args, cwd=None, prefix=(), timeout=120):
    return subprocess.run([*prefix, cli_path(), *args], capture_output=True, text=True,
                          cwd=cwd, timeout=timeout)


@pytest.fixture(scope="module")
def expected(tmp_path_factory):
    """The bytes ONE_POINT writes to a fresh regular file."""
    out = tmp_path_factory.mktemp("expected") / "out.csv"
    p = run(*ONE_POINT, "--output", str(out))
    assert p.returncode == 0, p.stderr
    text = out.read_bytes()
    assert text.startswith(b"model,") and text.count(b"\n") == 2
    return text


def leftovers(directory):
    return sorted(n for n in os.listdir(directory) if ".tmp-" in n)


def write_rows(path, n, bad_row_at=None):
    with open(path, "w", encoding="utf-8") as f:
        f.write("theta_i,theta_s,phi_s\n")
        for k in range(n):
            if k == bad_row_at:
                f.write("10,20,oops\n")
            else:
                f.write(f"{k * 7 % 800 / 10},{k * 13 % 800 / 10},{k * 17 % 3600 / 10}\n")


# -------------------------------------------------------------------------------------------------
# Regular files and symlinks

def test_existing_file_is_replaced_and_keeps_mode_0600(tmp_path, expected):
    out = tmp_path / "out.csv"
    out.write_text("old\n")
    out.chmod(0o600)
    p = run(*ONE_POINT, "--output", str(out))
    assert p.returncode == 0, p.stderr
    assert out.read_bytes() == expected
    assert stat.S_IMODE(out.stat().st_mode) == 0o600
    assert leftovers(tmp_path) == []


def test_symlink_is_written_through(tmp_path, expected):
    (tmp_path / "real").mkdir()
    target = tmp_path / "real" / "target.csv"
    target.write_text("old\n")
    link = tmp_path / "link.csv"
    link.symlink_to("real/target.csv")
    p = run(*ONE_POINT, "--output", str(link))
    assert p.returncode == 0, p.stderr
    assert link.is_symlink() and os.readlink(link) == "real/target.csv"
    assert target.read_bytes() == expected
    assert leftovers(tmp_path) == [] and leftovers(tmp_path / "real") == []


def test_output_into_a_directory_is_a_data_error(tmp_path):
    p = run(*ONE_POINT, "--output", str(tmp_path))
    assert p.returncode == 4
    assert "cannot write" in p.stderr and "is a directory" in p.stderr
    assert os.listdir(tmp_path) == []


# -------------------------------------------------------------------------------------------------
# Devices, FIFOs, standard output

def test_fifo_reader_gets_the_output(tmp_path, expected):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    received = {}

    def reader():
        with open(fifo, "rb") as f:
            received["data"] = f.read()

    t = threading.Thread(target=reader)
    t.start()
    p = run(*ONE_POINT, "--output", str(fifo), timeout=60)
    t.join(timeout=60)
    assert p.returncode == 0, p.stderr
    assert received.get("data") == expected
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert sorted(os.listdir(tmp_path)) == ["pipe"]


def test_character_device_stays_a_device(tmp_path):
    if os.geteuid() != 0:
        pytest.skip("mknod of a character device needs root")
    dev = tmp_path / "null"
    os.mknod(dev, stat.S_IFCHR | 0o666, os.makedev(1, 3))  # a copy of /dev/null
    p = run(*ONE_POINT, "--output", str(dev))
    assert p.returncode == 0, p.stderr
    assert stat.S_ISCHR(os.lstat(dev).st_mode)
    assert os.lstat(dev).st_rdev == os.makedev(1, 3)
    assert sorted(os.listdir(tmp_path)) == ["null"]


def test_dash_writes_to_standard_output(tmp_path, expected):
    p = run(*ONE_POINT, "--output", "-", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert p.stdout.encode() == expected
    assert os.listdir(tmp_path) == []  # no file named "-"


# -------------------------------------------------------------------------------------------------
# Files the user may not write

@pytest.fixture
def unprivileged():
    """(directory, command prefix): a 0777 folder and the prefix that runs the CLI as a user
    without privileges (setpriv to nobody when the tests run as root)."""
    directory = pathlib.Path(tempfile.mkdtemp(prefix="roughscope_ro_"))
    directory.chmod(0o777)
    prefix = ()
    if os.geteuid() == 0:
        if shutil.which("setpriv") is None:
            pytest.skip("running as root and setpriv is not available")
        prefix = ("setpriv", "--reuid=65534", "--regid=65534", "--clear-groups")
    yield directory, prefix
    shutil.rmtree(directory, ignore_errors=True)


def test_read_only_file_is_refused_and_unchanged(unprivileged):
    directory, prefix = unprivileged
    out = directory / "ro.csv"
    out.write_text("keep me\n")
    out.chmod(0o444)
    p = run(*ONE_POINT, "--output", str(out), prefix=prefix)
    assert p.returncode == 4, (p.returncode, p.stderr)
    assert p.stderr.startswith("roughscope: error: cannot write ")
    assert "permission denied" in p.stderr
    assert out.read_text() == "keep me\n"
    assert stat.S_IMODE(out.stat().st_mode) == 0o444
    assert sorted(os.listdir(directory)) == ["ro.csv"]


def test_writable_file_in_the_same_folder_is_replaced(unprivileged, expected):
    # The success twin: the same user, a file it may write (0666), is replaced with its mode.
    directory, prefix = unprivileged
    out = directory / "rw.csv"
    out.write_text("old\n")
    out.chmod(0o666)
    p = run(*ONE_POINT, "--output", str(out), prefix=prefix)
    assert p.returncode == 0, p.stderr
    assert out.read_bytes() == expected
    assert stat.S_IMODE(out.stat().st_mode) == 0o666
    assert sorted(os.listdir(directory)) == ["rw.csv"]


# -------------------------------------------------------------------------------------------------
# Nothing half-written

@pytest.mark.parametrize("fmt", [[], ["--json"]])
def test_bad_row_near_the_end_leaves_the_old_output(tmp_path, fmt):
    rows = tmp_path / "rows.csv"
    write_rows(rows, 20000, bad_row_at=19990)  # the output outgrows the write buffer first
    out = tmp_path / "out.txt"
    old = b"old output\x00\xff\n"
    out.write_bytes(old)
    p = run("model", "--csv", str(rows), "--sigma", "1", "--T", "2", *fmt, "--output", str(out))
    assert p.returncode == 4, p.stderr
    assert f"{rows}:19992: column phi_s: 'oops' is not a number" in p.stderr
    assert out.read_bytes() == old
    assert sorted(os.listdir(tmp_path)) == ["out.txt", "rows.csv"]


def test_sigterm_during_a_long_write_removes_the_temporary_file(tmp_path):
    rows = tmp_path / "rows.csv"
    write_rows(rows, 400000)
    out = tmp_path / "out.csv"
    out.write_text("old\n")
    proc = subprocess.Popen([cli_path(), "model", "--csv", str(rows), "--sigma", "1", "--T", "2",
                             "--output", str(out)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 60
        while not leftovers(tmp_path) and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.02)
        assert leftovers(tmp_path), "no temporary file seen while the output was written"
        proc.send_signal(signal.SIGTERM)
        proc.wait(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == -signal.SIGTERM
    assert out.read_text() == "old\n"
    assert leftovers(tmp_path) == []
