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
"""
import concurrent.futures
import hashlib
import json
import os
import shlex
import subprocess
import sys
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
        print(f"lint: clang-tidy on {len(todo)} of {len(units)} translation units "
              f"({len(units) - len(todo)} unchanged since found clean)", flush=True)
        results = dict(zip(todo, pool.map(lambda u: run_tidy(build, u), todo)))

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
