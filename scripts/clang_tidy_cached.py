#!/usr/bin/env python3
"""clang-tidy over translation units, skipping those already found clean with the same input.

Usage: clang_tidy_cached.py BUILD_DIR LOG_FILE UNIT... (environment: JOBS, default 2;
ROUGHSCOPE_TIDY_CACHE, default ${XDG_CACHE_HOME:-~/.cache}/roughscope-clang-tidy; "off" disables it)

clang-tidy is deterministic: for the same configuration, the same clang-tidy and the same source
text it gives the same diagnostics. The key of a unit is the SHA-256 of
  - `clang-tidy --version` and the extra arguments,
  - the .clang-tidy file,
  - the unit's compile command without its paths and without -Werror (flags and defines),
  - the unit's preprocessed text *with comments kept* (`-E -P -C`): every header it includes (the
    project's headers, which clang-tidy also checks, and the libraries'), and every NOLINT comment.
A unit is checked unless its key is in the cache; a unit found clean adds its key. A unit with a
diagnostic is never cached, so the log always lists every problem. The cache lives outside the
clone, so a fresh clone on the same machine (CI) re-checks only what changed.

Time budget (ROUGHSCOPE_TIDY_SECONDS, default: none). With an empty cache (a new machine) every
unit is unchecked and clang-tidy on all of them takes longer than CI's budget. Given a budget,
the unchecked units are ordered — first those whose source, or header of the same name, changed
in the last ROUGHSCOPE_TIDY_RECENT_COMMITS commits (default 30), then the rest in an order that
rotates from day to day — and no unit is started once the budget is spent. The units left for a
later run are listed; they stay unchecked (not cached), so the next run takes them up, and every
unit is checked within a few runs. A warm cache leaves only what changed, within budget.
"""
import concurrent.futures
import datetime
import hashlib
import json
import os
import shlex
import subprocess
import sys
import threading
import time
import zlib
from pathlib import Path

EXTRA_ARGS = ["-extra-arg=-Wno-unknown-pragmas"]


def cache_dir() -> Path | None:
    setting = os.environ.get("ROUGHSCOPE_TIDY_CACHE", "")
    if setting == "off":
        return None
    if setting:
        return Path(setting)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "roughscope-clang-tidy"


def preprocess_command(entry: dict) -> list[str]:
    args = entry.get("arguments") or shlex.split(entry["command"])
    out: list[str] = []
    skip = False
    for arg in args:
        if skip:
            skip = False
            continue
        if arg in ("-o", "-c"):
            skip = arg == "-o"
            continue
        if arg == entry["file"] or arg.endswith(".cpp"):
            continue
        out.append(arg)
    return out + ["-E", "-P", "-C", entry["file"]]


def flags_without_paths(entry: dict) -> str:
    """The compile flags that can change clang-tidy's findings. -Werror is left out: it turns a
    warning into an error, and a unit with either is never cached, so a unit found clean without it
    (make lint) is clean with it (CI, ROUGHSCOPE_WERROR=ON) and shares the key."""
    args = entry.get("arguments") or shlex.split(entry["command"])
    return " ".join(a for a in args[1:]
                    if not a.startswith(("-I", "/", "-o")) and "/" not in a and a != "-Werror")


def unit_key(entry: dict, common: bytes) -> str | None:
    result = subprocess.run(preprocess_command(entry), cwd=entry["directory"],
                            capture_output=True, check=False)
    if result.returncode != 0:
        return None  # let clang-tidy report it
    digest = hashlib.sha256(common)
    digest.update(flags_without_paths(entry).encode())
    digest.update(result.stdout)
    return digest.hexdigest()


def run_tidy(build: str, unit: str) -> tuple[int, str]:
    result = subprocess.run(["clang-tidy", "-quiet", "-p", build, *EXTRA_ARGS, unit],
                            capture_output=True, text=True, check=False)
    return result.returncode, result.stdout + result.stderr


def recently_changed(commits: int) -> set[str]:
    """Resolved paths of the files changed in the last `commits` commits (empty outside git)."""
    result = subprocess.run(["git", "log", f"-{commits}", "--name-only", "--format="],
                            capture_output=True, text=True, check=False)
    if result.returncode != 0:
        return set()
    return {str(Path(line).resolve()) for line in result.stdout.splitlines() if line.strip()}


def touched(unit: str, changed: set[str]) -> bool:
    """The unit's source, or the public header of the same name, is among `changed`."""
    path = Path(unit)
    root = path.parents[1] if path.parent.parent.name in ("src",) else path.parents[0]
    header = root.parent / "include" / "roughscope" / path.parent.name / (path.stem + ".hpp")
    return unit in changed or str(header) in changed


def priority_order(units: list[str], changed: set[str]) -> list[str]:
    """Recently changed units first, then the others in an order that rotates daily."""
    day = datetime.date.today().toordinal()

    def rotation(unit: str) -> int:
        return zlib.crc32(f"{day}:{Path(unit).name}".encode())

    return sorted(units, key=lambda u: (not touched(u, changed), rotation(u)))


def run_with_budget(pool, build: str, todo: list[str], seconds: float | None):
    """clang-tidy on the units in order; none is started once `seconds` are spent (None: no
    budget)."""
    start = time.monotonic()
    lock = threading.Lock()
    skipped: list[str] = []

    def job(unit: str):
        if seconds is not None and time.monotonic() - start > seconds:
            with lock:
                skipped.append(unit)
            return None
        return run_tidy(build, unit)

    results = {u: r for u, r in zip(todo, pool.map(job, todo)) if r is not None}
    return results, [u for u in todo if u in skipped]


def main() -> int:
    build, log_path, units = sys.argv[1], sys.argv[2], [str(Path(u).resolve()) for u in sys.argv[3:]]
    jobs = int(os.environ.get("JOBS", "2"))
    database = {str(Path(e["file"]).resolve()): e
                for e in json.loads(Path(build, "compile_commands.json").read_text())}
    version = subprocess.run(["clang-tidy", "--version"], capture_output=True, text=True,
                             check=True).stdout
    common = (version + " ".join(EXTRA_ARGS)).encode() + Path(".clang-tidy").read_bytes()
    cache = cache_dir()
    if cache is not None:
        cache.mkdir(parents=True, exist_ok=True)

    missing = [u for u in units if u not in database]
    if missing:
        print("lint: not in the compile database: " + " ".join(missing), file=sys.stderr)
        return 1

    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        keys = dict(zip(units, pool.map(
            lambda u: unit_key(database[u], common) if cache is not None else None, units)))
        todo = [u for u in units if keys[u] is None or not (cache / keys[u]).exists()]
        budget = os.environ.get("ROUGHSCOPE_TIDY_SECONDS")
        seconds = float(budget) if budget else None
        changed: set[str] = set()
        if seconds is not None:
            recent = int(os.environ.get("ROUGHSCOPE_TIDY_RECENT_COMMITS", "30"))
            changed = recently_changed(recent)
            todo = priority_order(todo, changed)
        print(f"lint: clang-tidy on {len(todo)} of {len(units)} translation units "
              f"({len(units) - len(todo)} unchanged since found clean"
              + (f"; time budget {seconds:.0f} s" if seconds is not None else "") + ")", flush=True)
        results, deferred = run_with_budget(pool, build, todo, seconds)
        todo = [u for u in todo if u in results]
        if deferred:
            root = str(Path.cwd()) + "/"
            print(f"lint: time budget spent; {len(deferred)} units left for a later run: " + " ".join(u.replace(root, "") for u in deferred), flush=True)

    failed = []
    with open(log_path, "w", encoding="utf-8") as log:
        for unit in todo:
            code, text = results[unit]
            log.write(f"== {unit} (exit {code})\n{text}\n")
            if code != 0 or "warning:" in text or "error:" in text:
                failed.append(unit)
            elif keys[unit] is not None:
                (cache / keys[unit]).touch()
    if failed:
        print("lint: clang-tidy found problems in: " + " ".join(failed), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
