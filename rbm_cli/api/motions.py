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
from rbm_cli.config.types import ONLY_FOR, Config

__all__ = ["Motion", "motion_config", "motion_from_arrays"]

#: Keys of a config's excitation that say the form of a ground motion other than a record
#: (its type, length, phase and pulse shape): the arrays of a motion replace them.
REPLACED_KEYS = ("type", "duration", "phase", "gamma", "nu")


def motion_from_arrays(time_s, acceleration, units: str = "g", name: str | None = None, *,
                       acceleration_y=None) -> Motion:  # fmt: skip
    """A ground motion from arrays, checked as a record file is, to run as a record.

    Parameters
    ----------
    time_s : list or numpy array of float  Sample times [s]: the first >= 0, strictly
        increasing (the steps may be uneven, as a CSV record's)
    acceleration : list or numpy array of float  Horizontal ground acceleration at those
        times, in ``units``; positive in +x (along ``excitation.angle`` for a model in
        three dimensions). Linear between samples, 0 before the first and after the last
        (as a record file's)
    units : str  'g' (9.81 m/s^2, the default) or 'm/s2' (also 'm/s^2')
    name : str, optional  Its name in a domain (the ``record`` and ``excitation.file``
        columns); default ``motion-`` and the first 8 hex digits of its SHA-256
    acceleration_y : list or numpy array of float, optional  A second horizontal
        component at the same times, in ``units``, 90 degrees counter-clockwise from the
        first: a pair of records on one time base, run by the models in three dimensions
        (rbm-3d, housner-3d, bullet) as ``excitation.file`` with ``excitation.file_y``
        is, scaled by one factor (with ``scale: pga`` the larger of its two components'
        PGAs to the amplitude); a planar model refuses it

    Returns
    -------
    Motion  Read-only: ``.name``, ``.time_s`` [s], ``.acceleration_m_s2`` [m/s^2],
        ``.acceleration_y_m_s2`` [m/s^2] (None for one component), ``.pga_g`` [g],
        ``.duration_s`` [s], ``.sha256`` (of the samples in SI, its identity in a
        sweep's config hash, as a record file's digest is)

    Raises
    ------
    ConfigError  One line naming the problem, as for a record file (a sample is named by
        its index): lengths, fewer than 2 samples or more than 10,000,000 (checked first),
        nested or ragged lists, a sample that is not a number, a non-finite value, a
        negative first time, times that do not increase, a peak above 1000 g, unknown
        units

    Examples
    --------
    >>> import numpy as np, rbm
    >>> t = np.linspace(0.0, 0.5, 501)  # [s]
    >>> m = rbm.motion_from_arrays(t, 0.4 * np.sin(2 * np.pi * t), name="pulse")  # [g]
    >>> m.name, len(m), round(m.pga_g, 6)
    ('pulse', 501, 0.4)
    >>> both = rbm.motion_from_arrays(t, 0.4 * np.sin(2 * np.pi * t), name="circle",
    ...                               acceleration_y=0.4 * np.cos(2 * np.pi * t))  # [g]
    >>> both.acceleration_y_m_s2 is not None, round(both.pga_g, 6)
    (True, 0.4)
    >>> rbm.motion_from_arrays([0.0, 0.02, 0.01], [0.0, 0.1, 0.0])
    Traceback (most recent call last):
    ...
    rbm_cli.base.errors.ConfigError: motion: sample 2: time must increase, got 0.01 after 0.02
    """
    return _from_arrays(time_s, acceleration, units, name, acceleration_y)


def motion_config(config: Config, motions: Sequence[Motion], *, axis: bool) -> Config:
    """``config`` with its ground motion the record ``motions[0]`` (``axis``: a grid axis
    over ``excitation.file`` holding every motion, a suite) and the grid without
    frequencies (a record has none), validated again as a record config is.

    Every key of the config's excitation is carried but those the arrays replace: of a
    record config its file (and so its scale, free time, units, vertical record,
    processing, im_periods, angle and initial conditions are kept); of another its form
    (``type``, ``duration``, ``phase``, ``gamma``, ``nu``), the motion then run with a
    record's defaults (scale: pga, free_time: 5 s) and the rest kept (``angle``,
    ``initial``). A key that applies to the replaced form only, or a second component
    from a file (``excitation.file_y``, an axis over it) beside motions, is refused in one
    line: a pair given as arrays carries its own y component (``acceleration_y``)."""
    motions = unique_names(motions, "motions")
    if config.written is None:
        raise ConfigError("a config to run a motion needs the mapping it was written as")
    written = copy.deepcopy(dict(config.written))
    excitation = written.get("excitation")
    excitation = dict(excitation) if isinstance(excitation, dict) else {}
    if "file_y" in excitation:
        raise ConfigError(
            "excitation.file_y is a record file's second component, and a motion given as"
            " arrays replaces excitation.file: give the pair as arrays"
            " (rbm.motion_from_arrays(..., acceleration_y=...)) or delete excitation.file_y"
        )
    if config.excitation.type == "record":
        excitation.pop("file", None)
    else:
        kind = config.excitation.type
        excitation = {k: v for k, v in excitation.items() if k not in REPLACED_KEYS}
        for key in excitation:
            if key in ONLY_FOR and "record" not in ONLY_FOR[key]:
                raise ConfigError(
                    f"excitation.{key} applies to type {kind}, whose ground motion the arrays"
                    " replace: delete it (a second component of the arrays is"
                    " acceleration_y)"
                )
    excitation.update(type="record", file=motions[0])
    written["excitation"] = excitation
    grid = written.get("grid")
    grid = {k: v for k, v in grid.items() if k not in ("frequencies", "excitation.file")} \
        if isinstance(grid, dict) else {}  # fmt: skip
    if "excitation.file_y" in grid:
        raise ConfigError(
            "grid.excitation.file_y: excitation.file_y is a record file's second component,"
            " and motions given as arrays replace excitation.file: give the pairs as arrays"
            " (rbm.motion_from_arrays(..., acceleration_y=...)) or delete the axis"
        )
    for group in grid.get("linked") or []:
        if isinstance(group, dict) and "excitation.file_y" in group:
            raise ConfigError(
                "grid.linked: excitation.file_y is a record file's second component, and"
                " motions given as arrays replace excitation.file: give the pairs as arrays"
                " (rbm.motion_from_arrays(..., acceleration_y=...)) or unlink them"
            )
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
