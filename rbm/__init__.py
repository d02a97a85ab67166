"""rbm: seismic rocking of freestanding stone columns with the Rigid Beam Model, from Python.

The surface of :mod:`rbm_cli.api` (the functions the ``rbm`` command runs), documented in
docs/api.md. Units at this edge: amplitudes in g (9.81 m/s^2), frequencies in Hz, times in
s; inside a config lengths in m and stiffnesses in N m/rad or Pa/m. Every name has a
docstring with its units and an example (``help(rbm.run)``).

- :func:`load_config` a YAML file or a dict; :func:`with_value` / :func:`with_values` change
  values by dotted key path (``"column.height"``), validated again
- :func:`info` what ``rbm info`` prints: masses, capacities, frequencies, as data
- :func:`run` one cell (amplitude [g], frequency [Hz], or a ``motion``): a :class:`CellRun`
  with ``.status``, ``.t_collapse_s`` [s], ``.history`` (a pandas DataFrame) and
  ``.result`` (a :class:`CellResult`, a read-only mapping of every figure of the run)
- :func:`motion_from_arrays` a ground motion given as arrays (times [s], acceleration in g
  or m/s^2; a second horizontal component on the same times, ``acceleration_y``, for a
  pair), checked as a record file is: a :class:`Motion` to run or sweep as a record
- :func:`sweep` a config's grid (or a suite of motions, ``motions=[...]``): a DataFrame
  with the rows of domain.csv; :func:`read_domain` reads a stored one
- :func:`compare` two domains, as ``rbm compare`` (a :class:`DomainComparison`);
  :func:`fragility` the lognormal fragility of a suite's domain with its bootstrap band,
  as ``rbm fragility`` fits it (no files)
- :func:`read_design` the design of a config's uncertain keys (a row per sample: the value
  each key takes), or of a domain swept with them; :func:`sensitivity` which uncertain key
  moves a domain's outcome most (rank correlations, as ``rbm sensitivity``)
- :func:`migrate` brings a domain stored by an earlier rbm to this version's config hash,
  once it has checked that the domain was made by the config this version reads from it
- :func:`plot_domain`, :func:`plot_history` draw on a matplotlib axes and return it
- :class:`Config`, :class:`ConfigError`, :class:`RbmError`, :class:`SweepInterrupted`,
  ``__version__``

Examples
--------
>>> import numpy as np, rbm
>>> cfg = rbm.load_config({"name": "block", "column": {"height": 2.0, "base_width": 0.5}})
>>> rbm.run(cfg, amplitude_g=0.1, frequency_hz=1.0).status  # below B/H = 0.25 g
'survived'
>>> rbm.with_value(cfg, "column.height", 4.0).column.height
4.0
>>> t = np.linspace(0.0, 1.0, 1001)  # [s]: a half-sine of 1 s
>>> pulse = rbm.motion_from_arrays(t, np.sin(np.pi * t), units="g", name="pulse")
>>> rbm.run(cfg, amplitude_g=2.5, motion=pulse).status  # its PGA scaled to ten times B/H
'collapsed'
"""

from rbm_cli.api import (
    CellResult,
    CellRun,
    Config,
    ConfigError,
    DomainComparison,
    Motion,
    RbmError,
    SweepInterrupted,
    __version__,
    compare,
    fragility,
    info,
    load_config,
    migrate,
    motion_from_arrays,
    plot_domain,
    plot_history,
    read_design,
    read_domain,
    run,
    sensitivity,
    sweep,
    with_value,
    with_values,
)

__all__ = [
    "CellResult",
    "CellRun",
    "Config",
    "ConfigError",
    "DomainComparison",
    "Motion",
    "RbmError",
    "SweepInterrupted",
    "__version__",
    "compare",
    "fragility",
    "info",
    "load_config",
    "migrate",
    "motion_from_arrays",
    "plot_domain",
    "plot_history",
    "read_design",
    "read_domain",
    "run",
    "sensitivity",
    "sweep",
    "with_value",
    "with_values",
]
