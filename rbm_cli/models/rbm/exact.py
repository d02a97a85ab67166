"""Exact integration of the Rigid Beam Model (`solver.method: exact`), in Python.

Inside one set of active law pieces the column's equations are linear with constant
coefficients; the integrator decomposes them once per set of pieces (cached) and moves
every mode in closed form (rbm_cli.models.rbm.exact_modal, exact_piece): no time step
and no truncation error, only rounding. The events are those of the Runge-Kutta
integrator (rbm_cli.models.rbm.python, same surfaces, same EVENT_EPS, same actions):

- a law argument reaching the end of its piece (uplift, kink, impact with restitution;
  the pieces change and a new piece starts there);
- a collapse quantity reaching c times its limit (the run stops);
- with e = 1 and a law linear through zero, the first zero crossing after an excursion
  (a silent impact: counted, nothing changes). The step integrators count these at step
  ends; here they are located like any other event, so none is missed;
- a rigid monolith at rest, lifting when the ground demand exceeds its uplift level, and
  put to rest by an impact that leaves it almost no rate (REST_RATE);
- the end of the pulse, the end of the run, and the early stop of free motion after a
  pulse or a record once a peak is passed below the collapse barrier (monolithic columns).

Events are roots of sums of exponentials and sinusoids, found without a chance of missing
one by certified intervals (rbm_cli.models.rbm.exact_search). Outcome counters: n_steps
counts the certified intervals, n_rhs the closed-form evaluations of the state.

Formulations `relative` and `geometric` (symmetric stiffness) only; `absolute` stays with
the Runge-Kutta methods. Excitations: harmonic, free, the sine pulses (half-sine, one-sine,
cycloidal) and records, piecewise linear in time, which the closed form takes exactly per
sample interval (Forcing 'linear'); exact_motion says what is refused and why.
"""

from __future__ import annotations

import time

import numpy as np

from rbm_cli.config.types import SolverConfig
from rbm_cli.models.events import REST_RATE, Pieces
from rbm_cli.models.outcome import Outcome
from rbm_cli.models.rbm.exact_bounds import FIRST_STEP
from rbm_cli.models.rbm.exact_modal import Forcing
from rbm_cli.models.rbm.exact_motion import resolve_segments
from rbm_cli.models.rbm.exact_piece import LinearPiece, ModalSystem
from rbm_cli.models.rbm.exact_search import Evaluator, Point, next_point, refine_peaks
from rbm_cli.physics.equations import Model
from rbm_cli.physics.excitation import GroundMotion


class ExactRun:
    """One run of the exact integrator: the model's fixed data and the moving state."""

    def __init__(self, model, system, motion, theta0, rate0, solver, record, output_dt, deadline):
        n = model.n
        self.model, self.system, self.motion, self.solver = model, system, motion, solver
        self.n, self.record, self.output_dt, self.deadline = n, record, output_dt, deadline
        self.out = Outcome()
        self.out.max_ratio = np.zeros(n)
        self.out.friction = np.zeros(n)
        self.maxima = np.zeros(n + 1)
        self.pieces = Pieces(model, silent=True)
        self.theta = np.asarray(theta0, dtype=float).copy()
        self.rate = np.asarray(rate0, dtype=float).copy()
        self.pieces.locate(model.arg_map @ self.theta, model.arg_map @ self.rate)
        self.t = 0.0
        self.next_out = 0.0
        self.h = FIRST_STEP
        tu = model.column.rotation_capacity
        self.uplift_level = model.uplift_level
        self.rigid_mono = self.uplift_level is not None
        self.rest_rate = REST_RATE * model.rocking_p * tu.min()
        self.at_rest = self.rigid_mono and not (np.any(self.theta) or np.any(self.rate))
        self.barrier = None
        if n == 1:
            barrier = model.energy(np.array([model.collapse_ratio * tu[0]]), np.zeros(1))
            self.barrier = float(barrier[0])

    def emit(self, t_stop: float, piece: LinearPiece | None = None, a: Point | None = None):
        """Record the samples due up to t_stop [s]: from the piece's closed form from a,
        or zeros at rest."""
        n = self.n
        while self.record and self.next_out <= t_stop + 1e-12:
            if piece is None:
                self.out.samples.append((self.next_out, np.zeros(n), np.zeros(n)))
            else:
                q, v = piece.at(a.t, a.q, a.v, self.next_out - a.t)
                theta, rate = piece.theta(q, v)
                self.out.samples.append((self.next_out, theta, rate))
            self.next_out += self.output_dt

    def finish_peaks(self) -> None:
        n, out = self.n, self.out
        out.max_ratio = np.maximum(out.max_ratio, self.maxima[:n])
        out.max_top = max(out.max_top, float(self.maxima[n]))

    def budget(self) -> Outcome | None:
        """The failed Outcome if a budget is exceeded, else None."""
        return self.out.past_budget(self.solver, self.deadline, self.t)


def _friction(run: ExactRun, piece: LinearPiece, p: Point) -> None:
    """Friction demand |T_i / N_i| at a sample point (as the step integrators, at their
    step ends)."""
    ag = piece.forcing.accel(p.t)
    acc = piece.phi @ (-piece.lam * p.q + piece.f + piece.g * ag)
    fr = run.model.shear_ratios(acc[None, :], np.array([ag]))[0]
    run.out.friction = np.maximum(run.out.friction, fr)


def _passed_peak(run: ExactRun, piece: LinearPiece, prev: Point, p: Point) -> bool:
    """Early stop of free motion (monolithic column): a peak of |theta| passed between
    prev and p (as the step integrators judge it at their step ends; here also when p
    is an event, which the steps would have reached after a step end past the peak),
    with the energy (constant in free motion) below the collapse barrier."""
    if run.barrier is None or not prev.z[0] * prev.dz[0] > 0.0:
        return False
    if not (p.z[0] * p.dz[0] <= 0.0 or p.dz[0] * prev.dz[0] < 0.0):
        return False
    theta, rate = piece.theta(p.q, p.v)
    return float(run.model.energy(theta, rate)[0]) < run.barrier * (1.0 - 1e-9)


def _march(run: ExactRun, piece: LinearPiece, seg_end: float, can_stop: bool):
    """Advance through the piece up to its first event or seg_end [s].

    Returns the event row (the run's state is then on the event), None at seg_end, or
    the Outcome when the run ends here (a budget, the early stop)."""
    out = run.out
    ev = Evaluator(piece)
    a = ev.start(piece.t0, piece.q0, piece.v0)
    if a.d.min() <= 0.0:  # on a surface already (as the step integrators: an event at once)
        return int(np.argmin(a.d))
    row = None
    try:
        while a.t < seg_end and row is None:
            out.n_steps += 1
            stop = run.budget()
            if stop is not None:
                return stop
            b, row, run.h = next_point(ev, a, run.h, seg_end)
            refine_peaks(ev, a, b, run.maxima)
            run.emit(b.t, piece, a)
            _friction(run, piece, b)
            if can_stop and _passed_peak(run, piece, a, b):
                run.t = b.t
                out.t_end = b.t
                return out.stopped_early()
            a = b
    finally:
        out.n_rhs += ev.n_evals
    run.t = a.t
    run.theta, run.rate = piece.theta(a.q, a.v)
    return row


def _handle(run: ExactRun, piece: LinearPiece, row: int) -> Outcome | None:
    """Apply the event of the given row at (run.t, run.theta, run.rate), as
    rbm_cli.models.rbm.python_steps.handle_event does; a silent zero crossing
    (rows past the 4 n law and collapse rows) only flips its side and is counted."""
    out, n, t, model = run.out, run.n, run.t, run.model
    if row >= 4 * n:
        i = int(piece.silent[row - 4 * n])
        run.pieces.side[i] *= -1
        run.pieces.awaiting[i] = False
        out.n_impacts += 1
        return None
    out.n_events += 1
    if out.past_events(run.solver, t) is not None:
        return out
    which, i = divmod(row, n)
    if which >= 2:
        run.maxima[i] = max(run.maxima[i], model.collapse_ratio)
        out.t_end = t
        return out.collapse(t, i + 1)
    going_up = which == 1
    lo, hi = run.pieces.bounds()
    bound = hi[i] if going_up else lo[i]
    x_i = float(model.arg_map[i] @ run.theta)
    run.theta = run.theta + model.arg_inverse[:, i] * (bound - x_i)
    crossing = run.pieces.cross(i, going_up)
    if crossing == "uplift":
        out.n_uplifts += 1
    elif crossing == "impact":
        out.n_impacts += 1
        if model.restitution < 1.0:
            run.rate = model.impact_rates(run.rate, i)
        if run.rigid_mono and abs(run.rate[0]) < run.rest_rate:
            run.theta, run.rate = np.zeros(n), np.zeros(n)
            run.at_rest = True
    return None


def _leave_rest(run: ExactRun, seg_end: float, forced: bool) -> str:
    """A rigid monolith at rest: wait until the ground demand exceeds the uplift level
    (exact, from the excitation) and lift away from it (python_steps.leave_rest)."""
    kind, t_stop = run.motion.rest_end(run.t, seg_end, run.uplift_level, forced)
    run.emit(t_stop - (1e-15 if kind == "uplift" else 0.0))
    run.t = t_stop
    if kind in ("end", "segment"):
        return kind
    run.theta, run.rate = np.zeros(run.n), np.zeros(run.n)
    run.pieces.side[0] = run.motion.uplift_side(run.t)
    run.pieces.k[0] = 0
    run.at_rest = False
    run.out.n_uplifts += 1
    return kind


def _segment(run: ExactRun, forcing: Forcing, seg_end: float, can_stop: bool):
    """Run up to seg_end [s] under one forcing; the Outcome if the run ends inside."""
    while run.t < seg_end:
        if run.at_rest:
            before = run.motion.is_pulse and run.t < run.motion.pulse_end  # a record's start
            kind = _leave_rest(run, seg_end, forcing.kind != "zero" or before)
            if kind == "end":
                run.out.t_end = run.t
                return run.out
            if kind == "segment":
                return None
        piece = LinearPiece(run.system, run.pieces, forcing, run.t, run.theta, run.rate)
        event = _march(run, piece, seg_end, can_stop)
        if isinstance(event, Outcome):
            return event
        if event is not None:
            stop = _handle(run, piece, event)
            if stop is not None:
                return stop
    return None


def integrate_exact(
    model: Model,
    motion: GroundMotion,
    theta0: np.ndarray,
    rate0: np.ndarray,
    solver: SolverConfig,
    record: bool = False,
    output_dt: float = 0.002,
    early_stop: bool = True,
    system: ModalSystem | None = None,
    segments: list | None = None,
) -> Outcome:
    """One run of the model under a ground motion, exactly (same arguments and Outcome as
    rbm_cli.models.rbm.python.integrate; solver's budgets apply, its tolerances do not).

    system : ModalSystem, optional  The column's modes, cached across runs (a sweep);
        made here when None.
    segments : list of (start [s], end [s], Forcing), optional  The forcing, instead of
        the motion's (exact_motion.resolve_segments): a sampled record as piecewise-linear
        segments (exact_motion.sampled_segments).
    """
    segments = resolve_segments(model, motion, segments)
    if system is None:
        system = ModalSystem(model)
    deadline = time.monotonic() + solver.max_wall_time
    run = ExactRun(model, system, motion, theta0, rate0, solver, record, output_dt, deadline)
    try:
        last = "zero"
        for start, end, forcing in segments:
            if run.t >= end:
                continue
            if not (forcing.kind == "linear" and last == "linear"):
                run.h = min(run.h, FIRST_STEP)  # a record's next sample keeps its step
            last = forcing.kind
            free = forcing.kind == "zero" and start >= motion.pulse_end
            can_stop = early_stop and free and motion.is_pulse
            stop = _segment(run, forcing, end, can_stop)
            if stop is not None:
                return stop
        run.out.t_end = run.t
        return run.out
    finally:
        run.finish_peaks()
