"""The library's structure as docs/architecture.md states it: the umbrella header includes every
public header, each topic includes only the topics below it, and no source file or function is
over the size limits (scripts/code_size.py)."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
INCLUDE = ROOT / "include" / "roughscope"

# The direction of dependency (docs/architecture.md): the project headers a topic's sources and
# public headers may include, besides its own.
ALLOWED = {
    "core": set(),
    "io": {"core"},
    "scattering": {"core"},
    "estimation": {"core", "scattering"},
    "fit": {"core", "scattering", "estimation"},
    "brdf": {"core", "io", "scattering", "estimation", "fit"},
    "surface": {"core", "io", "scattering"},
    "simulation": {"core", "io", "scattering", "surface"},
    "photo": {"core", "io"},
    "region": {"core", "io", "photo"},
    "maps": {"core", "io", "photo", "scattering", "estimation", "surface"},
    "objects": {"core", "io", "photo", "scattering", "estimation", "fit", "brdf"},
    "measure": {"core", "io", "scattering", "estimation", "fit", "brdf", "surface", "photo", "region",
                "maps", "objects"},
}
ALLOWED["serialize"] = set(ALLOWED) - {"serialize"}

# Over the limits (file: lines; file:function): none. An entry must still be over, so that the
# list only shrinks if one is ever added.
KNOWN_OVER: set[str] = set()

INCLUDE_RE = re.compile(r'^\s*#\s*include\s*[<"](?:roughscope/)?([a-z_]+)/[a-z_0-9]+\.hpp[>"]', re.M)


def public_headers() -> list[str]:
    return sorted(str(p.relative_to(INCLUDE.parent)) for p in INCLUDE.glob("*/*.hpp"))


def test_umbrella_header_includes_every_public_header():
    umbrella = (INCLUDE / "roughscope.hpp").read_text(encoding="utf-8")
    included = set(re.findall(r'#include "(roughscope/[a-z_]+/[a-z_0-9]+\.hpp)"', umbrella))
    headers = public_headers()
    assert len(headers) > 50
    missing = [h for h in headers if h not in included]
    assert not missing, f"roughscope/roughscope.hpp does not include {missing}"
    stale = sorted(included - set(headers))
    assert not stale, f"roughscope/roughscope.hpp includes headers that do not exist: {stale}"


def test_every_topic_has_its_allowed_dependencies():
    topics = sorted(p.name for p in INCLUDE.iterdir() if p.is_dir())
    assert topics == sorted(ALLOWED), "a topic folder without a rule in ALLOWED (or a rule without a folder)"


@pytest.mark.parametrize("topic", sorted(ALLOWED))
def test_topic_includes_only_the_topics_below_it(topic):
    files = [*(ROOT / "src" / topic).glob("*.[ch]pp"), *(INCLUDE / topic).glob("*.hpp")]
    assert files, f"no sources for topic {topic}"
    wrong = []
    for f in files:
        for used in INCLUDE_RE.findall(f.read_text(encoding="utf-8")):

            # Only the project's topics (not <nlohmann/json.hpp>, roughscope/version.hpp).
            if used in ALLOWED and used != topic and used not in ALLOWED[topic]:
                wrong.append(f"{f.relative_to(ROOT)} includes {used}")
    assert not wrong, "\n".join(wrong)


def over_limits() -> set[str]:
    out = subprocess.run([sys.executable, str(ROOT / "scripts" / "code_size.py"), "src", "cli", "python",
                          "include"], cwd=ROOT, capture_output=True, text=True, check=False)
    assert out.returncode in (0, 1), out.stderr
    found = set()
    for line in out.stdout.splitlines():
        m = re.match(r"^(\S+?):(\d+): (\S+): \d+ lines", line)
        if m:
            found.add(f"{m.group(1)}:{m.group(3)}")
            continue
        m = re.match(r"^(\S+): \d+ lines", line)
        assert m, line
        found.add(m.group(1))
    return found


def test_no_new_file_or_function_over_the_size_limits():
    found = over_limits()
    new = sorted(found - KNOWN_OVER)
    assert not new, f"over the limits (1,000 lines per file, 200 per function): {new}"
    fixed = sorted(KNOWN_OVER - found)
    assert not fixed, f"no longer over the limits, remove from KNOWN_OVER: {fixed}"


def test_size_scan_finds_a_long_function(tmp_path):
    body = "\n".join(f"    x += {i};" for i in range(250))
    src = tmp_path / "long.cpp"
    src.write_text(f"namespace a {{\nint long_one(int x) {{\n{body}\n    return x;\n}}\n"
                   "int short_one() { return 1; }\n}\n", encoding="utf-8")
    out = subprocess.run([sys.executable, str(ROOT / "scripts" / "code_size.py"), str(src)],
                         capture_output=True, text=True, check=False)
    assert out.returncode == 1
    assert "long_one: 253 lines (limit 200)" in out.stdout
    assert "short_one" not in out.stdout
