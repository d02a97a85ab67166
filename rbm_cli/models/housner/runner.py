"""Housner's rigid rocking block (`housner`): true geometry, large rotations.

A monolithic column as one rigid block rocking on the corners of its base:

    theta'' = -p^2 [ sin(alpha sgn(theta) - theta) + (a_g / g) cos(alpha sgn(theta) - theta) ]

with the true centre of mass and the rotary inertia of the tapered solid about
a base corner (not the RBM's mid-height lumping). Integrated by scipy's DOP853
driven step by step, restarted at every impact and at the end of a pulse;
impacts (theta = 0), collapse (|theta| = c alpha) and peaks (theta' = 0) are
located by root finding on the step's dense output. Under a record every step ends at
a sample (rbm_cli.base.knots), where the acceleration has a kink.

References
----------
.. [1] G. W. Housner (1963). The behavior of inverted pendulum structures
   during earthquakes. Bulletin of the Seismological Society of America
   53(2), 403-417.
.. [2] P. D. Spanos and A.-S. Koh (1984). Rocking of rigid blocks due to
   harmonic shaking. Journal of Engineering Mechanics 110(11), 1627-1642.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy.integrate import DOP853, RK23, RK45

from rbm_cli.base.events import EVENT_EPS, STOP_MARGIN, first_crossing, hermite_dip
from rbm_cli.base.knots import clip_at_knots
from rbm_cli.config.types import G, SolverConfig
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.inputs.ground import SINE
from rbm_cli.models import methods
from rbm_cli.models.block.base import BlockRunner
from rbm_cli.models.housner.state import BlockRun, Recorder
from rbm_cli.models.housner.steps import (
    HousnerBlock,
    HousnerRun,
    HousnerSide,
    HousnerStep,
    peak_in_step,
)
from rbm_cli.models.methods import step_method
from rbm_cli.models.outcome import Outcome, budget_message
from rbm_cli.structures.arrays import REST_RATE
from rbm_cli.structures.block import (
    BlockGeometry,
    housner_energy,
    top_displacement,
)
from rbm_cli.structures.restitution import block_restitution, resolve

_METHODS = {m.__name__: clip_at_knots(m) for m in (DOP853, RK45, RK23)}


def ground_over_g(motion: GroundMotion):
    """a_g(t) / g [-] of the motion's forced segments, t [s]: the sine as
    amp_g sin(omega t + phase) with amp_g = A / g (the operations of the model's first
    version, so its results keep their bits), any other form as a_g(t) / g."""
    if motion.form == SINE:
        amp_g, om, ph = motion.amplitude / G, motion.omega, motion.phase
        return lambda tt: amp_g * math.sin(om * tt + ph)
    accel = motion.scalar(True)
    return lambda tt: accel(tt) / G


def _start(geometry, motion, e_rest, collapse_ratio, solver, record, output_dt, initial, events):
    """The block's constants and the state of the run at t = 0."""
    alpha, p = geometry.slenderness, geometry.frequency_parameter
    limit = collapse_ratio * alpha
    blk = HousnerBlock(
        alpha=alpha,
        p=p,
        e_rest=e_rest,
        limit=limit,
        barrier=float(housner_energy(min(limit, alpha), 0.0, alpha, p)),
        rest_rate=REST_RATE * p * alpha,
        eps=EVENT_EPS * alpha,
        level=G * math.tan(alpha),
        atol=solver.atol * np.array([alpha, p * alpha]),
        ground=ground_over_g(motion),
        gravity=motion.gravity(True),
        solver=solver,
        record=record,
    )
    y = np.array([float(initial[0]), float(initial[1])])
    run = HousnerRun(
        alpha=alpha,
        limit=limit,
        **BlockRun.parts(record, output_dt, events),
        top=lambda peak: float(top_displacement(geometry, peak)),
        side=int(np.sign(y[0])) or int(np.sign(y[1])) or 1,
        at_rest=not np.any(y),
        peak=abs(y[0]),
        y=y,
    )
    return blk, run


def _cut_at_event(eqs: HousnerSide, integ, y_old) -> HousnerStep:
    """The step just taken, cut at its first impact or collapse: a distance below zero at
    the step's end, or a dip of the cubic Hermite confirmed on the dense output; each
    row's own root (_earliest), an impact polished onto theta = 0."""
    t_old, t_new, y_new = integ.t_old, integ.t, integ.y
    kind = None
    dense = None
    d_old, d_new = eqs.dist(y_old), eqs.dist(y_new)
    t_hit = t_new if d_new.min() < 0.0 else None
    if t_hit is None:
        t_min = hermite_dip(d_old, d_new, eqs.ddist(y_old), eqs.ddist(y_new), t_new - t_old)
        if t_min is not None:
            dense = integ.dense_output()
            if eqs.dist(dense(t_old + t_min)).min() < 0.0:
                t_hit = t_old + t_min
    if t_hit is not None:
        dense = integ.dense_output() if dense is None else dense
        t_e, row = _earliest(dense, eqs.dist, eqs.ddist, t_old, t_hit)
        kind = "impact" if row == 0 else "collapse"
        if kind == "impact":
            t_e = _polish_zero(dense, t_e, t_old)
        t_new, y_new = t_e, dense(t_e)
    return HousnerStep(t_old, y_old, t_new, y_new, kind, dense)


def _step_to_event(blk: HousnerBlock, run: HousnerRun, eqs: HousnerSide, integ, stop_ok: bool):
    """Step the integrator up to the first event on this side.

    Returns
    -------
    str, None or Outcome  The event's kind ('impact' or 'collapse'; the state is then on
        it), None when the stepper reached its bound, the Outcome when the run ends here
        (a budget exceeded, or a peak of free motion below the barrier when stop_ok).
    """
    solver, out = blk.solver, run.out
    while integ.status == "running":
        msg = integ.step()
        if integ.status == "failed":
            return _fail(run.finish(), f"integrator: {msg} at t={run.t:.6g} s")
        out.n_steps += 1
        if out.n_steps > solver.max_steps:
            return _fail(run.finish(), budget_message("step", solver.max_steps))
        step = _cut_at_event(eqs, integ, run.y)
        t_pk, dense = peak_in_step(run, eqs.s, integ, step)
        if t_pk is not None and stop_ok:
            if blk.record:
                _emit(run.rec, dense, t_pk)
            run.t = t_pk
            return run.finish(message="free motion below the collapse barrier: stopped early")
        if blk.record:
            _emit(run.rec, integ.dense_output() if dense is None else dense, step.t_new)
        run.t, run.y = step.t_new, step.y_new
        if step.kind is not None:
            return step.kind
    return None


def _on_event(blk: HousnerBlock, run: HousnerRun, kind: str) -> Outcome | None:
    """Collapse ends the run (returns the Outcome); an impact multiplies the rate by e,
    flips the side and rests a block whose rate is below the rest rate."""
    out, t = run.out, run.t
    if kind == "collapse":
        out.t_collapse, out.collapse_interface = t, 1
        run.peak = max(run.peak, blk.limit)
        run.note((t, "collapse"))
        return run.finish("collapsed", "the block reached its collapse limit")
    out.n_impacts += 1
    run.note((t, "impact"))
    if out.n_uplifts + out.n_impacts > blk.solver.max_events:
        return _fail(run.finish(), budget_message("event", blk.solver.max_events))
    run.y = np.array([0.0, blk.e_rest * run.y[1]])
    run.side = -run.side
    if abs(run.y[1]) < blk.rest_rate:
        run.y, run.at_rest = np.zeros(2), True
        run.note((t, "rest"))
    return None


def _segment(
    blk: HousnerBlock,
    run: HousnerRun,
    motion: GroundMotion,
    seg_end: float,
    forced: bool,
    can_stop: bool,
) -> Outcome | None:
    """Run up to seg_end [s], the end of a segment of the motion, from rest to uplift and
    from impact to impact (the stepper restarted at each). Returns the Outcome if the run
    ends inside the segment, else None."""
    out, solver = run.out, blk.solver
    while run.t < seg_end:
        if run.at_rest:
            kind = run.wait(motion, seg_end, blk.level, forced)
            if kind == "end":  # no ground motion from here on: rests to the end
                return run.finish(message="at rest in free motion: stopped")
            if kind == "segment":
                return None
            run.y = np.zeros(2)
            if out.n_uplifts + out.n_impacts > solver.max_events:
                return _fail(run.finish(), budget_message("event", solver.max_events))
        eqs = HousnerSide(blk, run.side, forced, out)
        y = run.y
        stop_ok = can_stop and housner_energy(y[0], y[1], blk.alpha, blk.p) < blk.barrier * (
            1.0 - STOP_MARGIN
        )
        stepper = _METHODS[step_method(solver)]  # auto: DOP853
        integ = stepper(eqs.rhs, run.t, y, seg_end, rtol=solver.rtol, atol=blk.atol)
        integ.knots = motion.knots if motion.clipped else None  # a record's samples
        kind = _step_to_event(blk, run, eqs, integ, stop_ok)
        if isinstance(kind, Outcome):
            return kind
        if kind is None:
            run.t = seg_end
            continue
        stop = _on_event(blk, run, kind)
        if stop is not None:
            return stop
    return None


def housner_run(
    geometry: BlockGeometry,
    motion: GroundMotion,
    restitution: float | str = 1.0,
    collapse_ratio: float = 1.0,
    solver: SolverConfig = SolverConfig(),  # noqa: B008 (frozen dataclass)
    record: bool = False,
    output_dt: float = 0.002,
    *,
    initial: tuple[float, float] = (0.0, 0.0),
    early_stop: bool = True,
    events: list | None = None,
) -> Outcome:
    """One run of Housner's rigid block (large rotations).

    Parameters
    ----------
    geometry : BlockGeometry  alpha [rad], p [rad/s], H and b [m]
    motion : GroundMotion  a_g(t) [m/s^2] and the simulated time [s]
    restitution : float or 'housner'  Angular-velocity ratio e at impacts, in (0, 1]
    collapse_ratio : float  Collapse at |theta| >= collapse_ratio * alpha [-]
    solver : SolverConfig  Runge-Kutta pair, rtol, atol (scaled by alpha [rad]
        and p alpha [rad/s]), step and event budgets
    record : bool  Keep samples (t [s], [theta] [rad], [rate] [rad/s]) every output_dt [s]
    output_dt : float  Sampling interval of the history [s]
    initial : (float, float)  Initial rotation [rad] and rate [rad/s]
    early_stop : bool  After a pulse or a record, stop at rest, or at a peak
        when the energy is below the collapse barrier
    events : list or None  If a list, (t [s], kind) is appended for every
        'uplift', 'impact', 'rest' and 'collapse'

    Returns
    -------
    Outcome  max_top is the exact top displacement of :func:`top_displacement`.

    Notes
    -----
    .. math:: \\theta'' = -p^2 [\\sin(\\alpha s - \\theta) + (a_g/g) \\cos(\\alpha s - \\theta)],
              \\quad s = \\mathrm{sgn}\\,\\theta

    Rest until |a_g| > g tan(alpha), lifting on the side turning away from a_g;
    impact at theta = 0 (theta' <- e theta'; a rate below REST_RATE p alpha
    rests); collapse at |theta| = c alpha. Energy per unit corner inertia,
    E = theta'^2/2 + p^2 (cos(alpha - |theta|) - cos(alpha)), is conserved in
    free motion; its barrier is E at |theta| = min(c, 1) alpha.

    References
    ----------
    Housner (1963): see the module references.
    """
    e_rest = resolve(restitution, lambda: block_restitution(geometry))
    if not 0.0 < e_rest <= 1.0:
        raise ValueError("restitution must be in (0, 1]")
    solver = solver.for_run(motion.t_end, 1)
    blk, run = _start(
        geometry, motion, e_rest, collapse_ratio, solver, record, output_dt, initial, events
    )
    collapsed = run.collapsed_at_start()
    if collapsed is not None:
        return collapsed
    for seg_start, seg_end in motion.segments():
        if run.t >= seg_end:
            continue
        forced = motion.forced(seg_start)
        can_stop = early_stop and motion.after_pulse(seg_start)
        stop = _segment(blk, run, motion, seg_end, forced, can_stop)
        if stop is not None:
            return stop
    return run.finish()


def _earliest(dense, dist, ddist, t_old: float, t_hit: float) -> tuple[float, int]:
    """(time, row) of the earliest crossing of either event row (0: impact, 1:
    collapse) in [t_old, t_hit], each row's own root on the dense output
    (events.first_crossing), not a root of their minimum, which can be a later one."""

    def rows(ts):
        yy = dense(np.atleast_1d(ts))  # (2, m): theta, rate
        return dist(yy), ddist(yy)

    hit = first_crossing(rows, t_old, t_hit, xtol=1e-15)
    if hit is None:  # t_hit is below zero by construction; only round-off gets here
        return t_hit, int(np.argmin(dist(dense(t_hit))))
    return hit


def _polish_zero(dense, t_e: float, t_lo: float) -> float:
    """Move an impact found at s theta = -EVENT_EPS alpha onto theta = 0 (Newton)."""
    for _ in range(2):
        th, v = dense(t_e)
        if v == 0.0:
            break
        t_e = max(t_e - th / v, t_lo)
    return t_e


def _emit(rec: Recorder, dense, t_stop: float) -> None:
    ts = rec.times(t_stop)
    if len(ts):
        yy = dense(ts)
        rec.emit(ts, yy[0], yy[1])


def _fail(out: Outcome, message: str) -> Outcome:
    out.status, out.message = "failed", message
    return out


class HousnerRunner(BlockRunner):
    """`housner` (rbm_cli.models.contract.Runner): the config's monolithic column as Housner's
    rigid block, with its true geometry (rbm_cli.structures.block)."""

    def __init__(self, config) -> None:
        super().__init__(config)
        methods.resolve(config)  # an explicit method that does not apply: refused

    def _integrate(self, motion: GroundMotion, solver: SolverConfig, **options) -> Outcome:
        method = methods.resolve(self.config, solver).name
        solver = dataclasses.replace(solver, method=method)  # auto: DOP853
        out = housner_run(
            self.geometry,
            motion,
            solver=solver,
            restitution=self.restitution,
            collapse_ratio=self.config.collapse.ratio,
            initial=self.initial,
            **options,
        )
        out.method = solver.method
        return out
