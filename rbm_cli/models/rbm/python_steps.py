"""The parts of the RBM's readable integrator (rbm_cli.models.rbm.python.integrate).

- RunState: the run's fixed matrices and its moving state (t, y, at rest or not, the
  law pieces, the outcome being filled, the next sample time);
- SmoothPiece: the linear system of the current law pieces and the distances to its
  event surfaces;
- step_to_event: Runge-Kutta steps through one piece, each checked for an event on its
  dense output, with the peaks, the friction demand and the early stop of free motion;
- handle_event, leave_rest: what an event does (collapse, uplift, kink, impact and the
  rest of a rigid block) and how a block at rest lifts again.

Same algorithm, same operations in the same order, as the module docstring of
rbm_cli.models.rbm.python describes.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial
from typing import NamedTuple

import numpy as np

from rbm_cli.config.types import SolverConfig
from rbm_cli.models.events import (
    BIG,
    EVENT_EPS,
    REST_RATE,
    Pieces,
    first_crossing,
    hermite_peaks,
    within_reach,
)
from rbm_cli.models.outcome import Outcome
from rbm_cli.physics.equations import Model
from rbm_cli.physics.excitation import GroundMotion


@dataclass
class RunState:
    """One run of the integrator: fixed matrices (rows over theta) and the moving state.

    Attributes
    ----------
    t : float  Current time [s]
    y : (2n,) ndarray  Current state: rotations [rad], then rates [rad/s]
    at_rest : bool  A rigid monolithic column resting (no integration)
    next_out : float  Time of the next recorded sample [s]
    h_carry : float or None  Step size proposed before the last event, carried over it [s]
    knots : ndarray or None  Times every step ends at (a record's samples) [s]
    track : (n + 1, n) ndarray  Collapse quantities over their limits [-], then the top
        displacement [m]
    g_rows : (4n, n) ndarray  Event surfaces (law bounds over theta_u, collapse)
    barrier : float or None  Energy at the collapse rotation (n = 1) [J]
    """

    model: Model
    solver: SolverConfig
    pieces: Pieces
    out: Outcome
    deadline: float  # time.monotonic() beyond which the run fails [s]
    record: bool
    output_dt: float  # [s]
    n: int
    tu: np.ndarray  # rotation capacities theta_u [rad]
    silent: bool
    c_ratio: float
    track: np.ndarray
    g_rows: np.ndarray
    c_vec: np.ndarray
    argmap: np.ndarray
    arg_inv: np.ndarray
    e_rest: float
    atol: np.ndarray
    rest_rate: float  # [rad/s]
    uplift_level: float | None  # [m/s^2]
    rigid_mono: bool
    barrier: float | None
    t: float
    y: np.ndarray
    at_rest: bool
    next_out: float = 0.0
    h_carry: float | None = None
    knots: np.ndarray | None = None  # times steps end at (a record's samples) [s]

    @classmethod
    def start(
        cls,
        model: Model,
        pieces: Pieces,
        theta0: np.ndarray,
        rate0: np.ndarray,
        solver: SolverConfig,
        record: bool,
        output_dt: float,
        deadline: float,
    ) -> RunState:
        """The state at t = 0 from the initial rotations [rad] and rates [rad/s]; the
        pieces are located there."""
        n = model.n
        col = model.column
        out = Outcome()
        out.max_ratio = np.zeros(n)
        out.friction = np.zeros(n)
        tu = col.rotation_capacity
        c_ratio = model.collapse_ratio
        cmap = model.collapse_map / model.collapse_limit[:, None]
        top = col.heights.copy()
        track = np.vstack([cmap, top[None, :]])
        g_rows = np.vstack([model.arg_map / tu[:, None], -model.arg_map / tu[:, None], -cmap, cmap])
        atol = solver.atol * np.concatenate([np.full(n, tu.min()), np.full(n, tu.min() * 10.0)])
        uplift_level = model.uplift_level
        rigid_mono = uplift_level is not None
        # early stop of free motion (after a half-sine pulse), monolithic columns:
        # energy never grows in free motion, so once a peak has been passed with
        # the energy below the collapse barrier, no later peak is larger.
        barrier = None
        if n == 1:
            barrier = float(model.energy(np.array([c_ratio * tu[0]]), np.zeros(1))[0])
        y = np.concatenate([np.asarray(theta0, float), np.asarray(rate0, float)])
        argmap = model.arg_map
        pieces.locate(argmap @ y[:n], argmap @ y[n:])
        return cls(
            model=model,
            solver=solver,
            pieces=pieces,
            out=out,
            deadline=deadline,
            record=record,
            output_dt=output_dt,
            n=n,
            tu=tu,
            silent=bool(pieces.silent.any()),
            c_ratio=c_ratio,
            track=track,
            g_rows=g_rows,
            c_vec=np.full(n, c_ratio),
            argmap=argmap,
            arg_inv=model.arg_inverse,
            e_rest=model.restitution,
            atol=atol,
            rest_rate=REST_RATE * model.rocking_p * tu.min(),
            uplift_level=uplift_level,
            rigid_mono=rigid_mono,
            barrier=barrier,
            t=0.0,
            y=y,
            at_rest=rigid_mono and not np.any(y),
        )

    def emit_until(self, t_stop: float, dense=None, rest: bool = False) -> None:
        """Record the samples due up to t_stop [s]: from the dense output, or zeros at rest."""
        n = self.n
        while self.next_out <= t_stop + 1e-12:
            if rest:
                self.out.samples.append((self.next_out, np.zeros(n), np.zeros(n)))
            else:
                yy = dense(self.next_out)
                self.out.samples.append((self.next_out, yy[:n].copy(), yy[n:].copy()))
            self.next_out += self.output_dt


class SmoothPiece:
    """The linear system of the current law pieces, theta'' = A theta + c + e a_g(t), and
    the distances to its event surfaces, linear in theta: d = G theta + h0 (>= 0 inside).
    With a vertical record, python_vertical.VerticalPiece."""

    def __init__(self, run: RunState, ag, gam=None):
        self.n = run.n
        self.out = run.out
        self.ag = ag
        self.gam = gam
        self.g_rows = run.g_rows
        self.A, self.cvec, self.evec = run.pieces.system()
        self.lo, self.hi = run.pieces.bounds()
        lo, hi, tu = self.lo, self.hi, run.tu
        self.h0 = (
            np.concatenate(
                [np.minimum(-lo / tu, BIG), np.minimum(hi / tu, BIG), run.c_vec, run.c_vec]
            )
            + EVENT_EPS
        )

    def rhs(self, tt, yy, counted=True):
        """dy/dt at (tt [s], yy); counted in the outcome's n_rhs unless told not."""
        n = self.n
        self.out.n_rhs += counted
        return np.concatenate([yy[n:], self.acc(tt, yy)])

    def acc(self, tt, yy) -> np.ndarray:
        """Angular accelerations theta'' at (tt [s], yy) [rad/s^2]."""
        n = self.n
        return self.A @ yy[:n] + self.cvec + self.evec * self.ag(tt)

    def distances(self, yy, t=None, t_piece=None) -> tuple[np.ndarray, np.ndarray]:
        """Event distances and their rates at the state yy (at t [s]; the rate of gam(t) of
        the ground piece a step from t_piece runs on: VerticalPiece's)."""
        n = self.n
        return self.g_rows @ yy[:n] + self.h0, self.g_rows @ yy[n:]

    def curvature(self, acc, t=None, t_piece=None) -> np.ndarray:
        """Second time derivatives of the event distances for accelerations acc [rad/s^2]."""
        return self.g_rows @ acc

    def bound(self, i: int, going_up: bool, t: float) -> float:
        """The bound [rad] interface i's argument reached at its event at t [s]."""
        return float(self.hi[i] if going_up else self.lo[i])

    def dist(self, dense, ts):
        """Event distances and rates on the dense output at the times ts, (rows, m)."""
        n = self.n
        yy = dense(ts)
        return self.g_rows @ yy[:n] + self.h0[:, None], self.g_rows @ yy[n:]


class StepEnd(NamedTuple):
    """Where a step ends: its own end, or the earliest event inside it."""

    t: float  # [s]
    y: np.ndarray
    acc: np.ndarray  # theta'' there [rad/s^2]
    dense: object  # the step's dense output, if it was made
    surfaces: tuple  # event distances, rates and second derivatives at the step's end
    event_row: int | None  # row of g_rows crossed, or None


def take_step(run: RunState, integ) -> Outcome | None:
    """One step of the stepper within the step and wall-clock budgets; the Outcome if the
    run fails there, else None."""
    out, solver, t = run.out, run.solver, run.t
    msg = integ.step()
    if integ.status == "failed":
        return out.stop("failed", f"integrator: {msg}", t)
    out.n_steps += 1
    return out.past_budget(solver, run.deadline, t)


def end_of_step(run: RunState, piece: SmoothPiece, integ, surfaces: tuple) -> StepEnd:
    """The end of the step just taken, or its earliest event: a surface crossed, or touched
    and left, inside the step is found on the dense output (the earliest crossing of any
    row), when the step comes within reach of one. surfaces: (d, d', d'') at its start."""
    t_old = integ.t_old
    t_new, y_new = integ.t, integ.y
    d_new, dd_new = piece.distances(y_new, t_new, t_old)
    acc = piece.acc(t_new, y_new)
    d2_new = piece.curvature(acc, t_new, t_old)
    hit = None
    dense = None
    d_old, dd_old, d2_old = surfaces
    if within_reach(d_old, d_new, dd_old, dd_new, d2_old, d2_new, t_new - t_old):
        dense = integ.dense_output()
        hit = first_crossing(partial(piece.dist, dense), t_old, t_new)
    event_row = None
    if hit is not None:
        t_e, event_row = hit
        y_new = dense(t_e)
        acc = piece.acc(t_e, y_new)
        t_new = t_e
    return StepEnd(t_new, y_new, acc, dense, (d_new, dd_new, d2_new), event_row)


def account(
    run: RunState, z_old, z_new, dz_old, dz_new, dt: float, acc, ag_new, gam_new=1.0
) -> None:
    """Peaks (collapse ratios, top displacement) and friction demand over a step of dt [s]
    (the normal forces times gam_new = (g + a_v) / g)."""
    out, n = run.out, run.n
    peaks = hermite_peaks(z_old, z_new, dz_old, dz_new, dt)
    out.max_ratio = np.maximum(out.max_ratio, peaks[:n])
    out.max_top = max(out.max_top, peaks[n])
    fr = run.model.shear_ratios(acc[None, :], np.array([ag_new]))[0] / gam_new
    out.friction = np.maximum(out.friction, fr)


def below_barrier(run: RunState, z_prev, dz_prev, z_old, dz_old) -> bool:
    """Whether a monolithic column has just passed a peak with its energy below the
    collapse barrier (then no later peak of free motion is larger)."""
    n, y = run.n, run.y
    if run.barrier is not None and z_prev[0] * dz_prev[0] > 0 >= z_old[0] * dz_old[0]:
        if float(run.model.energy(y[:n], y[n:])[0]) < run.barrier * (1.0 - 1e-9):
            return True
    return False


def step_to_event(run: RunState, piece: SmoothPiece, integ, can_stop: bool):
    """Step the integrator through the piece up to its first event.

    Returns
    -------
    int, None or Outcome  The event's row of g_rows (the state is then on the event),
        None when the stepper reached its bound, the Outcome when the run ends here
        (a budget exceeded, or the early stop of free motion).
    """
    n, out, track = run.n, run.out, run.track
    y = run.y
    z_old = track @ y[:n]
    dz_old = track @ y[n:]
    d_old, dd_old = piece.distances(y, run.t)
    surfaces = (d_old, dd_old, piece.curvature(piece.acc(run.t, y), run.t))
    while integ.status == "running":
        stop = take_step(run, integ)
        if stop is not None:
            return stop
        t_old = integ.t_old
        end = end_of_step(run, piece, integ, surfaces)
        t_new, y_new = end.t, end.y
        if run.record:
            run.emit_until(t_new, end.dense if end.dense is not None else integ.dense_output())
        if run.silent:
            out.n_impacts += run.pieces.settle(run.argmap @ y_new[:n])
        # peaks and friction demand over [t_old, t_new]
        z_new = track @ y_new[:n]
        dz_new = track @ y_new[n:]
        gam_new = 1.0 if piece.gam is None else piece.gam(t_new)
        account(run, z_old, z_new, dz_old, dz_new, t_new - t_old, end.acc, piece.ag(t_new), gam_new)
        z_prev, dz_prev = z_old, dz_old
        z_old, dz_old = z_new, dz_new
        surfaces = end.surfaces
        run.t, run.y = t_new, y_new
        if end.event_row is not None:
            return end.event_row
        if can_stop and below_barrier(run, z_prev, dz_prev, z_old, dz_old):
            out.t_end = run.t
            return out.stopped_early()
    return None


def handle_event(run: RunState, piece: SmoothPiece, event_row: int) -> Outcome | None:
    """Apply the event met at (run.t, run.y): a collapse ends the run (returns the Outcome);
    a law bound moves the interface to its next piece (an uplift, a kink or an impact,
    which applies the restitution and may put a rigid block to rest)."""
    out, n, t = run.out, run.n, run.t
    out.n_events += 1
    if out.past_events(run.solver, t) is not None:
        return out
    which, i = divmod(event_row, n)
    if which >= 2:
        out.max_ratio[i] = max(out.max_ratio[i], run.c_ratio)
        out.t_end = t
        return out.collapse(t, i + 1)
    going_up = which == 1
    # put the argument exactly on the surface it crossed (the event is
    # located EVENT_EPS beyond it); removes the energy that repeated
    # overshoots would pump into chattering impacts
    bound = piece.bound(i, going_up, t)
    x_i = float(run.argmap[i] @ run.y[:n])
    y = run.y.copy()
    y[:n] += run.arg_inv[:, i] * (bound - x_i)
    crossing = run.pieces.cross(i, going_up)
    if crossing == "uplift":
        out.n_uplifts += 1
    elif crossing == "impact":
        out.n_impacts += 1
        if run.e_rest < 1.0:
            y[n:] = run.model.impact_rates(y[n:], i)
        if run.rigid_mono and abs(y[n]) < run.rest_rate:
            y = np.zeros(2 * n)
            run.at_rest = True
    run.y = y
    return None


def leave_rest(run: RunState, motion: GroundMotion, seg_end: float, forced: bool) -> str:
    """A rigid monolithic column at rest: wait (recording zeros) until the ground demand
    exceeds the uplift level, found exactly from the excitation, and lift on the side
    turning away from it. Returns what ended the rest: 'uplift', 'segment' (the segment
    ended first) or 'end' (no ground motion from here on)."""
    kind, t_stop = motion.rest_end(run.t, seg_end, run.uplift_level, forced)
    if run.record:
        run.emit_until(t_stop - (1e-15 if kind == "uplift" else 0.0), rest=True)
    run.t = t_stop
    if kind in ("end", "segment"):
        return kind
    run.y = np.zeros(2 * run.n)
    run.pieces.side[0] = motion.uplift_side(run.t)
    run.pieces.k[0] = 0
    run.at_rest = False
    run.out.n_uplifts += 1
    run.h_carry = None
    return kind
