"""The folder of one run (`rbm run`): history.csv, summary.json, history.png, shapes.png.

The folder is created only once the simulation has succeeded and all its files are
written (atomic writers in :mod:`rbm_cli.base.files`).
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from rbm_cli import __version__
from rbm_cli.base.files import (
    OutputError,
    check_writable_dir,
    current_umask,
    json_ready,
    make_dirs,
    remove_stale_staging,
    save_figure_atomic,
    write_csv_atomic,
    write_json_atomic,
)
from rbm_cli.models.result import History, RunResult

if TYPE_CHECKING:
    import pandas as pd

#: Number of deformed shapes drawn in shapes.png.
N_SHAPES = 6


# --------------------------------------------------------------------------- folders


def format_number(x: float) -> str:
    """Compact form of a number for folder names: 0.5 -> '0.5', 1.0 -> '1'."""
    text = f"{float(x):.6g}"
    return "0" if text == "-0" else text


def run_folder_name(amplitude_g: float, frequency_hz: float | None, excitation_type: str) -> str:
    """``run_A<A>_f<F>`` (e.g. ``run_A0.5_f1``); ``run_A<A>`` for a record (no
    frequency); ``run_free`` for free motion."""
    if excitation_type == "free":
        return "run_free"
    if frequency_hz is None:
        return f"run_A{format_number(amplitude_g)}"
    return f"run_A{format_number(amplitude_g)}_f{format_number(frequency_hz)}"


# --------------------------------------------------------------------------- one run


def history_frame(history: History) -> pd.DataFrame:
    """history.csv as a table: t_s, ag_m_s2, ug_m, u1_m..u{n+1}_m, theta1_rad..thetan_rad.

    The u columns are node displacements relative to the ground [m]; the theta
    columns absolute drum rotations [rad]. (pandas is imported here, not with the module.)
    """
    import pandas as pd

    u = np.atleast_2d(np.asarray(history.node_displacements, dtype=float))
    theta = np.atleast_2d(np.asarray(history.rotations, dtype=float))
    data: dict[str, np.ndarray] = {
        "t_s": np.asarray(history.t, dtype=float),
        "ag_m_s2": np.asarray(history.ground_acceleration, dtype=float),
        "ug_m": np.asarray(history.ground_displacement, dtype=float),
    }
    for i in range(u.shape[1]):
        data[f"u{i + 1}_m"] = u[:, i]
    for i in range(theta.shape[1]):
        data[f"theta{i + 1}_rad"] = theta[:, i]
    # + 0.0 turns -0.0 into 0.0, so the file never shows "-0"
    return pd.DataFrame({k: v + 0.0 for k, v in data.items()})


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


def run_summary(
    result: RunResult,
    config,
    *,
    config_path: str | os.PathLike | None,
    amplitude_g: float,
    frequency_hz: float,
    output_dt: float | None,
) -> dict:
    """summary.json: RunResult.summary() plus the resolved inputs and the version."""
    summary = dict(result.summary())
    summary["inputs"] = {
        "config_file": os.fspath(config_path) if config_path is not None else None,
        "amplitude_g": amplitude_g,
        "frequency_hz": frequency_hz,
        "output_dt_s": output_dt,
    }
    summary["config"] = json_ready(config.resolved())
    summary["config_written"] = json_ready(config.written)
    summary["rbm_version"] = __version__
    return json_ready(summary)


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


def _run_column(summary: dict):
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


def _history_figure(
    history: History,
    t_collapse: float | None,
    title: str | None = None,
    joints: tuple | None = None,
):
    """history.png: base and top displacement, top relative to base, and for more than
    one drum each joint's rotation over its limit (``joints`` = (Column, formulation,
    collapse ratio), see :func:`rbm_cli.report.plots.plot_joint_rotations`)."""
    from matplotlib.figure import Figure

    from rbm_cli.report.plots import plot_history, plot_joint_rotations, plot_top_relative

    multi = joints is not None and joints[0].n > 1
    fig = Figure(figsize=(9.0, 8.5 if multi else 6.0))
    axes = fig.subplots(3 if multi else 2, 1, sharex=True)
    plot_history(history, ax=axes[0], t_collapse=t_collapse)
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
    for ax in axes:  # legends beside the axes, so every panel has the same width
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="x-small")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def _shapes_figure(
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


def write_run(
    out_dir: str | os.PathLike,
    name: str,
    folder: str,
    result: RunResult,
    summary: dict,
    *,
    widths,
    elevations,
) -> Path:
    """Write history.csv, history.png, shapes.png and summary.json of one run.

    The files are written into a hidden staging folder beside the destination
    ``out_dir/name/folder``, which then replaces its files (or is renamed into
    place). Nothing is left behind if writing fails.

    Parameters
    ----------
    out_dir : path  Output root (``-o``) [folder]
    name : str  Config name (second level of the output tree)
    folder : str  Run folder name, see :func:`run_folder_name`
    result : RunResult  A run with its history recorded
    summary : dict  Contents of summary.json; when made by :func:`run_summary`, the
        figures' title (config and cell) and the column's rotation limits come from it
    widths : (n+1,) Column widths at the nodes [m]
    elevations : (n+1,) Node elevations [m]

    Returns
    -------
    Path of the run folder.

    Raises
    ------
    OutputError
        If a folder or file cannot be created or written.
    """
    if result.history is None:
        raise ValueError("write_run needs a result recorded with record=True")
    parent = Path(out_dir) / name
    target = parent / folder
    check_writable_dir(parent)
    make_dirs(parent)
    if target.exists() and not target.is_dir():
        raise OutputError(f"cannot create run folder {target}: a file of that name exists")
    t_collapse = result.t_collapse_s if result.collapsed else None
    remove_stale_staging(parent, folder)
    try:
        staging = Path(tempfile.mkdtemp(prefix=f".{folder}.{os.getpid()}.", dir=parent))
        os.chmod(staging, 0o777 & ~current_umask())  # mkdtemp makes 0o700 folders
    except OSError as exc:
        raise OutputError(f"cannot write in output folder {parent}: {exc.strerror}") from None
    try:
        write_csv_atomic(staging / "history.csv", history_frame(result.history))
        title = run_title(summary)
        figure = _history_figure(result.history, t_collapse, title, _run_column(summary))
        save_figure_atomic(figure, staging / "history.png")
        save_figure_atomic(
            _shapes_figure(result.history, widths, elevations, t_collapse, title),
            staging / "shapes.png",
        )
        write_json_atomic(staging / "summary.json", summary)
        if target.is_dir():
            for item in staging.iterdir():
                os.replace(item, target / item.name)
            staging.rmdir()
        else:
            os.replace(staging, target)
    except OSError as exc:
        raise OutputError(f"cannot write run folder {target}: {exc.strerror or exc}") from None
    finally:
        if staging.exists():
            shutil.rmtree(staging, ignore_errors=True)
    return target
