"""Figures of `rbm bench`: work-precision (bench.png) and scaling (scaling.png).

Each function builds a new :class:`matplotlib.figure.Figure` (no pyplot state, no
backend chosen) from the table the benchmark returns, and returns it; saving is
the caller's (the CLI, through :func:`rbm_cli.report.files.save_figure_atomic`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from rbm_cli.study.bench import PEAK_TARGET, PROBLEMS
from rbm_cli.study.bench_scaling import CELL, ROCKING_CELL


def _series_label(impl: str, method: str) -> str:
    return f"{method} ({impl})" if impl != "baseline" else "baseline: solve_ivp RK45"


def _log_ticks(ax) -> None:
    """Labelled decades only, at most ~6 per axis (minor labels overlap into a smear)."""
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.ticker import LogLocator, NullFormatter

    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_locator(LogLocator(base=10.0, numticks=7))
        axis.set_minor_locator(LogLocator(base=10.0, subs=np.arange(2, 10) * 0.1, numticks=12))
        axis.set_minor_formatter(NullFormatter())
    ax.grid(True, which="major", alpha=0.3)


def _draw_problem(ax_peak, ax_diff, sub: pd.DataFrame, max_cells: float | None) -> None:
    """One problem's two panels; a method whose cells all agree (fraction 0) is left out of
    the log axis and named in a note instead."""
    none = 0
    for (impl, method), grp in sub.groupby(["implementation", "method"], sort=False):
        grp = grp.sort_values("rtol")
        x = grp["domain_wall_s"].to_numpy(float)
        style = (
            dict(marker="o", linestyle="-")
            if impl == "compiled"
            else dict(marker="s", linestyle="none")
        )
        label = _series_label(impl, method)
        peak = grp["peak_err_median"].to_numpy(float)
        ax_peak.plot(x, np.where(peak > 0, peak, np.nan), label=label, gid=label, **style)
        frac = grp["fraction_differ"].to_numpy(float)
        ax_diff.plot(x, np.where(frac > 0, frac, np.nan), label=label, gid=label, **style)
        none += int(np.sum(frac == 0))
    ax_peak.axhline(PEAK_TARGET, color="0.4", lw=0.9, ls="--", gid="target",
                    label=f"accuracy target of the peak: {PEAK_TARGET:g}")  # fmt: skip
    if max_cells is not None:
        ax_diff.axhline(max_cells, color="0.4", lw=0.9, ls=":", gid="target",
                        label=f"target: at most {max_cells:.1%} of cells differ")  # fmt: skip
    for ax in (ax_peak, ax_diff):
        ax.set_xscale("log")
        ax.set_yscale("log")
    if none:
        note = f"no cell differs (not drawn): {none} of {len(sub)} runs"
        ax_diff.text(0.02, 0.02, note, transform=ax_diff.transAxes, fontsize="x-small", gid="none")


def _log_range(values: np.ndarray, target: float) -> tuple[float, float]:
    """A y range over the positive values and the target, padded by a factor 2."""
    positive = values[np.isfinite(values) & (values > 0)]
    lo = min(float(np.min(positive)) if positive.size else target, target)
    hi = max(float(np.max(positive)) if positive.size else target, target)
    return lo / 2.0, hi * 2.0


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
        Top row: median relative error of the peak rotation, with the accuracy
        target dashed; bottom row: fraction of converged cells whose outcome
        differs, with the problem's target dotted. Each row shares its y axis
        (one quantity); the x axes are each problem's own (their times differ by
        decades). Zeros (no error, no differing cell) have no place on a log axis:
        they are left out, and a note in the panel counts them. One legend below.
    """
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.figure import Figure

    probs = list(dict.fromkeys(table["problem"]))
    targets = {p.name: p.max_cells for p in PROBLEMS}
    fig = Figure(figsize=(4.0 * len(probs), 7.8))
    axes = fig.subplots(2, len(probs), squeeze=False, sharex="col", sharey="row")
    for j, name in enumerate(probs):
        _draw_problem(axes[0, j], axes[1, j], table[table["problem"] == name], targets.get(name))
        wall = table.loc[table["problem"] == name, "domain_wall_s"].to_numpy(float)
        axes[0, j].set_xlim(float(np.min(wall)) / 1.5, float(np.max(wall)) * 1.5)
        axes[0, j].set_title(name)
        axes[1, j].set_xlabel("domain wall time [s] (2 workers)")
        axes[0, j].tick_params(labelbottom=False)
        for ax in axes[:, j]:
            _log_ticks(ax)
    for row, column, target in ((0, "peak_err_median", PEAK_TARGET), (1, "fraction_differ", 0.005)):
        axes[row, 0].set_ylim(*_log_range(table[column].to_numpy(float), target))
    axes[0, 0].set_ylabel("peak rotation error, median (relative)")
    axes[1, 0].set_ylabel("fraction of converged cells differing")
    handles = {}
    for ax in axes.ravel():
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            handles.setdefault(lab, h)
    fig.legend(list(handles.values()), list(handles), loc="lower center", ncol=4, fontsize="small")
    fig.tight_layout(rect=(0.0, 0.1, 1.0, 1.0))
    return fig


#: Series of the scaling table drawn on log-log axes, with their x labels.
_SCALING_SERIES = (
    ("drums", "drums"),
    ("k_n", "joint normal stiffness k_n [Pa/m] (4 drums)"),
    ("duration", "duration [s] (8 drums)"),
)


def scaling_figure(table: pd.DataFrame):
    """Time per run against drums, k_n and duration for both methods, and the 2-worker
    speed-up.

    Parameters
    ----------
    table : pandas.DataFrame
        The table of :func:`rbm_cli.study.bench_scaling.run_scaling` (``series``,
        ``x``, ``method``, ``cell``, ``time_per_run_s`` [s], ``speedup_2_over_1`` [-]).

    Returns
    -------
    matplotlib.figure.Figure
        Four axes side by side: three log-log series (one line per method and cell:
        circles the step kernel, squares the exact integrator; solid the elastic cell,
        dashed the rocking one) and a bar chart of the speed-up of 2 workers over 1
        (2 dashed).
    """
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    import matplotlib.ticker

    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.figure import Figure

    fig = Figure(figsize=(16, 3.8))
    axes = fig.subplots(1, 4)
    for ax, (series, xlabel) in zip(axes[:3], _SCALING_SERIES, strict=True):
        sub = table[table["series"] == series]
        xs = np.unique(sub["x"].astype(float))
        _draw_methods(ax, sub)
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
    fig.suptitle(f"rbm scaling, 10 s at {CELL[0]} g {CELL[1]} Hz (stays elastic) and "
                 f"{ROCKING_CELL[0]} g {ROCKING_CELL[1]} Hz (rocks)")  # fmt: skip
    axes[0].legend(fontsize="x-small")
    fig.tight_layout()
    return fig


def _draw_methods(ax, sub: pd.DataFrame) -> None:
    """One line per method and cell of a scaling series (a table without those columns:
    one line)."""
    if "method" not in sub or sub["method"].isna().all():
        ax.loglog(sub["x"].astype(float), sub["time_per_run_s"], "o-")
        return
    for (method, cell), grp in sub.groupby(["method", "cell"], sort=False):
        marker, color = ("s", "C3") if method == "exact" else ("o", "C0")
        ls = "--" if cell == "rocking" else "-"
        label = f"{method}, {cell} cell"
        ax.loglog(grp["x"].astype(float), grp["time_per_run_s"], marker=marker, ls=ls,
                  color=color, label=label, gid=label)  # fmt: skip


__all__ = ["scaling_figure", "work_precision_figure"]
