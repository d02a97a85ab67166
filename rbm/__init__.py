"""rbm: seismic rocking of freestanding stone columns with the Rigid Beam Model, from Python.

The surface of :mod:`rbm_cli.api` (the functions the ``rbm`` command runs), documented in
docs/api.md. Units at this edge: amplitudes in g (9.81 m/s^2), frequencies in Hz, times in
s; inside a config lengths in m and stiffnesses in N m/rad or Pa/m.

- :func:`load_config` a YAML file or a dict; :func:`with_value` / :func:`with_values` change
  values by dotted key path (``"column.height"``), validated again
- :func:`run` one cell (amplitude [g], frequency [Hz]): a :class:`CellRun` with ``.status``,
  ``.t_collapse_s`` [s] and ``.history`` (a pandas DataFrame)
- :func:`sweep` a config's grid: a DataFrame with the rows of domain.csv;
  :func:`read_domain` reads a stored one
- :func:`plot_domain`, :func:`plot_history` draw on a matplotlib axes and return it

Examples
--------
>>> import rbm
>>> cfg = rbm.load_config({"name": "block", "column": {"height": 2.0, "base_width": 0.5}})
>>> rbm.run(cfg, amplitude_g=0.1, frequency_hz=1.0).status  # below B/H = 0.25 g
'survived'
>>> rbm.with_value(cfg, "column.height", 4.0).column.height
4.0
"""

from rbm_cli.api import (
    CellRun,
    Config,
    ConfigError,
    RbmError,
    SweepInterrupted,
    __version__,
    load_config,
    plot_domain,
    plot_history,
    read_domain,
    run,
    sweep,
    with_value,
    with_values,
)

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
    "sweep",
    "with_value",
    "with_values",
]
