"""Every `roughscope ...` command shown in README.md and docs/*.md runs as documented.

The commands are extracted from the fenced code blocks of the Markdown files (one test per
command, named FILE:LINE) and run with the built executable ($ROUGHSCOPE_CLI) through bash, from
a fresh temporary directory, so that an example cannot depend on the project's working tree:

* A command line starts with `roughscope` (optionally after `VAR=value` assignments); in a block
  that shows a terminal session (any line starting with `$ `) only the `$ ` lines are commands
  and the other lines are their output. A line ending with `\\` continues on the next line.
  Pipes and redirections work as in a shell (bash, pipefail).
* The command must exit 0, unless a trailing comment gives the expected code: `# exit 3`. A
  non-zero code must come with the one-line `roughscope: error: ...` message.
* Example input files are in docs/examples/ and are named by their path from the project root
  (`docs/examples/measurements.csv`); the temporary directory holds a copy of that folder.
  Outputs go to the temporary directory.
* `paper tables` and `curet` without `--reference`, `--table` or `--data` read the shared
  reference data (io/data_locator.hpp): ROUGHSCOPE_SHARED_DIR is set to the shared folder when it
  is found, and the command is skipped when it is not (a failure under
  ROUGHSCOPE_REQUIRE_SHARED_DATA=1).
"""

import os
import pathlib
import re
import shlex
import shutil
import subprocess
import sys

import pytest

from conftest import CURET_DIR, PAPER_TABLES, REPO_ROOT, cli_path, need_shared

pytestmark = pytest.mark.cli

DOC_FILES = [REPO_ROOT / "README.md", *sorted((REPO_ROOT / "docs").glob("**/*.md"))]
EXAMPLES_DIR = REPO_ROOT / "docs" / "examples"

FENCE = re.compile(r"^\s{0,3}(```+|~~~+)")
COMMAND = re.compile(r"^(?:[A-Za-z_][A-Za-z0-9_]*=\S*\s+)*roughscope(?:\s|$)")
EXPECTED_EXIT = re.compile(r"\s#\s*exit\s+(\d+)\s*$")


def extract_commands(text):
    """[(line, command, expected_exit)] from the fenced code blocks of a Markdown text."""
    commands = []
    block, fence = None, None
    for number, line in enumerate(text.splitlines(), start=1):
        match = FENCE.match(line)
        if match:
            if fence is None:
                fence, block = match.group(1), []
            elif match.group(1).startswith(fence):
                commands.extend(_block_commands(block))
                fence, block = None, None
            continue
        if fence is not None:
            block.append((number, line))
    return commands


def _block_commands(block):
    session = any(line.lstrip().startswith("$ ") for _, line in block)
    commands = []
    k = 0
    while k < len(block):
        number, line = block[k]
        k += 1
        text = line.strip()
        if session:
            if not text.startswith("$ "):
                continue
            text = text[2:].strip()
        if not COMMAND.match(text):
            continue
        while text.endswith("\\") and k < len(block):
            text = text[:-1].rstrip() + " " + block[k][1].strip()
            k += 1
        expected = 0
        match = EXPECTED_EXIT.search(text)
        if match:
            expected = int(match.group(1))
        text = re.sub(r"\s#.*$", "", text).strip()  # drop the trailing comment
        commands.append((number, text, expected))
    return commands


def documented_commands():
    params = []
    for path in DOC_FILES:
        rel = path.relative_to(REPO_ROOT).as_posix()
        for line, command, expected in extract_commands(path.read_text(encoding="utf-8")):
            params.append(pytest.param(rel, command, expected, id=f"{rel}:{line}"))
    return params


def shared_data_needed(command):
    """'paper', 'curet' or None: the shared data a command reads through the locator."""
    words = shlex.split(command, comments=True)
    if "roughscope" not in words:
        return None
    args = words[words.index("roughscope") + 1:]
    if args[:2] == ["paper", "tables"] and "--reference" not in args:
        return "paper"
    if args[:1] == ["curet"] and not {"--table", "--data", "--help", "-h"} & set(args):
        return "curet"
    return None


def shared_dir():
    """The shared folder the library found (None when absent)."""
    if os.environ.get("ROUGHSCOPE_SHARED_DIR"):
        return os.environ["ROUGHSCOPE_SHARED_DIR"]
    for found in (PAPER_TABLES, CURET_DIR):  # <shared>/reference/..., <shared>/data/curet
        if found is not None:
            return str(pathlib.Path(found).resolve().parents[1])
    return None


def run_documented(command, workdir):
    """Runs `command` with bash in `workdir`, `roughscope` being the built executable."""
    bindir = workdir / ".bin"
    bindir.mkdir()
    (bindir / "roughscope").symlink_to(cli_path())
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join([str(bindir), os.path.dirname(sys.executable),
                                   env.get("PATH", "")])
    # The package under test for `python3 -m roughscope...` in pipelines, as absolute paths.
    env["PYTHONPATH"] = os.pathsep.join(str(pathlib.Path(p).resolve()) for p in sys.path if p)
    env.setdefault("MPLBACKEND", "Agg")
    env.pop("ROUGHSCOPE_SHARED_DIR", None)
    shared = shared_dir()
    if shared is not None:
        env["ROUGHSCOPE_SHARED_DIR"] = shared
    return subprocess.run(["bash", "-o", "pipefail", "-c", command], cwd=workdir, env=env,
                          capture_output=True, text=True, timeout=900)


@pytest.mark.parametrize("doc, command, expected_exit", documented_commands())
def test_documented_command_runs(doc, command, expected_exit, tmp_path):
    needed = shared_data_needed(command)
    if needed == "paper":
        need_shared(PAPER_TABLES, "reference/paper-tables.json")
    elif needed == "curet":
        need_shared(CURET_DIR, "data/curet")
    workdir = tmp_path / "cwd"
    workdir.mkdir()
    if EXAMPLES_DIR.is_dir():
        shutil.copytree(EXAMPLES_DIR, workdir / "docs" / "examples")
    proc = run_documented(command, workdir)
    assert proc.returncode == expected_exit, (
        f"{doc}: `{command}` exited {proc.returncode}, documented {expected_exit}\n"
        f"stderr: {proc.stderr[-3000:]}")
    if expected_exit != 0:
        assert "roughscope: error: " in proc.stderr, proc.stderr


# ---------------------------------------------------------------------------------------------
# The extraction itself (so that a change to it cannot silently drop every command).

def test_extract_commands_follows_the_conventions():
    text = "\n".join([
        "Text `roughscope model` in prose is not a command.",
        "```sh",
        "roughscope model --retro 30 \\",
        "    --sigma-over-T 0.5          # Eq. 9",
        "python3 -m roughscope.plot curet --out fig.png",
        "ROUGHSCOPE_PYTHON=/opt/none roughscope curet --sample 25   # exit 4",
        "```",
        "```text",
        "$ roughscope estimate slope --ratio 1.0 --theta1 30 --theta2 45   # exit 3",
        "roughscope: error: no solution",
        "roughscope 0.1.0",
        "```",
    ])
    assert extract_commands(text) == [
        (3, "roughscope model --retro 30 --sigma-over-T 0.5", 0),
        (6, "ROUGHSCOPE_PYTHON=/opt/none roughscope curet --sample 25", 4),
        (9, "roughscope estimate slope --ratio 1.0 --theta1 30 --theta2 45", 3),
    ]


def test_extract_commands_ignores_text_outside_code_blocks():
    assert extract_commands("roughscope model --retro 30\n    roughscope --help\n") == []


def test_shared_data_needed():
    assert shared_data_needed("roughscope paper tables --json") == "paper"
    assert shared_data_needed("roughscope paper tables --reference t.json") is None
    assert shared_data_needed("roughscope curet --sample 25 | python3 -m x") == "curet"
    assert shared_data_needed("roughscope curet --table docs/examples/brdf.csv") is None
    assert shared_data_needed("roughscope model --retro 30 --sigma-over-T 0.5") is None


def test_readme_and_cli_guide_show_commands():
    found = {p.values[0] for p in documented_commands()}
    assert {"README.md", "docs/cli.md", "docs/estimation.md", "docs/curet.md"} <= found


def test_a_wrong_documented_exit_code_fails(tmp_path):
    proc = run_documented("roughscope model --retro 95 --sigma-over-T 0.5", tmp_path)
    assert proc.returncode == 2
    assert proc.stderr.startswith("roughscope: error: ")
