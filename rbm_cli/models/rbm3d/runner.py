"""`rbm-3d`: the Rigid Beam Model of a column of circular drums in two horizontal directions
(rbm_cli.physics.beam3d), integrated by scipy's DOP853 (RK45, RK23) step by step as
`housner-3d` is, the events located on each step's dense output:

- **a kink** where a joint's |phi_i| reaches an edge of its law's piece (the edges move
  with a vertical record as in the plane): the piece changes. Leaving the elastic branch
  is an **uplift** (the joint opens);
- **an impact** where an open joint closes. A joint that comes back onto its elastic
  branch after an excursion has its direction c pinned there (phi_i / |phi_i|); the
  impact is where phi_i crosses the line across c (phi_i . c = 0: phi_i = 0 in a plane).
  For a rigid law (no elastic branch: a rigid monolith) the joint is pinned within
  UPRIGHT_LEAN theta_u of closure, where its direction is round-off (as `housner-3d`
  pins its contact), and closes there (crossing the line, or turning away); after the
  impact it rocks on toward where it moves, pinned until |phi| is LEAVE_FACTOR times that
  distance. A joint that passes farther from closure rolls round it (a wobble).
  The rule: an impulsive moment along c acts at the joint, so that the component of its
  relative rate along c becomes e times itself (momentum-consistent, as in the plane:
  Model.impact_rates; `absolute` scales that rate alone) and the rolling component across
  c is kept. In a plane c is the plane's direction and this is the planar impact. With
  e = 1 and an elastic joint the impact changes nothing: it is counted, not stopped at;
- **collapse** where a joint's collapse quantity (the magnitude of the pair of its
  directions) reaches collapse.ratio times its limit (Outcome.azimuth: the direction of
  that pair);
- **rest** (a rigid monolith) after an impact below REST_RATE p theta_u, and an uplift
  away from the ground's acceleration when it exceeds the uplift level.

Peaks (max_ratio per joint, the top's displacement in plan) are taken at step ends and
where their rates turn inside a step (Brent on the dense output); the friction demand
|T_i| / N_i at step ends. Outcome.turns: the largest angle a joint's direction swept while
it was open (a wobble), in turns. A history's rotations are seen in the motion's vertical
plane (theta_x cos angle + theta_y sin angle); the top's path in plan is kept beside them.
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np
from scipy.integrate import DOP853, RK23, RK45
from scipy.optimize import brentq

from rbm_cli.base.events import EVENT_EPS, first_crossing
from rbm_cli.base.knots import clip_at_knots
from rbm_cli.config.types import SolverConfig
from rbm_cli.models.housner.state import Recorder
from rbm_cli.models.methods import step_method
from rbm_cli.models.outcome import Outcome
from rbm_cli.models.rbm.runner import RbmRunner
from rbm_cli.physics.arrays import rest_levels
from rbm_cli.physics.beam3d import Beam3d, beam3d
from rbm_cli.physics.excitation import GroundMotion

_METHODS = {m.__name__: clip_at_knots(m) for m in (DOP853, RK45, RK23)}

#: A closed rigid joint's direction is pinned within UPRIGHT_LEAN theta_u of closure.
UPRIGHT_LEAN = 1e-6
#: ... and after an uplift or an impact, until LEAVE_FACTOR times that distance.
LEAVE_FACTOR = 2.0
#: A joint's phase: free (its own direction), leaving or approaching closure (pinned).
FREE, LEAVING, APPROACH = 0, 1, 2
#: The events watched: a kink up or down, near closure, left it, across the pinned line,
#: turned away near closure, collapse.
UP, DOWN, NEAR, LEFT, ACROSS, TURNED, COLLAPSE = range(7)


@dataclasses.dataclass
class _Run:
    """The moving state of one run: time, state y = (theta_x, theta_y, rates) (4n,), each
    joint's piece k, excursion (pending), phase and pinned direction c, the peaks."""

    beam: Beam3d
    out: Outcome
    rec: Recorder
    y: np.ndarray
    k: np.ndarray
    pending: np.ndarray
    phase: np.ndarray
    c: np.ndarray
    t: float = 0.0
    at_rest: bool = False
    h: float | None = None  # the last step size, carried over an event [s]
    peaks: np.ndarray | None = None
    top_max: float = 0.0
    swept: np.ndarray | None = None
    azimuth: float = math.nan
    plan: list = dataclasses.field(default_factory=list)
    friction: np.ndarray | None = None
    slip: tuple | None = None
    gam = None  # (g + a_v(t)) / g of the current segment, a function of t [s]
    end = None  # a list the final state is appended to (integrate3d's end)


def _pinned(run: _Run) -> np.ndarray:
    """(n,) bool: the joints whose law reads along their pinned direction (rigid laws near
    closure; an elastic joint's pinned direction only tells where it closes)."""
    return (run.phase != FREE) & run.beam.rigid


def _phi(beam: Beam3d, y: np.ndarray):
    n = beam.n
    phx, phy = beam.arguments(y[:n], y[n : 2 * n])
    dphx, dphy = beam.arguments(y[2 * n : 3 * n], y[3 * n :])
    return phx, phy, dphx, dphy


def _move(beam: Beam3d, y: np.ndarray, i: int, dx: float, dy: float) -> None:
    """Move joint i's argument by (dx, dy) [rad] (the drums through the argument map's
    inverse), in place."""
    n, col = beam.n, beam.model.arg_inverse[:, i]
    y[:n] += col * dx
    y[n : 2 * n] += col * dy


def integrate3d(
    model,
    motion: GroundMotion,
    theta0: np.ndarray,
    rate0: np.ndarray,
    solver: SolverConfig,
    *,
    record: bool = False,
    output_dt: float = 0.002,
    early_stop: bool = True,
    friction_limit: float = math.inf,
    beam: Beam3d | None = None,
    state: np.ndarray | None = None,
    end: list | None = None,
) -> Outcome:
    """One run of a column's RBM in two directions (the module's rules).

    Parameters
    ----------
    model : Model  The column's planar equations (rbm_cli.physics.equations)
    motion : GroundMotion  The ground motion, in any direction, one or two components
    theta0, rate0 : (n,)  Initial drum rotations [rad] and rates [rad/s] in the motion's
        vertical plane
    solver : SolverConfig  Runge-Kutta pair, rtol, atol (scaled by theta_u and 10 theta_u
        per second, as the planar step kernel), step, event and wall-clock budgets
    record, output_dt, early_stop : as the planar integrators (a rigid monolith at rest
        after the motion stops the run)
    friction_limit : float  Outcome.slip where |T_i| / N_i first exceeds it (inf: none)
    beam : Beam3d, optional  The equations in two directions, made once by a caller
    state : (4n,) array, optional  A whole initial state (theta_x, theta_y, their rates) in
        place of theta0, rate0
    end : list, optional  If a list, the state where the run ended is appended to it
    """
    beam = beam3d(model) if beam is None else beam
    n = model.n
    d = motion.direction
    if state is None:
        y0 = np.concatenate([theta0 * d[0], theta0 * d[1], rate0 * d[0], rate0 * d[1]])
    else:
        y0 = np.array(state, dtype=float)
    out = Outcome()
    run = _Run(
        beam=beam, out=out, rec=Recorder(output_dt, out.samples if record else None),
        y=y0.astype(float), k=np.zeros(n, dtype=np.int64), pending=np.zeros(n, bool),
        phase=np.full(n, FREE), c=np.tile(d, (n, 1)), peaks=np.zeros(n),
        swept=np.zeros(n), friction=np.zeros(n),
    )  # fmt: skip
    tu = model.column.rotation_capacity
    level, rest_rate, _ = rest_levels(model)
    scale = float(tu.min())
    k = dict(
        tu=tu, level=level, rest_rate=rest_rate, d=d, mu=friction_limit, solver=solver,
        atol=solver.atol * np.concatenate([np.full(2 * n, scale), np.full(2 * n, 10 * scale)]),
        rigid_mono=level is not None, deadline=time.monotonic() + float(solver.max_wall_time),
    )  # fmt: skip
    run.end = end
    _locate(run, k)
    if np.any(beam.ratios(run.y)[0] >= model.collapse_ratio):
        i = int(np.argmax(beam.ratios(run.y)[0]))
        return _collapse(run, i)
    _consider(run, run.y)
    for seg_start, seg_end in motion.segments():
        if run.t >= seg_end:
            continue
        stop = _segment(run, motion, seg_end, motion.forced(seg_start), k)
        if stop is not None:
            return stop
    return _finish(run)


def _locate(run: _Run, k: dict) -> None:
    """The pieces and phases of the initial state; a rigid monolith with no motion rests."""
    beam, y = run.beam, run.y
    phx, phy, dphx, dphy = _phi(beam, y)
    r = np.hypot(phx, phy)
    for i in range(beam.n):
        q = 0
        while q < beam.nedges[i] and beam.edges[i, q] <= r[i]:
            q += 1
        run.k[i] = q
        run.pending[i] = q > 0 and not beam.rigid[i]
    if k["rigid_mono"]:
        run.at_rest = not np.any(y)
        if r[0] <= LEAVE_FACTOR * UPRIGHT_LEAN * k["tu"][0] and not run.at_rest:
            v = np.array([phx[0], phy[0]]) if r[0] > 0.0 else np.array([dphx[0], dphy[0]])
            run.phase[0], run.c[0] = LEAVING, v / math.hypot(*v)


def _segment(run: _Run, motion: GroundMotion, seg_end: float, forced: bool, k: dict):
    """Run up to seg_end [s], restarting the stepper at every event; the Outcome if the run
    ends here, else None."""
    beam, out, solver = run.beam, run.out, k["solver"]
    horizontal, gravity = motion.horizontal(forced), motion.gravity(forced)

    def gam(t):
        return 1.0 if gravity is None else gravity(t)

    def gam_at(ts):  # at the times ts (m,) of a step's checks
        return 1.0 if gravity is None else np.array([gravity(t) for t in ts])

    run.gam = gam

    while run.t < seg_end:
        if run.at_rest:
            kind, t_stop = motion.rest_end(run.t, seg_end, k["level"], forced)
            run.rec.rest(t_stop - (1e-15 if kind == "uplift" else 0.0))
            run.t = t_stop
            if kind == "end":
                return _finish(run, message="at rest in free motion: stopped")
            if kind == "segment":
                return None
            run.y[:] = 0.0
            run.phase[0], run.c[0] = LEAVING, motion.uplift_direction(run.t)
            run.at_rest, run.h = False, None
            out.n_uplifts += 1
        kk, pinned, c = run.k.copy(), _pinned(run), run.c.copy()

        def rhs(t, y, kk=kk, pinned=pinned, c=c):
            out.n_rhs += 1
            ax, ay = horizontal(t)
            return beam.rates(y, ax, ay, gam(t), kk, pinned, c)

        stepper = _METHODS[step_method(solver)]
        first = None if run.h is None else min(run.h, seg_end - run.t)
        integ = stepper(rhs, run.t, run.y, seg_end, rtol=solver.rtol, atol=k["atol"],
                        first_step=first)  # fmt: skip
        integ.knots = motion.knots if motion.clipped else None
        hit = _steps(run, integ, k, gam_at, horizontal)
        if isinstance(hit, Outcome):
            return hit
        if hit is not None:
            stop = _event(run, hit, k)
            if stop is not None:
                return stop
    return None


def _watch(run: _Run, k: dict) -> list[tuple[int, int]]:
    """The events (kind, joint) of the current pieces and phases."""
    beam, rows = run.beam, []
    silent = beam.model.restitution == 1.0
    for i in range(beam.n):
        q, phase = run.k[i], run.phase[i]
        if q < beam.nedges[i]:
            rows.append((UP, i))
        if q > 0:
            rows.append((DOWN, i))
        if beam.rigid[i]:
            rows += {FREE: [(NEAR, i)] if q == 0 else [], LEAVING: [(LEFT, i), (ACROSS, i)],
                     APPROACH: [(ACROSS, i), (TURNED, i)]}[phase]  # fmt: skip
        elif phase == APPROACH and not silent:
            rows.append((ACROSS, i))
        rows.append((COLLAPSE, i))
    return rows


def _distances(run: _Run, rows, yy: np.ndarray, gam_t, k: dict):
    """The watched events' distances and rates at states yy (4n, m) [-], [-/s]."""
    beam, tu = run.beam, k["tu"]
    phx, phy, dphx, dphy = _phi(beam, yy)
    r = np.hypot(phx, phy)
    dr = (phx * dphx + phy * dphy) / np.where(r > 0.0, r, 1.0)
    cq, dcq = beam.ratios(yy)
    pin = UPRIGHT_LEAN * tu
    D, R = np.empty((len(rows), yy.shape[1])), np.empty((len(rows), yy.shape[1]))
    for j, (kind, i) in enumerate(rows):
        if kind == UP:
            D[j], R[j] = (beam.edge(i, run.k[i], gam_t) - r[i]) / tu[i] + EVENT_EPS, -dr[i] / tu[i]
        elif kind == DOWN:
            D[j] = (r[i] - beam.edge(i, run.k[i] - 1, gam_t)) / tu[i] + EVENT_EPS
            R[j] = dr[i] / tu[i]
        elif kind == NEAR:
            D[j], R[j] = (r[i] - pin[i]) / tu[i], dr[i] / tu[i]
        elif kind == LEFT:
            D[j], R[j] = (LEAVE_FACTOR * pin[i] - r[i]) / tu[i], -dr[i] / tu[i]
        elif kind == ACROSS:
            cx, cy = run.c[i]
            D[j] = (phx[i] * cx + phy[i] * cy) / tu[i] + EVENT_EPS
            R[j] = (dphx[i] * cx + dphy[i] * cy) / tu[i]
        elif kind == TURNED:
            D[j], R[j] = -dr[i] / tu[i], 0.0
        else:
            D[j], R[j] = run.beam.model.collapse_ratio + EVENT_EPS - cq[i], -dcq[i]
    return D, R


def _steps(run: _Run, integ, k: dict, gam_at, horizontal):
    """Step until the first watched event: (kind, joint) with the run on it, None at the
    segment's end, or the Outcome when the run ends (a budget)."""
    out, solver = run.out, k["solver"]
    rows = _watch(run, k)
    while integ.status == "running":
        t_old, y_old = run.t, run.y
        msg = integ.step()
        if integ.status == "failed":
            return _fail(run, f"integrator: {msg} at t={run.t:.6g} s")
        out.n_steps += 1
        over = out.past_budget(solver, k["deadline"], run.t)
        if over is not None:
            return _finish_as(run, over)
        dense = integ.dense_output()

        def dist(ts, dense=dense):
            ts = np.atleast_1d(ts)
            return _distances(run, rows, dense(ts), gam_at(ts), k)

        hit = first_crossing(dist, t_old, integ.t, xtol=1e-15)
        t_new = integ.t if hit is None else hit[0]
        y_new = dense(t_new) if hit is not None else integ.y.copy()
        run.h = integ.h_abs if hit is None else max(integ.h_abs, 1e-12)
        _peaks(run, dense, t_old, t_new, y_old, y_new)
        if run.rec.samples is not None:
            _emit(run, dense, t_new, k["d"])
        _friction(run, t_new, y_new, integ.f if hit is None else None, k, horizontal)
        _swept(run, y_old, y_new)
        run.t, run.y = t_new, y_new
        _silent(run)  # before the event's change of pieces (an uplift on the other side)
        if hit is None:
            continue
        return rows[hit[1]]
    return None


def _event(run: _Run, hit: tuple[int, int], k: dict) -> Outcome | None:
    """The state change of an event (kind, joint i) at run.t."""
    kind, i = hit
    beam, out, y = run.beam, run.out, run.y
    out.n_events += 1
    if out.n_events > k["solver"].max_events:
        return _finish_as(run, out.out_of_events(k["solver"], run.t))
    phx, phy, _, _ = _phi(beam, y)
    px, py = phx[i], phy[i]
    r = math.hypot(px, py)
    if kind == COLLAPSE:
        return _collapse(run, i)
    if kind in (UP, DOWN):
        q = run.k[i] if kind == UP else run.k[i] - 1
        e = beam.edge(i, q, run.gam(run.t))  # the kink's place now: the state moved onto it
        if r > 0.0:
            _move(beam, y, i, px * (e / r - 1.0), py * (e / r - 1.0))
        if kind == UP:
            if run.k[i] == 0 and not beam.rigid[i] and not run.pending[i]:
                out.n_uplifts += 1
            if not beam.rigid[i]:
                run.pending[i] = True
            run.k[i] += 1
            if run.phase[i] == APPROACH and not beam.rigid[i]:
                run.phase[i] = FREE
        else:
            run.k[i] -= 1
            if run.k[i] == 0 and run.pending[i]:
                run.phase[i], run.c[i] = APPROACH, (px / r, py / r)
                # a silent closure (e = 1) is counted, not stopped at: back on its elastic
                # branch the joint is closed, as in the plane (a new excursion is an uplift)
                run.pending[i] = beam.model.restitution != 1.0
        return None
    if kind == NEAR:
        run.phase[i], run.c[i] = APPROACH, (px / r, py / r)
        return None
    if kind == LEFT:
        run.phase[i] = FREE
        return None
    return _impact(run, i, k)


def _impact(run: _Run, i: int, k: dict) -> Outcome | None:
    """Joint i closes: onto the line across c (a rigid joint: closed), its relative rate
    along c times e by an impulsive moment along c, the rolling rate across c kept."""
    beam, out, y = run.beam, run.out, run.y
    model, n = beam.model, beam.n
    cx, cy = run.c[i]
    phx, phy, dphx, dphy = _phi(beam, y)
    along = phx[i] * cx + phy[i] * cy
    if beam.rigid[i]:
        _move(beam, y, i, -phx[i], -phy[i])
    else:
        _move(beam, y, i, -along * cx, -along * cy)
    xdot = dphx[i] * cx + dphy[i] * cy
    e = model.restitution
    if model.formulation == "absolute":
        change = model.arg_inverse[:, i] * (e - 1.0) * xdot
    else:
        directions, w = model.impulse_directions
        change = directions[:, i] * ((e - 1.0) * xdot / w[i])
    y[2 * n : 3 * n] += change * cx
    y[3 * n :] += change * cy
    out.n_impacts += 1
    run.pending[i], run.phase[i] = False, FREE
    if beam.rigid[i]:
        _, _, dphx, dphy = _phi(beam, y)
        speed = math.hypot(dphx[i], dphy[i])
        if k["rigid_mono"] and speed < k["rest_rate"]:
            y[:] = 0.0
            run.at_rest = True
            return None
        run.phase[i] = LEAVING
        if speed > 0.0:
            run.c[i] = (dphx[i] / speed, dphy[i] / speed)
    return None


def _silent(run: _Run) -> None:
    """Count the silent closures (e = 1, an elastic joint) of the step just taken."""
    beam = run.beam
    if beam.model.restitution != 1.0:
        return
    phx, phy, _, _ = _phi(beam, run.y)
    for i in range(beam.n):
        if run.phase[i] == APPROACH and not beam.rigid[i]:
            if phx[i] * run.c[i, 0] + phy[i] * run.c[i, 1] <= 0.0:
                run.out.n_impacts += 1
                run.pending[i], run.phase[i] = False, FREE


def _consider(run: _Run, y: np.ndarray) -> None:
    cq, _ = run.beam.ratios(y)
    np.maximum(run.peaks, cq, out=run.peaks)
    run.top_max = max(run.top_max, float(run.beam.top(y)[0]))


def _peaks(run: _Run, dense, t_old, t_new, y_old, y_new) -> None:
    """The peaks of the collapse ratios and of the top's displacement over [t_old, t_new]:
    at the end, and where a rate turns from rising to falling (Brent on the dense output)."""
    beam = run.beam
    _consider(run, y_new)
    r0, r1 = beam.ratios(y_old)[1], beam.ratios(y_new)[1]
    tr0, tr1 = beam.top(y_old)[1], beam.top(y_new)[1]
    for i in np.nonzero((r0 > 0.0) & (r1 < 0.0))[0]:
        ts = brentq(lambda t, i=i: float(beam.ratios(dense(t))[1][i]), t_old, t_new, xtol=1e-15)
        run.peaks[i] = max(run.peaks[i], float(beam.ratios(dense(ts))[0][i]))
    if tr0 > 0.0 and tr1 < 0.0:
        ts = brentq(lambda t: float(beam.top(dense(t))[1]), t_old, t_new, xtol=1e-15)
        run.top_max = max(run.top_max, float(beam.top(dense(ts))[0]))


def _swept(run: _Run, y0: np.ndarray, y1: np.ndarray) -> None:
    """Add the angle each open joint's direction turned over a step (a step turns it by
    less than a half turn)."""
    beam = run.beam
    ax, ay, _, _ = _phi(beam, y0)
    bx, by, _, _ = _phi(beam, y1)
    # open: off its elastic branch (or a rigid joint away from closure)
    open_ = (run.k > 0) | (beam.rigid & (run.phase == FREE))
    cross, dot = ax * by - ay * bx, ax * bx + ay * by
    turn = np.abs(np.arctan2(cross, dot))
    run.swept += np.where(open_, turn, 0.0)


def _friction(run: _Run, t, y, f, k, horizontal) -> None:
    """The friction demand at a step's end (f: y' there, if known), and where it first
    exceeded the friction limit."""
    beam, n = run.beam, run.beam.n
    ax, ay = horizontal(t)
    g = run.gam(t)
    if f is None:
        f = beam.rates(y, ax, ay, g, run.k, _pinned(run), run.c)
        run.out.n_rhs += 1
    demand = beam.shear_demand(f[2 * n : 3 * n], f[3 * n :], ax, ay, g)
    np.maximum(run.friction, demand, out=run.friction)
    if run.slip is None and demand.max() > k["mu"]:
        run.slip = (float(t), int(np.argmax(demand)) + 1)


def _emit(run: _Run, dense, t_stop: float, d: np.ndarray) -> None:
    n = run.beam.n
    for t in run.rec.times(t_stop):
        y = dense(t)
        th = y[:n] * d[0] + y[n : 2 * n] * d[1]
        rate = y[2 * n : 3 * n] * d[0] + y[3 * n :] * d[1]
        run.rec.samples.append((float(t), th, rate))
        h = run.beam.heights
        run.plan.append((float(h @ y[:n]), float(h @ y[n : 2 * n])))


def _collapse(run: _Run, i: int) -> Outcome:
    beam = run.beam
    vx, vy = beam.collapse[i] @ run.y[: beam.n], beam.collapse[i] @ run.y[beam.n : 2 * beam.n]
    run.azimuth = math.atan2(vy, vx)
    run.peaks[i] = max(run.peaks[i], beam.model.collapse_ratio)
    out = _finish(run)
    return out.collapse(run.t, i + 1)


def _finish(run: _Run, status: str = "survived", message: str = "") -> Outcome:
    if run.end is not None:
        run.end.append(run.y.copy())
    out = run.out
    out.status, out.message, out.t_end = status, message, run.t
    out.max_ratio, out.max_top = run.peaks.copy(), run.top_max
    out.friction, out.slip = run.friction.copy(), run.slip
    out.azimuth, out.turns = run.azimuth, float(run.swept.max()) / (2.0 * math.pi)
    if run.rec.samples is not None:
        plan = run.plan + [(0.0, 0.0)] * (len(out.samples) - len(run.plan))
        out.top_plan = np.array(plan, dtype=float).reshape(-1, 2)
    return out


def _finish_as(run: _Run, stopped: Outcome) -> Outcome:
    status, message, t = stopped.status, stopped.message, stopped.t_end
    out = _finish(run)
    out.status, out.message, out.t_end = status, message, t
    return out


def _fail(run: _Run, message: str) -> Outcome:
    out = _finish(run)
    out.status, out.message = "failed", message
    return out


class Rbm3dRunner(RbmRunner):
    """`rbm-3d` (rbm_cli.models.contract.Runner): the config's column of circular drums in
    the Rigid Beam Model, in two horizontal directions."""

    def integrator_of(self, method):
        """The integrator of every method that runs `rbm-3d` (a step pair): this module's."""
        beam = beam3d(self.model)

        def run(model, motion, theta0, rate0, solver, **options):
            return integrate3d(model, motion, theta0, rate0, solver, beam=beam, **options)

        return run

    def run(self, motion: GroundMotion, solver: SolverConfig, **options) -> Outcome:
        """One run (rbm_cli.models.contract.Runner.run); a recorded history carries the
        top's path in plan."""
        out = super().run(motion, solver, **options)
        if out.history is not None and out.top_plan is not None:
            out.history = dataclasses.replace(out.history, top_plan=out.top_plan)
        return out


__all__ = ["Rbm3dRunner", "integrate3d"]
