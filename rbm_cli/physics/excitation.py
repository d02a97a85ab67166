"""Ground motions (SPEC section 3), SI inside: a_g [m/s^2], t [s], omega [rad/s].

A :class:`GroundMotion` is what every model integrates: a horizontal ground acceleration
a_g(t) in one of the forms of :mod:`rbm_cli.physics.ground_forms` (a sine, a Ricker or
Mavroeidis-Papageorgiou pulse, or a sampled record, linear between its samples), its
segments (the intervals on which a_g is smooth enough for an integrator to step through;
it restarts between them), where the pulse or record ends and the run ends.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass
from functools import cached_property, lru_cache
from pathlib import Path

import numpy as np

from rbm_cli.base.errors import RbmError
from rbm_cli.config.types import PULSES, ExcitationConfig, G
from rbm_cli.physics.ground_forms import (
    FORM_OF_KIND,
    MP,
    RICKER,
    SAMPLED,
    SINE,
    exceedance_on_pieces,
    mp_knots,
    ricker_knots,
    sampled_displacement,
    scalar_form,
)
from rbm_cli.physics.pulses import (
    mavroeidis_papageorgiou,
    mavroeidis_papageorgiou_duration,
    mp_peak,
    one_sine_duration,
    ricker_duration,
    ricker_wavelet,
)
from rbm_cli.physics.records import Record, read_record

#: Kinds whose motion ends (pulse_end) before the run may: free motion follows.
PULSE_KINDS = ("half-sine", *PULSES, "record")
#: Points a formula pulse is sampled at for its displacement (plots only) [-].
_DISPLACEMENT_POINTS = 20_000
#: Samples a period of a pulse made a record (GroundMotion.sampled) [-].
SAMPLES_PER_PERIOD = 2000


@dataclass(frozen=True, eq=False)
class GroundMotion:
    """A ground acceleration a_g(t) on [0, pulse_end], then 0, simulated up to t_end.

    kind : str  'harmonic', 'half-sine', 'free', 'one-sine', 'cycloidal', 'ricker',
        'mavroeidis-papageorgiou' or 'record'
    amplitude : float  Peak acceleration max |a_g| [m/s^2]
    omega : float  Circular frequency [rad/s] (2 pi f_p for the pulses; 0 for a record)
    phase : float  [rad] (the harmonic's phase; pi/2 for the cycloidal pulse, whose
        acceleration is a cosine; nu for Mavroeidis-Papageorgiou)
    pulse_end : float  Time after which a_g = 0 [s] (the harmonic: its duration)
    t_end : float  Maximum simulated time [s]
    gain : float or None  Multiplier of the form (ground_forms) [m/s^2]; None: amplitude
        (a sine or Ricker pulse); amplitude / peak of the unit shape (MP); 1 (a record,
        whose values are in m/s^2)
    center : float  Centre t0 of a Ricker or MP pulse [s]
    gamma : float  MP's oscillatory character gamma [-]
    knots : ndarray or None  Times a_g is monotone between [s]: a record's sample times,
        the extrema of a Ricker or MP pulse
    values : ndarray or None  A record's accelerations at its sample times [m/s^2]
    name : str  A record's name (its file stem)
    """

    kind: str
    amplitude: float
    omega: float
    phase: float
    pulse_end: float
    t_end: float
    gain: float | None = None
    center: float = 0.0
    gamma: float = 0.0
    knots: np.ndarray | None = None
    values: np.ndarray | None = None
    name: str = ""

    @property
    def form(self) -> int:
        """The form of a_g (ground_forms: SINE, RICKER, MP or SAMPLED)."""
        return FORM_OF_KIND[self.kind]

    @property
    def shape_gain(self) -> float:
        """The multiplier of the form [m/s^2] (see ``gain``)."""
        return self.amplitude if self.gain is None else self.gain

    @property
    def is_pulse(self) -> bool:
        """Whether the motion ends before the run may (free motion follows it)."""
        return self.kind in PULSE_KINDS

    @property
    def clipped(self) -> bool:
        """Whether integrator steps must end at every knot (a record: a_g has a kink at
        every sample)."""
        return self.form == SAMPLED

    @cached_property
    def _scalar(self):
        return scalar_form(
            self.form,
            self.shape_gain,
            self.omega,
            self.phase,
            self.center,
            self.gamma,
            self.knots,
            self.values,
        )

    def scalar(self, forced: bool = True):
        """a_g(t) [m/s^2] as a function of a float t [s], for the integrators: the
        motion's form when ``forced``, else 0 (a free segment)."""
        if not forced or self.amplitude == 0.0:
            return lambda tt: 0.0
        return self._scalar

    def accel(self, t: float | np.ndarray) -> np.ndarray | float:
        """Ground acceleration a_g(t) [m/s^2] (0 after the pulse), vectorised: a Ricker or
        MP pulse by physics/pulses.py (the integrators evaluate the same formula,
        ground_forms.scalar_form, to round-off)."""
        if self.amplitude == 0.0:
            return np.zeros_like(t) if isinstance(t, np.ndarray) else 0.0
        tt = np.asarray(t, dtype=float)
        if self.form == SINE:
            a = self.amplitude * np.sin(self.omega * tt + self.phase)
        elif self.form == SAMPLED:
            a = np.interp(tt, self.knots, self.values, left=0.0, right=0.0)
        elif self.form == RICKER:
            a = ricker_wavelet(tt, self.shape_gain, self.omega / (2.0 * math.pi), self.center)
        elif self.form == MP:
            f = self.omega / (2.0 * math.pi)
            peak = math.copysign(self.amplitude, self.shape_gain)
            a = mavroeidis_papageorgiou(tt, peak, f, self.gamma, self.phase)
        if self.kind != "harmonic":
            a = np.where(tt <= self.pulse_end, a, 0.0)
        return a if isinstance(t, np.ndarray) else float(a)

    def displacement(self, t: np.ndarray) -> np.ndarray:
        """Ground displacement u_g(t) [m] (for plots; the dynamics see only a_g).

        Harmonic: the steady form -a_g / omega^2. Pulses and records: integrated from
        rest, so the ground keeps the velocity it has at the end of the pulse (half-sine:
        2 A / omega); a record exactly (cubic between samples), a Ricker or MP pulse on
        20 000 points of its duration.
        """
        t = np.asarray(t, dtype=float)
        if self.amplitude == 0.0:
            return np.zeros_like(t)
        A, w = self.amplitude, self.omega
        if self.kind == "harmonic":
            return -A / w**2 * np.sin(w * t + self.phase)
        if self.kind == "half-sine":
            tp = np.minimum(t, self.pulse_end)
            u = A / w * tp - A / w**2 * np.sin(w * tp)
            return u + 2.0 * A / w * np.maximum(t - self.pulse_end, 0.0) * (t > self.pulse_end)
        if self.form == SAMPLED:
            return sampled_displacement(self.knots, self.values, t)
        ts = np.linspace(0.0, self.pulse_end, _DISPLACEMENT_POINTS + 1)
        return sampled_displacement(ts, np.asarray(self.accel(ts)), t)

    def segments(self) -> list[tuple[float, float]]:
        """Intervals on which a_g is continuous (the integrator restarts between them):
        a pulse, then its free motion; a record also restarts at its first sample when
        the acceleration jumps there from rest."""
        cuts = [0.0]
        if self.form == SAMPLED and self.knots[0] > 0.0 and self.values[0] != 0.0:
            cuts.append(float(self.knots[0]))
        if self.is_pulse and self.pulse_end < self.t_end:
            cuts.append(self.pulse_end)
        cuts.append(self.t_end)
        return list(zip(cuts[:-1], cuts[1:], strict=True))

    def after_pulse(self, seg_start: float) -> bool:
        """Whether the segment starting at seg_start [s] is the free motion after a pulse
        or a record."""
        return self.is_pulse and seg_start >= self.pulse_end

    def forced(self, seg_start: float) -> bool:
        """Whether a_g is non-zero on the segment starting at seg_start [s]."""
        return self.amplitude > 0.0 and not self.after_pulse(seg_start)

    def next_exceedance(self, t0: float, level: float) -> float | None:
        """First time t >= t0 with |a_g(t)| > level, or None before t_end.

        Exact for the sine: |sin(psi)| > s with s = level / amplitude holds on
        (asin(s) + k pi, pi - asin(s) + k pi). The returned time is where
        |a_g| = level and rising (or t0 itself when already above). Other forms:
        exact on their monotone pieces (ground_forms.exceedance_on_pieces).
        """
        if self.amplitude <= level:
            return None
        last = min(self.pulse_end, self.t_end)
        if t0 >= last:
            return None
        if self.form != SINE:
            values = self.values if self.form == SAMPLED else None
            return exceedance_on_pieces(self._scalar, self.knots, t0, level, last, values)
        s = level / self.amplitude
        psi0 = self.omega * t0 + self.phase
        if abs(math.sin(psi0)) > s:
            return t0
        lo = math.asin(s)
        k = math.ceil((psi0 - lo) / math.pi)
        psi = lo + k * math.pi
        if psi < psi0:
            psi += math.pi
        t = (psi - self.phase) / self.omega
        if t >= last:
            return None
        return t

    def rest_end(self, t: float, seg_end: float, level: float, forced: bool) -> tuple[str, float]:
        """How the rest of a rigid block, at rest at time t, ends.

        Returns ('end', t_end) when no ground motion is left (it rests to the end
        of the run), ('segment', seg_end) when |a_g| stays below `level`
        [m/s^2] in the current segment, or ('uplift', t_up) when it exceeds it.
        """
        if not forced:
            return "end", self.t_end
        t_up = self.next_exceedance(t, level)
        if t_up is None or t_up >= seg_end:
            return "segment", seg_end
        return "uplift", t_up

    def uplift_side(self, t: float) -> int:
        """Side (sign of theta) a block lifts on at time t: away from a_g (a pulse's
        formula as the integrators evaluate it)."""
        if self.form in (RICKER, MP):
            return -1 if self._scalar(t) > 0.0 else 1
        return -1 if self.accel(t) > 0.0 else 1

    def sampled(self, per_period: int = SAMPLES_PER_PERIOD) -> GroundMotion:
        """This pulse as a record: sampled on [0, pulse_end], per_period samples a period
        2 pi / omega and at its knots (its extrema, so the peak is kept), linear between.

        For a model that integrates piecewise-linear forcing only (housner-linear's closed
        form). Linear interpolation errs by at most h^2 max|a''| / 8 with h the sample
        step: for a Ricker pulse (max|a''| = 6 (pi f)^2 A) and the default 2000 samples a
        period, 1.9e-6 A. Measured against the rigid RBM, which evaluates the formula
        (tests/test_pulses_run.py, Ricker and two MP pulses, 18 cells each): collapse
        times within 2.1e-5 s and peak ratios within 4.2e-5, falling 100-fold with 10
        times the samples (the sampling's h^2, not the models, makes the difference).
        """
        if self.form == SAMPLED or self.form == SINE:
            return self
        count = max(2, math.ceil(per_period * self.omega * self.pulse_end / (2.0 * math.pi)))
        ts = np.union1d(np.linspace(0.0, self.pulse_end, count + 1), self.knots)
        values = np.asarray(self.accel(ts), dtype=float)
        return GroundMotion(
            "record",
            float(np.max(np.abs(values))),
            0.0,
            0.0,
            self.pulse_end,
            self.t_end,
            gain=1.0,
            knots=ts,
            values=values,
            name=f"{self.kind} (sampled)",
        )


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


def record_motion(excitation: ExcitationConfig, amplitude_g: float) -> GroundMotion:
    """The ground motion of a record excitation at amplitude [g] (its PGA after scaling
    with scale 'pga', a plain factor [-] with scale 'factor'): the scaled record, then
    free motion for excitation.free_time [s]."""
    path = excitation.file_path or excitation.file
    if path is None:
        raise RbmError("excitation.file is required for type record")
    rec = load_record(str(path), excitation.units, excitation.file_sha256)
    if excitation.scale == "pga":
        factor = amplitude_g * G / rec.pga
    else:
        factor = float(amplitude_g)
    values = rec.acceleration * factor
    values.setflags(write=False)
    peak = float(np.max(np.abs(values)))
    end = rec.duration
    return GroundMotion(
        "record",
        peak,
        0.0,
        0.0,
        end,
        end + excitation.free_time,
        gain=1.0,
        knots=rec.t,
        values=values,
        name=rec.name,
    )


def pulse_motion(excitation: ExcitationConfig, amplitude: float, frequency_hz: float):
    """A near-fault pulse of peak acceleration amplitude [m/s^2] and frequency f_p [Hz]
    (physics/pulses.py), then free motion up to excitation.duration [s] (the whole pulse
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
    """Ground motion of a run; amplitude in g and frequency in Hz at this edge only.

    frequency_hz is not used by 'free' and 'record' (None is accepted there)."""
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
