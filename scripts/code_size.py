#!/usr/bin/env python3
"""Source files and functions over the project's size limits (DEVELOPERS.md, "Size limits").

Usage: code_size.py [--max-file N] [--max-function N] [--list N] [PATH...]
  PATH: files or folders (default: src cli python include); C++ sources and headers only.
  --list N   also print every function longer than N lines (default: the function limit).
Exit status 1 when a file is longer than --max-file lines (default 1000) or a function body longer
than --max-function lines (default 200); 0 otherwise.

A function is a brace block opened at namespace or class scope after a parameter list (`)`,
optionally followed by qualifiers, a trailing return type or a constructor's initialiser list);
its length is the number of lines from the line of its name to its closing brace. Lambdas, loops
and nested blocks count toward the function that holds them. Comments, strings and character
literals are blanked before braces are counted.
"""
from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

EXTENSIONS = {".cpp", ".hpp", ".h", ".cc"}
CONTROL = re.compile(r"\b(if|for|while|switch|catch|else|do|return)\b\s*(\(|$)")


def strip_code(text: str) -> str:
    """Comments, string and character literals replaced by spaces (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            if m:
                end = text.find(")" + m.group(1) + '"', i)
                j = n if end < 0 else end + len(m.group(1)) + 2
                out.append(re.sub(r"[^\n]", " ", text[i:j]))
                i = j
            else:
                out.append(c)
                i += 1
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum() and text[i + 1 : i + 2].isalnum():
                out.append(" ")  # digit separator 1'000
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(text: str) -> list[tuple[str, int, int]]:
    """(name, first line, last line) of every function body in the text."""
    code = strip_code(text)
    code = re.sub(r"(?m)^\s*#.*$", lambda m: " " * len(m.group(0)), code)
    result = []
    stack: list[str] = []  # "scope" (namespace/class/extern) or "other"
    starts: list[tuple[str, int]] = []
    header_start = 0
    for pos, c in enumerate(code):
        if c in ";":
            if not stack or stack[-1] == "scope":
                header_start = pos + 1
        elif c == "{":
            header = code[header_start:pos]
            if stack and stack[-1] != "scope":
                stack.append("other")
                starts.append(("", 0))
                continue
            compact = " ".join(header.split())
            kind = "other"
            name = ""
            if re.search(r"\b(namespace|class|struct|union|enum)\b[^()]*$", compact) or compact.startswith(
                'extern "'
            ) or compact.endswith("extern"):
                kind = "scope"
            else:
                # strip a trailing initialiser list / qualifiers to find the parameter list
                m = re.search(r"([~\w:<>]+)\s*\((.*)\)\s*(const|noexcept|override|final|mutable|->|:|\s|[\w:<>,&*()\[\]]|\{|\})*$",
                              compact, re.S)
                if m and not CONTROL.search(compact.split("(")[0].split()[-1] if compact.split("(")[0].split() else ""):
                    name = m.group(1)
                    if name not in {"if", "for", "while", "switch", "catch", "return", "sizeof", "decltype"} and "=" not in compact.split("(")[0]:
                        kind = "function"
            if kind == "function":
                first = code.count("\n", 0, header_start + len(header) - len(header.lstrip())) + 1
                stack.append("function")
                starts.append((name, first))
            else:
                stack.append(kind)
                starts.append(("", 0))
            header_start = pos + 1
        elif c == "}":
            if not stack:
                continue
            kind = stack.pop()
            name, first = starts.pop()
            if kind == "function":
                last = code.count("\n", 0, pos) + 1
                result.append((name, first, last))
            if not stack or stack[-1] == "scope":
                header_start = pos + 1
    return result


def sources(paths: list[str]) -> list[Path]:
    out = []
    for p in map(Path, paths):
        if p.is_dir():
            out += sorted(f for f in p.rglob("*") if f.suffix in EXTENSIONS and f.is_file())
        elif p.suffix in EXTENSIONS:
            out.append(p)
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("paths", nargs="*", default=["src", "cli", "python", "include"])
    parser.add_argument("--max-file", type=int, default=1000)
    parser.add_argument("--max-function", type=int, default=200)
    parser.add_argument("--list", type=int, default=None)
    args = parser.parse_args()
    listing = args.max_function if args.list is None else args.list
    failed = False
    for path in sources(args.paths):
        text = path.read_text(encoding="utf-8", errors="replace")
        lines = text.count("\n")
        if lines > args.max_file:
            print(f"{path}: {lines} lines (limit {args.max_file})")
            failed = True
        for name, first, last in functions(text):
            length = last - first + 1
            if length > listing:
                over = length > args.max_function
                failed |= over
                print(f"{path}:{first}: {name}: {length} lines" + (f" (limit {args.max_function})" if over else ""))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
