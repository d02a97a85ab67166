"""What the exact integrator takes of a ground motion, and what it refuses.

A sampled record (times t_k, accelerations a_k) is exact per sample interval as a
piecewise-linear forcing, as Nigam and Jennings integrate response spectra:
forcing_arrays.record_arrays turns it into one 'linear' segment per interval. The sine
pulses (half-sine, one-sine, cycloidal: a sine of phase 0 or pi/2 on [0, pulse_end]) are
one harmonic segment, then free motion (forcing_arrays.sine_arrays).

Refused, each in one line: the Ricker and Mavroeidis-Papageorgiou pulses (a Gaussian times
a polynomial, and a sine times a raised cosine cut at its ends: the latter is a sum of
three sines and could be exact, not done yet), a vertical record (the weights change with
g + a_v(t): the pieces' coefficients vary in time, no constant-coefficient closed form),
the absolute formulation (not symmetric) and a damped column (interface.damping: its
closed form would need the damped modes of every set of pieces, not written).
"""

from __future__ import annotations

from rbm_cli.base.errors import RbmError
from rbm_cli.structures.equations import Model

#: Ground motions the exact integrator takes: sines (one harmonic forcing a segment) and
#: records (one linear forcing a sample interval).
SINE_KINDS = ("harmonic", "half-sine", "free", "one-sine", "cycloidal")
EXACT_KINDS = (*SINE_KINDS, "record")
#: Why the others are refused.
_NOT_EXACT = {
    "ricker": "a Gaussian times a polynomial has no closed-form modal response",
    "mavroeidis-papageorgiou": "its sum of three sines is not integrated exactly yet",
}


def exact_why_not(
    formulation: str, kind: str, vertical: bool = False, damping: float = 0.0, method="exact"
) -> str | None:
    """Why the exact method does not take an interface formulation and an excitation type
    (vertical: whether the excitation has a vertical record; damping: interface.damping), in
    one line naming the method asked for (exact, or exact-first, which runs it); None if it
    does."""
    if damping > 0.0:
        return (
            f"solver.method {method} does not take interface.damping (its pieces' closed form is"
            " undamped): use a Runge-Kutta method (DOP853, as auto does)"
        )
    if formulation == "absolute":
        return (
            f"solver.method {method} needs interface.formulation relative or geometric (absolute"
            " is not symmetric): use a Runge-Kutta method (DOP853) for absolute"
        )
    if kind in _NOT_EXACT:
        return (
            f"solver.method {method} does not take excitation.type {kind} ({_NOT_EXACT[kind]}):"
            " use a Runge-Kutta method (DOP853)"
        )
    if kind not in EXACT_KINDS:
        return f"solver.method {method} does not take excitation.type {kind}"
    if vertical:
        return (
            f"solver.method {method} does not take excitation.vertical (the weights vary with"
            " g + a_v(t): no constant-coefficient pieces): use a Runge-Kutta method (DOP853)"
        )
    return None


def check_exact(model: Model, kind: str, vertical: bool = False) -> None:
    """Raise RbmError (one line) unless the exact method takes this model and excitation
    (vertical: whether the excitation has a vertical record)."""
    reason = exact_why_not(model.formulation, kind, vertical, model.damping)
    if reason is not None:
        raise RbmError(reason)
