"""The library's entry points for scripts, notebooks and the CLI: load a config (a file or a
dict), change a value, run one cell, run a sweep, plot a domain or a history; the `rbm`
package re-exports them (docs/api.md). Above report (it wires the report's figures into the
study's runs), below the CLI. Amplitudes in g (9.81 m/s^2), frequencies in Hz, times in s,
lengths in m.
"""

from __future__ import annotations

import copy
import math
import os
import re
import tempfile
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from rbm_cli import __version__
from rbm_cli.base.errors import ConfigError, RbmError
from rbm_cli.config.load import AMPLITUDE_RANGE_G, FREQUENCY_RANGE_HZ, parse_config
from rbm_cli.config.load import load_config as _load_file
from rbm_cli.config.types import Config
from rbm_cli.config.validate import describe, fmt, is_number
from rbm_cli.config.written import plain_copy
from rbm_cli.models.result import RunResult
from rbm_cli.report.figure_process import domain_figure
from rbm_cli.report.plots import plot_history as _plot_history
from rbm_cli.report.run_folder import history_frame
from rbm_cli.study.domain import read_domain
from rbm_cli.study.simulate import simulate
from rbm_cli.study.sweep import SweepInterrupted, SweepSummary
from rbm_cli.study.sweep import run_sweep as _run_sweep

if TYPE_CHECKING:  # pandas is imported where a DataFrame is built: `rbm sweep` never does
    import pandas as pd

__all__ = [
    "CellRun",
    "Config",
    "ConfigError",
    "RbmError",
    "SweepInterrupted",
    "__version__",
    "load_config",
    "plot_domain",
    "plot_history",
    "read_domain",
    "run",
    "run_sweep",
    "sweep",
    "with_value",
    "with_values",
]

#: One key of a key path.
_KEY = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


# --------------------------------------------------------------------------- configs


def load_config(source: str | os.PathLike | Mapping[str, Any]) -> Config:
    """A validated config from a YAML file or from a mapping (a dict).

    Parameters
    ----------
    source : str, path-like or mapping  A YAML file or the mapping it holds (numbers may be
        numpy numbers, lists numpy arrays); lengths [m], stiffnesses [N m/rad] or [Pa/m],
        grid amplitudes [g] and frequencies [Hz] (SPEC section 4)

    Returns
    -------
    Config  Frozen, in SI (the grid in g and Hz); ``Config.written`` keeps the mapping

    Raises
    ------
    ConfigError  One line naming the key path (``<dict>: column.height must be ...``)

    Examples
    --------
    >>> import rbm
    >>> cfg = rbm.load_config({"name": "block", "column": {"height": 2.0, "base_width": 0.5}})
    >>> cfg.column.height, cfg.model
    (2.0, 'rbm')
    >>> cfg = rbm.load_config("configs/spanos_koh_slender.yaml")  # doctest: +SKIP
    """
    if isinstance(source, Mapping):
        return parse_config(source, "<dict>")
    if isinstance(source, str | os.PathLike):
        return _load_file(source)
    raise ConfigError(f"a config is a YAML file's path or a mapping, got {type(source).__name__}")


def _as_config(config: Config | str | os.PathLike | Mapping[str, Any]) -> Config:
    return config if isinstance(config, Config) else load_config(config)


def with_values(config: Config, changes: Mapping[str, Any]) -> Config:
    """The config with values changed at dotted key paths, validated again: the changes are
    made on the mapping the user wrote (``config.written``), validated as a file is.

    Parameters
    ----------
    config : Config  A config from :func:`load_config`; it is not changed
    changes : mapping  {key path: value}, paths as error messages name them, in the config's
        units: ``column.height`` [m], ``interface.stiffness.normal`` [Pa/m], ``column.drums``
        (a list is given whole). Missing sections are made; a value on the way that is not
        a mapping (``stiffness: rigid``) is replaced by one

    Returns
    -------
    Config  The new config

    Raises
    ------
    ConfigError  A malformed path, or a bad value (one line naming its key path)

    Examples
    --------
    >>> import rbm
    >>> cfg = rbm.load_config({"name": "block", "column": {"height": 2.0, "base_width": 0.5}})
    >>> taller = rbm.with_values(cfg, {"column.height": 4.0, "interface.restitution": 0.9})
    >>> taller.column.height, taller.interface.restitution, cfg.column.height
    (4.0, 0.9, 2.0)
    """
    if config.written is None:
        raise ConfigError(f"config {config.name} keeps no written mapping: use rbm.load_config")
    if not isinstance(changes, Mapping):
        raise ConfigError(f"changes must be a mapping {{key path: value}}, got {describe(changes)}")
    written = copy.deepcopy(config.written)
    told = ", ".join(f"{path} = {_shown(value)}" for path, value in changes.items())
    source = f"{config.name} with {told}" if told else config.name
    try:
        for path, value in changes.items():
            _set(written, path, plain_copy(value))
    except ConfigError as exc:
        raise ConfigError(f"{source}: {exc}") from None
    return parse_config(written, source)


def _shown(value: Any) -> str:
    """A value as a message shows it: numbers as written (a numpy number as its number),
    anything else by its repr, cut to 60 characters."""
    if isinstance(value, np.generic | np.ndarray) and np.ndim(value) == 0:
        value = value.item()
    if is_number(value):
        return fmt(value)
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def with_value(config: Config, path: str, value: Any) -> Config:
    """The config with one value changed at a dotted key path, validated again.

    ``with_value(cfg, path, value)`` is ``with_values(cfg, {path: value})`` (which see).

    Examples
    --------
    >>> import rbm
    >>> cfg = rbm.load_config({"name": "block", "column": {"height": 2.0, "base_width": 0.5}})
    >>> rbm.with_value(cfg, "column.height", 6.0).column.height
    6.0
    >>> rbm.with_value(cfg, "column.height", -1.0)
    Traceback (most recent call last):
    ...
    rbm_cli.base.errors.ConfigError: block with column.height = -1: column.height must be a number > 0 [m], got -1
    """  # noqa: E501
    return with_values(config, {path: value})


def _set(data: dict, path: str, value: Any) -> None:
    """Set ``value`` at a dotted key path in the nested mapping ``data``."""
    keys = path.split(".") if isinstance(path, str) else []
    if not keys or not all(_KEY.fullmatch(key) for key in keys):
        raise ConfigError(f"{path!r} is not a key path (keys joined by dots: column.height)")
    node = data
    for key in keys[:-1]:
        if not isinstance(node.get(key), dict):
            node[key] = {}
        node = node[key]
    node[keys[-1]] = value


# --------------------------------------------------------------------------- one cell


@dataclass(frozen=True)
class CellRun:
    """One cell's run: its outcome, times and (when recorded) its history.

    Attributes
    ----------
    config : Config  The config it ran
    result : RunResult  Every figure of the run (rbm_cli.models.result.RunResult): amplitude_g
        [g], frequency_hz [Hz], max_rotation_ratio [-], max_top_displacement_m [m],
        n_uplifts, n_impacts, wall_time_s [s], ...
    status : str  'collapsed', 'survived' or 'failed'
    t_collapse_s : float  Time of collapse [s]; nan if none
    """

    config: Config
    result: RunResult

    @property
    def status(self) -> str:
        return self.result.status

    @property
    def t_collapse_s(self) -> float:
        return self.result.t_collapse_s

    @cached_property
    def history(self) -> pd.DataFrame | None:
        """history.csv's table (None unless recorded): t_s [s], ag_m_s2 [m/s^2] and ug_m [m]
        (ground), u1_m..u{n+1}_m (nodes, relative to the ground) [m], theta1_rad.. [rad]."""
        return None if self.result.history is None else history_frame(self.result.history)


def run(
    config: Config | str | os.PathLike | Mapping[str, Any],
    amplitude_g: float | None = None,
    frequency_hz: float | None = None,
    *,
    record: bool = True,
    output_dt: float | None = None,
) -> CellRun:
    """Run one cell of a config: its model under one ground motion.

    Parameters
    ----------
    config : Config, path or mapping  The config (else loaded with :func:`load_config`)
    amplitude_g : float  Peak ground acceleration [g], in [0, 1000] (not used by `free`)
    frequency_hz : float  Excitation frequency [Hz], in [0.001, 1000] (not used by `free`)
    record : bool  Keep the history, as ``rbm run`` (the run goes on to the end of the
        motion or to collapse); False: as a sweep, stop once the outcome cannot change
    output_dt : float, optional  Sampling interval of the history [s]; default 0.002 s

    Returns
    -------
    CellRun  ``.status``, ``.t_collapse_s`` [s], ``.history`` (a DataFrame), ``.result``

    Raises
    ------
    RbmError  A missing or out-of-range amplitude or frequency, a bad config (one line)

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
    cfg = _as_config(config)
    amplitude_g, frequency_hz = check_cell(cfg, amplitude_g, frequency_hz)
    output_dt = check_output_dt(cfg, output_dt)
    result = simulate(cfg, amplitude_g, frequency_hz, record=record, output_dt=output_dt)
    return CellRun(config=cfg, result=result)


#: Most samples a run's history may have (duration / output_dt).
MAX_HISTORY_SAMPLES = 10_000_000


def check_cell(config: Config, amplitude_g: Any, frequency_hz: Any) -> tuple[float, float | None]:
    """(amplitude [g], frequency [Hz] or None) of one cell of ``config``, checked: numbers
    (not booleans) in the grid's ranges; a record has no frequency, ``free`` neither
    (both 0).

    Raises
    ------
    RbmError  One line naming the argument, its range and the value given
    """
    kind = config.excitation.type
    if kind == "free":
        return 0.0, 0.0
    checks = [("amplitude_g", amplitude_g, AMPLITUDE_RANGE_G, "g")]
    if kind != "record":
        checks.append(("frequency_hz", frequency_hz, FREQUENCY_RANGE_HZ, "Hz"))
    for name, value, (lo, hi), unit in checks:
        if value is None:
            raise RbmError(f"{name} [{unit}] is required for excitation.type {kind}")
        if not (_finite(value) and lo <= value <= hi):
            raise RbmError(
                f"{name} must be a number in [{lo:g}, {hi:g}] [{unit}], got {_shown(value)}"
            )
    return float(amplitude_g), None if kind == "record" else float(frequency_hz)


def check_output_dt(config: Config, output_dt: Any) -> float | None:
    """The history's sampling interval [s], checked: None (the default), or a number > 0
    that gives at most :data:`MAX_HISTORY_SAMPLES` samples over the run.

    Raises
    ------
    RbmError  One line naming the problem
    """
    if output_dt is None:
        return None
    if not (_finite(output_dt) and output_dt > 0.0):
        raise RbmError(f"output_dt must be a number > 0 [s], got {_shown(output_dt)}")
    samples = config.excitation.duration / float(output_dt)
    if samples > MAX_HISTORY_SAMPLES:
        raise RbmError(
            f"output_dt {fmt(float(output_dt))} s gives {samples:.3g} samples over"
            f" {fmt(config.excitation.duration)} s (at most {MAX_HISTORY_SAMPLES:,}):"
            " use a larger output_dt"
        )
    return float(output_dt)


def _finite(value: Any) -> bool:
    """A finite real number: int, float or a numpy number (a 0-d array's), not a boolean."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value.item()
    if isinstance(value, bool | np.bool_) or not isinstance(value, int | float | np.number):
        return False
    return not isinstance(value, np.complexfloating) and math.isfinite(value)


# --------------------------------------------------------------------------- sweeps


def run_sweep(
    config: Config,
    output: str | os.PathLike = "out",
    *args,
    figure: Callable[[pd.DataFrame, Config], object] | None = None,
    figure_process=None,
    **kwargs,
) -> SweepSummary:
    """Run a config's grid into OUTPUT/<name>/ (domain.csv, boundary.csv, domain.png, meta.json):
    rbm_cli.study.sweep.run_sweep with the domain figure (or `figure`; the CLI's figure_process
    draws the former in its child). Same parameters; :func:`sweep` returns the domain itself."""
    draw = figure if figure is not None else domain_figure
    if figure_process is not None and draw is figure_process.draws:
        draw = figure_process.figure
    return _run_sweep(config, output, *args, figure=draw, **kwargs)


def sweep(
    config: Config | str | os.PathLike | Mapping[str, Any],
    output: str | os.PathLike | None = None,
    *,
    jobs: int = 1,
    **options,
) -> pd.DataFrame:
    """Run a config's grid and return its domain: the rows of domain.csv.

    Parameters
    ----------
    config : Config, path or mapping  A config with a grid (amplitudes [g], frequencies [Hz])
    output : path, optional  Output root: writes OUTPUT/<name>/ (domain.csv, boundary.csv,
        domain.png, meta.json) as ``rbm sweep -o OUTPUT``; None: a temporary folder,
        deleted once the domain is read
    jobs : int  Worker processes; 1 (the default) runs in this process
    **options  Other settings of rbm_cli.study.sweep.run_sweep (resume, force, ensemble...)

    Returns
    -------
    pandas.DataFrame  The rows of domain.csv, one per cell (amplitude_g [g], frequency_hz
        [Hz], status, collapsed, t_collapse_s [s], ...); ``attrs["folder"]``: the folder

    Examples
    --------
    >>> import rbm
    >>> cfg = rbm.load_config({"name": "block", "column": {"height": 2.0, "base_width": 0.5},
    ...     "grid": {"amplitudes": [0.1, 2.5], "frequencies": [0.5, 1.0]}})
    >>> df = rbm.sweep(cfg)
    >>> df[["amplitude_g", "frequency_hz", "status"]].values.tolist()
    [[0.1, 0.5, 'survived'], [2.5, 0.5, 'collapsed'], [0.1, 1.0, 'survived'], [2.5, 1.0, 'collapsed']]
    """  # noqa: E501
    cfg = _as_config(config)
    with tempfile.TemporaryDirectory(prefix="rbm-sweep-") as tmp:
        summary = run_sweep(cfg, tmp if output is None else output, jobs=jobs, **options)
        df = read_domain(Path(summary.folder) / "domain.csv")
    df.attrs["folder"] = None if output is None else str(summary.folder)
    return df


# --------------------------------------------------------------------------- plots


def plot_domain(
    df: pd.DataFrame,
    ax=None,
    config: Config | str | os.PathLike | Mapping[str, Any] | None = None,
    *,
    dimensionless: bool = False,
    layout: str = "auto",
    **options,
):
    """Draw a safe-unsafe domain (frequency [Hz] x amplitude [g]) on a matplotlib axes.

    Parameters
    ----------
    df : pandas.DataFrame  A domain: :func:`sweep`'s or :func:`read_domain`'s
    ax : matplotlib Axes, optional  None: a new Figure, not held by pyplot
    config : Config, path or mapping, optional  The config swept: adds the level [g] where
        the column starts to rock (B/H for a rigid monolith) and the closed forms that apply
    dimensionless : bool  Axes omega / p and A / (g tan alpha) instead (read from the domain's
        scale columns, or computed from ``config`` for domains written before them)
    layout : str  A domain over more axes than amplitude and frequency: 'panels' (one per
        point of the others), 'overlay' (each point's boundary a line) or 'auto'
        (rbm_cli.report.domain_view: with one frequency the innermost axis goes on x)
    **options  For rbm_cli.report.plot_domain.plot_domain (compare, labels, ...)

    Returns
    -------
    matplotlib Axes  (panels: the list of their axes, in the place of ``ax``)

    Examples
    --------
    >>> import rbm
    >>> ax = rbm.plot_domain(rbm.read_domain("out/block/domain.csv"))  # doctest: +SKIP
    """
    from rbm_cli.report.domain_figure import draw_domain_on  # matplotlib, pandas: when drawn

    cfg = None if config is None else _as_config(config)
    return draw_domain_on(df, ax, cfg, dimensionless=dimensionless, layout=layout, **options)


def plot_history(run: CellRun | RunResult, ax=None):
    """Draw a run's base and top displacement [m] against time [s] on a matplotlib axes.

    Parameters
    ----------
    run : CellRun or RunResult  A recorded run; its collapse time is marked
    ax : matplotlib Axes, optional  None: a new Figure, not held by pyplot

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
    if not isinstance(result, RunResult):
        raise RbmError(f"plot_history takes a run, got a value of type {type(run).__name__}")
    if result.history is None:
        raise RbmError("this run kept no history: run it with record=True")
    return _plot_history(result.history, ax=ax, t_collapse=result.t_collapse_s)
