"""The HTML pieces every report page is made of: escaping, number formatting, images, the style
sheet and the page writer.

Used by :mod:`roughscope.report` (the report of ``make demo``), :mod:`roughscope.report_measure`
(the page of ``roughscope measure --report``) and the section modules; nothing here computes a
value, it only shows one.
"""

import base64
import contextlib
import html
import os
import pathlib
import tempfile

#: What a missing value (None) is shown as.
MISSING = "–"

CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", sans-serif; max-width: 1100px;
       margin: 2em auto; padding: 0 1em; color: #1d1d1f; line-height: 1.45; }
h1 { margin-bottom: 0.1em; } h2 { border-bottom: 1px solid #ccc; padding-bottom: 0.2em;
       margin-top: 2em; }
.meta { color: #666; margin-top: 0; }
figure { margin: 1.2em 0; } figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { font-size: 0.92em; color: #444; }
table { border-collapse: collapse; margin: 1em 0; font-size: 0.92em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: right; }
th { background: #f3f3f3; } td.l, th.l { text-align: left; }
.pass { color: #0a7d2c; font-weight: 600; } .fail { color: #b00020; font-weight: 600; }
code { background: #f3f3f3; padding: 0 0.2em; }
"""


def escape(text):
    """`text` (any object, shown by str) with &, <, >, " and ' escaped for HTML."""
    return html.escape(str(text))


def number(value, spec=".4g", missing=MISSING):
    """`value` formatted with the format spec `spec`; `missing` for None."""
    return missing if value is None else format(value, spec)


def fmt(value, err=None, digits=4, decimals=None):
    """"value ± error": `digits` significant digits of the value and two of a positive standard
    error (left out when it is None or 0), or with `decimals` both to that many decimal places;
    "–" for a missing value."""
    if value is None:
        return MISSING
    if decimals is None:
        text, err_spec = f"{value:.{digits}g}", ".2g"
    else:
        text, err_spec = f"{value:.{decimals}f}", f".{decimals}f"
    if err is not None and err > 0:
        text += f" ± {err:{err_spec}}"
    return text


def quantity(value, unit=""):
    """A value of a table with its unit: 4 significant digits, a string escaped, "–" for None."""
    if value is None:
        return MISSING
    if isinstance(value, str):
        return escape(value)
    return f"{value:.4g}" + (f" {unit}" if unit else "")


def relative_difference(value, reference):
    """(value − reference)/reference in per cent, signed, 3 decimals; "—" without a reference."""
    if value is None or reference in (None, 0):
        return "—"
    return f"{100.0 * (value - reference) / reference:+.3f} %"


def verdict(good):
    """A coloured yes/no mark."""
    return f"<span class='{'pass' if good else 'fail'}'>{'yes' if good else 'no'}</span>"


def within_two_sigma(value, err, truth):
    """The yes/no mark of |value − truth| <= 2 err, or "" when one of them is unknown."""
    if truth is None or value is None or not err:
        return ""
    return verdict(abs(value - truth) <= 2 * err)


def embedded_image(png, alt):
    """An <img> holding the PNG bytes `png` as a data URI (a page that needs no other file)."""
    data = base64.b64encode(png).decode("ascii")
    return f'<img src="data:image/png;base64,{data}" alt="{escape(alt)}">'


def linked_figure(name, alt, caption):
    """A <figure> showing the image file `name` (beside the page) with its caption (HTML)."""
    return (f"<figure><img src='{escape(name)}' alt='{escape(alt)}'><figcaption>{caption}"
            "</figcaption></figure>")


_PAGE = """<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title}</title>
<style>{css}</style>
</head>
<body>
<h1>{title}</h1>
<p class="meta">{meta}</p>
{body}
</body>
</html>
"""


def page_html(body, title, meta):
    """The complete page: `title` (text) as title and heading, `meta` (HTML) under it, `body`
    (HTML), the style sheet inline."""
    return _PAGE.format(title=escape(title), css=CSS, meta=meta, body=body)


def prepare_folder(out):
    """`out` as a folder for index.html: created when missing (with its parents); an error
    naming the path when it exists and is not a folder."""
    out = pathlib.Path(out)
    if out.exists() and not out.is_dir():
        raise NotADirectoryError(f"cannot write the report to {out}: it is not a folder")
    out.mkdir(parents=True, exist_ok=True)
    return out


def write_text_atomically(path, text):
    """Write `path` as a temporary file beside it renamed over it (mode 0644): a reader sees the
    old file or the new one, never a part."""
    path = pathlib.Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.tmp-", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return path


def write_page(out, page):
    """Write the page `page` (text) as out/index.html atomically and nothing else: nothing
    already in `out` is removed or changed; `out` (or a symbolic link to a folder) is created
    when missing. A path that exists and is not a folder is an error."""
    return write_text_atomically(prepare_folder(out) / "index.html", page)


def one_line_error(exc):
    """A one-line message for `exc`: an OSError as "<path>: <reason>" (no Python reprs)."""
    if isinstance(exc, OSError) and exc.strerror and exc.filename is not None:
        reason = exc.strerror[0].lower() + exc.strerror[1:]
        return f"{os.fsdecode(exc.filename)}: {reason}"
    return " ".join(str(exc).split()) or type(exc).__name__
