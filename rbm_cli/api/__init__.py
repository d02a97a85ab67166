"""The library's entry points for scripts, notebooks and the CLI: load a config (a file or a
dict), change a value, run one cell, run a sweep, plot a domain or a history; the `rbm`
package re-exports them (docs/api.md). Above report (it wires the report's figures into the
study's runs), below the CLI, which imports nothing else of the package. Amplitudes in g
(9.81 m/s^2), frequencies in Hz, times in s, lengths in m.

Modules by surface: configs (load, change, check), motions (ground motions given as
arrays), cells (one run, ``rbm run``'s folder), sweeps (in memory or into a folder),
domains (read, compare, draw), column_info (``rbm info``), fragility_curves (its fit
imported when one is made) and bench (imported when that command runs), errors. Each name
is imported from its module when first used.
"""

from __future__ import annotations

import importlib

from rbm_cli import __version__

#: Where each public name lives (rbm_cli.api.<module>): imported on first use, so that the
#: CLI, which reads only an error class and the version at start-up, does not load numba,
#: pandas and the physics for `rbm --help` (PEP 562's module __getattr__).
_HOME = {
    "CellResult": "cells", "CellRun": "cells", "plot_history": "cells", "run": "cells",
    "MAX_HISTORY_SAMPLES": "configs", "Config": "configs", "check_cell": "configs",
    "check_output_dt": "configs", "load_config": "configs", "parse_config": "configs",
    "with_value": "configs", "with_values": "configs",
    "DomainComparison": "domains", "compare": "domains", "plot_domain": "domains",
    "migrate": "domains", "read_domain": "domains",
    "ConfigError": "errors", "RbmError": "errors",
    "fragility": "fragility_curves", "info": "column_info",
    "Motion": "motions", "motion_from_arrays": "motions",
    "SweepInterrupted": "sweeps", "run_sweep": "sweeps", "sweep": "sweeps",
    "read_design": "uncertain", "sensitivity": "uncertain",
}  # fmt: skip


def __getattr__(name: str):
    if name not in _HOME:
        raise AttributeError(f"module 'rbm_cli.api' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"rbm_cli.api.{_HOME[name]}"), name)
    globals()[name] = value  # found once
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_HOME))


__all__ = ["__version__", *sorted(_HOME)]  # every public name, from where it lives
