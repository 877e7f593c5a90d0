"""Figures from result documents: the one entry point the command line uses to draw.

Command line (``roughscope curet --plot FILE.png`` runs exactly this, feeding the document
through a pipe)::

    roughscope curet --sample 25 --json --series | python3 -m roughscope.plot curet --out fig10.png
    roughscope curet --all --json | python3 -m roughscope.plot curet --out summary.png

The comparison document is read from standard input as JSON: one comparison (an object with its
``series``) draws the paper's Fig. 10, a list of comparisons the database summary. On success
nothing is printed and the exit status is 0. On failure one line
``roughscope.plot: error: <message>`` goes to standard error and the exit status is 1; no file
is left behind (figures are written atomically).

From Python, :func:`curet` takes the document (a dict or a list of dicts, e.g. from
``roughscope.curet.compare``) and the output path and raises on error.
"""

import argparse
import json
import os
import sys

__all__ = ["curet", "surface", "main"]


def curet(document, out):
    """Draw a CUReT comparison: Fig. 10 for one comparison (dict with 'series'), the summary for
    a list. Returns the path written. Raises ValueError for a document of the wrong shape and
    OSError when `out` cannot be written."""
    from . import curet_figures

    out = os.fspath(out)
    directory = os.path.dirname(os.path.abspath(out))
    if not os.path.isdir(directory):
        raise FileNotFoundError(f"cannot write {out}: directory {directory} does not exist")
    if not os.access(directory, os.W_OK):
        raise PermissionError(f"cannot write {out}: directory {directory} is not writable")
    if isinstance(document, list):
        if not document:
            raise ValueError("the comparison list is empty: nothing to draw")
        return curet_figures.summary(document, out)
    if not isinstance(document, dict):
        raise ValueError(f"expected a comparison object or a list of them, got "
                         f"{type(document).__name__}")
    if "series" not in document:
        raise ValueError("the comparison has no 'series' (produce it with "
                         "`roughscope curet --json --series`)")
    return curet_figures.fig10(document, out)


def surface(document, out):
    """Draw the height-data figure (height image, ACF with the fitted curves and the 1/e line,
    PSD) from a statistics document with 'curves' and 'image' (``roughscope surface stats FILE
    --plot OUT.png``). Returns the path written; ValueError for a document of the wrong shape."""
    from . import surface_figures

    out = os.fspath(out)
    directory = os.path.dirname(os.path.abspath(out))
    if not os.path.isdir(directory):
        raise FileNotFoundError(f"cannot write {out}: directory {directory} does not exist")
    return surface_figures.stats_figure(document, out)


def main(argv=None, stdin=None):
    parser = argparse.ArgumentParser(prog="python3 -m roughscope.plot",
                                     description="Draw a figure from a result document on "
                                                 "standard input (JSON).")
    sub = parser.add_subparsers(dest="kind", required=True)
    p = sub.add_parser("curet", help="CUReT comparison: Fig. 10 (one sample) or the summary")
    p.add_argument("--out", required=True, help="PNG file to write")
    p = sub.add_parser("surface", help="height data: image, ACF with fits and 1/e line, PSD")
    p.add_argument("--out", required=True, help="PNG file to write")
    args = parser.parse_args(argv)
    stream = sys.stdin if stdin is None else stdin
    try:
        try:
            document = json.load(stream)
        except json.JSONDecodeError as e:
            raise ValueError(f"standard input is not a JSON document ({e})") from None
        (surface if args.kind == "surface" else curet)(document, args.out)
    except Exception as e:  # one line for the caller (the CLI shows it)
        message = " ".join(str(e).split()) or type(e).__name__
        print(f"roughscope.plot: error: {message}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
