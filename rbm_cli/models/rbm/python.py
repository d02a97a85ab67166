"""Event-driven integration of the Rigid Beam Model.

Inside one set of active law pieces the equations are smooth (linear), so the
integrator runs an explicit Runge-Kutta pair (scipy's DOP853/RK45 stepper,
driven step by step here) and stops exactly at every event, found by root
finding on the step's dense output:

- a law argument reaching the end of its current piece (a kink of the law):
  the pieces change and the integrator restarts there;
- a zero crossing of a law argument after an excursion beyond its elastic
  branch (every crossing for a rigid law): an impact, the argument's rate is
  multiplied by the restitution e and the integrator restarts. With e = 1 and
  a law linear through zero (an elastic first piece) the crossing changes
  nothing: it is no event, only counted at the step's end (Pieces.settle);
- a collapse quantity reaching c times its limit: the run stops.

The normalised distances to these surfaces are evaluated once per step
(vectorised over interfaces); a step that comes within reach of a surface is
checked on its dense output, and the earliest crossing of any surface is the
event (events.first_crossing).

For a rigid monolithic column the column stays at rest, with no integration,
until the ground demand exceeds the uplift level (found exactly from the
excitation); a rigid block that loses its velocity at an impact returns to
rest (rest detection: post-impact rate below REST_RATE * p * theta_u).
"""

from __future__ import annotations

import math
import time

import numpy as np
from scipy.integrate import DOP853, RK23, RK45

from rbm_cli.base.detmath import pow_pos_python as pow_pos
from rbm_cli.config.types import SolverConfig
from rbm_cli.models.events import BIG, EVENT_EPS, REST_RATE, Pieces  # noqa: F401 (kernel's)
from rbm_cli.models.knots import clip_at_knots, next_knot
from rbm_cli.models.methods import step_method
from rbm_cli.models.outcome import Outcome
from rbm_cli.models.rbm.python_steps import (
    RunState,
    SmoothPiece,
    handle_event,
    leave_rest,
    step_to_event,
)
from rbm_cli.models.rbm.python_vertical import VerticalPiece
from rbm_cli.physics.equations import Model
from rbm_cli.physics.excitation import GroundMotion


class _ErrorNorm(float):
    """An error norm whose power is rbm_cli.base.detmath.pow_pos, the compiled kernel's:
    scipy's step-size control (SAFETY * norm ** exponent) then takes the kernel's
    steps, whatever the machine's libm."""

    __slots__ = ()

    def __pow__(self, exponent):
        return pow_pos(float(self), float(exponent))


def _with_kernel_power(method):
    class Stepper(clip_at_knots(method)):
        def _estimate_error_norm(self, K, h, scale):
            return _ErrorNorm(super()._estimate_error_norm(K, h, scale))

    Stepper.__name__ = method.__name__
    return Stepper


_METHODS = {m.__name__: _with_kernel_power(m) for m in (DOP853, RK45, RK23)}


def initial_step(rhs, t0: float, y0, f0, t_bound: float, order: int, rtol, atol) -> float:
    """scipy's select_initial_step (Hairer, Norsett and Wanner, II.4) with the kernel's
    power (rbm_cli.base.detmath.pow_pos), as rbm_cli.models.rbm.kernel_rk._initial_step computes it.
    rhs(t, y) is the right-hand side (called once), f0 its value at (t0, y0)."""
    interval = abs(t_bound - t0)
    if interval == 0.0:
        return 0.0
    scale = atol + np.abs(y0) * rtol

    def rms(v):
        return math.sqrt(float(np.sum(v * v)) / v.size)

    d0, d1 = rms(y0 / scale), rms(f0 / scale)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, interval)
    d2 = rms((rhs(t0 + h0, y0 + h0 * f0) - f0) / scale) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = pow_pos(0.01 / max(d1, d2), 1.0 / (order + 1))
    return min(100.0 * h0, h1, interval)


def _start_stepper(run: RunState, piece: SmoothPiece, seg_end: float):
    """The Runge-Kutta stepper from (run.t, run.y) to seg_end [s]. After an event it
    restarts with the step size its error control proposed before it (the solution stays
    smooth up to its second derivative; a fresh initial-step guess was rejected 1.4 times
    per event)."""
    solver = run.solver
    stepper = _METHODS[step_method(solver)]  # auto: DOP853
    if run.h_carry is None:  # counted as scipy counts it: its own f0, then one call
        f0 = piece.rhs(run.t, run.y, counted=False)
        bound = seg_end  # a record: its guess stays on the straight piece (the kernel's)
        if run.knots is not None:
            t = run.t
            bound = next_knot(run.knots, t + 10 * abs(np.nextafter(t, np.inf) - t), seg_end)
        first = initial_step(
            piece.rhs, run.t, run.y, f0, bound, stepper.order, solver.rtol, run.atol
        )
    else:
        first = min(run.h_carry, seg_end - run.t)
    integ = stepper(
        piece.rhs, run.t, run.y, seg_end, rtol=solver.rtol, atol=run.atol, first_step=first
    )
    integ.knots = run.knots
    return integ


def _run_segment(
    run: RunState, motion: GroundMotion, seg_end: float, free_seg: bool, can_stop: bool
) -> Outcome | None:
    """Integrate up to seg_end [s], the end of a segment of the motion (forced, or free
    when free_seg), piece by piece and event by event. Returns the Outcome if the run
    ends inside the segment, else None."""
    ag, gam = motion.scalar(not free_seg), motion.gravity(not free_seg)
    while run.t < seg_end:
        if run.at_rest:
            kind = leave_rest(run, motion, seg_end, not free_seg)
            if kind == "end":
                run.out.t_end = run.t
                return run.out
            if kind == "segment":
                return None
        if gam is None:
            piece = SmoothPiece(run, ag)
        else:
            piece = VerticalPiece(run, ag, gam, motion.vertical)
        integ = _start_stepper(run, piece, seg_end)
        event = step_to_event(run, piece, integ, can_stop)
        if isinstance(event, Outcome):
            return event
        if event is None:
            if integ.status == "finished":
                run.t = seg_end
            continue
        run.h_carry = integ.h_abs
        stop = handle_event(run, piece, event)
        if stop is not None:
            return stop
    return None


def integrate(
    model: Model,
    motion: GroundMotion,
    theta0: np.ndarray,
    rate0: np.ndarray,
    solver: SolverConfig,
    record: bool = False,
    output_dt: float = 0.002,
    early_stop: bool = True,
) -> Outcome:
    """Integrate one run of the model under a ground motion.

    Parameters
    ----------
    model : Model  Assembled equations
    motion : GroundMotion  a_g(t) [m/s^2] and the simulated time
    theta0, rate0 : (n,) Initial absolute rotations [rad] and rates [rad/s]
    solver : SolverConfig  Method, tolerances and budgets
    record : bool  Keep samples every output_dt [s] for a time history
    early_stop : bool  Stop a free motion (after a pulse or a record) whose
        energy is below the lowest collapse barrier (`relative` only)
    """
    deadline = time.monotonic() + solver.max_wall_time
    pieces = Pieces(model, silent=True)
    run = RunState.start(model, pieces, theta0, rate0, solver, record, output_dt, deadline)
    run.knots = motion.knots if motion.clipped else None  # a record: steps end at samples
    for seg_start, seg_end in motion.segments():
        if run.t >= seg_end:
            continue
        run.h_carry = None  # the step size proposed before an event, carried over it
        free_seg = not motion.forced(seg_start)
        can_stop = early_stop and free_seg and motion.is_pulse
        stop = _run_segment(run, motion, seg_end, free_seg, can_stop)
        if stop is not None:
            return stop
    out, t = run.out, run.t
    out.t_end = t
    return out
