"""One version everywhere, as the command line reports it, and its bash completion.

Every JSON document the CLI writes starts with "roughscope_version" (serialize::versioned), equal
to `roughscope --version`, to roughscope.__version__ and to the project() version of
CMakeLists.txt (the one place it is set). `roughscope completion bash` prints a completion
script generated from the command tree: driven here through bash's own completion variables.
"""
import csv
import json
import pathlib
import re
import shutil
import subprocess

import pytest

import roughscope as rs

from conftest import cli_path, project_version

REPO = pathlib.Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "docs" / "examples" / "measure"



def run(*args, check=True, cwd=None):
    proc = subprocess.run([cli_path(), *map(str, args)], capture_output=True, text=True,
                          timeout=600, cwd=cwd)
    if check:
        assert proc.returncode == 0, f"exit {proc.returncode}: {proc.stderr}"
    return proc


def test_versions_agree():
    version = project_version()
    assert run("--version").stdout.strip() == f"roughscope {version}"
    assert rs.__version__ == version
    changelog = (REPO / "CHANGELOG.md").read_text(encoding="utf-8")
    assert re.search(r"^## \[(\d+\.\d+\.\d+)\]", changelog, re.M).group(1) == version, \
        "CHANGELOG.md's newest entry is not the project's version"


def _measurements(tmp_path):
    import numpy as np

    ti = np.array([10.0, 20, 30, 40, 50, 60])
    b = 2.0 * rs.very_rough_brightness(ti, 0.0 * ti, 0.0 * ti, 0.4)
    path = tmp_path / "m.csv"
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["theta_i", "phi_i", "theta_s", "phi_s", "brightness"])
        for a, v in zip(ti, b):
            w.writerow([repr(float(a)), 180, 0, 0, repr(float(v))])
    return path


def _documents(tmp_path):
    """(command, parsed --json output) for one command of every JSON-writing subcommand."""
    rows = tmp_path / "rows.csv"
    rows.write_text("theta_i,theta_s,phi_s\n30,0,0\n45,10,90\n")
    surface = tmp_path / "s.gsf"
    run("surface", "generate", "--nx", 32, "--ny", 32, "--dx-um", 1, "--T-um", 4, "--seed", 1,
        "--out", surface)
    commands = [
        ["model", "--retro", "30", "--sigma-over-T", "0.2"],
        ["model", "--csv", rows, "--sigma-over-T", "0.2"],
        ["estimate", "specular", "--r-spec", "0.014", "--theta", "14"],
        ["estimate", "fit", "--measurements", _measurements(tmp_path)],
        ["surface", "stats", surface],
        ["simulate", "scatter", "--sigma-um", "0.04", "--T-um", "1", "--wavelength-um", "0.5",
         "--theta-i", "20", "--theta-s", "20", "--phi-s", "0", "--realisations", "10"],
        ["measure", EXAMPLES / "capture-file.json"],
    ]
    for args in commands:
        yield args, json.loads(run(*args, "--json").stdout)


def test_every_json_document_starts_with_the_version(tmp_path):
    version = project_version()
    seen = 0
    for args, doc in _documents(tmp_path):
        records = doc if isinstance(doc, list) else [doc]
        assert records, args
        for record in records:
            assert next(iter(record)) == "roughscope_version", (args, list(record)[:3])
            assert record["roughscope_version"] == version, args
            assert list(record).count("roughscope_version") == 1
        seen += 1
    assert seen == 7


def test_capture_sidecar_carries_the_version(tmp_path):
    run("simulate", "capture", "--width", 32, "--height", 24, "--out", tmp_path / "c")
    sidecar = next((tmp_path / "c").glob("*.json"))
    doc = json.loads(sidecar.read_text())
    assert next(iter(doc)) == "roughscope_version" and doc["roughscope_version"] == project_version()


# ---- bash completion -----------------------------------------------------------------------------

def complete(script, words, cwd):
    """COMPREPLY of the script's completion function for the command line `words` (the last word
    is the one being completed)."""
    bash = shutil.which("bash")
    quoted = " ".join("'" + w.replace("'", "'\\''") + "'" for w in words)
    program = (f"source '{script}'\nCOMP_WORDS=({quoted})\nCOMP_CWORD={len(words) - 1}\n"
               "_roughscope\nprintf '%s\\n' \"${COMPREPLY[@]}\"\n")
    proc = subprocess.run([bash, "--norc", "--noprofile", "-c", program], capture_output=True,
                          text=True, cwd=cwd, timeout=60)
    assert proc.returncode == 0, proc.stderr
    return [line for line in proc.stdout.splitlines() if line]


@pytest.fixture
def script(tmp_path):
    path = tmp_path / "roughscope.bash"
    path.write_text(run("completion", "bash").stdout)
    return path


def test_completion_of_subcommands_and_options(script, tmp_path):
    assert complete(script, ["roughscope", ""], tmp_path) == [
        "model", "estimate", "paper", "curet", "surface", "simulate", "measure", "calibrate",
        "plan", "completion"]
    assert complete(script, ["roughscope", "me"], tmp_path) == ["measure"]
    assert complete(script, ["roughscope", "estimate", "s"], tmp_path) == ["specular", "slope"]
    assert complete(script, ["roughscope", "estimate", "specular", "--r"], tmp_path) == [
        "--r-spec", "--r0"]
    # An option's name is completed from the subcommand given, not from another one.
    assert "--maps" in complete(script, ["roughscope", "measure", "--m"], tmp_path)
    assert complete(script, ["roughscope", "model", "--m"], tmp_path) == ["--model"]


def test_completion_of_values_and_positionals_gives_files(script, tmp_path):
    (tmp_path / "capture-a.json").write_text("{}")
    (tmp_path / "capture-b.json").write_text("{}")
    # measure takes the capture file as a positional; --csv takes a value; --json does not.
    assert sorted(complete(script, ["roughscope", "measure", "capture-"], tmp_path)) == [
        "capture-a.json", "capture-b.json"]
    assert complete(script, ["roughscope", "model", "--csv", "capture-a"], tmp_path) == [
        "capture-a.json"]
    assert complete(script, ["roughscope", "model", "--json", "capture-a"], tmp_path) == []


def test_completion_script_matches_the_installed_one():
    built = pathlib.Path(cli_path()).parents[1] / "share" / "bash-completion" / "completions" / \
        "roughscope"
    if not built.is_file():
        pytest.skip(f"{built} not generated by this build (CLI outside a CMake build folder)")
    assert built.read_text() == run("completion", "bash").stdout


def test_completion_for_an_unknown_shell_is_refused():
    proc = run("completion", "zsh", check=False)
    assert proc.returncode == 2 and proc.stdout == ""
    assert "'zsh'" in proc.stderr and "valid: bash" in proc.stderr
    proc = run("completion", check=False)
    assert proc.returncode != 0 and "shell" in proc.stderr
