"""Height files read from a named pipe (FIFO): the reader takes a non-seekable input whole,
and `surface stats` on the pipe prints what it prints for the same bytes in a regular file.
A regular file is read in one call into storage of its size; a pipe in chunks until its end."""

import json
import os
import subprocess
import threading

import pytest

from conftest import cli_path

pytestmark = pytest.mark.cli


def stats_json(path, *extra):
    p = subprocess.run([cli_path(), "surface", "stats", str(path), "--json", *extra],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout)


def without_file_names(value, names):
    """The document with every string equal to one of `names` replaced (the input's path)."""
    if isinstance(value, dict):
        return {k: without_file_names(v, names) for k, v in value.items()}
    if isinstance(value, list):
        return [without_file_names(v, names) for v in value]
    if isinstance(value, str):
        for n in names:
            value = value.replace(n, "FILE")
    return value


@pytest.mark.parametrize("extension", ["csv", "x3p", "sdf"])
def test_stats_of_a_pipe_equal_those_of_the_file(tmp_path, extension):
    regular = tmp_path / f"surface.{extension}"
    # 300 x 200 points: the x3p and binary SDF files (~0.5 MB) are larger than a pipe's buffer,
    # so the reader must take several reads before the writer finishes.
    subprocess.run([cli_path(), "surface", "generate", "--nx", "300", "--ny", "200",
                    "--T-um", "8", "--seed", "5", "--out", str(regular)],
                   check=True, capture_output=True, timeout=300)
    data = regular.read_bytes()
    assert len(data) > 65536
    pipe = tmp_path / f"pipe.{extension}"
    os.mkfifo(pipe)

    def feed():
        with open(pipe, "wb") as w:
            w.write(data)

    writer = threading.Thread(target=feed)
    writer.start()
    try:
        from_pipe = stats_json(pipe)
    finally:
        writer.join(timeout=60)
    from_file = stats_json(regular)
    assert from_file["sigma_um"] > 0
    names = [str(pipe), str(regular), pipe.name, regular.name]
    assert without_file_names(from_pipe, names) == without_file_names(from_file, names)


def test_a_truncated_pipe_is_a_data_error_naming_it(tmp_path):
    regular = tmp_path / "surface.x3p"
    subprocess.run([cli_path(), "surface", "generate", "--nx", "64", "--ny", "64",
                    "--out", str(regular)], check=True, capture_output=True, timeout=300)
    data = regular.read_bytes()
    pipe = tmp_path / "cut.x3p"
    os.mkfifo(pipe)

    def feed():
        with open(pipe, "wb") as w:
            w.write(data[: len(data) // 2])

    writer = threading.Thread(target=feed)
    writer.start()
    try:
        p = subprocess.run([cli_path(), "surface", "stats", str(pipe), "--json"],
                           capture_output=True, text=True, timeout=300)
    finally:
        writer.join(timeout=60)
    assert p.returncode != 0
    assert "cut.x3p" in p.stderr
    assert p.stdout == ""
