"""Figures of `rbm bench`: work-precision (bench.png) and scaling (scaling.png).

Each function builds a new :class:`matplotlib.figure.Figure` (no pyplot state, no
backend chosen) from the table the benchmark returns, and returns it; saving is
the caller's (the CLI, through :func:`rbm_cli.report.files.save_figure_atomic`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from rbm_cli.study.bench import PEAK_TARGET
from rbm_cli.study.bench_scaling import CELL


def work_precision_figure(table: pd.DataFrame):
    """Error against domain wall time, one column of axes per problem.

    Parameters
    ----------
    table : pandas.DataFrame
        The table of :func:`rbm_cli.study.bench.run_bench` (one row per problem
        and method; ``domain_wall_s`` [s], ``peak_err_median`` and
        ``fraction_differ`` [-]).

    Returns
    -------
    matplotlib.figure.Figure
        Top row: median relative error of the peak rotation (floored at 1e-16),
        with the accuracy target dashed; bottom row: fraction of converged cells
        whose outcome differs (floored at 1e-4, meaning none).
    """
    from matplotlib.figure import Figure

    probs = list(dict.fromkeys(table["problem"]))
    fig = Figure(figsize=(4.2 * len(probs), 7.5))
    axes = fig.subplots(2, len(probs), squeeze=False)
    for j, name in enumerate(probs):
        sub = table[table["problem"] == name]
        for (impl, method), grp in sub.groupby(["implementation", "method"], sort=False):
            grp = grp.sort_values("rtol")
            x = grp["domain_wall_s"].to_numpy()
            label = f"{method} ({impl})" if impl != "baseline" else "baseline: solve_ivp RK45"
            y1 = np.maximum(grp["peak_err_median"].to_numpy(float), 1e-16)
            y2 = np.maximum(grp["fraction_differ"].to_numpy(float), 1e-4)
            style = "o-" if impl == "compiled" else "s"
            axes[0, j].loglog(x, y1, style, label=label)
            axes[1, j].loglog(x, y2, style, label=label)
        axes[0, j].set_title(name)
        axes[1, j].set_xlabel("domain wall time [s] (2 workers)")
        axes[0, j].axhline(PEAK_TARGET, color="0.6", lw=0.8, ls="--")
    axes[0, 0].set_ylabel("peak rotation error, median (relative)")
    axes[1, 0].set_ylabel("fraction of converged cells differing\n(1e-4 = none)")
    axes[0, -1].legend(fontsize=7)
    fig.tight_layout()
    return fig


#: Series of the scaling table drawn on log-log axes, with their x labels.
_SCALING_SERIES = (
    ("drums", "drums"),
    ("k_n", "joint normal stiffness k_n [Pa/m] (4 drums)"),
    ("duration", "duration [s] (8 drums)"),
)


def scaling_figure(table: pd.DataFrame):
    """Time per run against drums, k_n and duration, and the 2-worker speed-up.

    Parameters
    ----------
    table : pandas.DataFrame
        The table of :func:`rbm_cli.study.bench_scaling.run_scaling` (``series``,
        ``x``, ``time_per_run_s`` [s], ``speedup_2_over_1`` [-]).

    Returns
    -------
    matplotlib.figure.Figure
        Four axes side by side: three log-log series and a bar chart of the
        speed-up of 2 workers over 1 (2 dashed).
    """
    import matplotlib.ticker
    from matplotlib.figure import Figure

    fig = Figure(figsize=(16, 3.8))
    axes = fig.subplots(1, 4)
    for ax, (series, xlabel) in zip(axes[:3], _SCALING_SERIES, strict=True):
        sub = table[table["series"] == series]
        xs = sub["x"].astype(float)
        ax.loglog(xs, sub["time_per_run_s"], "o-")
        if series != "k_n":  # label the points themselves (the log axis's minor labels overlap)
            ax.set_xticks(xs, [f"{x:g}" for x in xs])
            ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xlabel(xlabel)
        ax.set_ylabel("time per run [s]")
        ax.grid(True, which="both", alpha=0.3)
    sub = table[table["series"] == "workers"]
    axes[3].bar(sub["x"].astype(str), sub["speedup_2_over_1"])
    axes[3].axhline(2.0, color="0.5", ls="--", lw=0.8)
    axes[3].set_ylabel("speed-up, 2 workers over 1")
    fig.suptitle(f"rbm scaling, one cell {CELL[0]} g {CELL[1]} Hz (stays elastic)")
    fig.tight_layout()
    return fig


__all__ = ["scaling_figure", "work_precision_figure"]
