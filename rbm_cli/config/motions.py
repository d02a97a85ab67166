"""Ground motions given as arrays (a notebook's): checked as a record file is, and named in a
config where a record file would be (``excitation.file``, or the points of a grid axis over
it), so that a cell or a sweep runs them as it runs records.

A :class:`Motion` is immutable and identified by its content: the SHA-256 of its times and
accelerations in SI (float64, little-endian), which takes the place of a record file's
digest in a config's hash. Its name takes the place of the file as written: it is the
value of a domain's ``excitation.file`` and ``record`` columns. A motion may hold a second
horizontal component on the same times (``acceleration_y``): a pair of records given as
arrays, which a config takes as it takes ``excitation.file`` with ``excitation.file_y``.

The arrays are checked as a record file's samples are, without a loop over the samples in
Python: their sizes first (at most :data:`~rbm_cli.config.record_files.MAX_SAMPLES`), then
their types (numbers, not booleans or strings), then the values, each check over whole
arrays.
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
from rbm_cli.config.validate import describe

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
    acceleration_m_s2 : numpy.ndarray  Ground acceleration at those times [m/s^2], along
        x (along ``excitation.angle`` for a model in three dimensions)
    acceleration_y_m_s2 : numpy.ndarray or None  A second horizontal component at the same
        times [m/s^2], 90 degrees counter-clockwise from the first (a record's y
        component, as ``excitation.file_y``); None for a motion of one component
    units : str  The units the accelerations were given in ('g' or 'm/s2')
    sha256 : str  SHA-256 of the samples in SI (both components of a pair): its identity
        in a config's hash
    sha256_y : str or None  SHA-256 of the times and the y component alone (a pair's
        ``excitation.file_y`` digest); None for one component
    pga_g : float  Peak |acceleration| [g]; of a pair, the larger of its two components'
        (the PGA a pair is scaled to, as a pair of record files is)
    duration_s : float  Time of the last sample [s]

    Between samples the acceleration is linear, and 0 before the first and after the
    last, as a record file's (rbm_cli.inputs.records).

    Examples
    --------
    >>> import rbm
    >>> m = rbm.motion_from_arrays([0.0, 0.1, 0.2], [0.0, 0.3, 0.0], name="tri")  # [s], [g]
    >>> isinstance(m, rbm.Motion), m.duration_s, round(m.pga_g, 9), float(m.acceleration_m_s2[1])
    (True, 0.2, 0.3, 2.943)
    """

    __slots__ = ("_a", "_ay", "_t", "name", "sha256", "sha256_y", "units")

    def __init__(self, name: str, time_s: np.ndarray, acceleration_m_s2: np.ndarray,
                 units: str, acceleration_y_m_s2: np.ndarray | None = None) -> None:  # fmt: skip
        t = np.array(time_s, dtype="<f8", copy=True)
        a = np.array(acceleration_m_s2, dtype="<f8", copy=True)
        ay = None if acceleration_y_m_s2 is None else np.array(acceleration_y_m_s2, "<f8")
        digest = hashlib.sha256(t.tobytes())
        digest.update(a.tobytes())
        digest_y = None
        for values in (t, a) if ay is None else (t, a, ay):
            values.setflags(write=False)
        if ay is not None:  # a pair: both components in its identity
            digest.update(ay.tobytes())
            digest_y = hashlib.sha256(t.tobytes())
            digest_y.update(ay.tobytes())
        object.__setattr__(self, "_t", t)
        object.__setattr__(self, "_a", a)
        object.__setattr__(self, "_ay", ay)
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "units", units)
        object.__setattr__(self, "sha256", digest.hexdigest())
        object.__setattr__(self, "sha256_y", None if digest_y is None else digest_y.hexdigest())

    def __setattr__(self, key, value):
        raise AttributeError("a Motion is read-only")

    @property
    def time_s(self) -> np.ndarray:
        return self._t

    @property
    def acceleration_m_s2(self) -> np.ndarray:
        return self._a

    @property
    def acceleration_y_m_s2(self) -> np.ndarray | None:
        return self._ay

    @property
    def is_pair(self) -> bool:
        """Whether it holds a second horizontal component (``acceleration_y``)."""
        return self._ay is not None

    @property
    def pga_g(self) -> float:
        peak = float(np.max(np.abs(self._a)))
        if self._ay is not None:
            peak = max(peak, float(np.max(np.abs(self._ay))))
        return peak / G

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
        what = "pair of " if self.is_pair else ""
        return (
            f"Motion({self.name!r}: {what}{len(self)} samples over {self.duration_s:.6g} s, PGA"
            f" {self.pga_g:.4g} g, sha256 {self.sha256[:12]}...)"
        )

    def __copy__(self) -> Motion:
        return self

    def __deepcopy__(self, memo) -> Motion:  # immutable: a config's copies share it
        return self

    def __reduce__(self):
        return (_rebuilt, (self.name, self._t, self._a, self.units, self._ay))


def _rebuilt(name, t, a, units, ay=None) -> Motion:
    return Motion(name, t, a, units, ay)


#: numpy kinds of arrays of real numbers (signed, unsigned integers, floats).
_REAL_KINDS = "iuf"


def _is_real_type(kind: type) -> bool:
    """A type of real numbers (int, float, numpy's), not a boolean."""
    return issubclass(kind, numbers.Real) and not issubclass(kind, bool | np.bool_)


def _series(value: Any, where: str, what: str) -> np.ndarray:
    """A 1-d array of floats from a list or an array of numbers, or a one-line ConfigError.

    Its size is checked first (at most MAX_SAMPLES), then its type, over the whole of it:
    a numpy array by its dtype, a list or a tuple by the set of its items' types (a scan
    in C); a sample is named by its index only when one is refused."""
    shape = None
    if value is None or isinstance(value, str | bytes | Mapping | numbers.Number):
        shape = "a string" if isinstance(value, str | bytes) else describe(value)
    elif not isinstance(value, list | tuple | np.ndarray):
        if not hasattr(value, "__array__"):  # a pandas Series is read as its array
            shape = f"a {type(value).__name__}"
        else:
            value = np.asarray(value)
    if shape is None and isinstance(value, np.ndarray) and value.ndim != 1:
        shape = f"a {value.ndim}-d array"
    if shape is not None:
        raise ConfigError(f"{where}: {what} must be a 1-d list or array of numbers, got {shape}")
    if len(value) > MAX_SAMPLES:
        raise ConfigError(
            f"{where}: {what} has {len(value):,} samples, more than the {MAX_SAMPLES:,} allowed"
        )
    if isinstance(value, np.ndarray) and value.dtype.kind in _REAL_KINDS:
        return value.astype(float)
    items = value.tolist() if isinstance(value, np.ndarray) else value
    if not all(_is_real_type(kind) for kind in set(map(type, items))):
        k, v = next((k, v) for k, v in enumerate(items) if not _is_real_type(type(v)))
        if isinstance(v, list | tuple | np.ndarray):
            raise ConfigError(
                f"{where}: {what} must be a 1-d list or array of numbers, got a sequence at"
                f" sample {k} (nested or ragged lists)"
            )
        raise ConfigError(f"{where}: sample {k}: {what} must be a number, got {v!r}")
    return np.asarray(items, dtype=float)


def motion_from_arrays(time_s, acceleration, units: str = "g", name: str | None = None,
                       acceleration_y=None) -> Motion:  # fmt: skip
    """A :class:`Motion` from sample times [s] and accelerations (in ``units``), and a second
    horizontal component on the same times if ``acceleration_y`` is given, checked as a
    record file's samples are (rbm_cli.config.record_files.check_samples: the same rules,
    the same messages, a sample named by its index instead of a line; each check over
    whole arrays, the sizes first).

    Raises
    ------
    ConfigError  One line naming the motion and the problem: unknown units, a name that is
        not a string, arrays that are not 1-d numbers (nested, ragged, strings, booleans)
        or of different lengths, fewer than 2 or more than MAX_SAMPLES samples, a
        non-finite value, a negative first time, times that do not increase, a peak above
        1000 g (of either component).
    """
    shown = "motion" if name is None else f"motion {name!r}"
    if name is not None and (not isinstance(name, str) or not name.strip()):
        raise ConfigError(f"motion: name must be a non-empty string, got {name!r}")
    if not isinstance(units, str) or units not in UNITS:
        raise ConfigError(f"{shown}: units must be 'g' or 'm/s2', got {units!r}")
    t = _series(time_s, shown, "time")
    a = _series(acceleration, shown, "acceleration")
    ay = None if acceleration_y is None else _series(acceleration_y, shown, "acceleration_y")
    if t.size != a.size:
        raise ConfigError(f"{shown}: {t.size} times but {a.size} accelerations")
    if ay is not None and ay.size != t.size:
        raise ConfigError(
            f"{shown}: {t.size} times but {ay.size} values of acceleration_y (a pair's two"
            " components share its times)"
        )
    if t.size < 2:
        raise ConfigError(f"{shown}: needs at least 2 samples, has {t.size}")
    try:
        check_samples(shown, t, a, units, lambda k: f"sample {k}")
        if ay is not None:
            check_samples(f"{shown}: acceleration_y", t, ay, units, lambda k: f"sample {k}")
    except RbmError as exc:
        raise ConfigError(str(exc)) from None
    values = a * UNITS[units]
    values_y = None if ay is None else ay * UNITS[units]
    if name is None:
        name = "motion-" + Motion("", t, values, units, values_y).sha256[:8]
    return Motion(name, t, values, units, values_y)


def unique_names(motions, where: str) -> tuple[Motion, ...]:
    """The motions, checked to be Motions with one name each (a name is a domain row's
    identity), all pairs (``acceleration_y``) or all of one component (a suite's runs
    are of one kind: a model that moves in three dimensions under a pair only would
    otherwise change its dimensions from row to row)."""
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
        if m.is_pair != motions[0].is_pair:
            which = (k, 0) if m.is_pair else (0, k)
            raise ConfigError(
                f"{where}[{which[0]}] is a pair (acceleration_y) and {where}[{which[1]}] has one"
                " component: sweep pairs and motions of one component apart"
            )
    return tuple(motions)


def storable(data: Any) -> Any:
    """A written config with each motion replaced by what identifies it (name, SHA-256,
    samples, units), so that it can be stored as JSON (meta.json); such a stored config
    cannot be run again without the arrays."""
    if isinstance(data, Motion):
        stored = {STORED_KEY: data.name, "sha256": data.sha256, "samples": len(data),
                  "units": data.units}  # fmt: skip
        if data.is_pair:
            stored["components"] = 2
        return stored
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
