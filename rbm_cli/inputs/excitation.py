"""Ground motions of a config, SI inside: a_g [m/s^2], t [s], omega [rad/s].

:func:`make_ground_motion` turns a config's excitation, an amplitude [g] and a frequency
[Hz] (the grid's, at this edge only) into the :class:`~rbm_cli.inputs.motion.GroundMotion`
every model integrates: a harmonic, a half-sine or near-fault pulse (inputs/pulses.py),
or a record read from its file (inputs/records.py) or given as arrays
(rbm_cli.config.motions.Motion), with its vertical record if any, both processed as
``excitation.processing`` says before they are scaled; a harmonic or a pulse with its
analytic second horizontal component (``excitation.y``: :func:`second_component`).
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
from functools import lru_cache
from pathlib import Path

import numpy as np

from rbm_cli.base.errors import RbmError
from rbm_cli.config.types import PULSES, ExcitationConfig, G, ProcessingConfig
from rbm_cli.inputs.ground import MP, RICKER, SINE, mp_knots, ricker_knots
from rbm_cli.inputs.motion import PULSE_KINDS, SAMPLES_PER_PERIOD, GroundMotion
from rbm_cli.inputs.pulses import (
    mavroeidis_papageorgiou_duration,
    mp_peak,
    one_sine_duration,
    ricker_duration,
)
from rbm_cli.inputs.records import Record, read_record

__all__ = [
    "PULSE_KINDS",
    "SAMPLES_PER_PERIOD",
    "GroundMotion",
    "common_knots",
    "load_record",
    "make_ground_motion",
    "merge_records",
    "pair_times",
    "processed_record",
    "pulse_motion",
    "record_motion",
    "second_component",
]


# --------------------------------------------------------------------------- records


@lru_cache(maxsize=64)
def load_record(path: str, units: str, sha256: str | None) -> Record:
    """The record of a config's file (read once per process), checked against the
    SHA-256 the config took when it was loaded (None: not checked).

    Raises
    ------
    RbmError  A malformed file (one line naming the file and line), or a file that
        changed since the config was loaded.
    """
    record = read_record(path, units)
    if sha256 is not None:
        digest = hashlib.sha256(Path(path).read_bytes()).hexdigest()
        if digest != sha256:
            raise RbmError(
                f"{path}: the record file changed since the config was loaded (SHA-256"
                f" {digest[:12]}..., the config has {sha256[:12]}...): load the config again"
            )
    return record


@lru_cache(maxsize=64)
def processed_record(
    path: str, units: str, sha256: str | None, processing: ProcessingConfig | None
) -> Record:
    """The record of a config's file (:func:`load_record`) processed as ``processing``
    says (:meth:`~rbm_cli.inputs.records.Record.processed`), once per process."""
    return load_record(path, units, sha256).processed(processing)


def record_motion(excitation: ExcitationConfig, amplitude_g: float) -> GroundMotion:
    """The ground motion of a record excitation at amplitude [g] (its PGA after scaling
    with scale 'pga', a plain factor [-] with scale 'factor'): the scaled record (and its
    second horizontal component and its vertical record, scaled by the same factor; with
    scale 'pga' a pair's PGA is the larger of its two components'), then free motion for
    excitation.free_time [s].

    The records are processed (excitation.processing: baseline, band-pass) before they
    are scaled, so with scale 'pga' the amplitude is the processed record's PGA."""
    path = excitation.file_path or excitation.file
    if path is None:
        raise RbmError("excitation.file is required for type record")
    rec_y = None
    if excitation.motion is not None:  # given as arrays: the same record, from memory
        motion = excitation.motion
        path = path_y = f"motion {motion.name!r}"
        rec = Record(motion.time_s, motion.acceleration_m_s2, motion.name, "in memory")
        rec = rec.processed(excitation.processing)
        if motion.is_pair:  # its y component, on the same times
            rec_y = Record(motion.time_s, motion.acceleration_y_m_s2, motion.name, "in memory")
            rec_y = rec_y.processed(excitation.processing)
    else:
        rec = processed_record(str(path), excitation.units, excitation.file_sha256,
                               excitation.processing)  # fmt: skip
    if excitation.file_y is not None and excitation.motion is None:
        path_y = excitation.file_y_path or excitation.file_y
        rec_y = processed_record(str(path_y), excitation.units, excitation.file_y_sha256,
                                 excitation.processing)  # fmt: skip
    with np.errstate(all="ignore"):  # checked below, with the file named
        if excitation.scale == "pga":  # a pair: the larger of its two components' PGAs
            factor = amplitude_g * G / max(rec.pga, 0.0 if rec_y is None else rec_y.pga)
        else:
            factor = float(amplitude_g)
        series = [(rec.t, _scaled(rec, factor, path))]
        if rec_y is not None:
            series.append((rec_y.t, _scaled(rec_y, factor, path_y)))
    end = max(float(t[-1]) for t, _ in series)  # the records' last samples, from t = 0
    if excitation.vertical is not None:
        path = excitation.vertical_path or excitation.vertical
        ver = processed_record(str(path), excitation.units, excitation.vertical_sha256,
                               excitation.processing)  # fmt: skip
        series.append((ver.t, _scaled(ver, factor, path)))
        end = max(end, ver.duration)
    if len(series) == 1 or (excitation.vertical is None and pair_times(excitation) == "shared"):
        # one time base already: the samples as read
        knots, columns = series[0][0], [values for _, values in series]
    else:  # a vertical record, or a pair sampled at other times: on their union
        knots, *columns = common_knots(series)
    values = columns[0]
    values_y = columns[1] if rec_y is not None else None
    vertical = columns[-1] if excitation.vertical is not None else None
    for column in columns:
        column.setflags(write=False)
    peak = float(np.max(np.abs(values)))
    if values_y is not None:
        peak = float(np.max(np.hypot(values, values_y)))
    return GroundMotion(
        "record",
        peak,
        0.0,
        0.0,
        end,
        end + excitation.free_time,
        gain=1.0,
        knots=knots,
        values=values,
        name=rec.name,
        vertical=vertical,
        values_y=values_y,
    )


def pair_times(excitation: ExcitationConfig) -> str | None:
    """How a pair of records (``excitation.file_y``) is put on one time base: ``shared``
    when both have the same sample times (run as read), ``union`` when they differ (both
    on the union of their times, each linear between its own samples:
    :func:`common_knots`); None without a second component."""
    if excitation.motion is not None:  # given as arrays: a pair has one time base
        return "shared" if excitation.motion.is_pair else None
    if excitation.file_y is None:
        return None
    path = excitation.file_path or excitation.file
    t = load_record(str(path), excitation.units, excitation.file_sha256).t
    path_y = excitation.file_y_path or excitation.file_y
    t_y = load_record(str(path_y), excitation.units, excitation.file_y_sha256).t
    return "shared" if np.array_equal(t, t_y) else "union"


#: Largest peak acceleration of a scaled record [g]: the grid's largest amplitude.
MAX_SCALED_PGA_G = 1e3


def _scaled(record: Record, factor: float, path) -> np.ndarray:
    """The record's accelerations times ``factor`` [m/s^2], checked finite and at most
    MAX_SCALED_PGA_G in peak (a factor from a tiny PGA, or a large factor on a large
    record, would run a motion no column meets and arithmetic that is not sound)."""
    with np.errstate(all="ignore"):
        values = record.acceleration * factor
        peak = float(np.max(np.abs(values))) if values.size else 0.0
    if not (math.isfinite(factor) and math.isfinite(peak) and peak <= MAX_SCALED_PGA_G * G):
        shown = f"{peak / G:.4g} g" if math.isfinite(peak) else "not finite"
        raise RbmError(
            f"{path}: scaled by {factor:.4g}, its peak acceleration is {shown} (at most"
            f" {MAX_SCALED_PGA_G:g} g): lower the amplitude"
        )
    return values


def _limits(t: np.ndarray, ts: np.ndarray, vs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(values just before, values just after) the times t [s] of a record (ts [s], vs),
    linear between its samples and 0 outside them."""
    inside = np.interp(t, ts, vs)
    before = np.where((ts[0] < t) & (t <= ts[-1]), inside, 0.0)
    after = np.where((ts[0] <= t) & (t < ts[-1]), inside, 0.0)
    return before, after


def common_knots(series) -> tuple[np.ndarray, ...]:
    """Records given as (times [s], values), each linear between its own samples and 0
    outside them, on one set of knots: (knots, the values of each record at them, in the
    order given). The knots are the union of all their sample times, so every record is
    linear between consecutive knots and its values there are its own (at its samples) or
    its linear interpolation (between them): the motion each record describes, exactly,
    with no sample lost. Where any record jumps (its first or last value not 0, inside
    the run) the time is written twice, the values before then after. At the first knot
    the values after it are kept (the ground rests before), at the last those before it."""
    times = np.unique(np.concatenate([np.asarray(t, dtype=float) for t, _ in series]))
    limits = [_limits(times, np.asarray(ts, dtype=float), np.asarray(vs, dtype=float))
              for ts, vs in series]  # fmt: skip
    jump = np.zeros(times.size, dtype=bool)
    for before, after in limits:
        jump |= before != after
    jump[[0, -1]] = False
    counts = 1 + jump.astype(np.int64)
    at = np.repeat(np.arange(times.size), counts)
    first = (np.cumsum(counts) - counts)[jump]  # the first of each time written twice
    columns = []
    for before, after in limits:
        after = after.copy()
        after[-1] = before[-1]
        column = after[at]
        column[first] = before[jump]
        columns.append(column)
    return (times[at], *columns)


def merge_records(
    th: np.ndarray, ah: np.ndarray, tv: np.ndarray, av: np.ndarray, ay: np.ndarray | None = None
) -> tuple[np.ndarray, ...]:
    """A horizontal record (th [s], ah) and a vertical one (tv, av) on one set of knots
    (:func:`common_knots`): (knots, horizontal, vertical), and the second horizontal
    component ay (at the times th) after them when given."""
    series = [(th, ah), (tv, av)] + ([] if ay is None else [(th, ay)])
    return common_knots(series)


def pulse_motion(excitation: ExcitationConfig, amplitude: float, frequency_hz: float):
    """A near-fault pulse of peak acceleration amplitude [m/s^2] and frequency f_p [Hz]
    (inputs/pulses.py), then free motion up to excitation.duration [s] (the whole pulse
    is always simulated):

    - one-sine: A sin(w t) on [0, 1/f_p] (Zhang and Makris's cycloidal type A);
    - cycloidal: A cos(w t) on [0, 1/f_p] (type B; a sine of phase pi/2), whose ground
      velocity and displacement return to 0;
    - ricker: A (1 - 2 u^2) exp(-u^2), u = pi f_p (t - t0), on [0, 2 t0], t0 = 1.5 / f_p;
    - mavroeidis-papageorgiou: MP's acceleration pulse of gamma, nu on [0, gamma / f_p],
      scaled to the peak A.
    """
    kind, f = excitation.type, frequency_hz
    omega = 2.0 * math.pi * f
    if kind in ("one-sine", "cycloidal"):
        end = one_sine_duration(f)
        phase = 0.0 if kind == "one-sine" else 0.5 * math.pi
        return GroundMotion(kind, amplitude, omega, phase, end, max(excitation.duration, end))
    if kind == "ricker":
        end = ricker_duration(f)
        center = 0.5 * end
        knots = ricker_knots(omega, center)
        t_end = max(excitation.duration, end)
        return GroundMotion(kind, amplitude, omega, 0.0, end, t_end, center=center, knots=knots)
    gamma, nu = float(excitation.gamma), float(excitation.nu)
    end = mavroeidis_papageorgiou_duration(f, gamma)
    return GroundMotion(
        kind,
        amplitude,
        omega,
        nu,
        end,
        max(excitation.duration, end),
        gain=amplitude / mp_peak(gamma, nu),
        center=0.5 * end,
        gamma=gamma,
        knots=mp_knots(f, gamma, nu),
    )


def make_ground_motion(
    excitation: ExcitationConfig, amplitude_g: float, frequency_hz: float | None = None
) -> GroundMotion:
    """Ground motion of a run; amplitude in g, frequency in Hz and the angle in degrees at
    this edge only.

    frequency_hz is not used by 'free' and 'record' (None is accepted there). With
    excitation.y the motion has its analytic second component (:func:`second_component`),
    along (-sin angle, cos angle) as a record pair's y."""
    motion = _motion(excitation, amplitude_g, frequency_hz)
    y = excitation.y
    if y is not None and y.amplitude_ratio != 0.0 and motion.amplitude != 0.0:
        motion = dataclasses.replace(
            motion, second=second_component(motion, y.amplitude_ratio, y.phase_deg)
        )
    if excitation.angle == 0.0:
        return motion
    return dataclasses.replace(motion, angle=math.radians(excitation.angle))


def second_component(motion: GroundMotion, ratio: float, phase_deg: float) -> GroundMotion:
    """The analytic second horizontal component (excitation.y) of a harmonic or a pulse:
    its formula times ratio r [-], its phase led by phi = phase_deg [deg], on the same
    support (a_y = 0 where a_x is, after the pulse):

    - a sine (harmonic, half-sine, one-sine, cycloidal): a_y = r A sin(omega t + phase +
      phi), phase the first's (the harmonic's excitation.phase, pi/2 for the cycloidal);
    - mavroeidis-papageorgiou: the same pulse with nu + phi and the same velocity
      amplitude times r, so its peak is r A where phi is a multiple of pi;
    - ricker (no phase): the same wavelet times r, or -r where phi is an odd multiple of
      180 degrees (the config takes multiples of 180 only).
    """
    phi = math.radians(phase_deg)
    if motion.form == SINE:
        return dataclasses.replace(motion, amplitude=ratio * motion.amplitude,
                                   phase=motion.phase + phi)  # fmt: skip
    if motion.form == RICKER:
        sign = 1.0 if phase_deg % 360.0 == 0.0 else -1.0
        return dataclasses.replace(motion, amplitude=ratio * motion.amplitude,
                                   gain=sign * ratio * motion.shape_gain)  # fmt: skip
    if motion.form != MP:
        raise RbmError(f"excitation.y does not apply to a motion of kind {motion.kind}")
    nu, gain = motion.phase + phi, ratio * motion.shape_gain
    return dataclasses.replace(
        motion,
        amplitude=abs(gain) * mp_peak(motion.gamma, nu),
        phase=nu,
        gain=gain,
        knots=mp_knots(motion.omega / (2.0 * math.pi), motion.gamma, nu),
    )


def _motion(
    excitation: ExcitationConfig, amplitude_g: float, frequency_hz: float | None
) -> GroundMotion:
    if excitation.type == "free":
        return GroundMotion("free", 0.0, 1.0, 0.0, 0.0, excitation.duration)
    if excitation.type == "record":
        return record_motion(excitation, amplitude_g)
    if frequency_hz is None:
        raise RbmError(f"a frequency [Hz] is required for excitation type {excitation.type}")
    omega = 2.0 * math.pi * frequency_hz
    amplitude = amplitude_g * G
    if excitation.type in PULSES:
        return pulse_motion(excitation, amplitude, frequency_hz)
    if excitation.type == "half-sine":
        pulse_end = 0.5 / frequency_hz
        # the whole pulse is always simulated, then free motion up to `duration`
        t_end = max(excitation.duration, pulse_end)
        return GroundMotion("half-sine", amplitude, omega, 0.0, pulse_end, t_end)
    return GroundMotion(
        "harmonic", amplitude, omega, excitation.phase, excitation.duration, excitation.duration
    )
