"""Figures of the CUReT comparison (paper §5.3): Fig. 10 and a database-wide summary.

Fig. 10: normalised brightness of each model (solid) and the data (dashed) against the
measurement index sorted by increasing measured value, one panel per model.

Inputs are the comparison documents of ``roughscope curet --json --series`` (one sample) and
``roughscope curet --all --json`` (a list), or the dicts of ``roughscope.curet.compare``. The
command-line entry point (used by ``roughscope curet --plot FILE.png``) is
``python3 -m roughscope.plot curet --out FILE.png`` (roughscope/plot.py). Figures are written
atomically (temporary file, then rename). matplotlib is imported only here.
"""

import numpy as np

from ._plotting import pyplot, save
from .curet import LABELS, MODELS, PAPER_MODELS


def _title(result):
    if result.get("sample"):
        name = result.get("name") or ""
        return f"CUReT sample {result['sample']}" + (
            f" ({name})" if name and not name.startswith("CUReT") else "")
    return result.get("name") or "BRDF table"


def sorted_series(result, model, gain=False):
    """(data, model) brightness sorted by increasing measured value, or None when the model is
    unavailable. Both are divided by their maxima (the paper's Fig. 10), or with gain=True the
    model is scaled by the optimal gain instead (what the least-squares fits minimise)."""
    series = result.get("series")
    if not series:
        raise ValueError("the comparison has no 'series' (compute it with series=True)")
    data = np.asarray(series["data"], float)
    pred = series["models_gain" if gain else "models"].get(model)
    if pred is None:
        return None
    order = np.argsort(data, kind="stable")
    return data[order], np.asarray(pred, float)[order]


def draw_fig10_panel(ax, result, model, show_error=True, gain=False):
    """One Fig. 10 panel: data dashed, model solid, index sorted by increasing data."""
    s = sorted_series(result, model, gain)
    label = LABELS.get(model, model)
    if s is None:
        reason = result["models"][model].get("reason") or "unavailable"
        ax.text(0.5, 0.5, f"{label}: unavailable\n" + _wrap(reason, 40), ha="center",
                va="center", fontsize=7, transform=ax.transAxes)
        ax.set_xticks([])
        ax.set_yticks([])
        return
    data, pred = s
    idx = np.arange(1, data.size + 1)
    ax.plot(idx, pred, "-", color="C0", lw=1.0, label=label)
    ax.plot(idx, data, "--", color="k", lw=1.0, label="data")
    ax.set_ylim(-0.05, max(1.05, float(np.max(pred)) * 1.05))
    ax.set_xlim(0, data.size + 1)
    text = label
    if show_error:
        key, name = ("sse_gain", "SSE") if gain else ("sse", "Table-4 error")
        err = result[key].get(model)
        if err is not None:
            text += f"  ({name} {err:.3f})"
    ax.set_title(text, fontsize=8)
    ax.tick_params(labelsize=7)


def _wrap(text, width):
    words, lines, line = text.split(), [], ""
    for w in words:
        if len(line) + len(w) + 1 > width:
            lines.append(line)
            line = w
        else:
            line = (line + " " + w).strip()
    lines.append(line)
    return "\n".join(lines[:6])


def fig10(result, path, models=PAPER_MODELS, gain=False):
    """Fig. 10 for one comparison (dict with 'series'): one panel per model. gain=True plots each
    model times its optimal gain instead of divided by its maximum."""
    plt = pyplot()
    n = len(models)
    cols = 3 if n > 4 else n
    rows = int(np.ceil(n / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(3.2 * cols, 2.4 * rows), squeeze=False,
                             dpi=110)
    for k, model in enumerate(models):
        draw_fig10_panel(axes[k // cols][k % cols], result, model, gain=gain)
    for k in range(n, rows * cols):
        axes[k // cols][k % cols].axis("off")
    for ax in axes[-1]:
        ax.set_xlabel("data index (sorted by measured brightness)", fontsize=7)
    for row in axes:
        row[0].set_ylabel("normalised brightness", fontsize=7)
    fig.suptitle(_title(result) + ": data (dashed) and models (solid"
                 + (", times the optimal gain)" if gain else ", divided by their maxima)"),
                 fontsize=9)
    fig.tight_layout()
    save(fig, path)
    plt.close(fig)
    return path


def fig10_paper_layout(results, path, models=PAPER_MODELS):
    """The paper's Fig. 10 layout: one row per model, one column per sample."""
    plt = pyplot()
    rows, cols = len(models), len(results)
    fig, axes = plt.subplots(rows, cols, figsize=(3.2 * cols, 1.9 * rows), squeeze=False,
                             dpi=110, sharex=True)
    for c, result in enumerate(results):
        for r, model in enumerate(models):
            draw_fig10_panel(axes[r][c], result, model)
        axes[0][c].set_title(_title(result) + "\n" + axes[0][c].get_title(), fontsize=8)
        axes[-1][c].set_xlabel("data index (sorted)", fontsize=7)
    for r in range(rows):
        axes[r][0].set_ylabel("normalised", fontsize=7)
    fig.tight_layout()
    save(fig, path)
    plt.close(fig)
    return path


def summary(results, path):
    """Database-wide summary: how often each model wins (by the Table-4 metric among the paper's
    methods, and by the gain-optimal SSE with the fits) and the distribution of each error."""
    plt = pyplot()
    fig, axes = plt.subplots(2, 2, figsize=(12, 8), dpi=100)

    def counts(key, candidates):
        c = {m: 0 for m in candidates}
        for r in results:
            w = r.get(key)
            if w in c:
                c[w] += 1
        return c

    for ax, key, candidates, title in (
        (axes[0][0], "winner_paper_metric", PAPER_MODELS,
         "Winner by the paper's Table-4 error (paper's methods)"),
        (axes[0][1], "winner", MODELS, "Winner by the SSE after the optimal gain (fits included)"),
    ):
        c = counts(key, candidates)
        labels = [LABELS[m] for m in candidates]
        ax.bar(range(len(candidates)), [c[m] for m in candidates], color="C0")
        ax.set_xticks(range(len(candidates)))
        ax.set_xticklabels(labels, rotation=45, ha="right", fontsize=8)
        ax.set_ylabel("samples")
        ax.set_title(title + f" ({len(results)} samples)", fontsize=9)

    for ax, key, candidates, title in (
        (axes[1][0], "sse", PAPER_MODELS, "Table-4 error per sample (paper's methods)"),
        (axes[1][1], "sse_gain", MODELS, "SSE after the optimal gain per sample"),
    ):
        data, labels = [], []
        for m in candidates:
            v = [r[key][m] for r in results if r[key].get(m) is not None]
            data.append(v if v else [np.nan])
            labels.append(f"{LABELS[m]}\n(n={len(v)})")
        ax.boxplot(data, showfliers=True)
        ax.set_xticks(range(1, len(candidates) + 1))
        ax.set_xticklabels(labels, rotation=45, ha="right", fontsize=7)
        ax.set_yscale("log")
        ax.set_title(title, fontsize=9)
    fig.suptitle("CUReT: models against the measured BRDFs of every sample", fontsize=10)
    fig.tight_layout()
    save(fig, path)
    plt.close(fig)
    return path
