"""Ground motions given as arrays (a notebook's): checked as a record file is, and named in a
config where a record file would be (``excitation.file``, or the points of a grid axis over
it), so that a cell or a sweep runs them as it runs records.

A :class:`Motion` is immutable and identified by its content: the SHA-256 of its times and
accelerations in SI (float64, little-endian), which takes the place of a record file's
digest in a config's hash. Its name takes the place of the file as written: it is the
value of a domain's ``excitation.file`` and ``record`` columns.
"""

from __future__ import annotations

import hashlib
import numbers
from collections.abc import Mapping
from typing import Any

import numpy as np

from rbm_cli.base.errors import ConfigError, RbmError
from rbm_cli.config.record_files import MAX_SAMPLES, UNITS, check_samples
from rbm_cli.config.types import G

__all__ = [
    "Motion",
    "holds_stored_motions",
    "motion_from_arrays",
    "named",
    "storable",
    "unique_names",
]

#: What a stored config (meta.json) holds in the place of a motion: its identity, not its
#: samples (key -> what it says).
STORED_KEY = "motion_in_memory"


class Motion:
    """A horizontal ground acceleration given as arrays, checked, in SI; read-only.

    Made by :func:`motion_from_arrays` (``rbm.motion_from_arrays``).

    Attributes
    ----------
    name : str  Its name (a domain's ``record`` and ``excitation.file`` columns)
    time_s : numpy.ndarray  Sample times [s], strictly increasing, the first >= 0
    acceleration_m_s2 : numpy.ndarray  Ground acceleration at those times [m/s^2]
    units : str  The units the accelerations were given in ('g' or 'm/s2')
    sha256 : str  SHA-256 of the samples in SI: its identity in a config's hash
    pga_g : float  Peak |acceleration| [g]
    duration_s : float  Time of the last sample [s]

    Between samples the acceleration is linear, and 0 before the first and after the
    last, as a record file's (rbm_cli.physics.records).

    Examples
    --------
    >>> import rbm
    >>> m = rbm.motion_from_arrays([0.0, 0.1, 0.2], [0.0, 0.3, 0.0], name="tri")  # [s], [g]
    >>> isinstance(m, rbm.Motion), m.duration_s, round(m.pga_g, 9), float(m.acceleration_m_s2[1])
    (True, 0.2, 0.3, 2.943)
    """

    __slots__ = ("_a", "_t", "name", "sha256", "units")

    def __init__(self, name: str, time_s: np.ndarray, acceleration_m_s2: np.ndarray,
                 units: str) -> None:  # fmt: skip
        t = np.array(time_s, dtype="<f8", copy=True)
        a = np.array(acceleration_m_s2, dtype="<f8", copy=True)
        t.setflags(write=False)
        a.setflags(write=False)
        digest = hashlib.sha256(t.tobytes())
        digest.update(a.tobytes())
        object.__setattr__(self, "_t", t)
        object.__setattr__(self, "_a", a)
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "units", units)
        object.__setattr__(self, "sha256", digest.hexdigest())

    def __setattr__(self, key, value):
        raise AttributeError("a Motion is read-only")

    @property
    def time_s(self) -> np.ndarray:
        return self._t

    @property
    def acceleration_m_s2(self) -> np.ndarray:
        return self._a

    @property
    def pga_g(self) -> float:
        return float(np.max(np.abs(self._a))) / G

    @property
    def duration_s(self) -> float:
        return float(self._t[-1])

    def __len__(self) -> int:
        return int(self._t.size)

    def __eq__(self, other) -> bool:
        if not isinstance(other, Motion):
            return NotImplemented
        return (self.name, self.sha256) == (other.name, other.sha256)

    def __hash__(self) -> int:
        return hash((self.name, self.sha256))

    def __str__(self) -> str:  # what a domain's excitation.file column holds
        return self.name

    def __repr__(self) -> str:
        return (
            f"Motion({self.name!r}: {len(self)} samples over {self.duration_s:.6g} s, PGA"
            f" {self.pga_g:.4g} g, sha256 {self.sha256[:12]}...)"
        )

    def __copy__(self) -> Motion:
        return self

    def __deepcopy__(self, memo) -> Motion:  # immutable: a config's copies share it
        return self

    def __reduce__(self):
        return (_rebuilt, (self.name, self._t, self._a, self.units))


def _rebuilt(name, t, a, units) -> Motion:
    return Motion(name, t, a, units)


def _series(value: Any, where: str, what: str) -> np.ndarray:
    """A 1-D array of floats from a list or an array of numbers (one line otherwise)."""
    if isinstance(value, str | bytes | Mapping) or np.ndim(value) != 1:
        shape = "a string" if isinstance(value, str | bytes) else f"{np.ndim(value)}-d"
        raise ConfigError(f"{where}: {what} must be a 1-d list or array of numbers, got {shape}")
    items = value.tolist() if isinstance(value, np.ndarray) else list(value)
    for k, v in enumerate(items):
        if isinstance(v, bool | np.bool_) or not isinstance(v, numbers.Real):
            raise ConfigError(f"{where}: sample {k}: {what} must be a number, got {v!r}")
    return np.asarray(items, dtype=float)


def motion_from_arrays(time_s, acceleration, units: str = "g", name: str | None = None) -> Motion:
    """A :class:`Motion` from sample times [s] and accelerations (in ``units``), checked as a
    record file's samples are (rbm_cli.config.record_files.check_samples: the same rules,
    the same messages, a sample named by its index instead of a line).

    Raises
    ------
    ConfigError  One line naming the motion and the problem: unknown units, a name that is
        not a string, arrays that are not 1-d numbers or of different lengths, fewer than
        2 or more than MAX_SAMPLES samples, a non-finite value, a negative first time,
        times that do not increase, a peak above 1000 g.
    """
    shown = "motion" if name is None else f"motion {name!r}"
    if name is not None and (not isinstance(name, str) or not name.strip()):
        raise ConfigError(f"motion: name must be a non-empty string, got {name!r}")
    if not isinstance(units, str) or units not in UNITS:
        raise ConfigError(f"{shown}: units must be 'g' or 'm/s2', got {units!r}")
    t = _series(time_s, shown, "time")
    a = _series(acceleration, shown, "acceleration")
    if t.size != a.size:
        raise ConfigError(f"{shown}: {t.size} times but {a.size} accelerations")
    if t.size < 2:
        raise ConfigError(f"{shown}: needs at least 2 samples, has {t.size}")
    if t.size > MAX_SAMPLES:
        raise ConfigError(f"{shown}: more than the {MAX_SAMPLES} samples allowed")
    try:
        check_samples(shown, t, a, units, lambda k: f"sample {k}")
    except RbmError as exc:
        raise ConfigError(str(exc)) from None
    values = a * UNITS[units]
    if name is None:
        name = "motion-" + Motion("", t, values, units).sha256[:8]
    return Motion(name, t, values, units)


def unique_names(motions, where: str) -> tuple[Motion, ...]:
    """The motions, checked to be Motions with one name each (a name is a domain row's
    identity)."""
    if isinstance(motions, Motion) or not isinstance(motions, list | tuple) or not motions:
        raise ConfigError(f"{where} must be a non-empty list of motions (rbm.motion_from_arrays)")
    seen: dict[str, int] = {}
    for k, m in enumerate(motions):
        if not isinstance(m, Motion):
            raise ConfigError(
                f"{where}[{k}] must be a motion (rbm.motion_from_arrays), got {type(m).__name__}"
            )
        if m.name in seen:
            raise ConfigError(
                f"{where}[{k}]: the name {m.name!r} is also that of {where}[{seen[m.name]}]:"
                " give each motion its own name"
            )
        seen[m.name] = k
    return tuple(motions)


def storable(data: Any) -> Any:
    """A written config with each motion replaced by what identifies it (name, SHA-256,
    samples, units), so that it can be stored as JSON (meta.json); such a stored config
    cannot be run again without the arrays."""
    if isinstance(data, Motion):
        return {STORED_KEY: data.name, "sha256": data.sha256, "samples": len(data),
                "units": data.units}  # fmt: skip
    if isinstance(data, Mapping):
        return {k: storable(v) for k, v in data.items()}
    if isinstance(data, list | tuple):
        return [storable(v) for v in data]
    return data


def named(data: Any) -> Any:
    """Plain data with each motion replaced by its name (as a config's hash and a domain's
    rows write it: its samples are in the config's ``grid.records`` by SHA-256)."""
    if isinstance(data, Motion):
        return data.name
    if isinstance(data, Mapping):
        return {k: named(v) for k, v in data.items()}
    if isinstance(data, list | tuple):
        return type(data)(named(v) for v in data)
    return data


def holds_stored_motions(data: Any) -> bool:
    """Whether a stored config (:func:`storable`) named motions given in memory."""
    if isinstance(data, Mapping):
        return STORED_KEY in data or any(holds_stored_motions(v) for v in data.values())
    if isinstance(data, list):
        return any(holds_stored_motions(v) for v in data)
    return False
