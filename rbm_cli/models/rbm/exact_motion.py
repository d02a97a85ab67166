"""What the exact integrator takes of a ground motion: smooth segments, each with one
closed-form forcing (rbm_cli.models.rbm.exact_modal.Forcing), and what it refuses.

A sampled record (times t_k, accelerations a_k) is exact per sample interval as a
piecewise-linear forcing, as Nigam and Jennings integrate response spectra:
sampled_segments turns it into one 'linear' segment per interval.
"""

from __future__ import annotations

import numpy as np

from rbm_cli.base.errors import RbmError
from rbm_cli.models.rbm.exact_modal import Forcing
from rbm_cli.physics.equations import Model
from rbm_cli.physics.excitation import GroundMotion

#: Ground motions the exact integrator takes today.
EXACT_KINDS = ("harmonic", "half-sine", "free")


def check_exact(model: Model, kind: str) -> None:
    """Raise RbmError (one line) unless the exact method takes this model and excitation."""
    if model.formulation == "absolute":
        raise RbmError(
            "solver.method exact needs interface.formulation relative or geometric (absolute"
            " is not symmetric): use a Runge-Kutta method (DOP853) for absolute"
        )
    if kind not in EXACT_KINDS:
        raise RbmError(
            f"solver.method exact takes harmonic, half-sine and free excitations, not {kind}"
        )


def forcing_segments(motion: GroundMotion) -> list[tuple[float, float, Forcing]]:
    """(start [s], end [s], forcing) of the motion's smooth segments."""
    out = []
    for start, end in motion.segments():
        if motion.forced(start):
            forcing = Forcing("harmonic", motion.amplitude, motion.omega, motion.phase)
        else:
            forcing = Forcing("zero")
        out.append((start, end, forcing))
    return out


def sampled_segments(
    times: np.ndarray, accel: np.ndarray, t_end: float
) -> list[tuple[float, float, Forcing]]:
    """Segments of a sampled record: a_g linear between samples (times [s], increasing;
    accel [m/s^2]), zero after the last sample up to t_end [s]."""
    times, accel = np.asarray(times, dtype=float), np.asarray(accel, dtype=float)
    out = []
    for k in range(times.size - 1):
        t0, t1 = float(times[k]), float(times[k + 1])
        if t0 >= t_end:
            break
        slope = (accel[k + 1] - accel[k]) / (t1 - t0)
        out.append((t0, min(t1, t_end), Forcing("linear", t0=t0, a0=float(accel[k]), a1=slope)))
    if times.size and times[-1] < t_end:
        out.append((float(times[-1]), t_end, Forcing("zero")))
    return out


def resolve_segments(model: Model, motion: GroundMotion, segments=None) -> list:
    """The forcing segments of a run: the motion's (forcing_segments, which checks its kind),
    or segments given by the caller (a sampled record: sampled_segments), for which the
    motion gives only its end and kind. A rigid monolith rests until its uplift level is
    exceeded, found from a harmonic's formula: under a given piecewise-linear forcing it
    is not supported yet (one-line RbmError)."""
    if segments is None:
        check_exact(model, motion.kind)
        return forcing_segments(motion)
    check_exact(model, "free")
    if model.uplift_level is not None and any(f.kind == "linear" for _, _, f in segments):
        raise RbmError(
            "solver.method exact: a rigid monolith under a piecewise-linear forcing is not"
            " supported yet (its rest and uplift are found for harmonic motions only)"
        )
    return list(segments)
