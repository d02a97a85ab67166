"""The ground motion every model integrates, SI inside: a_g [m/s^2], t [s].

A :class:`GroundMotion` is a horizontal ground acceleration a_g(t) in one of the forms of
:mod:`rbm_cli.inputs.ground` (a sine, a Ricker or Mavroeidis-Papageorgiou pulse, or
a sampled record, linear between its samples, with its upward acceleration a_v(t) if any),
its segments (the intervals on which a_g is continuous: an integrator restarts between
them), where the pulse or record ends and the run ends. :mod:`rbm_cli.inputs.excitation`
makes one from a config (``make_ground_motion``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from rbm_cli.config.types import PULSES, G
from rbm_cli.inputs.ground import (
    FORM_OF_KIND,
    MP,
    RICKER,
    SAMPLED,
    SINE,
    as_samples,
    form_function,
    next_uplift,
    pair_uplift,
    sampled_displacement,
    vertical_factor,
)
from rbm_cli.inputs.pulses import mavroeidis_papageorgiou, ricker_wavelet

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
    gain : float or None  Multiplier of the form (inputs.ground) [m/s^2]; None: amplitude
        (a sine or Ricker pulse); amplitude / peak of the unit shape (MP); 1 (a record,
        whose values are in m/s^2)
    center : float  Centre t0 of a Ricker or MP pulse [s]
    gamma : float  MP's oscillatory character gamma [-]
    knots : ndarray or None  Times a_g is monotone between [s]: a record's sample times,
        the extrema of a Ricker or MP pulse
    values : ndarray or None  A record's accelerations at its sample times [m/s^2]
    name : str  A record's name (its file stem)
    vertical : ndarray or None  A record's upward ground acceleration a_v at the knots
        [m/s^2] (excitation.vertical): every weight acts as if gravity were g + a_v(t).
        With it, the knots are the union of both records' samples, a time written twice
        where either jumps (its first or last value not 0), value before then after.
    angle : float  Azimuth of the ground's motion in plan [rad], from the x axis: the
        ground accelerates along (cos angle, sin angle). The planar models rock in the x
        plane and take 0 only; the models in three dimensions take any.
    values_y : ndarray or None  A record's second horizontal component at the knots
        [m/s^2], acting along (-sin angle, cos angle) (excitation.file_y; models in three
        dimensions only). Sampled at other times than the record, both are on the union
        of their samples' times (each linear between its own samples, as read)
    second : GroundMotion or None  A harmonic's or a pulse's analytic second horizontal
        component (excitation.y: the same form and support, its own gain, phase and
        knots), acting along (-sin angle, cos angle) as values_y does
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
    vertical: np.ndarray | None = None
    angle: float = 0.0
    values_y: np.ndarray | None = None
    second: GroundMotion | None = None

    @property
    def paired(self) -> bool:
        """Whether the motion has a second horizontal component (a record's, values_y, or
        a formula's, second)."""
        return self.values_y is not None or self.second is not None

    @property
    def direction(self) -> np.ndarray:
        """The unit vector in plan the ground accelerates along, (cos angle, sin angle)."""
        if self.angle == 0.0:
            return np.array([1.0, 0.0])
        return np.array([math.cos(self.angle), math.sin(self.angle)])

    @cached_property
    def _y_component(self) -> GroundMotion:
        """The second horizontal component as a motion of its own (a record's samples on the
        same knots, or the formula's second), whose compiled form a run evaluates."""
        if self.second is not None:
            return self.second
        peak = float(np.max(np.abs(self.values_y)))
        return dataclasses.replace(self, amplitude=peak, values=self.values_y, values_y=None)

    def accel_y(self, t: np.ndarray) -> np.ndarray | None:
        """A pair's second component a_y(t) [m/s^2] as read (along (-sin angle, cos angle)),
        vectorised as :meth:`accel`; None for a motion of one component."""
        if not self.paired:
            return None
        return self._y_component.accel(t)

    @property
    def ground_y(self) -> tuple:
        """The second component's ground tuple as the compiled functions read it
        (inputs.ground; a record pair's says SAMPLED, its values being values_y; gain 0
        for a motion of one component)."""
        if self.second is not None:
            return self.second._ground
        if self.values_y is not None:
            return (SAMPLED, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)
        return (SINE, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)

    @property
    def knots_y(self) -> np.ndarray:
        """The knots of a formula's second component (empty for none or a record's)."""
        return as_samples(None if self.second is None else self.second.knots)

    @cached_property
    def horizontal_peak(self) -> float:
        """max over the motion of |(a_x, a_y)| [m/s^2]: the amplitude, or a pair's
        resultant (a record pair's at its samples; a formula pair's on its pulse, or a
        period of a harmonic, sampled 256 times a period and at both knots, its best local
        maxima then refined by Brent's method)."""
        if self.second is None:
            return self.amplitude
        # lazy: scipy.optimize loads only where needed (docs/architecture.md, Start-up)
        from scipy.optimize import minimize_scalar  # here: no scipy at import

        end = min(self.pulse_end, self.t_end)
        if self.kind == "harmonic":  # periodic: one period holds its largest value
            end = min(end, 2.0 * math.pi / self.omega)
        count = max(8, math.ceil(256 * self.omega * end / (2.0 * math.pi)))
        extra = [k for k in (self.knots, self.second.knots) if k is not None]
        ts = np.union1d(np.linspace(0.0, end, count + 1), np.concatenate([[0.0], *extra]))
        ts = ts[(ts >= 0.0) & (ts <= end)]

        def size(t):
            ax, ay = self.accel(t), self.second.accel(t)
            return np.hypot(ax, ay)

        values = size(ts)
        best = float(np.max(values))
        inner = np.nonzero((values[1:-1] >= values[:-2]) & (values[1:-1] >= values[2:]))[0] + 1
        for k in inner[np.argsort(values[inner])[::-1][:4]]:
            found = minimize_scalar(lambda x: -float(size(x)), bounds=(ts[k - 1], ts[k + 1]),
                                    method="bounded", options={"xatol": 1e-13 * end})  # fmt: skip
            best = max(best, -float(found.fun))
        return best

    def accel_plan(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(a_x(t), a_y(t)) [m/s^2] in the ground's axes at times t [s] (vectorised as
        :meth:`accel`): the motion along ``direction``, plus a pair's second component
        across it (the values :meth:`horizontal` gives one time at a time)."""
        d = self.direction
        a = np.asarray(self.accel(t), dtype=float)
        b = self.accel_y(t)
        if b is None:
            return a * d[0], a * d[1]
        b = np.asarray(b, dtype=float)
        return a * d[0] - b * d[1], a * d[1] + b * d[0]

    def horizontal(self, forced: bool = True):
        """(a_x(t), a_y(t)) [m/s^2] in the ground's axes as a function of a float t [s]: the
        motion along ``direction``, plus the second component across it (a pair of
        records); 0 off a forced segment."""
        d = self.direction
        a = self.scalar(forced)
        if not self.paired:
            return lambda tt: (a(tt) * d[0], a(tt) * d[1])
        b = self._y_component.scalar(forced)

        def pair(tt):
            ax, ay = a(tt), b(tt)
            return ax * d[0] - ay * d[1], ax * d[1] + ay * d[0]

        return pair

    def next_pair_exceedance(self, t0: float, ratio: float, t_stop: float) -> float | None:
        """A pair: the first time t in [t0, t_stop) where the horizontal acceleration's
        magnitude exceeds ratio (g + a_v(t)) [m/s^2] (ratio = tan(alpha) for a block's
        uplift), or None (inputs.ground.pair_uplift: exact on each sample interval of a
        record pair; two sines in closed form; other formulas to the last bit)."""
        knots, values, vertical = self._samples
        last = min(self.pulse_end, self.t_end, t_stop)
        t = pair_uplift(float(t0), float(ratio), float(last), self._ground, self.ground_y,
                        knots, values, as_samples(self.values_y), self.knots_y,
                        vertical)  # fmt: skip
        return None if t < 0.0 else t

    @property
    def form(self) -> int:
        """The form of a_g (inputs.ground: SINE, RICKER, MP or SAMPLED)."""
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
        knots, values, _ = self._samples
        return form_function(self._ground, knots, values)

    @property
    def has_vertical(self) -> bool:
        """Whether an upward ground acceleration changes the weights (a record's)."""
        return self.vertical is not None

    def gravity(self, forced: bool = True):
        """(g + a_v(t)) / g [-] as a function of a float t [s] on a forced segment, or None
        (no vertical motion: the integrators keep their expressions without it)."""
        if not forced or self.vertical is None:
            return None
        knots, vertical = as_samples(self.knots), as_samples(self.vertical)
        return lambda tt: vertical_factor(tt, knots, vertical)

    @cached_property
    def lift_off(self) -> float | None:
        """First time [s] the ground's upward acceleration reaches -g (g + a_v <= 0: the
        column would leave the ground), or None."""
        if self.vertical is None or not np.any(self.vertical <= -G):
            return None
        k = int(np.argmax(self.vertical <= -G))
        if k == 0 or self.knots[k] == self.knots[k - 1]:
            return float(self.knots[k])
        t_a, t_b = float(self.knots[k - 1]), float(self.knots[k])
        v_a, v_b = float(self.vertical[k - 1]), float(self.vertical[k])
        return t_a + (t_b - t_a) * ((-G - v_a) / (v_b - v_a))

    def until(self, t_stop: float) -> GroundMotion:
        """The motion simulated up to t_stop [s] only (its pulse cut there)."""
        second = None if self.second is None else self.second.until(t_stop)
        return dataclasses.replace(
            self,
            pulse_end=min(self.pulse_end, t_stop),
            t_end=min(self.t_end, t_stop),
            second=second,
        )

    def scalar(self, forced: bool = True):
        """a_g(t) [m/s^2] as a function of a float t [s], for the integrators: the
        motion's form when ``forced``, else 0 (a free segment)."""
        if not forced or self.amplitude == 0.0:
            return lambda tt: 0.0
        return self._scalar

    def accel(self, t: float | np.ndarray) -> np.ndarray | float:
        """Ground acceleration a_g(t) [m/s^2] (0 after the pulse), vectorised: a Ricker or
        MP pulse by inputs/pulses.py (the integrators evaluate the same formula,
        inputs.ground.ground_at, to round-off)."""
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
        if self.form == SAMPLED:
            first = self.values[0] != 0.0 or (self.has_vertical and self.vertical[0] != 0.0)
            if self.knots[0] > 0.0 and first:
                cuts.append(float(self.knots[0]))
            twice = np.nonzero(np.diff(self.knots) == 0.0)[0]
            cuts += [float(self.knots[k]) for k in twice if 0.0 < self.knots[k] < self.pulse_end]
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
        """First time t >= t0 with |a_g(t)| > level [m/s^2], or None before the end of
        the pulse or run: the compiled search the integrators share
        (inputs.ground.next_uplift: exact for the sine, exact on the monotone pieces of
        the other forms; with a vertical record the level is level (g + a_v(t)) / g). The
        time returned is where |a_g| = level and rising (t0 itself when already above)."""
        if self.amplitude <= level and self.vertical is None and self.second is None:
            return None  # (a record pair's amplitude is its resultant's peak)
        last = min(self.pulse_end, self.t_end)
        if t0 >= last:
            return None
        if self.paired:  # a pair: the magnitude of the two components
            return self.next_pair_exceedance(t0, level / G, last)
        t = next_uplift(float(t0), float(level), float(self.amplitude), self._ground,
                        *self._samples, float(last))  # fmt: skip
        return None if t < 0.0 else t

    @cached_property
    def _ground(self) -> tuple:
        """The motion's ground tuple, as the compiled functions read it (inputs.ground)."""
        return (int(self.form), float(self.shape_gain), float(self.omega), float(self.phase),
                float(self.center), float(self.gamma), 0.0, 0.0, 0.0)  # fmt: skip

    @cached_property
    def _samples(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """knots, values and vertical as float64 arrays (empty for None)."""
        return as_samples(self.knots), as_samples(self.values), as_samples(self.vertical)

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

    def uplift_direction(self, t: float) -> np.ndarray:
        """The unit vector in plan a block at rest lifts toward at time t: away from the
        horizontal acceleration (a pair's resultant, or a_g along ``direction``)."""
        if not self.paired:
            return self.uplift_side(t) * self.direction
        ax, ay = self.horizontal(True)(t)
        size = math.hypot(ax, ay)
        return np.array([-ax / size, -ay / size])

    def uplift_side(self, t: float) -> int:
        """Side (sign of theta) a block lifts on at time t: away from a_g (a pulse's
        formula or samples as the integrators evaluate them)."""
        if self.form != SINE:
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
            angle=self.angle,
        )
