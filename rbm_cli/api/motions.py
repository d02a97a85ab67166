"""Ground motions given as arrays, for the library: made and checked as a record file's
samples are (rbm_cli.config.motions), and run as a record of the config would be: one cell
(``rbm.run(cfg, a, motion=m)``) or a suite of them (``rbm.sweep(cfg, motions=[...])``)."""

from __future__ import annotations

import copy
from collections.abc import Sequence

from rbm_cli.base.errors import ConfigError
from rbm_cli.config.load import parse_config
from rbm_cli.config.motions import Motion, unique_names
from rbm_cli.config.motions import motion_from_arrays as _from_arrays
from rbm_cli.config.types import Config

__all__ = ["Motion", "motion_config", "motion_from_arrays"]

#: The keys of a record excitation a motion keeps from the config (the file is the motion).
RECORD_KEYS = ("type", "initial", "units", "free_time", "scale", "vertical")


def motion_from_arrays(time_s, acceleration, units: str = "g", name: str | None = None) -> Motion:
    """A ground motion from arrays, checked as a record file is, to run as a record.

    Parameters
    ----------
    time_s : list or numpy array of float  Sample times [s]: the first >= 0, strictly
        increasing (the steps may be uneven, as a CSV record's)
    acceleration : list or numpy array of float  Horizontal ground acceleration at those
        times, in ``units``; positive in +x. Linear between samples, 0 before the first
        and after the last (as a record file's)
    units : str  'g' (9.81 m/s^2, the default) or 'm/s2' (also 'm/s^2')
    name : str, optional  Its name in a domain (the ``record`` and ``excitation.file``
        columns); default ``motion-`` and the first 8 hex digits of its SHA-256

    Returns
    -------
    Motion  Read-only: ``.name``, ``.time_s`` [s], ``.acceleration_m_s2`` [m/s^2],
        ``.pga_g`` [g], ``.duration_s`` [s], ``.sha256`` (of the samples in SI, its
        identity in a sweep's config hash, as a record file's digest is)

    Raises
    ------
    ConfigError  One line naming the problem, as for a record file (a sample is named by
        its index): lengths, fewer than 2 samples, a non-finite value, a negative first
        time, times that do not increase, a peak above 1000 g, unknown units

    Examples
    --------
    >>> import numpy as np, rbm
    >>> t = np.linspace(0.0, 0.5, 501)  # [s]
    >>> m = rbm.motion_from_arrays(t, 0.4 * np.sin(2 * np.pi * t), name="pulse")  # [g]
    >>> m.name, len(m), round(m.pga_g, 6)
    ('pulse', 501, 0.4)
    >>> rbm.motion_from_arrays([0.0, 0.02, 0.01], [0.0, 0.1, 0.0])
    Traceback (most recent call last):
    ...
    rbm_cli.base.errors.ConfigError: motion: sample 2: time must increase, got 0.01 after 0.02
    """
    return _from_arrays(time_s, acceleration, units, name)


def motion_config(config: Config, motions: Sequence[Motion], *, axis: bool) -> Config:
    """``config`` with its ground motion the record ``motions[0]`` (``axis``: a grid axis
    over ``excitation.file`` holding every motion, a suite) and the grid without
    frequencies (a record has none), validated again as a record config is. A record
    config keeps its scale, free time, units and vertical record; another keeps only its
    initial conditions, with the record's defaults (scale: pga, free_time: 5 s)."""
    motions = unique_names(motions, "motions")
    if config.written is None:
        raise ConfigError("a config to run a motion needs the mapping it was written as")
    written = copy.deepcopy(dict(config.written))
    excitation = written.get("excitation")
    excitation = dict(excitation) if isinstance(excitation, dict) else {}
    if config.excitation.type != "record":
        excitation = {k: v for k, v in excitation.items() if k == "initial"}
    excitation = {k: v for k, v in excitation.items() if k in RECORD_KEYS}
    excitation.update(type="record", file=motions[0])
    written["excitation"] = excitation
    grid = written.get("grid")
    grid = {k: v for k, v in grid.items() if k not in ("frequencies", "excitation.file")} \
        if isinstance(grid, dict) else {}  # fmt: skip
    for group in grid.get("linked") or []:
        if isinstance(group, dict) and "excitation.file" in group:
            raise ConfigError(
                "grid.linked links excitation.file with other keys: motions given as arrays"
                " replace the records, so unlink them"
            )
    if axis:
        grid["excitation.file"] = list(motions)
    if grid:
        written["grid"] = grid
    else:
        written.pop("grid", None)
    shown = ", ".join(repr(m.name) for m in motions[:3]) + (", ..." if len(motions) > 3 else "")
    return parse_config(written, f"{config.name} with motion {shown}", base_dir=config.base_dir)
