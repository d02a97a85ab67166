"""The fragility of a suite over samples of uncertain keys, per tercile of one key
(``rbm fragility --by KEY``): fragility_by.png, a fitted curve per third of the key's
sampled values, and fragility_by.csv, the fits (rbm_cli.study.fragility_samples)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from rbm_cli.study.fragility_fit import collapse_probability

if TYPE_CHECKING:  # matplotlib is imported when a figure is drawn, not with this module
    import pandas as pd
    from matplotlib.figure import Figure

__all__ = ["BY_FILES", "tercile_figure"]

#: The files ``--by`` adds to the fragility's set.
BY_FILES = ("fragility_by.png", "fragility_by.csv")
#: The terciles' colours, lowest values first.
COLOURS = ("tab:blue", "tab:green", "tab:red")


def tercile_figure(table: pd.DataFrame, key: str, label: str, top: float,
                   title: str = "") -> Figure:  # fmt: skip
    """A new figure (no pyplot): the fitted curve of each tercile of ``table``
    (rbm_cli.study.fragility_samples.by_tercile), from 0 to ``top`` on the intensity axis
    (``label``), each labelled with the key's range in it; a tercile with no fit says why."""
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.figure import Figure

    ax = Figure(figsize=(7, 5)).subplots()
    x = np.linspace(0.0, top, 201)
    for colour, row in zip(COLOURS, table.itertuples(), strict=False):
        span = f"{key} {row.lowest:.4g}-{row.highest:.4g} ({row.n_samples} samples)"
        if math.isnan(row.median):
            ax.plot([], [], color=colour, label=f"{row.tercile}: {span}: no fit ({row.note})")
            continue
        fit = f"median {row.median:.3g}, beta {row.beta:.2f}"
        ax.plot(x, collapse_probability(x, row.median, row.beta), color=colour,
                label=f"{row.tercile}: {span}: {fit}")  # fmt: skip
    ax.set_xlabel(label)
    ax.set_ylabel("probability of collapse [-]")
    ax.set_ylim(-0.03, 1.03)
    ax.set_xlim(0.0, top)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(0.0, -0.14), borderaxespad=0.0)
    ax.set_title(title or f"fragility per tercile of {key}", fontsize=9)
    return ax.figure
