"""history.png and shapes.png of one run (`rbm run`): the figures of the run folder.

Drawn by :func:`run_pngs`, which returns the PNG files' bytes: `rbm run` has it run in the
figure's child forked as the command starts (rbm_cli.report.figure_process), so
the run's own process imports no matplotlib and the child writes no file; the run folder
(rbm_cli.report.run_folder.write_run) writes the bytes it gets back. matplotlib is imported
where a figure is built, not with this module.
"""

from __future__ import annotations

import dataclasses
import io
from collections.abc import Sequence

import numpy as np

from rbm_cli.base.errors import RbmError
from rbm_cli.config.load import parse_config
from rbm_cli.config.types import G
from rbm_cli.models.history import History
from rbm_cli.report.plots import (
    exaggeration_factor,
    ground_drifts,
    infer_elevations,
    plot_history,
    plot_joint_rotations,
    plot_shapes,
    plot_top_relative,
)
from rbm_cli.structures.column import build_column
from rbm_cli.structures.frame import beam_box
from rbm_cli.study.schema import C

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
    """'<config name> (<type>): A = <a> g, f = <f> Hz' (or ': free motion'; a record run:
    '<config name>: record <name> scaled to PGA <pga> g', and its vertical record if any)
    from a summary.json made by :func:`run_summary`; None if the summary does not hold
    them."""
    try:
        name = summary["config_written"]["name"]
        inputs = summary["inputs"]
        kind = summary["config_written"].get("excitation", {}).get("type", "harmonic")
        if kind == "free":
            return f"{name}: free motion"
        if kind == "record":
            return record_title(name, summary[C.record], float(inputs[C.amplitude_g]))
        amplitude, frequency = float(inputs[C.amplitude_g]), float(inputs[C.frequency_hz])
        cell = f"A = {amplitude:.4g} g, f = {frequency:.4g} Hz"
    except (KeyError, TypeError, ValueError, AttributeError):
        return None
    return f"{name} ({kind}): {cell}"


def record_title(name: str, record: dict, amplitude: float) -> str:
    """Title of a record run: the config's name, the record's, its scaled PGA [g] (and the
    scale factor with ``scale: factor``), the vertical record's name and scaled peak."""
    if record.get("record_y"):
        title = (f"{name}: records {record[C.record]} (x) and {record['record_y']} (y) scaled"
                 f" to PGA {float(record[C.pga_g]):.4g} g (the larger)")  # fmt: skip
    else:
        title = f"{name}: record {record[C.record]} scaled to PGA {float(record[C.pga_g]):.4g} g"
    if record.get("scale") == "factor":
        title += f" (factor {amplitude:.4g})"
    if record.get("vertical"):
        title += (f", with vertical record {record['vertical']} "
                  f"(peak {float(record['vertical_peak_g']):.4g} g)")  # fmt: skip
    return title


def plot_ground(history: History, ax, vertical=None, t_collapse: float | None = None):
    """The ground's acceleration against time [g]: a_g (gid 'a_g') and, with a vertical
    record, the upward a_v (gid 'a_v', ``vertical`` [m/s^2] at the history's times)."""
    t = np.asarray(history.t, dtype=float)
    ag = np.asarray(history.ground_acceleration, dtype=float) / G
    pair = history.ground_acceleration_y is not None
    label = "$a_x$ (horizontal, x)" if pair else "$a_g$ (horizontal)"
    ax.plot(t, ag, color="0.35", linewidth=0.8, label=label, gid="a_g")
    if pair:
        ay = np.asarray(history.ground_acceleration_y, dtype=float) / G
        ax.plot(t, ay, color="tab:purple", linewidth=0.8, label="$a_y$ (horizontal, y)",
                gid="a_y")  # fmt: skip
    if vertical is not None:
        av = np.asarray(vertical, dtype=float) / G
        ax.plot(t, av, color="tab:green", linewidth=0.8, label="$a_v$ (vertical, upward)",
                gid="a_v")  # fmt: skip
    if t_collapse is not None and np.isfinite(t_collapse):
        ax.axvline(t_collapse, color="tab:red", linestyle="--", linewidth=1.0,
                   label=f"collapse, t = {t_collapse:.3g} s")  # fmt: skip
    ax.axhline(0.0, color="0.6", linewidth=0.6)
    ax.set_ylabel("ground acc. [g]")
    ax.set_xlabel("time [s]")
    ax.grid(True, alpha=0.3)
    ax.set_title("ground acceleration" + (" (horizontal and vertical)" if vertical is not None
                                          else ""), fontsize="medium")  # fmt: skip
    return ax


def run_column(summary: dict):
    """(Column, formulation, collapse ratio) of the config a summary.json holds, or None."""
    try:
        # the column alone: the excitation's files (and a grid over them) are the run's
        # business, and may be relative to a folder the summary does not name
        written = {key: value for key, value in summary["config_written"].items()
                   if key not in ("excitation", "grid")}  # fmt: skip
        config = parse_config(written)
        column = build_column(config.column, config.interface)
    except (KeyError, TypeError, ValueError, RbmError):
        return None
    return column, config.interface.formulation, config.collapse.ratio


def history_figure(
    history: History,
    t_collapse: float | None,
    title: str | None = None,
    joints: tuple | None = None,
    ground: bool = False,
    vertical=None,
):
    """history.png: with ``ground`` (a record run) first the ground's acceleration (a_g,
    and a_v when ``vertical`` [m/s^2] is given: :func:`plot_ground`); base and top
    displacement (the top relative to the ground, and the ground on a right axis, when the
    ground drifts: rbm_cli.report.plots.ground_drifts), top relative to base, and for more
    than one drum each joint's rotation over its limit (``joints`` = (Column, formulation,
    collapse ratio), see :func:`rbm_cli.report.plots.plot_joint_rotations`); for a model in
    three dimensions the top's path in plan below them (:func:`plot_top_plan`)."""
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.figure import Figure

    multi = joints is not None and joints[0].n > 1
    ground = bool(ground or vertical is not None)
    count = 2 + int(multi) + int(ground)
    height = 2.0 + 2.2 * count if count > 2 else 6.0
    if history.top_plan is None:
        fig = Figure(figsize=(9.0, height))
        axes = list(fig.subplots(count, 1, sharex=True))
    else:  # a model in three dimensions: the top's path in plan below the time panels
        fig = Figure(figsize=(9.0, height + 4.0))
        grid = fig.add_gridspec(count + 1, 1, height_ratios=[1.0] * count + [2.0])
        axes = [fig.add_subplot(grid[0])]
        axes += [fig.add_subplot(grid[k], sharex=axes[0]) for k in range(1, count)]
        for ax in axes[:-1]:
            ax.tick_params(labelbottom=False)
        plot_top_plan(history, fig.add_subplot(grid[count]), t_collapse)
    if ground:
        plot_ground(history, axes.pop(0), vertical, t_collapse)
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
    axes = fig.axes[:count]  # the panels, top to bottom (a right axis comes after them)
    for ax in axes[:-1]:
        ax.set_xlabel("")
    first = int(ground)  # the panel of plot_history
    for k, ax in enumerate(axes):  # legends beside the axes (past a right axis, if any)
        beside = 1.1 if relative and k == first else 1.01
        ax.legend(loc="upper left", bbox_to_anchor=(beside, 1.0), fontsize="x-small")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_top_plan(history: History, ax, t_collapse: float | None = None) -> None:
    """The top centre's path in plan [m] (a model in three dimensions), from where it
    stood (a dot) to where the run ended or the column fell (an x), equal scales."""
    xy = np.asarray(history.top_plan, dtype=float)
    ax.plot(xy[:, 0], xy[:, 1], lw=0.8, color="C0", label="top centre in plan", gid="top_plan")
    ax.plot([xy[0, 0]], [xy[0, 1]], "o", color="k", ms=4, label="start")
    end = "collapse" if t_collapse is not None else "end"
    ax.plot([xy[-1, 0]], [xy[-1, 1]], "x", color="C3", ms=7, label=end)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title("the top's path in plan", fontsize="medium")


def shapes_figure(
    history: History,
    widths,
    elevations,
    t_collapse: float | None,
    title: str | None = None,
    frame: tuple[int, float, float] | None = None,
):
    """shapes.png's figure: the deformed column at chosen instants (a frame's columns and
    beam: plot_shapes's ``frame``); for a model in three dimensions in two elevations, the
    motion's vertical plane above and the plane across it below (the same instants and
    exaggeration)."""
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.figure import Figure

    instants = shape_instants(history.t)
    z = np.asarray(infer_elevations(history) if elevations is None else elevations, float)
    views, scale = [(history, "in the motion's plane")], None
    if history.rotations_across is not None:
        theta = np.atleast_2d(np.asarray(history.rotations_across, dtype=float))
        rise = np.cumsum(theta * np.diff(z)[None, :], axis=1)  # the nodes, drum by drum
        nodes = np.hstack([np.zeros((theta.shape[0], 1)), rise])
        seen = dataclasses.replace(history, rotations=theta, node_displacements=nodes)
        views.append((seen, "across the motion's plane (its direction turned +90 degrees)"))
        # one exaggeration for both views: the smaller of their own
        scale = min(exaggeration_factor(v, instants, float(z[-1] - z[0])) for v, _ in views)
    fig = Figure(figsize=(10.0, 5.0 * len(views)))
    axes = fig.subplots(len(views), 1, squeeze=False)[:, 0]
    for ax, (view, label) in zip(axes, views, strict=True):
        plot_shapes(view, widths, instants, ax=ax, elevations=z, scale=scale,
                    t_collapse=t_collapse, frame=frame)  # fmt: skip
        if len(views) > 1:
            ax.set_title(ax.get_title().replace("Deformed shapes", f"Deformed shapes {label}"),
                         fontsize="medium")  # fmt: skip
    x0, x1 = axes[0].get_xlim()
    y0, y1 = axes[0].get_ylim()
    per_view = float(np.clip(9.0 * (y1 - y0) / (x1 - x0) + 1.0, 3.0, 8.0))
    fig.set_size_inches(10.0, per_view * len(views))
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def png_bytes(fig) -> bytes:
    """The PNG file of a figure, as :func:`rbm_cli.base.files.save_figure_atomic` writes it."""
    buffer = io.BytesIO()
    fig.savefig(buffer, **SAVEFIG)
    return buffer.getvalue()


def history_png(history: History, t_collapse: float | None, summary: dict,
                vertical=None) -> bytes:  # fmt: skip
    """history.png of one run (see :func:`run_pngs` for the arguments); a record run's
    (its summary has ``record``) starts with the ground's acceleration."""
    figure = history_figure(history, t_collapse, run_title(summary), run_column(summary),
                            ground="record" in summary, vertical=vertical)  # fmt: skip
    return png_bytes(figure)


def drawn_frame(summary: dict) -> tuple[int, float, float] | None:
    """A run's frame as plot_shapes draws it, (columns, spacing [m], beam height [m]) from
    its summary's config (rbm_cli.structures.frame.beam_box), or None without one."""
    config = summary.get("config") or {}
    frame = config.get("frame")
    if not frame or not frame.get("beam_mass"):
        return None
    spacing, _, height, _ = beam_box(config["column"], frame)
    return int(frame["columns"]), spacing, height


def shapes_png(history: History, t_collapse: float | None, summary: dict, widths, elevations):
    """shapes.png of one run (see :func:`run_pngs` for the arguments), as bytes."""
    figure = shapes_figure(history, widths, elevations, t_collapse, run_title(summary),
                           frame=drawn_frame(summary))  # fmt: skip
    return png_bytes(figure)


def run_pngs(history: History, t_collapse: float | None, summary: dict, widths, elevations,
             vertical=None):  # fmt: skip
    """{'history.png': bytes, 'shapes.png': bytes} of one run.

    Parameters
    ----------
    history : History  The run's recorded history
    t_collapse : float or None  Collapse time [s], None if it did not collapse
    summary : dict  summary.json (rbm_cli.report.run_folder.run_summary): the title (config
        and cell) and the column's rotation limits come from it
    widths : (n+1,) Column widths at the nodes [m]
    elevations : (n+1,) Node elevations [m]
    vertical : (k,) or None  a_v [m/s^2] at the history's times, with a vertical record
        (rbm_cli.report.run_folder.vertical_history)
    """
    calls = run_png_calls(history, t_collapse, summary, widths, elevations, vertical)
    return {name: function(*args) for name, (function, args) in zip(RUN_PNGS, calls, strict=True)}


def run_png_calls(history: History, t_collapse, summary: dict, widths, elevations,
                  vertical=None) -> list:  # fmt: skip
    """The (function, args) pairs that draw :data:`RUN_PNGS` (see :func:`run_pngs`): for
    rbm_cli.report.figure_process.FigureProcess.submit_all, which draws them side by side."""
    return [
        (history_png, (history, t_collapse, summary, vertical)),
        (shapes_png, (history, t_collapse, summary, widths, elevations)),
    ]
