"""history.png and shapes.png of one run (`rbm run`): the figures of the run folder.

Drawn by :func:`run_pngs`, which returns the PNG files' bytes: `rbm run` has it run in the
figure's child forked as the command starts (rbm_cli.report.figure_process), so
the run's own process imports no matplotlib and the child writes no file; the run folder
(rbm_cli.report.run_folder.write_run) writes the bytes it gets back. matplotlib is imported
where a figure is built, not with this module.
"""

from __future__ import annotations

import io
from collections.abc import Sequence

import numpy as np

from rbm_cli.models.result import History

#: Number of deformed shapes drawn in shapes.png.
N_SHAPES = 6

#: The files :func:`run_pngs` draws, in the order of :func:`run_png_calls`.
RUN_PNGS = ("history.png", "shapes.png")

#: savefig's arguments for the run's figures (those of base.files.save_figure_atomic).
SAVEFIG = {"format": "png", "dpi": 150, "bbox_inches": "tight"}


def shape_instants(t: Sequence[float], count: int = N_SHAPES) -> list[int]:
    """Indices of ``count`` instants evenly spaced up to the last sample, which is included.

    The first instant is one step (t_end / count) after the start, since at
    t = 0 a column starting from rest shows nothing.
    """
    t = np.asarray(t, dtype=float)
    if t.size == 0:
        return []
    targets = np.linspace(t[0], t[-1], count + 1)[1:]
    idx = sorted({int(np.argmin(np.abs(t - target))) for target in targets})
    if idx[-1] != t.size - 1:
        idx.append(t.size - 1)
    return idx


def run_title(summary: dict) -> str | None:
    """'<config name>: A = <a> g, f = <f> Hz' (or ': free motion') from a summary.json
    made by :func:`run_summary`; None if the summary does not hold them."""
    try:
        name = summary["config_written"]["name"]
        inputs = summary["inputs"]
        kind = summary["config_written"].get("excitation", {}).get("type", "harmonic")
        if kind == "free":
            return f"{name}: free motion"
        amplitude, frequency = float(inputs["amplitude_g"]), float(inputs["frequency_hz"])
        cell = f"A = {amplitude:.4g} g, f = {frequency:.4g} Hz"
    except (KeyError, TypeError, ValueError, AttributeError):
        return None
    return f"{name} ({kind}): {cell}"


def run_column(summary: dict):
    """(Column, formulation, collapse ratio) of the config a summary.json holds, or None."""
    from rbm_cli.base.errors import RbmError
    from rbm_cli.config.load import parse_config
    from rbm_cli.physics.column import build_column

    try:
        config = parse_config(summary["config_written"])
        column = build_column(config.column, config.interface)
    except (KeyError, TypeError, ValueError, RbmError):
        return None
    return column, config.interface.formulation, config.collapse.ratio


def history_figure(
    history: History,
    t_collapse: float | None,
    title: str | None = None,
    joints: tuple | None = None,
):
    """history.png: base and top displacement (the top relative to the ground, and the
    ground on a right axis, when the ground drifts: rbm_cli.report.plots.ground_drifts),
    top relative to base, and for more than one drum each joint's rotation over its limit
    (``joints`` = (Column, formulation, collapse ratio), see
    :func:`rbm_cli.report.plots.plot_joint_rotations`)."""
    from matplotlib.figure import Figure

    from rbm_cli.report.plots import (
        ground_drifts,
        plot_history,
        plot_joint_rotations,
        plot_top_relative,
    )

    multi = joints is not None and joints[0].n > 1
    fig = Figure(figsize=(9.0, 8.5 if multi else 6.0))
    axes = fig.subplots(3 if multi else 2, 1, sharex=True)
    relative = ground_drifts(history)  # the ground then on a right axis of the first panel
    plot_history(history, ax=axes[0], t_collapse=t_collapse, relative=relative)
    plot_top_relative(history, ax=axes[1], t_collapse=t_collapse)
    if multi:
        column, formulation, ratio = joints
        plot_joint_rotations(
            history,
            column.rotation_capacity,
            ax=axes[2],
            formulation=formulation,
            collapse_ratio=ratio,
            t_collapse=t_collapse,
        )
        axes[2].set_title("joint rotations against their limits", fontsize="medium")
    for ax in axes[:-1]:
        ax.set_xlabel("")
    for k, ax in enumerate(axes):  # legends beside the axes (past a right axis, if any)
        beside = 1.1 if relative and k == 0 else 1.01
        ax.legend(loc="upper left", bbox_to_anchor=(beside, 1.0), fontsize="x-small")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def shapes_figure(
    history: History, widths, elevations, t_collapse: float | None, title: str | None = None
):
    from matplotlib.figure import Figure

    from rbm_cli.report.plots import plot_shapes

    fig = Figure(figsize=(10.0, 5.0))
    ax = fig.subplots()
    plot_shapes(
        history,
        widths,
        shape_instants(history.t),
        ax=ax,
        elevations=elevations,
        t_collapse=t_collapse,
    )
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    fig.set_size_inches(10.0, float(np.clip(9.0 * (y1 - y0) / (x1 - x0) + 1.0, 3.0, 8.0)))
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def png_bytes(fig) -> bytes:
    """The PNG file of a figure, as :func:`rbm_cli.base.files.save_figure_atomic` writes it."""
    buffer = io.BytesIO()
    fig.savefig(buffer, **SAVEFIG)
    return buffer.getvalue()


def history_png(history: History, t_collapse: float | None, summary: dict) -> bytes:
    """history.png of one run (see :func:`run_pngs` for the arguments)."""
    figure = history_figure(history, t_collapse, run_title(summary), run_column(summary))
    return png_bytes(figure)


def shapes_png(history: History, t_collapse: float | None, summary: dict, widths, elevations):
    """shapes.png of one run (see :func:`run_pngs` for the arguments), as bytes."""
    figure = shapes_figure(history, widths, elevations, t_collapse, run_title(summary))
    return png_bytes(figure)


def run_pngs(history: History, t_collapse: float | None, summary: dict, widths, elevations):
    """{'history.png': bytes, 'shapes.png': bytes} of one run.

    Parameters
    ----------
    history : History  The run's recorded history
    t_collapse : float or None  Collapse time [s], None if it did not collapse
    summary : dict  summary.json (rbm_cli.report.run_folder.run_summary): the title (config
        and cell) and the column's rotation limits come from it
    widths : (n+1,) Column widths at the nodes [m]
    elevations : (n+1,) Node elevations [m]
    """
    calls = run_png_calls(history, t_collapse, summary, widths, elevations)
    return {name: function(*args) for name, (function, args) in zip(RUN_PNGS, calls, strict=True)}


def run_png_calls(history: History, t_collapse, summary: dict, widths, elevations) -> list:
    """The (function, args) pairs that draw :data:`RUN_PNGS` (see :func:`run_pngs`): for
    rbm_cli.report.figure_process.FigureProcess.submit_all, which draws them side by side."""
    return [
        (history_png, (history, t_collapse, summary)),
        (shapes_png, (history, t_collapse, summary, widths, elevations)),
    ]
