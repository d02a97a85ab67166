"""One cell for the library: run a config's model under one ground motion, draw its
history, and (for ``rbm run``) write its run folder and compile its code ahead."""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rbm_cli.api.configs import as_config, check_cell, check_flag, check_output_dt
from rbm_cli.api.motions import Motion, motion_config
from rbm_cli.base.errors import ConfigError, RbmError
from rbm_cli.base.files import check_writable_dir
from rbm_cli.config.load import shown as shown_value
from rbm_cli.config.types import Config
from rbm_cli.models.compile_ahead import compile_once
from rbm_cli.models.methods import compiled_codes
from rbm_cli.report.plots import plot_history as _plot_history
from rbm_cli.report.run_folder import (
    history_frame,
    run_folder_name,
    run_summary,
    vertical_history,
    write_run,
)
from rbm_cli.structures.column import build_column
from rbm_cli.study.result import CSV_FIELDS, RESIDUAL_FIELDS, THREE_D_FIELDS, RunResult
from rbm_cli.study.schema import C
from rbm_cli.study.simulate import simulate

if TYPE_CHECKING:  # pandas is imported where a DataFrame is built: `rbm sweep` never does
    import pandas as pd

__all__ = [
    "CellResult",
    "CellRun",
    "check_run_output",
    "compile_ahead",
    "plot_history",
    "run",
    "write_run_folder",
]


class CellResult(Mapping):
    """Every figure of one cell's run, read-only: a mapping and a record at once.

    Keys (and attributes of the same names), in this order: domain.csv's columns of a
    run, ``amplitude_g`` [g], ``frequency_hz`` [Hz] (None for a record), ``status``
    ('collapsed', 'survived' or 'failed'), ``t_collapse_s`` [s] (nan if none),
    ``collapse_interface`` (int, 1 at the ground; None without a collapse),
    ``max_rotation_ratio`` [-] (the largest rotation over its collapse limit),
    ``max_top_displacement_m`` [m], for a run in three dimensions (as domain.csv)
    ``collapse_azimuth_deg`` [deg from x, in (-180, 180]; nan if it did not collapse] and
    ``wobble_turns`` [-], for the contact engine (model bullet, as domain.csv)
    ``residual_slip_m`` [m] (the largest |slip| of a joint where the run ended: the motion
    and its free time over, or at rest after the pulse), ``residual_top_offset_m`` [m] (the
    top's offset in plan from its start there) and ``residual_tilt_ratio`` [-] (the largest
    |relative rotation| / alpha_i of a joint there), nan if it collapsed or failed (an
    attribute of every model's result, nan for the others), then ``n_uplifts``,
    ``n_impacts``, ``n_steps``, ``n_rhs`` (int),
    ``message``, then ``friction_demand`` (per interface, the largest |T/N| held in
    one direction for 0.03 s [-]), ``friction_demand_peak`` (per interface, its
    instantaneous peak [-]; empty for the models without the RBM's joints),
    ``wall_time_s`` [s], ``method`` (the method that ran), ``friction_limit`` (the
    interface.friction of a model with the RBM's joints, rbm and rbm-3d, the coefficient
    the demand is checked against; None: not checked), ``slip`` ((t [s], interface) where
    the demand was first held above it, the start of its 0.03 s; None: it did not, or no
    check) and ``energy`` (a recorded
    run's energy account [J] where its method keeps one: ``initial_J``, ``final_J``,
    ``ground_work_J``, ``damping_J``, ``impacts_J``, ``residual_J``; else None). Whole
    numbers are ints, real numbers floats. The outputs reference defines the counts.

    Examples
    --------
    >>> import rbm
    >>> cfg = rbm.load_config({"name": "block", "column": {"height": 2.0, "base_width": 0.5}})
    >>> r = rbm.run(cfg, amplitude_g=2.5, frequency_hz=0.5, record=False).result
    >>> "max_rotation_ratio" in r, r["status"], r.collapse_interface, type(r["n_uplifts"])
    (True, 'collapsed', 1, <class 'int'>)
    >>> list(r)[:3]
    ['amplitude_g', 'frequency_hz', 'status']
    """

    __slots__ = ("_run", "_values")

    def __init__(self, run: RunResult) -> None:
        values = {}
        for k in FIELDS:
            values[k] = getattr(run, k)
            if k == C.max_top_displacement_m and run.three_d:  # where domain.csv has them
                values.update({extra: float(getattr(run, extra)) for extra in THREE_D_FIELDS})
            if k == C.max_top_displacement_m and run.residual:
                values.update({extra: float(getattr(run, extra)) for extra in RESIDUAL_FIELDS})
        interface = values[C.collapse_interface]
        values[C.collapse_interface] = None if interface is None else int(interface)
        for k in (C.n_uplifts, C.n_impacts, C.n_steps, C.n_rhs):
            values[k] = int(values[k])
        for k in (C.amplitude_g, C.t_collapse_s, C.max_rotation_ratio, C.max_top_displacement_m,
                  "wall_time_s"):  # fmt: skip
            values[k] = float(values[k])
        values[C.friction_demand] = tuple(float(v) for v in values[C.friction_demand])
        values["friction_demand_peak"] = tuple(float(v) for v in values["friction_demand_peak"])
        object.__setattr__(self, "_run", run)
        object.__setattr__(self, "_values", values)

    def __getitem__(self, key: str):
        return self._values[key]

    def __iter__(self):
        return iter(self._values)

    def __len__(self) -> int:
        return len(self._values)

    def __getattr__(self, name: str):
        values = object.__getattribute__(self, "_values")
        if name in values:
            return values[name]
        return getattr(object.__getattribute__(self, "_run"), name)  # history, row(), ...

    def __setattr__(self, name, value):
        raise AttributeError("a cell's result is read-only")

    def __repr__(self) -> str:
        shown = ", ".join(f"{k}={self._values[k]!r}" for k in FIELDS[:6])
        return f"CellResult({shown}, ...)"

    @property
    def run_result(self) -> RunResult:
        """The model's RunResult it was read from (rbm_cli.study.result)."""
        return self._run


#: CellResult's keys, in order: domain.csv's columns of a run (the collapsed flag is
#: status == 'collapsed'), then figures a domain does not keep.
FIELDS = tuple(k for k in CSV_FIELDS if k not in (C.collapsed, C.friction_demand)) + (
    C.friction_demand,
    "friction_demand_peak",
    "wall_time_s",
    "method",
    "friction_limit",
    "slip",
    "energy",
)


@dataclass(frozen=True)
class CellRun:
    """One cell's run: its outcome, times and (when recorded) its history.

    Attributes
    ----------
    config : Config  The config it ran (for a ``motion``: the record config that ran it)
    result : CellResult  Every figure of the run, a read-only mapping with attribute
        access: amplitude_g [g], frequency_hz [Hz], max_rotation_ratio [-],
        max_top_displacement_m [m], collapse_interface (int or None), n_uplifts,
        n_impacts, wall_time_s [s], ...
    status : str  'collapsed', 'survived' or 'failed'
    t_collapse_s : float  Time of collapse [s]; nan if none
    history : pandas.DataFrame or None  The history (with ``record=True``)

    Examples
    --------
    >>> import rbm
    >>> cfg = rbm.load_config({"name": "block", "column": {"height": 2.0, "base_width": 0.5}})
    >>> cell = rbm.run(cfg, amplitude_g=0.1, frequency_hz=1.0)
    >>> cell.status, cell.result["collapse_interface"]
    ('survived', None)
    """

    config: Config
    result: CellResult

    @property
    def status(self) -> str:
        return self.result.status

    @property
    def t_collapse_s(self) -> float:
        return self.result.t_collapse_s

    @cached_property
    def history(self) -> pd.DataFrame | None:
        """history.csv's table (None unless recorded): t_s [s], ag_m_s2 [m/s^2], av_m_s2
        [m/s^2] (the upward ground acceleration, with a vertical record only) and ug_m [m]
        (ground), u1_m..u{n+1}_m (nodes, relative to the ground) [m], theta1_rad.. [rad]."""
        history = self.result.history
        if history is None:
            return None
        vertical = vertical_history(self.config, self.result.run_result.amplitude_g, history.t)
        return history_frame(history, vertical)


def run(
    config: Config | str | os.PathLike | Mapping[str, Any],
    amplitude_g: float | None = None,
    frequency_hz: float | None = None,
    *,
    motion: Motion | None = None,
    record: bool = True,
    output_dt: float | None = None,
) -> CellRun:
    """Run one cell of a config: its model under one ground motion.

    Parameters
    ----------
    config : Config, path or mapping  The config (else loaded with :func:`load_config`)
    amplitude_g : float  Peak ground acceleration [g], in [0, 1000] (not used by `free`);
        of a record or a ``motion``: its PGA after scaling (``excitation.scale: pga``, the
        default; of a pair, the larger of its two components') or a plain scale factor
        [-] (``scale: factor``)
    frequency_hz : float  Excitation frequency [Hz], in [0.001, 1000] (not used by
        `free`; refused for a record or a ``motion``, which have none)
    motion : Motion, optional  A ground motion given as arrays
        (:func:`motion_from_arrays`, a pair with ``acceleration_y``), run as a record of
        the config would be: in its place, with every other key of the config's
        excitation (a record config's scale, free time, vertical record, processing,
        im_periods; any config's angle and initial conditions); another excitation's form
        is replaced (scale pga, 5 s of free motion after the last sample). A config's
        ``excitation.file_y`` is refused beside it (a pair as arrays: ``acceleration_y``)
    record : bool  True or False: keep the history, as ``rbm run`` (the run goes on to
        the end of the motion or to collapse); False: as a sweep, stop once the outcome
        cannot change
    output_dt : float, optional  Sampling interval of the history [s]; default 0.002 s

    Returns
    -------
    CellRun  ``.status``, ``.t_collapse_s`` [s], ``.history`` (a DataFrame), ``.result``

    Raises
    ------
    RbmError  A missing or out-of-range amplitude or frequency, a frequency for a record
        or a motion, a ``record`` that is not a boolean, a bad config (one line)

    Examples
    --------
    >>> import rbm
    >>> cfg = rbm.load_config({"name": "block", "column": {"height": 2.0, "base_width": 0.5}})
    >>> calm = rbm.run(cfg, amplitude_g=0.1, frequency_hz=1.0)  # below B/H = 0.25 g
    >>> calm.status, float(calm.history["theta1_rad"].abs().max())
    ('survived', 0.0)
    >>> list(calm.history.columns)
    ['t_s', 'ag_m_s2', 'ug_m', 'u1_m', 'u2_m', 'theta1_rad']
    >>> rbm.run(cfg, amplitude_g=2.5, frequency_hz=0.5).status  # ten times B/H
    'collapsed'
    """
    cfg = as_config(config)
    check_flag(record, "record")
    if motion is not None:
        if not isinstance(motion, Motion):
            raise ConfigError(
                f"motion must be a motion (rbm.motion_from_arrays), got {type(motion).__name__}"
            )
        cfg = motion_config(cfg, [motion], axis=False)
    if frequency_hz is not None and cfg.excitation.type == "record":
        what = "a motion given as arrays" if motion is not None else "a record"
        raise RbmError(
            f"frequency_hz does not apply to {what} (its samples are the motion), got"
            f" {shown_value(frequency_hz)}: leave it out"
        )
    amplitude_g, frequency_hz = check_cell(cfg, amplitude_g, frequency_hz)
    output_dt = check_output_dt(cfg, output_dt)
    result = simulate(cfg, amplitude_g, frequency_hz, record=record, output_dt=output_dt)
    return CellRun(config=cfg, result=CellResult(result))


def plot_history(run: CellRun | RunResult, ax=None, relative: bool | None = None):
    """Draw a run's base and top displacement [m] against time [s] on a matplotlib axes.

    Parameters
    ----------
    run : CellRun, CellResult or RunResult  A recorded run; its collapse time is marked
    ax : matplotlib Axes, optional  None: a new Figure, not held by pyplot
    relative : bool or None  True: the top relative to the ground, the ground's
        displacement on a right axis of its own; False: both on one scale; None (default):
        relative when the ground's displacement dwarfs the column's (a record that drifts)

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import rbm
    >>> cfg = rbm.load_config({"name": "block", "column": {"height": 2.0, "base_width": 0.5}})
    >>> ax = rbm.plot_history(rbm.run(cfg, amplitude_g=2.5, frequency_hz=0.5))
    >>> ax.get_xlabel()
    'time [s]'
    """
    result = run.result if isinstance(run, CellRun) else run
    if isinstance(result, CellResult):
        result = result.run_result
    if not isinstance(result, RunResult):
        raise RbmError(f"plot_history takes a run, got a value of type {type(run).__name__}")
    if result.history is None:
        raise RbmError("this run kept no history: run it with record=True")
    return _plot_history(result.history, ax=ax, t_collapse=result.t_collapse_s, relative=relative)


# --------------------------------------------------------------------------- rbm run


def compile_ahead(config: Config, notify: Callable[[str], None]) -> None:
    """Compile (or load) the compiled code a run of ``config`` needs (the kernel, the exact
    integrator, or the rigid block's closed form: rbm_cli.models.methods.compiled_codes)
    before it runs; a compile another rbm process runs is waited for, not repeated
    (rbm_cli.models.compile_ahead.compile_once), and ``notify`` is told what it waits
    for. Nothing to do for a run in Python (``solver.implementation: python``) or a model
    without compiled code."""
    for code in compiled_codes(config):
        compile_once(code, notify=notify)


def check_run_output(config: Config, output: str | os.PathLike):
    """Before a run: OUTPUT/<name>/ can be written, and the column can be built; returns
    the column (rbm_cli.structures.column.build_column) that :func:`write_run_folder` draws.

    Raises
    ------
    RbmError  An unwritable folder or a bad column (one line)
    """
    check_writable_dir(Path(output) / config.name)
    return build_column(config.column, config.interface)


def write_run_folder(config: Config, column, result: RunResult | CellResult,
                     output: str | os.PathLike, config_path: str | None, amplitude_g: float,
                     frequency_hz: float | None, output_dt: float | None,
                     figure_process=None) -> Path:  # fmt: skip
    """Write a run's folder OUTPUT/<name>/run_A<A>_f<F>/ (history.csv, history.png,
    shapes.png, summary.json: rbm_cli.report.run_folder.write_run); returns the folder.
    figure_process: the rbm_cli.report.figure_process.FigureProcess that draws the
    figures, or None to draw them here."""
    if isinstance(result, CellResult):
        result = result.run_result
    summary = run_summary(result, config, config_path=config_path, amplitude_g=amplitude_g,
                          frequency_hz=frequency_hz, output_dt=output_dt)  # fmt: skip
    vertical = vertical_history(config, amplitude_g, result.history.t) \
        if result.history is not None else None  # fmt: skip
    return write_run(
        output,
        config.name,
        run_folder_name(amplitude_g, frequency_hz, config.excitation.type),
        result,
        summary,
        widths=column.widths,
        elevations=list(column.bottoms) + [column.height],
        figure_process=figure_process,
        vertical=vertical,
    )
