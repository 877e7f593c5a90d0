"""One reading policy for every reader (docs/input-files.md), checked on the command line.

Each reader gets the same variants of a good input: a UTF-8 byte-order mark, CRLF line ends and
spaces/tabs around fields must be accepted; a hexadecimal number, NaN, binary garbage, an empty
file and a directory in place of the file must be refused with exit code 4 and a message that
names the file (and the line, where the format has lines). Integer and number flags follow the
same number syntax.
"""

import json
import os
import subprocess

import pytest

from conftest import cli_path

BINARY = b"\x7fELF\x02\x01\x01\x00\x00\x00\x1b[2J" + bytes(range(256))


def run(*args, cwd=None):
    return subprocess.run([cli_path(), *map(str, args)], capture_output=True, cwd=cwd,
                          timeout=600)


# ---------------------------------------------------------------------------------------------
# The readers: each writes its good input into a folder and says how to run the command on it.

def csv_spaces(text):
    """Spaces and tabs around every field of a comma-separated text."""
    return "\n".join(" \t" + line.replace(",", " \t, ") + " \t" if line else line
                     for line in text.split("\n"))


def ws_spaces(text):
    """Spaces and tabs around every line of a whitespace-separated text."""
    return "\n".join(" \t" + line + " \t" if line else line for line in text.split("\n"))


def json_spaces(text):
    return "\n".join(line + " \t" for line in text.split("\n"))


class Reader:
    """name, good text, the file it goes in, the command, how to add spaces, how to make a
    number hexadecimal or NaN (text → text), and whether its errors carry a line number."""

    def __init__(self, name, text, file, command, spaces, hex_number, nan_number, lines=True):
        self.name, self.text, self.file, self.command = name, text, file, command
        self.spaces, self.hex_number, self.nan_number, self.lines = (spaces, hex_number,
                                                                    nan_number, lines)


def _curet_table():
    rows = []
    for j in range(1, 206):
        tv, pv, ti, pi = 0.01 * (j % 80), 0.03 * j, 0.012 * (j % 100), -0.02 * j
        if j == 81:
            tv, pv, ti, pi = 0.0, 0.0, 0.785398, 0.0
        if j == 112:
            tv, pv, ti, pi = 1e-6, 0.0, 1.178097, 0.0
        rows.append(f"{j} {tv:.6f} {pv:.6f} {ti:.6f} {pi:.6f}")
    return "\n".join(rows) + "\n"


def _curet_brdf(sample=1):
    return f"{sample} " + " ".join(f"{0.05 * (1 + 0.001 * j):.6f}" for j in range(1, 206)) + "\n"


def _measurements():
    rows = ["theta_i,phi_i,theta_s,phi_s,brightness"]
    for k, ti in enumerate((10, 20, 30, 40, 50, 60)):
        rows.append(f"{ti},0,{10 + 5 * k},180,{0.3 + 0.02 * k}")
    return "\n".join(rows) + "\n"


def _brdf_table():
    rows = ["theta_i,phi_i,theta_s,phi_s,value"]
    for ti in (10, 30, 45, 60):
        for ts in (0, 20, 40):
            for ps in (0, 90, 180):
                rows.append(f"{ti},180,{ts},{ps},{0.1 + 0.001 * ti + 0.0001 * ts}")
    return "\n".join(rows) + "\n"


def _paper_tables():
    doc = {
        "table1_slightly_rough": {
            "conditions": {"specular_theta_deg": 14, "theta1_deg": 30, "theta2_deg": 45,
                           "lambda_um": 0.555},
            "rows": [{"surface": "paper", "R_spec": 0.014, "sigma_um": 0.094, "E1_over_E2": 1.043,
                      "T_um": 0.195, "sigma_over_T": 0.482}]},
        "table2_very_rough": {
            "conditions": {"theta1_deg": 30, "theta2_deg": 45},
            "rows": [{"surface": "tile", "E1_over_E2": 1.141, "sigma_over_T_G": 0.4833,
                      "theta_K_deg": 56, "xi_K_percent": 65.7, "sigma_over_T_E": 1.1315}]},
        "table3_curet_parameters": {
            "conditions": {"theta1_deg": 45, "theta2_deg": 67.5},
            "rows": [{"name": "Quarry tile", "sample": 25, "E1_over_E2": 1.880176,
                      "sigma_over_T_G": 0.3957, "sigma_over_T_E": 0.5978}]},
    }
    return json.dumps(doc, indent=1) + "\n"


def _first(text, old, new):
    assert old in text
    return text.replace(old, new, 1)


READERS = [
    Reader("model --csv", "theta_i,theta_s,phi_s,sigma_over_T\n30,20,0,0.5\n45,10,90,0.3\n",
           "in.csv", lambda p: ["model", "--csv", p], csv_spaces,
           lambda t: _first(t, "\n30,", "\n0x1e,"), lambda t: _first(t, ",0.5\n", ",nan\n")),
    Reader("estimate fit", _measurements(), "in.csv",
           lambda p: ["estimate", "fit", "--measurements", p, "--correlation", "gaussian"],
           csv_spaces, lambda t: _first(t, "\n10,", "\n0xa,"),
           lambda t: _first(t, ",0.3\n", ",NaN\n")),
    Reader("curet --table", _brdf_table(), "in.csv",
           lambda p: ["curet", "--table", p, "--no-fits", "--format", "json"], csv_spaces,
           lambda t: _first(t, "\n10,", "\n0xa,"), lambda t: _first(t, "\n10,180,0,0,", "\n10,180,0,nan,")),
    Reader("CUReT table.txt", _curet_table(), "curet/table.txt",
           lambda p: ["curet", "--sample", "1", "--data", os.path.dirname(p), "--no-fits",
                      "--format", "json"],
           ws_spaces, lambda t: _first(t, "\n7 ", "\n0x7 "),
           lambda t: _first(t, "\n7 0.070000", "\n7 nan")),
    Reader("CUReT abrdf.dat", _curet_brdf(), "curet/abrdf.dat",
           lambda p: ["curet", "--sample", "1", "--data", os.path.dirname(p), "--no-fits",
                      "--format", "json"],
           ws_spaces, lambda t: _first(t, " 0.050050 ", " 0x1p-4 "),
           lambda t: _first(t, " 0.050050 ", " nan ")),
    Reader("paper tables JSON", _paper_tables(), "tables.json",
           lambda p: ["paper", "tables", "--reference", p, "--json"], json_spaces,
           lambda t: _first(t, '"R_spec": 0.014', '"R_spec": 0x1e'),
           lambda t: _first(t, '"R_spec": 0.014', '"R_spec": NaN')),
]

ACCEPTED = {
    "bom": lambda r: b"\xef\xbb\xbf" + r.text.encode(),
    "crlf": lambda r: r.text.replace("\n", "\r\n").encode(),
    "spaces": lambda r: r.spaces(r.text).encode(),
    "bom+crlf+spaces": lambda r: b"\xef\xbb\xbf" + r.spaces(r.text).replace("\n", "\r\n").encode(),
}
REFUSED = {
    "hex number": lambda r: r.hex_number(r.text).encode(),
    "NaN": lambda r: r.nan_number(r.text).encode(),
    "binary garbage": lambda r: BINARY,
    "empty file": lambda r: b"",
    "directory": None,
}


def place(tmp_path, reader, content):
    """Writes the reader's inputs; `content` (bytes, or None for a directory) is the file under
    test. Returns its path."""
    curet = tmp_path / "curet"
    curet.mkdir(exist_ok=True)
    (curet / "table.txt").write_text(_curet_table())
    (curet / "abrdf.dat").write_text(_curet_brdf())
    path = tmp_path / reader.file
    if path.exists():
        path.unlink()
    if content is None:
        path.mkdir()
    else:
        path.write_bytes(content)
    return str(path)


@pytest.mark.parametrize("reader", READERS, ids=lambda r: r.name)
def test_good_input_is_read(tmp_path, reader):
    proc = run(*reader.command(place(tmp_path, reader, reader.text.encode())), cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr.decode(errors="replace")


@pytest.mark.parametrize("variant", list(ACCEPTED))
@pytest.mark.parametrize("reader", READERS, ids=lambda r: r.name)
def test_accepted_variants(tmp_path, reader, variant):
    proc = run(*reader.command(place(tmp_path, reader, ACCEPTED[variant](reader))), cwd=tmp_path)
    assert proc.returncode == 0, (variant, proc.stderr.decode(errors="replace"))
    assert proc.stderr == b""


@pytest.mark.parametrize("variant", list(REFUSED))
@pytest.mark.parametrize("reader", READERS, ids=lambda r: r.name)
def test_refused_variants_name_the_file_and_line(tmp_path, reader, variant):
    make = REFUSED[variant]
    path = place(tmp_path, reader, None if make is None else make(reader))
    proc = run(*reader.command(path), cwd=tmp_path)
    err = proc.stderr.decode("utf-8")  # valid UTF-8: raw bytes never reach the terminal
    assert proc.returncode == 4, (variant, err)
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("roughscope: error: "), err
    assert path in err, err
    assert "\x1b" not in err and "\x00" not in err
    if variant in ("hex number", "NaN", "binary garbage") and reader.lines:
        # "<file>:<line>: ..." for the line-based formats, "<file>: line L, column C: ..." for JSON
        after = err.split(path, 1)[1]
        assert after[:1] == ":" and (after[1:2].isdigit() or after.startswith(": line ")), err
    if variant == "directory":
        assert "is a directory" in err, err


# ---------------------------------------------------------------------------------------------
# Flags: the same number syntax (surrounding spaces accepted; hex, fractions for integers, NaN
# refused with exit code 2 naming the flag)

@pytest.mark.parametrize("text", ["30", " 30", "30 ", "\t30\t", "+30", "3e1"])
def test_number_flags_accept_spaces_on_both_sides(text):
    proc = run("model", "--theta-i", text, "--theta-s", "20", "--phi-s", "0",
               "--sigma-over-T", "0.5")
    assert proc.returncode == 0, proc.stderr.decode()


@pytest.mark.parametrize("text", ["0x1e", "0x1p4", "nan", "inf", "30x", ""])
def test_number_flags_refuse_other_syntax(text):
    proc = run("model", "--theta-i", text, "--theta-s", "20", "--phi-s", "0",
               "--sigma-over-T", "0.5")
    assert proc.returncode == 2, proc.stderr.decode()
    assert "--theta-i" in proc.stderr.decode()




@pytest.mark.parametrize("text", ["1", " 1", "1 ", "+1"])
def test_integer_flags_accept_decimal_digits_with_spaces(tmp_path, text):
    place(tmp_path, READERS[3], _curet_table().encode())
    proc = run("curet", "--sample", text, "--data", tmp_path / "curet", "--no-fits",
               "--format", "json")
    assert proc.returncode == 0, proc.stderr.decode()


@pytest.mark.parametrize("text", ["0x1", "1.0", "1e0", "0b1", "0o1", "nan", ""])
@pytest.mark.parametrize("flag", ["--sample", "--threads", "--max-iterations"])
def test_integer_flags_refuse_anything_but_decimal_digits(tmp_path, flag, text):
    if flag == "--max-iterations":
        (tmp_path / "m.csv").write_text(_measurements())
        args = ["estimate", "fit", "--measurements", tmp_path / "m.csv", flag, text]
    elif flag == "--threads":
        args = ["curet", "--all", "--data", tmp_path, flag, text]
    else:
        args = ["curet", "--data", tmp_path, flag, text]
    proc = run(*args)
    err = proc.stderr.decode()
    assert proc.returncode == 2, err
    assert flag in err, err
    if text:
        assert "not an integer" in err, err


def test_data_given_a_file_is_not_a_directory(tmp_path):
    f = tmp_path / "file.txt"
    f.write_text("x")
    proc = run("curet", "--sample", "1", "--data", f)
    err = proc.stderr.decode()
    assert proc.returncode == 4, err
    assert f"{f} is not a directory" in err and "does not exist" not in err, err
