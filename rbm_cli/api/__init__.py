"""The library's entry points for scripts, notebooks and the CLI: load a config (a file or a
dict), change a value, run one cell, run a sweep, plot a domain or a history; the `rbm`
package re-exports them (docs/api.md). Above report (it wires the report's figures into the
study's runs), below the CLI, which imports nothing else of the package. Amplitudes in g
(9.81 m/s^2), frequencies in Hz, times in s, lengths in m.

Modules by surface: configs (load, change, check), motions (ground motions given as
arrays), cells (one run, ``rbm run``'s folder), sweeps (in memory or into a folder),
domains (read, compare, draw), info (``rbm info``), fragility (its fit imported when one is
made) and bench (imported when that command runs), errors.
"""

from __future__ import annotations

from rbm_cli import __version__
from rbm_cli.api.cells import CellResult, CellRun, plot_history, run
from rbm_cli.api.configs import (
    MAX_HISTORY_SAMPLES,
    Config,
    check_cell,
    check_output_dt,
    load_config,
    parse_config,
    with_value,
    with_values,
)
from rbm_cli.api.domains import DomainComparison, compare, plot_domain, read_domain
from rbm_cli.api.errors import ConfigError, RbmError
from rbm_cli.api.fragility import fragility  # the function, in the place of its module's name
from rbm_cli.api.info import info  # the function, in the place of its module's name
from rbm_cli.api.motions import Motion, motion_from_arrays
from rbm_cli.api.sweeps import SweepInterrupted, run_sweep, sweep

__all__ = [
    "MAX_HISTORY_SAMPLES",
    "CellResult",
    "CellRun",
    "Config",
    "ConfigError",
    "DomainComparison",
    "Motion",
    "RbmError",
    "SweepInterrupted",
    "__version__",
    "check_cell",
    "check_output_dt",
    "compare",
    "fragility",
    "info",
    "load_config",
    "motion_from_arrays",
    "parse_config",
    "plot_domain",
    "plot_history",
    "read_domain",
    "run",
    "run_sweep",
    "sweep",
    "with_value",
    "with_values",
]
