"""The folder of one run (`rbm run`): history.csv, summary.json, history.png, shapes.png.

The folder is created only once the simulation has succeeded and all its files are
written (atomic writers in :mod:`rbm_cli.base.files`).
"""

from __future__ import annotations

import math
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from rbm_cli import __version__
from rbm_cli.base.files import (
    FLOAT_FORMAT,
    OutputError,
    check_writable_dir,
    current_umask,
    json_ready,
    make_dirs,
    remove_stale_staging,
    write_chunks_atomic,
    write_json_atomic,
)
from rbm_cli.base.jit import plain
from rbm_cli.config.types import G
from rbm_cli.inputs.excitation import make_ground_motion, pair_times
from rbm_cli.inputs.ground import as_samples, vertical_factor
from rbm_cli.models.history import History
from rbm_cli.report.run_figures import (  # noqa: F401  (the run folder's figures, here before)
    N_SHAPES,
    RUN_PNGS,
    run_png_calls,
    run_pngs,
    run_title,
    shape_instants,
)
from rbm_cli.study.result import RunResult
from rbm_cli.study.schema import C

if TYPE_CHECKING:
    import pandas as pd

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


def history_columns(history: History, vertical=None) -> dict[str, np.ndarray]:
    """The columns of history.csv: t_s [s], ag_m_s2 [m/s2], ag_y_m_s2 [m/s2] (a pair's
    second component), av_m_s2 [m/s2] (the upward
    ground acceleration, only when a vertical record is given: ``vertical``, a_v at the
    history's times, :func:`vertical_history`), ug_m [m], u1_m..u{n+1}_m [m] (node
    displacements relative to the ground), theta1_rad..thetan_rad [rad] (absolute drum
    rotations; a model in three dimensions: the tilt in the motion's plane), and for a model
    in three dimensions top_x_m, top_y_m [m] (the top centre in plan from where it stood)
    and theta1_across_rad.. [rad] (the rotations seen across the motion's plane);
    -0.0 made 0.0, so the file never shows "-0"."""
    u = np.atleast_2d(np.asarray(history.node_displacements, dtype=float))
    theta = np.atleast_2d(np.asarray(history.rotations, dtype=float))
    data: dict[str, np.ndarray] = {
        "t_s": np.asarray(history.t, dtype=float),
        "ag_m_s2": np.asarray(history.ground_acceleration, dtype=float),
    }
    if history.ground_acceleration_y is not None:  # a pair of records
        data["ag_y_m_s2"] = np.asarray(history.ground_acceleration_y, dtype=float)
    if vertical is not None:
        av = np.asarray(vertical, dtype=float)
        if av.shape != data["t_s"].shape:
            raise ValueError(f"vertical has {av.size} samples, the history {data['t_s'].size}")
        data["av_m_s2"] = av
    data["ug_m"] = np.asarray(history.ground_displacement, dtype=float)
    for i in range(u.shape[1]):
        data[f"u{i + 1}_m"] = u[:, i]
    for i in range(theta.shape[1]):
        data[f"theta{i + 1}_rad"] = theta[:, i]
    if history.top_plan is not None:  # a model in three dimensions
        plan = np.asarray(history.top_plan, dtype=float)
        data["top_x_m"], data["top_y_m"] = plan[:, 0], plan[:, 1]
    if history.rotations_across is not None:
        across = np.atleast_2d(np.asarray(history.rotations_across, dtype=float))
        for i in range(across.shape[1]):
            data[f"theta{i + 1}_across_rad"] = across[:, i]
    return {k: v + 0.0 for k, v in data.items()}


def history_frame(history: History, vertical=None) -> pd.DataFrame:
    """history.csv as a table (the columns of :func:`history_columns`; pandas is imported
    here, not with the module)."""
    # lazy: pandas loads only where needed (docs/architecture.md, Start-up)
    import pandas as pd

    return pd.DataFrame(history_columns(history, vertical))


def history_csv(history: History, rows_per_chunk: int = 4096, vertical=None) -> Iterator[str]:
    """The text of history.csv in pieces, without pandas: the file
    ``history_frame(history).to_csv(index=False, float_format="%.12g", lineterminator="\\n")``
    writes (base.files.write_csv_atomic), floats with 12 significant digits, empty for NaN
    (``vertical``: a_v at the history's times, see :func:`history_columns`)."""
    columns = history_columns(history, vertical)
    yield ",".join(columns) + "\n"
    table = np.column_stack(list(columns.values())) if columns else np.empty((0, 0))
    line = ",".join([FLOAT_FORMAT] * table.shape[1]) + "\n"
    for start in range(0, table.shape[0], rows_per_chunk):
        block = table[start : start + rows_per_chunk]
        rows = block.tolist()
        if np.isnan(block).any():  # pandas writes NaN as an empty field
            yield "".join(_csv_line(row) for row in rows)
        else:
            yield "".join([line % tuple(row) for row in rows])


def _csv_line(row: list[float]) -> str:
    return ",".join("" if math.isnan(v) else FLOAT_FORMAT % v for v in row) + "\n"


def record_of_run(config, amplitude_g: float) -> dict | None:
    """What a record run ran, for its summary.json and its figures' titles: the record's
    name, its peak acceleration as scaled [g] (the amplitude with ``scale: pga``; the
    factor times the processed record's PGA with ``scale: factor``; a pair's: the larger
    component's, with ``record_y`` the second record's name and ``pair_times`` how the two
    were put on one time base: ``shared`` (the same sample times) or ``union`` (the union
    of both records' times, each linear between its own samples)), and the vertical
    record's name and scaled peak [g] (None without one); None for another excitation."""
    excitation = config.excitation
    if excitation.type != "record":
        return None
    motion = make_ground_motion(excitation, amplitude_g)
    info = {C.record: motion.name, C.pga_g: float(np.max(np.abs(motion.values))) / G,
            "scale": excitation.scale, "vertical": None, "vertical_peak_g": None}  # fmt: skip
    if motion.values_y is not None:  # a pair: its PGA is the larger component's
        info["record_y"] = Path(str(excitation.file_y)).stem
        info["pair_times"] = pair_times(excitation)
        info[C.pga_g] = max(info[C.pga_g], float(np.max(np.abs(motion.values_y))) / G)
    if motion.vertical is not None:
        info["vertical"] = Path(str(excitation.vertical)).stem
        info["vertical_peak_g"] = float(np.max(np.abs(motion.vertical))) / G
    return info


def vertical_history(config, amplitude_g: float, t) -> np.ndarray | None:
    """a_v [m/s^2], the upward ground acceleration of a record run with a vertical record
    (excitation.vertical, scaled as the run scales it), at the times ``t`` [s]: as the
    run's ground motion gives it (rbm_cli.inputs.motion.GroundMotion, 0 outside the
    record); None without a vertical record."""
    excitation = config.excitation
    if excitation.type != "record" or excitation.vertical is None:
        return None
    motion = make_ground_motion(excitation, amplitude_g)
    knots, vertical = as_samples(motion.knots), as_samples(motion.vertical)
    factor = plain(vertical_factor)  # the run's own statements, not compiled once more
    times = np.asarray(t, dtype=float)
    return np.array([(factor(float(x), knots, vertical) - 1.0) * G for x in times])


def run_summary(
    result: RunResult,
    config,
    *,
    config_path: str | os.PathLike | None,
    amplitude_g: float,
    frequency_hz: float,
    output_dt: float | None,
) -> dict:
    """summary.json: RunResult.summary() plus the resolved inputs, the version and, for a
    record run, what it ran (``record``: :func:`record_of_run`)."""
    summary = dict(result.summary())
    summary["inputs"] = {
        "config_file": os.fspath(config_path) if config_path is not None else None,
        C.amplitude_g: amplitude_g,
        C.frequency_hz: frequency_hz,
        "output_dt_s": output_dt,
    }
    record = record_of_run(config, amplitude_g)
    if record is not None:
        summary[C.record] = record
    summary["config"] = json_ready(config.resolved())
    summary["config_written"] = json_ready(config.written)
    summary["rbm_version"] = __version__
    return json_ready(summary)


def _pngs(figure_process, figures: tuple) -> dict[str, bytes]:
    """{file name: PNG bytes} of the run's figures: the figure child's (their calls
    submitted to it, see :func:`write_run`), or drawn here without one."""
    if figure_process is None:
        return run_pngs(*figures)
    return dict(zip(RUN_PNGS, figure_process.result(), strict=True))


def write_run(
    out_dir: str | os.PathLike,
    name: str,
    folder: str,
    result: RunResult,
    summary: dict,
    *,
    widths,
    elevations,
    figure_process=None,
    vertical=None,
) -> Path:
    """Write history.csv, history.png, shapes.png and summary.json of one run.

    The files are written into a hidden staging folder beside the destination
    ``out_dir/name/folder``, which then replaces its files (or is renamed into
    place). Nothing is left behind if writing fails. With a ``figure_process``
    (rbm_cli.report.figure_process.FigureProcess, `rbm run`'s), its child draws the
    figures side by side (:func:`rbm_cli.report.run_figures.run_png_calls`) while this
    process writes history.csv, and sends back the PNG files' bytes, written here: the
    child writes no file, and this process imports neither matplotlib nor pandas.

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
    figure_process : FigureProcess or None  The child that draws the figures; None: drawn
        in this process
    vertical : (k,) or None  a_v [m/s^2] at the history's times, with a vertical record
        (:func:`vertical_history`): history.csv's av_m_s2 and the figures' a_v

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
        figures = (result.history, t_collapse, summary, widths, elevations, vertical)
        if figure_process is not None:  # drawn by the child while history.csv is written
            figure_process.submit_all(run_png_calls(*figures))
        rows = history_csv(result.history, vertical=vertical)
        write_chunks_atomic(staging / "history.csv", rows)
        for png, data in _pngs(figure_process, figures).items():
            write_chunks_atomic(staging / png, [data])
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
