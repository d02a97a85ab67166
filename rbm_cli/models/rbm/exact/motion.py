"""What the exact integrator takes of a ground motion: smooth segments, each with one
closed-form forcing (Forcing), and what it refuses.

A sampled record (times t_k, accelerations a_k) is exact per sample interval as a
piecewise-linear forcing, as Nigam and Jennings integrate response spectra:
forcing_arrays.record_arrays turns it into one 'linear' segment per interval
(sampled_segments for samples given by the caller). The sine pulses
(half-sine, one-sine, cycloidal: a sine of phase 0 or pi/2 on [0, pulse_end]) are one
harmonic segment, then free motion.

Refused, each in one line: the Ricker and Mavroeidis-Papageorgiou pulses (a Gaussian times
a polynomial, and a sine times a raised cosine cut at its ends: the latter is a sum of
three sines and could be exact, not done yet), a vertical record (the weights change with
g + a_v(t): the pieces' coefficients vary in time, no constant-coefficient closed form),
and the absolute formulation (not symmetric).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rbm_cli.base.errors import RbmError
from rbm_cli.physics.equations import Model

#: Ground motions the exact integrator takes: sines (one harmonic forcing a segment) and
#: records (one linear forcing a sample interval).
SINE_KINDS = ("harmonic", "half-sine", "free", "one-sine", "cycloidal")
EXACT_KINDS = (*SINE_KINDS, "record")
#: Why the others are refused.
_NOT_EXACT = {
    "ricker": "a Gaussian times a polynomial has no closed-form modal response",
    "mavroeidis-papageorgiou": "its sum of three sines is not integrated exactly yet",
}


@dataclass(frozen=True)
class Forcing:
    """The ground acceleration on a segment of the motion, from absolute time t [s]
    (rbm_cli.models.rbm.exact.modal.forcing_array makes its array).

    kind : str  'harmonic' (a_g = amplitude sin(omega t + phase)), 'linear'
        (a_g = a0 + a1 (t - t0), t0 the segment's start) or 'zero'
    amplitude [m/s^2], omega [rad/s], phase [rad]: the harmonic's
    t0 [s], a0 [m/s^2], a1 [m/s^3]: the linear piece's
    """

    kind: str
    amplitude: float = 0.0
    omega: float = 0.0
    phase: float = 0.0
    t0: float = 0.0
    a0: float = 0.0
    a1: float = 0.0


def exact_why_not(formulation: str, kind: str, vertical: bool = False) -> str | None:
    """Why the exact method does not take an interface formulation and an excitation type
    (vertical: whether the excitation has a vertical record), in one line; None if it does."""
    if formulation == "absolute":
        return (
            "solver.method exact needs interface.formulation relative or geometric (absolute"
            " is not symmetric): use a Runge-Kutta method (DOP853) for absolute"
        )
    if kind in _NOT_EXACT:
        return (
            f"solver.method exact does not take excitation.type {kind} ({_NOT_EXACT[kind]}):"
            " use a Runge-Kutta method (DOP853)"
        )
    if kind not in EXACT_KINDS:
        return f"solver.method exact does not take excitation.type {kind}"
    if vertical:
        return (
            "solver.method exact does not take excitation.vertical (the weights vary with"
            " g + a_v(t): no constant-coefficient pieces): use a Runge-Kutta method (DOP853)"
        )
    return None


def check_exact(model: Model, kind: str, vertical: bool = False) -> None:
    """Raise RbmError (one line) unless the exact method takes this model and excitation
    (vertical: whether the excitation has a vertical record)."""
    reason = exact_why_not(model.formulation, kind, vertical)
    if reason is not None:
        raise RbmError(reason)


def sampled_segments(
    times: np.ndarray, accel: np.ndarray, t_end: float
) -> list[tuple[float, float, Forcing]]:
    """Segments of a sampled record: a_g linear between samples (times [s], non-decreasing,
    a time written twice where a_g jumps; accel [m/s^2]), zero after the last sample up
    to t_end [s]."""
    times, accel = np.asarray(times, dtype=float), np.asarray(accel, dtype=float)
    out = []
    for k in range(times.size - 1):
        t0, t1 = float(times[k]), float(times[k + 1])
        if t0 >= t_end:
            break
        if t1 <= t0:  # a time written twice: a jump, from the value before to the one after
            continue
        slope = (accel[k + 1] - accel[k]) / (t1 - t0)
        out.append((t0, min(t1, t_end), Forcing("linear", t0=t0, a0=float(accel[k]), a1=slope)))
    if times.size and times[-1] < t_end:
        out.append((float(times[-1]), t_end, Forcing("zero")))
    return out


def given_segments(model: Model, segments) -> list:
    """Segments given by the caller (a sampled record: sampled_segments) instead of the
    motion's, checked: a rigid monolith rests until its uplift level is exceeded, found
    from a harmonic's formula; under a given piecewise-linear forcing it is not supported
    yet (one-line RbmError)."""
    check_exact(model, "free")
    if model.uplift_level is not None and any(f.kind == "linear" for _, _, f in segments):
        raise RbmError(
            "solver.method exact: a rigid monolith under a piecewise-linear forcing is not"
            " supported yet (its rest and uplift are found for harmonic motions only)"
        )
    return list(segments)
