"""Sweeps for the library and ``rbm sweep``: a config's grid in memory (nothing written)
or into a folder (domain.csv, boundary.csv, domain.png, meta.json)."""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rbm_cli.api.configs import as_config, check_flag
from rbm_cli.api.motions import Motion, motion_config
from rbm_cli.base.errors import RbmError
from rbm_cli.config.types import Config
from rbm_cli.report.figure_process import DOMAIN_IMPORTS, RUN_IMPORTS, FigureProcess, domain_figure
from rbm_cli.study.domain import read_domain
from rbm_cli.study.sweep import SweepInterrupted, SweepSummary, sweep_rows
from rbm_cli.study.sweep import run_sweep as _run_sweep

if TYPE_CHECKING:  # pandas is imported where a DataFrame is built: `rbm sweep` never does
    import pandas as pd

__all__ = [
    "DOMAIN_IMPORTS",
    "RUN_IMPORTS",
    "FigureProcess",
    "SweepInterrupted",
    "SweepSummary",
    "run_sweep",
    "sweep",
]

#: The settings of a sweep in memory (rbm_cli.study.sweep.sweep_rows) besides jobs.
IN_MEMORY_OPTIONS = ("backend", "scheduler", "ensemble", "force", "progress", "notify")
#: The settings only a sweep into a folder takes (rbm_cli.study.sweep.run_sweep).
FOLDER_OPTIONS = ("resume", "stop_after", "resume_command", "figure", "figure_process")
#: The settings that are True or False.
FLAGS = ("force", "resume")


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
    motions: Sequence[Motion] | None = None,
    **options,
) -> pd.DataFrame:
    """Run a config's grid and return its domain: the rows of domain.csv.

    Parameters
    ----------
    config : Config, path or mapping  A config with a grid (amplitudes [g], frequencies [Hz])
    output : path, optional  Output root: writes OUTPUT/<name>/ (domain.csv, boundary.csv,
        domain.png, meta.json) as ``rbm sweep -o OUTPUT``; None: the sweep runs in memory
        and writes nothing (rbm_cli.study.sweep.sweep_rows)
    jobs : int  Worker processes; 1 (the default) runs in this process
    motions : list of Motion, optional  Ground motions given as arrays
        (:func:`motion_from_arrays`, each with its own name), swept as a suite of records
        is: one row per motion and amplitude (grid.amplitudes: their PGA [g], or scale
        factors [-] with ``excitation.scale: factor``; grid.frequencies are not used),
        the motion's name in the ``record`` and ``excitation.file`` columns. They replace
        the config's ground motion (a record config keeps its scale, free time and
        vertical record). Their samples' SHA-256 is in the config's hash: a folder sweep
        (``output``) does not resume over other arrays under the same names. Every other
        key of the config's excitation is kept (:func:`run`'s ``motion``); pairs
        (``acceleration_y``) and motions of one component are not mixed
    **options  Other settings of rbm_cli.study.sweep.run_sweep (resume, force, ensemble...);
        without an output folder those of sweep_rows (backend, scheduler, ensemble, force,
        progress, notify). ``ensemble`` K runs each cell K times: the cells times K are
        the runs counted against the grid's limits (more than 100,000 need
        ``force=True``, more than 1,000,000 are refused)

    Returns
    -------
    pandas.DataFrame  The rows of domain.csv, one per cell (amplitude_g [g], frequency_hz
        [Hz], status, collapsed, t_collapse_s [s], ...); ``attrs["folder"]``: the folder
        (None without an output folder); with ``motions``, ``attrs["motions"]``: them
        (:func:`plot_domain` draws the domain with the config they were swept with)

    Raises
    ------
    RbmError  Bad arguments (one line): an unknown option, a flag that is not a boolean,
        an option that needs an output folder without one, too many runs

    Examples
    --------
    >>> import rbm
    >>> cfg = rbm.load_config({"name": "block", "column": {"height": 2.0, "base_width": 0.5},
    ...     "grid": {"amplitudes": [0.1, 2.5], "frequencies": [0.5, 1.0]}})
    >>> df = rbm.sweep(cfg)
    >>> df[["amplitude_g", "frequency_hz", "status"]].values.tolist()
    [[0.1, 0.5, 'survived'], [2.5, 0.5, 'collapsed'], [0.1, 1.0, 'survived'], [2.5, 1.0, 'collapsed']]
    """  # noqa: E501
    unknown = sorted(set(options) - set(IN_MEMORY_OPTIONS) - set(FOLDER_OPTIONS))
    if unknown:
        raise RbmError(
            f"sweep: unknown option {', '.join(map(repr, unknown))} (allowed: jobs, motions,"
            f" {', '.join(IN_MEMORY_OPTIONS)}; with an output folder also"
            f" {', '.join(FOLDER_OPTIONS)})"
        )
    for name in FLAGS:
        if name in options:
            check_flag(options[name], name)
    cfg = as_config(config)
    if motions is not None:
        cfg = motion_config(cfg, motions, axis=True)
    if output is None:
        folder_only = sorted(set(options) - set(IN_MEMORY_OPTIONS))
        if folder_only:
            raise RbmError(f"{', '.join(folder_only)}: needs an output folder (output=...)")
        df = sweep_rows(cfg, jobs=jobs, **options).frame()
        folder = None
    else:
        summary = run_sweep(cfg, output, jobs=jobs, **options)
        df = read_domain(Path(summary.folder) / "domain.csv")
        folder = str(summary.folder)
    df.attrs["folder"] = folder
    if motions is not None:  # plot_domain(df, config=...) runs the config with them again
        df.attrs["motions"] = tuple(motions)
    return df
