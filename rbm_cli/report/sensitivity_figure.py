"""The tornado figure of a domain's sensitivity to its uncertain keys (sensitivity.png):
per outcome, a horizontal bar per key, its partial rank correlation coefficient
(rbm_cli.study.sensitivity), the key that moves the peak rotation ratio most on top."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from rbm_cli.study.schema import label

if TYPE_CHECKING:  # matplotlib is imported when a figure is drawn, not with this module
    import pandas as pd
    from matplotlib.figure import Figure

__all__ = ["plot_tornado", "tornado_figure"]


def plot_tornado(table: pd.DataFrame, outcome: str, ax=None):
    """The tornado of one outcome on ``ax`` (a new Figure's when None): a bar per key of
    ``table`` (rbm_cli.study.sensitivity.sensitivity), its PRCC, in the table's order from
    the top; a key with no coefficient is drawn as none and says so. Returns the axes."""
    if ax is None:
        # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
        from matplotlib.figure import Figure

        ax = Figure(figsize=(6.0, 3.0)).add_subplot()
    rows = table[table["outcome"] == outcome]
    keys = list(rows["key"])
    values = [float(v) for v in rows["prcc"]]
    y = list(range(len(keys)))[::-1]
    shown = [0.0 if math.isnan(v) else v for v in values]
    colors = ["tab:red" if v > 0 else "tab:blue" for v in shown]
    ax.barh(y, shown, color=colors, height=0.6)
    for yi, v in zip(y, values, strict=True):
        text = "n/a" if math.isnan(v) else f"{v:+.2f}"
        ax.text(0.02 if v <= 0 or math.isnan(v) else -0.02, yi, text, va="center",
                ha="left" if v <= 0 or math.isnan(v) else "right", fontsize=8)  # fmt: skip
    ax.set_yticks(y, keys)
    ax.set_xlim(-1.0, 1.0)
    ax.axvline(0.0, color="black", lw=0.8)
    ax.set_xlabel("partial rank correlation coefficient (PRCC) [-]")
    ax.set_title(label(outcome) or outcome, fontsize=10)
    ax.grid(axis="x", alpha=0.3)
    return ax


def tornado_figure(table: pd.DataFrame, title: str = "") -> Figure:
    """sensitivity.png: a tornado per outcome of the table, one above the other."""
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.figure import Figure

    outcomes = list(dict.fromkeys(table["outcome"]))
    n_keys = max(1, table["key"].nunique())
    fig = Figure(figsize=(7.5, 1.2 + len(outcomes) * (0.9 + 0.45 * n_keys)), layout="constrained")
    axes = fig.subplots(len(outcomes), 1, squeeze=False)[:, 0]
    for ax, outcome in zip(axes, outcomes, strict=True):
        plot_tornado(table, outcome, ax)
    if title:
        fig.suptitle(title, fontsize=11)
    return fig
