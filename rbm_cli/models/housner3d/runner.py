"""`housner-3d`: the rigid cylinder rocking and rolling on its rim (rbm_cli.structures.cylinder)
under a ground motion in any horizontal direction, integrated by scipy's DOP853 (RK45,
RK23) step by step like `housner`, the events located on each step's dense output:

- **uplift** when |a_g| exceeds (g + a_v) tan(alpha), onto the rim's point away from a_g;
- **impact** where the lean crosses the vertical. Within the pinned lean of it
  (pinned_lean: 1000 solver.atol alpha, solver.atol alpha from an uplift from rest up to
  the next impact) the contact is pinned: a lean that comes that near is followed, its
  contact held where it leaned as it came in, until it crosses the line across that
  direction (theta = 0 exactly in a plane) or turns away. The horizontal angular velocity
  then becomes e times itself, the spin about the axis is kept, the lean is set upright,
  and the column rocks on toward where its axis moves, pinned until its lean is
  LEAVE_FACTOR times that distance out. A lean that passes farther from the vertical rolls
  round it (Srinivasan and Ruina 2008). In a plane this is Housner's impact
  (theta' <- e theta');
- **collapse** at a tilt of collapse.ratio alpha (Outcome.azimuth: where it leaned);
  Outcome.turns is the angle the lean's direction swept while the tilt was WOBBLE_LEVEL
  alpha or more at both ends of a step (a wobble), in turns;
- **rest** after an impact below REST_RATE p alpha.

max_rotation_ratio is the peak tilt over alpha in any direction (Brent on the dense output
where the tilt turns); max_top the top centre's largest distance in plan from where it
stood (rolling moves the base), at step ends and peaks.

The motion is run in its own frame (rbm_cli.models.plan): along x, a pair's second
component along y, and what is reported in plan (the top's path, the collapse azimuth) is
turned back to the ground's axes; a motion of one component stays in its vertical plane to
the bit. A run stops early at rest after the motion and, a sweep's run, where `housner`
stops: at a peak of free motion after a pulse or a record, its energy below the collapse
barrier, while it lies in that plane (one that left it may wobble, its later peaks higher:
it runs to rest or to the end). A history's rotation is the tilt in the motion's vertical
plane: Housner's theta in a planar motion.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy.integrate import DOP853, RK23, RK45
from scipy.optimize import brentq

from rbm_cli.base.events import EVENT_EPS, STOP_MARGIN, first_crossing
from rbm_cli.base.knots import clip_at_knots
from rbm_cli.config.types import G, SolverConfig
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.models import methods
from rbm_cli.models.block.base import BlockRunner
from rbm_cli.models.housner.state import BlockRun
from rbm_cli.models.methods import step_method
from rbm_cli.models.outcome import WOBBLE_LEVEL, Outcome, budget_message
from rbm_cli.models.plan import as_line, from_ground, to_ground, turned_start, wrapped
from rbm_cli.structures.arrays import REST_RATE
from rbm_cli.structures.cylinder import (
    STATE_SIZE,
    CylinderGeometry,
    cylinder_energy,
    cylinder_geometry,
    lean_direction,
    lean_rates,
    rolling_rates,
    tilt,
    tilt_in_plane,
    top_in_plan,
    uplift_level,
)

_METHODS = {m.__name__: clip_at_knots(m) for m in (DOP853, RK45, RK23)}


@dataclasses.dataclass
class _Run3d(BlockRun):
    """BlockRun with the state y (q, w, centre in plan), the contact direction c at q = 0,
    and the largest distance of the top from where it stood [m]."""

    y: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(STATE_SIZE))
    c: np.ndarray = dataclasses.field(default_factory=lambda: np.array([1.0, 0.0]))
    top_max: float = 0.0
    plan: dict = dataclasses.field(default_factory=dict)  # sample index -> top in plan [m]
    across: dict = dataclasses.field(default_factory=dict)  # ... -> tilt across the plane
    start_top: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(2))
    azimuth: float = math.nan
    phase: int = 0  # LEAVING, FREE or APPROACH (near the vertical)
    rising: bool = False  # from an uplift from rest up to the next impact (pinned_lean)
    swept: float = 0.0  # the angle the lean's direction swept while it wobbled [rad]
    angle: float = 0.0  # the motion's azimuth [rad]: its frame turned to the ground's axes


def _ground(motion: GroundMotion, forced: bool):
    """g_e(t) = (-a_x(t), -a_y(t), -(g + a_v(t))) [m/s^2] of a segment."""
    horizontal, gravity = motion.horizontal(forced), motion.gravity(forced)

    def ge(t: float) -> np.ndarray:
        ax, ay = horizontal(t)
        return np.array([-ax, -ay, -(G if gravity is None else G * gravity(t))])

    return ge


def cylinder_run(
    geo: CylinderGeometry,
    motion: GroundMotion,
    restitution: float,
    collapse_ratio: float = 1.0,
    solver: SolverConfig = SolverConfig(),  # noqa: B008 (frozen dataclass)
    record: bool = False,
    output_dt: float = 0.002,
    *,
    initial: tuple[float, float] = (0.0, 0.0),
    early_stop: bool = True,
    events: list | None = None,
    state: np.ndarray | None = None,
    across: tuple[float, float] = (0.0, 0.0),
) -> Outcome:
    """One run of the rigid cylinder in three dimensions (the module's rules).

    Parameters
    ----------
    geo : CylinderGeometry  The cylinder (rbm_cli.structures.cylinder)
    motion : GroundMotion  a_g(t) [m/s^2] along motion.direction, a_v(t), simulated time [s]
    restitution : float  e [-] in (0, 1]
    collapse_ratio : float  Collapse at a tilt of collapse_ratio alpha [-]
    solver : SolverConfig  Runge-Kutta pair, rtol, atol (scaled by alpha [rad], p alpha
        [rad/s] and h alpha [m]), step and event budgets
    record : bool  Keep samples every output_dt [s] (the module's history angle)
    initial : (float, float)  Initial tilt [rad] and its rate [rad/s] in the motion's plane
    across : (float, float)  The same across it (the motion's direction d turned by +90
        degrees in plan, d'): the column starts tilted by |(theta, theta')| toward theta d
        + theta' d' (theta the first of ``initial``, theta' the first of ``across``), its
        angular velocity horizontal, rate (e_z x d) + rate' (e_z x d') (the top moving
        along rate d + rate' d'), no spin about the vertical
    early_stop : bool  Stop at rest after the motion, and at a peak of free motion in the
        motion's plane below the collapse barrier (the module's notes)
    events : list or None  If a list, (t [s], kind) is appended for every 'uplift',
        'impact', 'rest' and 'collapse'
    state : (7,) array or None  A whole initial state in place of ``initial``: the lean q,
        the angular velocity w [rad/s] and the centre in plan [m], in the ground's axes (a
        wobble, say)

    Returns
    -------
    Outcome  max_ratio: [peak tilt / alpha]; max_top: the top's largest distance in plan
        from where it stood [m].
    """
    if not 0.0 < restitution <= 1.0:
        raise ValueError("restitution must be in (0, 1]")
    solver = solver.for_run(motion.t_end, 1)
    alpha, p = geo.slenderness, geo.block.frequency_parameter
    limit = collapse_ratio * alpha
    motion, beta = as_line(motion)  # a pair in phase: one component turned by beta
    if beta != 0.0:  # the start, given in the first component's plane, in the line's
        (initial, across) = zip(turned_start(float(initial[0]), float(across[0]), beta),
                                turned_start(float(initial[1]), float(across[1]), beta),
                                strict=True)  # fmt: skip
    angle = wrapped(motion.angle)  # the motion's frame (rbm_cli.models.plan)
    if motion.angle != 0.0:
        motion = dataclasses.replace(motion, angle=0.0)
    d = motion.direction
    run = _Run3d(
        alpha=alpha,
        limit=limit,
        **BlockRun.parts(record, output_dt, events),
        top=lambda peak: 0.0,
    )
    run.top = lambda peak: run.top_max
    theta0, rate0 = float(initial[0]), float(initial[1])
    side = 1.0 if theta0 > 0.0 or (theta0 == 0.0 and rate0 >= 0.0) else -1.0
    run.c = side * d
    run.y[0:2] = math.sin(abs(theta0)) * run.c
    run.y[2:4] = rate0 * np.array([-d[1], d[0]])  # about the horizontal normal to d
    if across[0] != 0.0 or across[1] != 0.0:
        run.y, run.c = _initial_state(d, theta0, rate0, float(across[0]), float(across[1]))
    run.angle = angle
    if state is not None:
        run.y = np.array(state, dtype=float)
        for part in (0, 2, 5):  # the lean, w's horizontal part, the centre: the motion's frame
            run.y[part : part + 2] = from_ground(run.y[None, part : part + 2], angle)[0]
        run.c = lean_direction(run.y[0:2], run.c)
    run.at_rest = not np.any(run.y[0:5])
    run.start_top = top_in_plan(geo, run.y)
    lean = math.hypot(run.y[0], run.y[1])
    run.phase = LEAVING if lean <= LEAVE_FACTOR * alpha * PIN_FACTOR * solver.atol else FREE
    run.peak = tilt(run.y[0:2])
    if run.peak >= limit:
        run.out.t_collapse, run.out.collapse_interface = 0.0, 1
        run.azimuth = math.atan2(run.c[1], run.c[0])
        return _finish(run, "collapsed", "initial rotation beyond the collapse limit")
    scale = np.array([alpha, alpha, p * alpha, p * alpha, p * alpha])
    atol = solver.atol * np.concatenate([scale, [geo.centre_height * alpha] * 2])
    at_barrier = np.zeros(STATE_SIZE)
    at_barrier[0] = math.sin(min(limit, alpha))
    consts = dict(
        geo=geo, e=restitution, s_limit=math.sin(limit), eps=EVENT_EPS * math.sin(alpha),
        rest_rate=REST_RATE * p * alpha, level=uplift_level(geo), atol=atol,
        barrier=cylinder_energy(geo, at_barrier, np.array([1.0, 0.0])),
        wobble=math.sin(WOBBLE_LEVEL * alpha), alpha=alpha, pin=PIN_FACTOR * solver.atol,
        rise=solver.atol,
        pin_rate=PIN_ROUNDOFF * EPS * p,
    )  # fmt: skip
    for seg_start, seg_end in motion.segments():
        if run.t >= seg_end:
            continue
        forced = motion.forced(seg_start)
        can_stop = early_stop and motion.after_pulse(seg_start)
        stop = _segment(run, motion, seg_end, forced, can_stop, solver, consts)
        if stop is not None:
            return stop
    return _finish(run)


def _initial_state(d: np.ndarray, theta: float, rate: float, theta_across: float,
                   rate_across: float) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """The state (7,) and the contact direction of a column tilted by theta along d and
    theta_across across it (d' = d turned by +90 degrees), turning at rate and rate_across
    (cylinder_run's ``across``): the lean q = sin|v| v / |v|, v = theta d + theta_across d',
    the angular velocity rate (e_z x d) + rate_across (e_z x d'); the contact toward v, or
    toward where the top moves when upright."""
    across = np.array([-d[1], d[0]])
    v = theta * d + theta_across * across
    size = math.hypot(v[0], v[1])
    moving = rate * d + rate_across * across
    speed = math.hypot(moving[0], moving[1])
    c = v / size if size > 0.0 else (moving / speed if speed > 0.0 else d)
    y = np.zeros(STATE_SIZE)
    y[0:2] = math.sin(size) * c
    y[2:4] = rate * np.array([-d[1], d[0]]) + rate_across * np.array([-across[1], across[0]])
    return y, c


def _finish(run: _Run3d, status: str = "survived", message: str = "") -> Outcome:
    out = run.finish(status, message)
    out.azimuth, out.turns = run.azimuth + run.angle, run.swept / (2.0 * math.pi)
    if run.rec.samples is not None:  # the top in plan at each sample; at rest where it was
        place, top_plan = run.start_top, np.zeros((len(out.samples), 2))
        across = np.zeros((len(out.samples), 1))
        for i in range(len(out.samples)):
            place = run.plan.get(i, place)
            top_plan[i] = place
            across[i, 0] = run.across.get(i, 0.0)
        out.top_plan, out.across = to_ground(top_plan, run.angle), across
    return out


def _in_plane(y: np.ndarray) -> bool:
    """Whether a state lies in the vertical plane of x to the bit (the lean, the rates and
    the centre: nothing across it)."""
    return y[1] == 0.0 and y[2] == 0.0 and y[4] == 0.0 and y[6] == 0.0


#: The phases of a rocking column near the vertical (rolling_rates' pinned contact):
#: leaving it after an uplift or an impact (pinned to the side it rocks onto) up to
#: LEAVE_FACTOR times the pinned lean; free (the lean's own direction); approaching it
#: within the pinned lean (pinned to where it leaned as it came in), up to the impact.
LEAVING, FREE, APPROACH = 0, 1, 2
LEAVE_FACTOR = 2.0
#: Spacing of doubles at 1 [-].
EPS = float(np.finfo(float).eps)
#: The pinned lean is never below PIN_ROUNDOFF eps p t alpha at time t [-] (pinned_lean).
PIN_ROUNDOFF = 100.0
#: The pinned lean is PIN_FACTOR atol alpha [-] (pinned_lean).
PIN_FACTOR = 1000.0


def pinned_lean(ts, k, rising: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """The pinned lean |q| at times ts [s] and its rate [1/s]: alpha times the larger of

    - PIN_FACTOR solver.atol: the integrator's absolute tolerance of the lean is atol
      alpha, so a lean that passes the vertical that near cannot be told from one through
      it, and its direction is not what the steps control; the events that pin and free
      the contact are located on the dense output, whose error is of that order: a
      thousand times it (at atol alone a record's 90 impacts along x moved the peak 1e-8
      from Housner's block, at 1000 atol 7e-12). 100 times smaller tolerances take it 100
      times nearer (a cell that turns on it is not robust to the solver);
    - PIN_ROUNDOFF eps p t: a lean that passes the vertical at a distance delta turns the
      contact round the rim at |q'| / delta (of the order of p alpha / delta), which steps
      of delta / |q'| resolve; at time t those must stay well above the spacing of
      doubles, eps t (at 1e-13 alpha and 21 s a run of this module's tests failed there).

    rising: from an uplift from rest up to the next impact, with solver.atol in place of
    PIN_FACTOR solver.atol: held to its uplift's direction while it leans slowly off the
    vertical as the motion turns, the column's peak moves by about the square root of that
    lean (a cylinder under an elliptic motion: 0.5820 alpha at 1e-9 alpha, 0.5793 at 1e-12
    and at 1e-14).
    """
    ts = np.asarray(ts, dtype=float)
    base = k["rise"] if rising else k["pin"]
    floor = k["pin_rate"] * ts
    pin = k["alpha"] * np.maximum(base, floor)
    return pin, np.where(floor > base, k["alpha"] * k["pin_rate"], 0.0)


def _segment(run, motion, seg_end, forced, can_stop, solver, k) -> Outcome | None:
    """Run up to seg_end [s], restarting the stepper at uplifts, impacts and where the
    lean leaves or comes near the vertical. The Outcome if the run ends here, else None."""
    out, geo = run.out, k["geo"]
    ge = _ground(motion, forced)
    d = motion.direction
    while run.t < seg_end:
        if run.at_rest:
            kind = run.wait(motion, seg_end, k["level"], forced)
            if kind == "end":  # no ground motion from here on: rests to the end
                return _finish(run, message="at rest in free motion: stopped")
            if kind == "segment":
                return None
            run.c = motion.uplift_direction(run.t)
            run.y, run.phase, run.rising = np.zeros(STATE_SIZE), LEAVING, True
            if out.n_uplifts + out.n_impacts > solver.max_events:
                return _fail(run, budget_message("event", solver.max_events))
        c0, pinned = run.c.copy(), run.phase != FREE
        # a peak of free motion may end the run (as `housner`'s): in the plane, below the
        # collapse barrier (its energy is constant up to the next impact)
        energy = cylinder_energy(geo, run.y, c0, pinned) if can_stop else math.inf
        stop_ok = _in_plane(run.y) and energy < k["barrier"] * (1.0 - STOP_MARGIN)

        def rhs(t, y, c0=c0, pinned=pinned):
            out.n_rhs += 1
            return rolling_rates(geo, y, c0, ge(t), pinned)

        stepper = _METHODS[step_method(solver)]
        integ = stepper(rhs, run.t, run.y, seg_end, rtol=solver.rtol, atol=k["atol"])
        integ.knots = motion.knots if motion.clipped else None
        kind = _steps(run, integ, k, solver, d, stop_ok)
        if isinstance(kind, Outcome):
            return kind
        if kind == "left":
            run.phase = FREE
        elif kind == "near":
            run.phase, run.c = APPROACH, lean_direction(run.y[0:2], run.c)
        elif kind == "impact":
            stop = _impact(run, k, solver)
            if stop is not None:
                return stop
    return None


def _steps(run, integ, k, solver, d, stop_ok=False):
    """Step until the phase's event, the state on it: 'left' (leaving: the lean is
    LEAVE_FACTOR pinned leans out), 'near' (free: the lean is within the pinned lean),
    'impact' (leaving or approaching: the lean crosses the line across its pinned
    direction; approaching: or turns away from the vertical), None at the segment's end,
    or the Outcome when the run ends (a collapse, a budget, or with stop_ok a peak of the
    tilt: every figure final)."""
    out, s_limit, eps = run.out, k["s_limit"], k["eps"]
    phase, c0, rising = run.phase, run.c, run.rising
    while integ.status == "running":
        t_old = run.t
        msg = integ.step()
        if integ.status == "failed":
            return _fail(run, f"integrator: {msg} at t={run.t:.6g} s")
        out.n_steps += 1
        if out.n_steps > solver.max_steps:
            return _fail(run, budget_message("step", solver.max_steps))
        dense = integ.dense_output()

        def rows(ts, dense=dense):
            yy = dense(np.atleast_1d(ts))
            q, dq = yy[0:2], lean_rates(yy)
            lean = np.hypot(q[0], q[1])
            d_lean = (q[0] * dq[0] + q[1] * dq[1]) / np.where(lean > 0.0, lean, 1.0)
            collapse, d_collapse = s_limit - lean, -d_lean
            pin, d_pin = pinned_lean(ts, k, rising)
            if phase == FREE:  # within the pinned lean: its square, smooth through the
                # vertical, so that a dip of a lean passing within it is seen
                near, d_near = lean * lean - pin * pin, 2.0 * (q[0] * dq[0] + q[1] * dq[1]
                                                              - pin * d_pin)  # fmt: skip
                return np.array([near, collapse]), np.array([d_near, d_collapse])
            # leaving or approaching: the lean back across the line across c0 (an impact)
            across = q[0] * c0[0] + q[1] * c0[1] + eps
            d_across = dq[0] * c0[0] + dq[1] * c0[1]
            if phase == LEAVING:  # or out to LEAVE_FACTOR pinned leans (free from there)
                dist, rate = LEAVE_FACTOR * pin - lean, LEAVE_FACTOR * d_pin - d_lean
                return (np.array([dist, collapse, across]),
                        np.array([rate, d_collapse, d_across]))  # fmt: skip
            turned = -d_lean  # > 0 while it comes nearer
            return (np.array([across, collapse, turned]),
                    np.array([d_across, d_collapse, np.zeros_like(lean)]))  # fmt: skip

        hit = first_crossing(rows, t_old, integ.t, xtol=1e-15)
        t_new = integ.t if hit is None else hit[0]
        y_end = dense(t_new)  # the dense output at the step's (cut) end, evaluated once
        t_pk = _peaks(run, dense, t_old, t_new, y_end, k["geo"])
        if stop_ok and t_pk is not None:
            if run.rec.samples is not None:
                _emit(run, dense, t_pk, d, k["geo"])
            run.t = t_pk
            return _finish(run, message="free motion below the collapse barrier: stopped early")
        if run.rec.samples is not None:
            _emit(run, dense, t_new, d, k["geo"])
        y_new = y_end if hit is not None else integ.y.copy()
        wobble = k["wobble"]  # a wobble: the lean WOBBLE_LEVEL alpha or more at both ends
        if math.hypot(run.y[0], run.y[1]) >= wobble and math.hypot(y_new[0], y_new[1]) >= wobble:
            run.swept += _turned(run.y, y_new)
        run.t, run.y = t_new, y_new
        if hit is None:
            continue
        if hit[1] == 1:
            out.t_collapse, out.collapse_interface = run.t, 1
            run.peak = max(run.peak, run.limit)
            q = run.y[0:2]
            run.azimuth = math.atan2(q[1], q[0])
            run.note((run.t, "collapse"))
            return _finish(run, "collapsed", "the column reached its collapse limit")
        if phase == LEAVING and hit[1] == 2:  # it fell back before it left the vertical
            return "impact"
        return ("left", "near", "impact")[phase]
    return None


def _turned(y0: np.ndarray, y1: np.ndarray) -> float:
    """|angle| [rad] between the leans' directions at two states (0 if either is upright):
    a step turns the lean by less than a half turn."""
    cross = y0[0] * y1[1] - y0[1] * y1[0]
    dot = y0[0] * y1[0] + y0[1] * y1[1]
    return abs(math.atan2(cross, dot)) if cross or dot else 0.0


def _impact(run, k, solver) -> Outcome | None:
    """The base strikes flat: horizontal rate times e, spin kept, q = 0, the contact
    direction where the axis now moves; rest below the rest rate."""
    out = run.out
    out.n_impacts += 1
    run.note((run.t, "impact"))
    if out.n_uplifts + out.n_impacts > solver.max_events:
        return _fail(run, budget_message("event", solver.max_events))
    y = run.y.copy()
    y[0:2] = 0.0
    y[2:4] *= k["e"]
    moving = np.array([y[3], -y[2]])  # n' = w x e_z in plan
    speed = math.hypot(moving[0], moving[1])
    run.phase, run.rising = LEAVING, False
    if speed < k["rest_rate"]:
        y[2:5] = 0.0
        run.y, run.at_rest = y, True
        run.note((run.t, "rest"))
        return None
    run.c, run.y = moving / speed, y
    return None


def _peaks(run, dense, t_old, t_new, y_end, geo) -> float | None:
    """The peak tilt and the top's farthest place on [t_old, t_new]: at the end (y_end, the
    dense output there), and where the tilt's rate turns from rising to falling (Brent on
    the dense output). Returns the time of a peak of the tilt in the step (the tilt rising
    at its start and not at its end, as `housner` finds it), or None."""

    def lean_rate(yy):
        dq = lean_rates(yy)
        return float(yy[0] * dq[0] + yy[1] * dq[1])

    def consider(y):
        run.peak = max(run.peak, tilt(y[0:2]))
        run.top_max = max(run.top_max, float(np.hypot(*top_in_plan(geo, y))))

    consider(y_end)
    r0, r1 = lean_rate(dense(t_old)), lean_rate(y_end)
    if r0 > 0.0 and r1 < 0.0:
        t_pk = brentq(lambda t: lean_rate(dense(t)), t_old, t_new, xtol=1e-15)
        consider(dense(t_pk))
        return t_pk
    return t_new if r0 > 0.0 and r1 == 0.0 else None


def _emit(run, dense, t_stop, d, geo) -> None:
    ts = run.rec.times(t_stop)
    for t in ts:
        y = dense(t)
        th, rate = tilt_in_plane(y, d)
        run.rec.emit(np.array([t]), th, rate)
        at = len(run.out.samples) - 1
        run.plan[at] = top_in_plan(geo, y)  # in the motion's frame, turned by _finish
        run.across[at] = tilt_in_plane(y, np.array([-d[1], d[0]]))[0]


def _fail(run: _Run3d, message: str) -> Outcome:
    out = _finish(run)
    out.status, out.message = "failed", message
    return out


class Housner3dRunner(BlockRunner):
    """`housner-3d` (rbm_cli.models.contract.Runner): the config's monolithic circular
    column as the rigid cylinder rocking and rolling on its rim."""

    def __init__(self, config) -> None:
        super().__init__(config)
        self.cylinder = cylinder_geometry(config.column)
        init = config.excitation.initial
        self.across = (
            float(init.rotations_across[0]) if init.rotations_across else 0.0,
            float(init.velocities_across[0]) if init.velocities_across else 0.0,
        )
        methods.resolve(config)  # an explicit method that does not apply: refused

    def _integrate(self, motion: GroundMotion, solver: SolverConfig, **options) -> Outcome:
        method = methods.resolve(self.config, solver).name
        solver = dataclasses.replace(solver, method=method)  # auto: DOP853
        out = cylinder_run(
            self.cylinder,
            motion,
            restitution=self.restitution,
            collapse_ratio=self.config.collapse.ratio,
            solver=solver,
            initial=self.initial,
            across=self.across,
            **options,
        )
        out.method = solver.method
        return out

    def run(self, motion: GroundMotion, solver: SolverConfig, **options) -> Outcome:
        """One run (rbm_cli.models.contract.Runner.run); a recorded history carries the
        top's path in plan."""
        return super().run(motion, solver, **options).carry_plan()
