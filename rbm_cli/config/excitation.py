"""The ``excitation`` section of a config and its record files.

Keys, by excitation type (a key of another type is refused, naming it):

- every type: ``type``, ``initial: {rotations, velocities}`` [rad, rad/s] (and, for the
  models in three dimensions, ``rotations_across``, ``velocities_across``: the same across
  the motion's plane; the loader refuses them for the others);
- ``harmonic``, ``half-sine``, ``free``: ``duration`` [s]; ``harmonic``: ``phase`` [rad]
  (0 is accepted with any type);
- pulses, ``one-sine``, ``cycloidal``, ``ricker``, ``mavroeidis-papageorgiou``: as
  ``half-sine``, ``duration`` [s] is the maximum simulated time (default 20 s), the pulse
  then free motion; ``mavroeidis-papageorgiou`` also ``gamma`` (> 1, at most 20 [-]) and
  ``nu`` (in [-2 pi, 2 pi] [rad]), both required;
- ``harmonic``, ``half-sine`` and the pulses: ``y: {amplitude_ratio, phase_deg}``, an
  analytic second horizontal component at 90 degrees counter-clockwise from the motion's
  direction, the same formula scaled by amplitude_ratio (in [0, 10] [-]) and shifted by
  phase_deg (in [-360, 360] [deg], default 0; a Ricker wavelet has no phase: 0 or
  +-180, its sign, or +-360) (:func:`second_component`; the loader refuses it for the
  planar models);
- ``record``: ``file`` (one PEER NGA ``.AT2`` or CSV file; a relative path is taken from the
  folder of the config file, or from the current directory for a config given as a
  mapping), ``units`` (``g``, default, or ``m/s2``: a CSV's values; an ``.AT2`` is in g),
  ``free_time`` [s] of free motion after the record's last sample (default
  :data:`~rbm_cli.config.types.DEFAULT_FREE_TIME`, 5 s), ``scale`` (``pga``, default: the
  grid's amplitude [g] is the scaled record's PGA; ``factor``: a plain scale factor),
  ``vertical`` (a second file, same formats and units: the upward ground acceleration,
  scaled by the same factor as the horizontal record; every model takes it),
  ``processing`` (``baseline``: ``none``, default, ``linear`` or ``quadratic``;
  ``filter: {low_hz, high_hz, order}``: a zero-phase Butterworth band-pass [Hz], order
  1-8, default 4; both records processed, before scaling: see :func:`processing_section`),
  ``im_periods`` (periods [s] of the 5 %-damped spectral accelerations a domain's rows
  report among the record's intensity measures, rbm_cli.inputs.intensity; no effect on
  a run).
  ``duration`` does not apply: the run lasts the record plus ``free_time``, and the loader
  sets ``ExcitationConfig.duration`` to that. A mapping made in Python may give a motion
  (:class:`rbm_cli.config.motions.Motion`, arrays checked when it was made) in the place
  of the file, here or among the values of a grid axis over ``excitation.file``: its name
  stands for the file as written, the SHA-256 of its samples for the file's. A motion with a
  second horizontal component (``acceleration_y``) is a pair on one time base: it sets
  ``file_y`` to its name and ``file_y_sha256`` to the digest of its y samples, as
  ``excitation.file_y`` would (which it then refuses).

The record file is read and checked when the config is loaded: a missing or malformed file
is a one-line :class:`~rbm_cli.base.errors.ConfigError` naming the key, the file and the
line (the parsers of :mod:`rbm_cli.config.record_files`). The config keeps the path as
written and the file's SHA-256 (its identity in the config's hash), and the absolute path,
which :meth:`~rbm_cli.config.types.ExcitationConfig.resolved` leaves out.
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
import os
import stat
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rbm_cli.base.errors import ConfigError, RbmError
from rbm_cli.config.motions import Motion
from rbm_cli.config.record_files import read_file, uniform_step
from rbm_cli.config.types import (
    BASELINES,
    DEFAULT_FREE_TIME,
    EXCITATIONS,
    ONLY_FOR,
    PULSES,
    RECORD_SCALES,
    RECORD_UNITS,
    ExcitationConfig,
    FilterConfig,
    G,
    InitialConfig,
    ProcessingConfig,
    SecondComponentConfig,
)
from rbm_cli.config.validate import (
    choice,
    describe,
    fmt,
    in_bounds,
    integer,
    join,
    mapping,
    number,
    number_list,
)
from rbm_cli.config.validate import one_line as _one_line

__all__ = [
    "RecordFile",
    "excitation_section",
    "filter_padding",
    "processing_section",
    "record_file",
    "resolve_record_path",
    "second_component",
    "with_record",
]

EXCITATION_KEYS = (
    "type",
    "duration",
    "phase",
    "initial",
    "file",
    "units",
    "free_time",
    "scale",
    "gamma",
    "nu",
    "vertical",
    "processing",
    "im_periods",
    "angle",
    "file_y",
    "y",
)
PROCESSING_KEYS = ("baseline", "filter")
FILTER_KEYS = ("low_hz", "high_hz", "order")
#: Largest order of each side of the band-pass [-]: the roll-off is 6 n dB an octave a
#: side, doubled by the forward and backward pass; strong-motion practice uses 2-8.
FILTER_ORDER_MAX = 8
INITIAL_KEYS = ("rotations", "velocities", "rotations_across", "velocities_across")
#: Keys of excitation.y, the analytic second component.
Y_KEYS = ("amplitude_ratio", "phase_deg")
#: Largest excitation.y.amplitude_ratio [-]: a second component stronger than ten times
#: the first is the first of the motion turned by 90 degrees (excitation.angle).
Y_RATIO_MAX = 10.0
#: Range of excitation.y.phase_deg [deg]: one turn either way.
Y_PHASE_RANGE_DEG = (-360.0, 360.0)
#: Default ``excitation.duration`` per type [s].
DEFAULT_DURATION = {"harmonic": 10.0, "half-sine": 20.0, "free": 10.0}
DEFAULT_DURATION.update({kind: 20.0 for kind in PULSES})  # as the half-sine [assumption]
#: Mavroeidis-Papageorgiou's gamma [-] (> 1; their fits 1.5-3; a long train above 20 is
#: a harmonic) and nu [rad] (a phase: one turn either way).
GAMMA_MAX = 20.0
NU_MAX = 2.0 * math.pi
MAX_DURATION = 1e4  # [s]
#: Initial rotations [rad] and rates [rad/s], phase [rad]: finite and bounded.
INITIAL_MAX = {"rotations": 10.0, "velocities": 1e4}
PHASE_MAX = 1e3
#: Range of excitation.angle [deg]: one turn either way.
ANGLE_RANGE_DEG = (-360.0, 360.0)
#: Periods of the spectral accelerations a record's rows report (excitation.im_periods)
#: [s], and how many a config may list.
IM_PERIOD_RANGE_S = (0.01, 20.0)
MAX_IM_PERIODS = 20
_DIGEST_CHUNK = 1 << 20


@dataclass(frozen=True)
class RecordFile:
    """A record file a config names, read and checked.

    written : str  The path as written in the config
    path : str  Its absolute path
    sha256 : str  SHA-256 of its bytes (hex)
    end : float  Time of its last sample [s]
    pga : float  Its peak ground acceleration [m/s^2]
    motion : Motion or None  The motion given as arrays in place of a file (then
        ``written`` is its name, ``path`` names it in messages, ``sha256`` is its digest)
    step : float or None  Its time step [s] when its samples are evenly spaced
        (record_files.uniform_step), else None
    samples : int  Its number of samples
    """

    written: str
    path: str
    sha256: str
    end: float
    pga: float
    motion: Motion | None = None
    step: float | None = None
    samples: int = 0

    @property
    def local_path(self) -> str | None:
        """The file's absolute path (None for a motion given as arrays)."""
        return None if self.motion is not None else self.path


def resolve_record_path(value: str | os.PathLike, base_dir: str | os.PathLike | None) -> Path:
    """The absolute path of a record file as a config writes it.

    An absolute path is kept; a relative one is taken from ``base_dir`` (the folder of the
    config file), or from the current directory when ``base_dir`` is None (a config given
    as a mapping). ``~`` is expanded; ``..`` is normalised; symbolic links are kept.
    """
    path = Path(os.path.expanduser(os.fspath(value)))
    if not path.is_absolute():
        path = Path(base_dir if base_dir is not None else os.getcwd()) / path
    return Path(os.path.abspath(path))


def _digest(path: Path) -> str:
    h = hashlib.sha256()
    with path.open("rb") as fh:
        for block in iter(lambda: fh.read(_DIGEST_CHUNK), b""):
            h.update(block)
    return h.hexdigest()


def record_file(
    value: Any, key: str, base_dir: str | os.PathLike | None, units: str = "g"
) -> RecordFile:
    """Read and check the record file ``value`` written at key path ``key``.

    Raises
    ------
    ConfigError  ``<key>: <file>: [line N: ]<problem>`` for a value that is not one path,
        a missing, unreadable or malformed file (record_files' checks).
    """
    if isinstance(value, Motion):  # arrays given in memory: checked when made
        acc = value.acceleration_m_s2
        return RecordFile(value.name, f"motion {value.name!r}", value.sha256, value.duration_s,
                          float(np.max(np.abs(acc))), motion=value,
                          step=uniform_step(value.time_s), samples=int(acc.size))  # fmt: skip
    if not isinstance(value, str) or not value.strip():
        raise ConfigError(
            f"{key} must be one record file (a path to a PEER NGA .AT2 or a .csv, as a"
            f" string) or a motion (rbm.motion_from_arrays), got {describe(value)}"
        )
    try:
        path = resolve_record_path(value, base_dir)
        signature = _signature(path)
        found = _READ.get((signature, units))
        if found is None:
            t, acc, _ = read_file(path, units)
            found = (_digest(path), float(t[-1]), float(np.max(np.abs(acc))),
                     uniform_step(t), int(t.size))  # fmt: skip
            if signature is not None:
                if len(_READ) >= _READ_SIZE:
                    _READ.pop(next(iter(_READ)))
                _READ[(signature, units)] = found
    except RbmError as exc:
        raise ConfigError(f"{key}: {_one_line(str(exc))}") from None
    except OSError as exc:
        raise ConfigError(f"{key}: {value}: cannot read ({exc.strerror or exc})") from None
    sha256, end, pga, step, samples = found
    return RecordFile(value, str(path), sha256, end, pga, step=step, samples=samples)


#: Records read in this process, by file and units: (SHA-256, end [s], PGA [m/s^2], even
#: step [s] or None, number of samples). The
#: points of a grid name the same file again and again; a file is read again when its
#: size, modification time or inode changed.
_READ: dict = {}
_READ_SIZE = 256


def _signature(path: Path) -> tuple | None:
    """What says a file is unchanged since it was read: (path, inode, size, mtime [ns],
    ctime [ns]); None for anything but a regular file (read_file refuses it)."""
    try:
        info = os.stat(path)
    except OSError:
        return None
    if not stat.S_ISREG(info.st_mode):
        return None
    return (str(path), info.st_ino, info.st_size, info.st_mtime_ns, info.st_ctime_ns)


def with_record(
    excitation: ExcitationConfig,
    value: Any,
    base_dir: str | os.PathLike | None,
    key: str = "excitation.file",
) -> ExcitationConfig:
    """The record excitation ``excitation`` with its file replaced by ``value`` (read and
    checked as :func:`record_file` does; same units, scale and free time; the duration
    recomputed). For a grid axis over record files."""
    rec = record_file(value, key, base_dir, excitation.units)
    _check_scalable(rec, excitation.scale, key)
    end = rec.end
    records = [(key, rec)]
    if excitation.vertical is not None:
        ver = record_file(excitation.vertical, "excitation.vertical", base_dir, excitation.units)
        end = max(end, ver.end)
        records.append(("excitation.vertical", ver))
    if excitation.processing is not None and excitation.processing.filter is not None:
        for where, each in records:
            _check_filterable(each, where, excitation.processing.filter)
    duration = _record_duration(end, excitation.free_time, key)
    return dataclasses.replace(
        excitation,
        type="record",
        file=rec.written,
        file_sha256=rec.sha256,
        file_path=rec.local_path,
        motion=rec.motion,
        duration=duration,
    )


#: Smallest PGA a record scaled to the grid's PGA may have [g]: below it the scale factor
#: (up to 1000 g / PGA) leaves the range where its arithmetic is sound, and the record
#: holds no ground motion worth scaling (a recording's noise floor is far above it).
MIN_SCALABLE_PGA_G = 1e-6


def _check_scalable(rec: RecordFile, scale: str, key: str) -> None:
    if scale != "pga":
        return
    if not rec.pga > 0.0:
        raise ConfigError(
            f"{key}: {rec.path}: every acceleration is 0, so it cannot be scaled to a PGA"
            " (excitation.scale: pga); use excitation.scale: factor"
        )
    if rec.pga < MIN_SCALABLE_PGA_G * G:
        raise ConfigError(
            f"{key}: {rec.path}: its PGA is {rec.pga / G:.3g} g, too small to be scaled to a"
            f" PGA (at least {MIN_SCALABLE_PGA_G:g} g with excitation.scale: pga): check"
            " excitation.units, or use excitation.scale: factor"
        )


def _record_duration(end: float, free_time: float, key: str) -> float:
    total = end + free_time
    if total > MAX_DURATION:
        raise ConfigError(
            f"{key}: the record ({fmt(end)} s) plus excitation.free_time ({fmt(free_time)} s)"
            f" must last at most {fmt(MAX_DURATION)} s, got {fmt(total)}"
        )
    return total


def _initial(raw: Any, n: int, kind: str) -> InitialConfig:
    path = "excitation.initial"
    init = mapping(raw, path, INITIAL_KEYS)
    per = f"one value per drum ({n})"
    units = {"rotations": "rad", "velocities": "rad/s"}
    values = {}
    for key in INITIAL_KEYS:
        unit, bound = units[key.removesuffix("_across")], INITIAL_MAX[key.removesuffix("_across")]
        values[key] = (
            tuple(
                in_bounds(x, join(join(path, key), i), unit, (-bound, bound))
                for i, x in enumerate(
                    number_list(init[key], join(path, key), unit, length=n, length_text=per)
                )
            )
            if key in init
            else ()
        )
    if kind == "free" and not any(any(v) for v in values.values()):
        raise ConfigError(
            f"{path}: excitation type free needs a non-zero initial rotation or velocity"
            f" ({path}.rotations or .velocities); with none the column stays at rest"
        )
    return InitialConfig(**values)


def second_component(raw: Any, kind: str) -> SecondComponentConfig:
    """The validated ``excitation.y`` of an excitation of type ``kind`` (a harmonic or a
    pulse): ``amplitude_ratio`` r in [0, Y_RATIO_MAX] (required) and ``phase_deg`` phi in
    Y_PHASE_RANGE_DEG (default 0); a Ricker wavelet, which has no phase, takes a multiple
    of 180 degrees only (its sign).

    Raises
    ------
    ConfigError  One line naming the key and its range.
    """
    path = "excitation.y"
    y = mapping(raw, path, Y_KEYS, required=("amplitude_ratio",))
    ratio = number(y["amplitude_ratio"], join(path, "amplitude_ratio"), "", 0.0, Y_RATIO_MAX,
                   lo_open=False, hint="a larger second component is the first of the motion"
                   " turned by 90 degrees: excitation.angle")  # fmt: skip
    phase = number(y.get("phase_deg", 0.0), join(path, "phase_deg"), "deg")
    phase = in_bounds(
        phase, join(path, "phase_deg"), "deg", Y_PHASE_RANGE_DEG, "one turn either way"
    )
    if kind == "ricker" and phase % 180.0 != 0.0:
        raise ConfigError(
            f"{path}.phase_deg: a Ricker wavelet has no phase, so its second component is the"
            f" same wavelet times r (phase_deg 0 or +-360) or -r (+-180), got {fmt(phase)}"
        )
    return SecondComponentConfig(float(ratio), float(phase))


def _refuse_foreign_keys(e: dict, kind: str) -> None:
    """A key of another excitation type is an error that names it."""
    for key, kinds in ONLY_FOR.items():
        if key in e and kind not in kinds:
            if key == "duration":
                raise ConfigError(
                    "excitation.duration does not apply to type record: the run lasts the"
                    " record plus excitation.free_time [s] (default"
                    f" {fmt(DEFAULT_FREE_TIME)} s): delete it"
                )
            if key == "y" and kind == "record":
                raise ConfigError(
                    "excitation.y is the analytic second component of a harmonic or a pulse;"
                    " a record's second component is a file: excitation.file_y"
                )
            raise ConfigError(
                f"excitation.{key} applies only to type {' or '.join(kinds)}"
                f" (type is {kind}): delete it"
            )


def _record_fields(e: dict, base_dir: str | os.PathLike | None) -> dict:
    """The record fields of ExcitationConfig from the section ``e`` of type record."""
    if "file" not in e:
        raise ConfigError(
            "excitation.file is required for type record (a PEER NGA .AT2 or a CSV file)"
        )
    units = choice(e.get("units", "g"), "excitation.units", RECORD_UNITS)
    scale = choice(e.get("scale", "pga"), "excitation.scale", RECORD_SCALES)
    free_time = number(
        e.get("free_time", DEFAULT_FREE_TIME),
        "excitation.free_time",
        "s",
        0.0,
        MAX_DURATION,
        lo_open=False,
    )
    rec = record_file(e["file"], "excitation.file", base_dir, units)
    _check_scalable(rec, scale, "excitation.file")
    fields = dict(file=rec.written, file_sha256=rec.sha256, file_path=rec.local_path,
                  motion=rec.motion)  # fmt: skip
    end = rec.end
    if "vertical" in e:
        ver = record_file(e["vertical"], "excitation.vertical", base_dir, units)
        if ver.motion is not None:
            raise ConfigError("excitation.vertical must be a record file; a motion given as"
                              " arrays is horizontal")  # fmt: skip
        fields.update(vertical=ver.written, vertical_sha256=ver.sha256, vertical_path=ver.path)
        end = max(end, ver.end)
    if "file_y" in e:
        rec_y = record_file(e["file_y"], "excitation.file_y", base_dir, units)
        _check_pair(rec, rec_y)
        fields.update(file_y=rec_y.written, file_y_sha256=rec_y.sha256, file_y_path=rec_y.path)
    elif rec.motion is not None and rec.motion.is_pair:  # its y component, on its times
        fields.update(file_y=rec.written, file_y_sha256=rec.motion.sha256_y)
    if "processing" in e:
        records = [("excitation.file", rec)]
        if "file_y" in e:
            records.append(("excitation.file_y", rec_y))
        if "vertical" in e:
            records.append(("excitation.vertical", ver))
        fields["processing"] = processing_section(e["processing"], records)
    return dict(
        fields,
        im_periods=_im_periods(e.get("im_periods", [])),
        units=units,
        scale=scale,
        free_time=free_time,
        duration=_record_duration(end, free_time, "excitation.file"),
    )


def _check_pair(rec: RecordFile, rec_y: RecordFile) -> None:
    """A second horizontal component sampled as the first: a file (not arrays), the same
    number of samples, step and last time (a station's two components are)."""
    if rec.motion is not None or rec_y.motion is not None:
        raise ConfigError(
            "excitation.file_y pairs two record files; a motion given as arrays takes its y"
            " component from its own arrays (rbm.motion_from_arrays(..., acceleration_y=...))"
        )
    if (rec.samples, rec.step, rec.end) != (rec_y.samples, rec_y.step, rec_y.end):
        raise ConfigError(
            f"excitation.file_y ({rec_y.path}) must be sampled as excitation.file"
            f" ({rec.path}): {rec_y.samples} samples to {fmt(rec_y.end)} s against"
            f" {rec.samples} to {fmt(rec.end)} s"
        )


def filter_padding(order: int) -> int:
    """Samples the band-pass of ``order`` (a side) extends a record by at each end before
    its forward and backward pass (rbm_cli.inputs.records.band_pass gives it to scipy's
    sosfiltfilt as padlen): 3 (2 s + 1) with s = 2 ceil(order / 2), the number of its
    second-order sections (a high-pass and a low-pass of that order), scipy's default for
    sections of second order. A record needs more samples than this."""
    return 3 * (2 * 2 * math.ceil(order / 2) + 1)


def _check_filterable(rec: RecordFile, key: str, band: FilterConfig) -> None:
    """A record the band-pass can run on: even steps, high_hz below its Nyquist frequency,
    more samples than the filter's padding."""
    where = "excitation.processing.filter"
    if rec.step is None:
        raise ConfigError(
            f"{where}: {key} ({rec.path}) has uneven time steps, and a band-pass needs one"
            " step: resample the record to an even step (baseline correction alone takes any"
            " steps)"
        )
    nyquist = 0.5 / rec.step
    if not band.high_hz < nyquist:
        raise ConfigError(
            f"{where}.high_hz must be below the Nyquist frequency of {key} ({rec.path}:"
            f" {fmt(nyquist)} Hz, step {fmt(rec.step)} s), got {fmt(band.high_hz)}"
        )
    need = filter_padding(band.order) + 1
    if rec.samples < need:
        raise ConfigError(
            f"{where}.order: {key} ({rec.path}) has {rec.samples} samples, and a band-pass of"
            f" order {band.order} needs at least {need}: lower the order or drop the filter"
        )


def processing_section(raw: Any, records: list[tuple[str, RecordFile]]) -> ProcessingConfig | None:
    """The validated ``excitation.processing`` of the records ``records`` ((key, record
    file) pairs: the horizontal record, and the vertical one if any).

    ``filter: {low_hz, high_hz, order}`` (applied first): a zero-phase Butterworth
    band-pass [Hz],
    0 < low_hz < high_hz < each record's Nyquist frequency, order 1..FILTER_ORDER_MAX
    (default 4) a side; it needs evenly sampled records (one with uneven steps is refused,
    not resampled). ``baseline`` (``none``, ``linear``, ``quadratic``; then): the polynomial
    in time removed from the acceleration, fitted by least squares to the displacement; any
    steps. A processing that changes nothing
    (``baseline: none`` and no filter) is None: the config is the record as read, with the
    same hash.

    Raises
    ------
    ConfigError  One line naming the key, its allowed range, and the record at fault.
    """
    path = "excitation.processing"
    p = mapping(raw, path, PROCESSING_KEYS)
    baseline = choice(p.get("baseline", "none"), join(path, "baseline"), BASELINES)
    band = None
    if "filter" in p:
        where = join(path, "filter")
        f = mapping(p["filter"], where, FILTER_KEYS, required=("low_hz", "high_hz"))
        order = integer(f.get("order", FilterConfig.order), join(where, "order"), 1,
                        FILTER_ORDER_MAX, " (the order of each side of the band-pass)")  # fmt: skip
        low = number(f["low_hz"], join(where, "low_hz"), "Hz", 0.0, None)
        high = number(f["high_hz"], join(where, "high_hz"), "Hz", 0.0, None)
        if not low < high:
            raise ConfigError(
                f"{where}.high_hz must be above {where}.low_hz ({fmt(low)} Hz), got {fmt(high)}"
            )
        band = FilterConfig(low, high, order)
        for key, rec in records:
            _check_filterable(rec, key, band)
    if baseline == "none" and band is None:
        return None
    return ProcessingConfig(baseline, band)


def _im_periods(raw: Any) -> tuple[float, ...]:
    """excitation.im_periods: distinct periods [s] in IM_PERIOD_RANGE_S, at most
    MAX_IM_PERIODS, as given (an empty list is none)."""
    path = "excitation.im_periods"
    lo, hi = IM_PERIOD_RANGE_S
    if isinstance(raw, list | tuple) and not raw:
        return ()
    periods = number_list(raw, path, "s", 0.0)
    if len(periods) > MAX_IM_PERIODS:
        raise ConfigError(f"{path}: at most {MAX_IM_PERIODS} periods, got {len(periods)}")
    for i, period in enumerate(periods):
        in_bounds(period, join(path, i), "s", (lo, hi), "the spectra of records are reported")
    if len(set(periods)) != len(periods):
        raise ConfigError(f"{path}: each period once, got {', '.join(map(fmt, periods))} [s]")
    return tuple(float(p) for p in periods)


def _mp_fields(e: dict) -> dict:
    """gamma and nu of the Mavroeidis-Papageorgiou pulse (both required)."""
    for key in ("gamma", "nu"):
        if key not in e:
            raise ConfigError(
                f"excitation.{key} is required for type mavroeidis-papageorgiou (gamma > 1,"
                " at most 20 [-]: the pulse's oscillatory character; nu in [-2 pi, 2 pi]"
                " [rad]: its phase)"
            )
    gamma = number(e["gamma"], "excitation.gamma", "", 1.0, GAMMA_MAX)
    nu = number(e["nu"], "excitation.nu", "rad", -NU_MAX, NU_MAX, lo_open=False)
    return dict(gamma=gamma, nu=nu)


def excitation_section(
    raw: Any, n: int, base_dir: str | os.PathLike | None = None
) -> ExcitationConfig:
    """The validated ``excitation`` section for a column of n drums.

    Parameters
    ----------
    raw : mapping or None  The section as written
    n : int  Number of drums (the length of the initial lists)
    base_dir : path or None  Folder relative record paths are taken from (None: the
        current directory)

    Raises
    ------
    ConfigError  One line naming the key path (and, for a record, the file and line).
    """
    e = mapping(raw, "excitation", EXCITATION_KEYS)
    kind = choice(e.get("type", "harmonic"), "excitation.type", EXCITATIONS)
    _refuse_foreign_keys(e, kind)
    fields: dict = {}
    if kind == "record":
        fields = _record_fields(e, base_dir)
    else:
        if kind == "mavroeidis-papageorgiou":
            fields = _mp_fields(e)
        fields["duration"] = number(
            e.get("duration", DEFAULT_DURATION.get(kind, 10.0)),
            "excitation.duration",
            "s",
            0.0,
            MAX_DURATION,
        )
    phase = number(e.get("phase", 0.0), "excitation.phase", "rad")
    phase = in_bounds(phase, "excitation.phase", "rad", (-PHASE_MAX, PHASE_MAX))
    if phase != 0.0 and kind != "harmonic":
        raise ConfigError(
            f"excitation.phase applies only to type harmonic (type is {kind}), got {fmt(phase)}"
        )
    angle = number(e.get("angle", 0.0), "excitation.angle", "deg")
    angle = in_bounds(angle, "excitation.angle", "deg", ANGLE_RANGE_DEG)
    return ExcitationConfig(
        type=kind,
        phase=phase,
        initial=_initial(e.get("initial"), n, kind),
        angle=angle,
        directed="angle" in e,
        y=second_component(e["y"], kind) if "y" in e else None,
        **fields,
    )
