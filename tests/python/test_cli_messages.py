"""Error messages of the command line and the Python module: never empty, never a raw control
character, never a value echoed whole, never a number rounded onto the limit it breaks, and
nothing from the solver's own logging on stderr (core/text.hpp, core/numbers.hpp, fit/engine)."""

import json
import subprocess

import pytest

import roughscope._core as core
from conftest import cli_path

BINARY = b"\x7fELF\x02\x01\x01\x00\x00\x00\x1b[2J" + bytes(range(256))
HEADER = "theta_i,phi_i,theta_s,phi_s,brightness\n"


def run(*args, cwd=None):
    return subprocess.run([cli_path(), *map(str, args)], capture_output=True, cwd=cwd,
                          timeout=600)


def one_error_line(proc):
    """The stderr of a failed run: exactly one `roughscope: error:` line, valid UTF-8."""
    err = proc.stderr.decode("utf-8")
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("roughscope: error: "), err
    return lines[0]


def test_binary_file_gives_a_message_naming_the_file(tmp_path):
    f = tmp_path / "data.csv"
    f.write_bytes(BINARY)
    for args in (["estimate", "fit", "--measurements", f], ["curet", "--table", f],
                 ["paper", "tables", "--reference", f]):
        line = one_error_line(run(*args))
        assert f"{f}" in line and "not a text file: NUL byte" in line, line


def test_python_data_errors_are_never_empty(tmp_path):
    # Bytes that are not UTF-8 (no NUL): the message used to be lost turning it into a str.
    f = tmp_path / "latin1.csv"
    f.write_bytes(b"theta_i,phi_i,theta_s,phi_s,value\n30,180,20,0,0.5\xff\xfe\n")
    with pytest.raises(core.DataError) as info:
        core.brdf_read_csv(str(f))
    message = str(info.value)
    assert message and str(f) in message and "\\xff\\xfe" in message, message
    g = tmp_path / "binary.csv"
    g.write_bytes(BINARY)
    with pytest.raises(core.DataError) as info:
        core.brdf_read_csv(str(g))
    assert f"{g}:1: not a text file: NUL byte at column 8" in str(info.value)


def test_control_characters_from_a_header_are_escaped(tmp_path):
    f = tmp_path / "ansi.csv"
    f.write_bytes(b"theta_i,\x1b[31mphi_i\x1b[0m,theta_s,phi_s,brightness\n30,0,20,180,1\n")
    line = one_error_line(run("estimate", "fit", "--measurements", f))
    assert "\x1b" not in line and "\\x1b[31mphi_i\\x1b[0m" in line, line


def test_control_characters_in_flags_are_escaped():
    line = one_error_line(run("model", "--theta-i", "1\x1b]0;owned\x07", "--theta-s", "20",
                              "--phi-s", "0", "--sigma-over-T", "0.5"))
    assert "\x1b" not in line and "\x07" not in line and "\\x1b]0;owned\\x07" in line, line
    line = one_error_line(run("curet", "--\x1b[2Jbogus"))
    assert "\x1b" not in line and "\\x1b[2Jbogus" in line, line


def test_a_huge_bad_field_is_cut(tmp_path):
    f = tmp_path / "huge.csv"
    f.write_text(HEADER + "30,0,20,180," + "9" * 10_000_000 + "x\n")
    proc = run("estimate", "fit", "--measurements", f)
    assert proc.returncode == 4
    line = one_error_line(proc)
    assert len(line) < 300 + len(str(f)), len(line)
    assert "(10000001 bytes in all)" in line and f"{f}:2: column brightness" in line, line


def test_a_value_just_outside_a_limit_is_not_printed_as_the_limit():
    # kappa = (E1/E2)/C just below 1: 7 significant digits printed "kappa = 1 must exceed 1".
    line = one_error_line(run("estimate", "slope", "--ratio", "1.02501896", "--theta1", "30",
                              "--theta2", "45", "--correlation", "gaussian"))
    assert "kappa = 0.99999999" in line and "kappa = 1 " not in line, line
    assert "theta1 = 30 deg" in line, line  # conversion noise is not shown
    assert "nan" not in line, line


@pytest.mark.parametrize("rows", [
    "30,0,20,180,1\n40,0,20,180,1e-300\n50,0,20,180,1e300\n",
    "30,0,20,180,1\n30,0,20,180,1\n30,0,20,180,1\n",
])
def test_the_solver_writes_nothing_to_stderr(tmp_path, rows):
    f = tmp_path / "degenerate.csv"
    f.write_text(HEADER + rows)
    proc = run("estimate", "fit", "--measurements", f, "--json")
    err = proc.stderr.decode()
    assert proc.returncode == 0 or len(err.splitlines()) == 1, err
    assert "trust_region_minimizer" not in err and "InitGoogleLogging" not in err, err
    assert all(line.startswith("roughscope: error: ") for line in err.splitlines()), err


def test_what_the_solver_logged_is_in_the_fit_message(tmp_path):
    f = tmp_path / "degenerate.csv"
    f.write_text(HEADER + "30,0,20,180,1\n40,0,20,180,1e-300\n50,0,20,180,1e300\n")
    proc = run("estimate", "fit", "--measurements", f, "--correlation", "gaussian")
    assert proc.stderr == b"", proc.stderr.decode()
    assert b"solver log: Terminating: Residual and Jacobian evaluation failed." in proc.stdout


def test_an_empty_output_directory_names_the_flag():
    proc = run("simulate", "capture", "--out", "")
    assert proc.returncode == 2
    line = one_error_line(proc)
    assert "--out" in line and "filesystem error" not in line, line


SCATTER = ["simulate", "scatter", "--sigma-um", "0.05", "--T-um", "1", "--realisations", "3"]


@pytest.mark.parametrize("flag,args", [
    ("--theta-i", [*SCATTER, "--theta-i", "30,,40", "--theta-s", "0", "--phi-s", "0"]),
    ("--theta-s", [*SCATTER, "--theta-i", "30", "--theta-s=0,", "--phi-s", "0"]),
    ("--phi-s", ["surface", "predict", "--sigma-um", "0.5", "--T-um", "5", "--theta-i", "30",
                 "--theta-s", "0", "--phi-s", ",0"]),
    ("--sigma-over-T", ["simulate", "capture", "--sigma-over-T", "0.2,,0.4", "--out", "never"]),
    ("--pair", ["curet", "--sample", "25", "--pair", "81, ,112"]),
])
def test_an_empty_list_element_is_refused(flag, args, tmp_path):
    # CLI11 alone drops it: "30,,40" read as 30, 40.
    proc = run(*args, cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    line = one_error_line(proc)
    assert f"{flag}: " in line and "empty element" in line, line
    assert not (tmp_path / "never").exists()


def test_control_characters_of_a_file_name_are_escaped_in_text_output(tmp_path):
    # A 16-bit pair without black_level_dn: the result's warnings name each photograph.
    names = []
    for k, theta in enumerate((30.0, 45.0)):
        name = f"cap\x1b[31m{k}\x07"
        core.write_capture(str(tmp_path), "png", stem=name, width=16, height=16, bits=16,
                           theta_i_deg=theta, sigma_over_T=0.3)
        names.append({"image": name + ".png", "theta_i_deg": theta, "exposure_s": 1})
    path = tmp_path / "capture-file.json"
    path.write_text(json.dumps({"roi": {"rect": [2, 2, 12, 12]}, "captures": names}))
    proc = run("measure", path)
    assert proc.returncode == 0, proc.stderr
    out = proc.stdout.decode("utf-8")
    assert "\\x1b[31m0\\x07" in out and "\x1b" not in out and "\x07" not in out, out
    # The JSON keeps the names as they are (escaped by JSON itself).
    doc = json.loads(run("measure", path, "--json").stdout)
    assert doc["captures"][0]["image"].endswith("cap\x1b[31m0\x07.png")
    proc = run("simulate", "capture", "--width", "8", "--height", "8", "--out",
               tmp_path / "out\x1b]0;x\x07")
    assert proc.returncode == 0 and b"\x1b" not in proc.stdout, proc.stdout
    assert b"out\\x1b]0;x\\x07" in proc.stdout
    heights = tmp_path / "h\x1b[31m.x3p"
    assert run("surface", "generate", "--sigma-um", "1", "--T-um", "5", "--nx", "32", "--out",
               heights).returncode == 0
    out = run("surface", "stats", heights).stdout
    assert b"\x1b" not in out and b"h\\x1b[31m.x3p (x3p): " in out, out
