"""Ground motions (SPEC section 3), SI inside: a_g [m/s^2], t [s], omega [rad/s]."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rbm_cli.config.types import ExcitationConfig, G


@dataclass(frozen=True)
class GroundMotion:
    """A ground acceleration a_g(t) = amplitude * sin(omega t + phase) on [0, t_pulse_end).

    kind : str  'harmonic', 'half-sine' or 'free'
    amplitude : float  Peak acceleration [m/s^2]
    omega : float  Circular frequency [rad/s]
    phase : float  [rad]
    pulse_end : float  Time after which a_g = 0 [s] (inf-like for harmonic: the duration)
    t_end : float  Maximum simulated time [s]
    """

    kind: str
    amplitude: float
    omega: float
    phase: float
    pulse_end: float
    t_end: float

    def accel(self, t: float | np.ndarray) -> np.ndarray | float:
        """Ground acceleration a_g(t) [m/s^2]."""
        if self.amplitude == 0.0:
            return np.zeros_like(t) if isinstance(t, np.ndarray) else 0.0
        a = self.amplitude * np.sin(self.omega * np.asarray(t) + self.phase)
        if self.kind == "half-sine":
            a = np.where(np.asarray(t) <= self.pulse_end, a, 0.0)
        return a if isinstance(t, np.ndarray) else float(a)

    def displacement(self, t: np.ndarray) -> np.ndarray:
        """Ground displacement u_g(t) [m] (for plots; the dynamics see only a_g).

        Harmonic: the steady form -a_g / omega^2. Half-sine: integrated from rest,
        so the ground keeps the pulse's velocity 2 A / omega after the pulse.
        """
        t = np.asarray(t, dtype=float)
        if self.amplitude == 0.0:
            return np.zeros_like(t)
        A, w = self.amplitude, self.omega
        if self.kind == "harmonic":
            return -A / w**2 * np.sin(w * t + self.phase)
        tp = np.minimum(t, self.pulse_end)
        u = A / w * tp - A / w**2 * np.sin(w * tp)
        return u + 2.0 * A / w * np.maximum(t - self.pulse_end, 0.0) * (t > self.pulse_end)

    def segments(self) -> list[tuple[float, float]]:
        """Intervals on which a_g is smooth (the integrator restarts between them)."""
        if self.kind == "half-sine" and self.pulse_end < self.t_end:
            return [(0.0, self.pulse_end), (self.pulse_end, self.t_end)]
        return [(0.0, self.t_end)]

    def after_pulse(self, seg_start: float) -> bool:
        """Whether the segment starting at seg_start [s] is the free motion after a half-sine."""
        return self.kind == "half-sine" and seg_start >= self.pulse_end

    def forced(self, seg_start: float) -> bool:
        """Whether a_g is non-zero on the segment starting at seg_start [s]."""
        return self.amplitude > 0.0 and not self.after_pulse(seg_start)

    def next_exceedance(self, t0: float, level: float) -> float | None:
        """First time t >= t0 with |a_g(t)| > level, or None before t_end.

        Exact for the sine: |sin(psi)| > s with s = level / amplitude holds on
        (asin(s) + k pi, pi - asin(s) + k pi). The returned time is where
        |a_g| = level and rising (or t0 itself when already above).
        """
        if self.amplitude <= level:
            return None
        last = min(self.pulse_end, self.t_end)
        if t0 >= last:
            return None
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
        """Side (sign of theta) a block lifts on at time t: away from a_g."""
        return -1 if self.accel(t) > 0.0 else 1


def make_ground_motion(
    excitation: ExcitationConfig, amplitude_g: float, frequency_hz: float
) -> GroundMotion:
    """Ground motion of a run; amplitude in g and frequency in Hz at this edge only."""
    if excitation.type == "free":
        return GroundMotion("free", 0.0, 1.0, 0.0, 0.0, excitation.duration)
    omega = 2.0 * math.pi * frequency_hz
    amplitude = amplitude_g * G
    if excitation.type == "half-sine":
        pulse_end = 0.5 / frequency_hz
        # the whole pulse is always simulated, then free motion up to `duration`
        t_end = max(excitation.duration, pulse_end)
        return GroundMotion("half-sine", amplitude, omega, 0.0, pulse_end, t_end)
    return GroundMotion(
        "harmonic", amplitude, omega, excitation.phase, excitation.duration, excitation.duration
    )
