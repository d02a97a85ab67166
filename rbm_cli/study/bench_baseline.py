"""The benchmark's baseline: the RBM as a researcher would first write it.

scipy's ``solve_ivp`` (RK45, rtol 1e-6) called once per smooth piece, with terminal events
for the law's kinks, the impacts and collapse (one Python function per event surface),
restarted after each event. The physics is the same as the step kernel's (the same law
pieces, rbm_cli.models.rbm.pieces, the same impact rule, the same rest of a rigid block),
so the benchmark compares integrators, not models. Only the outcome is kept: status,
collapse time and peak rotation ratio (from the solver's steps and the event states).
"""

from __future__ import annotations

import math
import time

import numpy as np
from scipy.integrate import solve_ivp

from rbm_cli.base.errors import RbmError
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.inputs.ground import SINE
from rbm_cli.models.outcome import Outcome
from rbm_cli.models.rbm.pieces import IMPACT, cross, locate, piece_bounds
from rbm_cli.structures.arrays import rest_levels
from rbm_cli.structures.equations import Model
from rbm_cli.structures.law import law_arrays

#: Tolerances of the baseline (a naive per-cell scipy solve: RK45, rtol 1e-6); atol in units of
#: theta_u for rotations and 10 theta_u for rates, as rbm's own solver.
BASELINE_RTOL = 1e-6
BASELINE_ATOL = 1e-9


def _event(row, offset):
    def ev(t, y):
        return float(row @ y[: row.size]) + offset

    ev.terminal = True
    ev.direction = -1
    return ev


class _Pieces:
    """The law piece of each interface (side, index, pending: rbm_cli.models.rbm.pieces),
    with the linear system of each set of pieces met, cached."""

    def __init__(self, model: Model):
        n = model.n
        self.model = model
        self.edges, self.nedges, self.intercepts, self.slopes, self.rigid = law_arrays(model.laws)
        self.side = np.ones(n, dtype=np.int64)
        self.k = np.zeros(n, dtype=np.int64)
        self.pending = np.zeros(n, dtype=np.bool_)
        self.awaiting = np.zeros(n, dtype=np.bool_)
        self.silent = np.zeros(n, dtype=np.bool_)  # the baseline stops at every impact
        self.systems: dict = {}
        locate(np.zeros(n), np.zeros(n), self.side, self.k, self.pending, self.rigid,
               self.edges, self.nedges)  # fmt: skip

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """The bounds lo, hi [rad] of the law arguments on the current pieces."""
        n = self.model.n
        lo, hi = np.empty(n), np.empty(n)
        for i in range(n):
            lo[i], hi[i] = piece_bounds(i, self.side, self.k, self.pending, self.rigid,
                                        self.edges, self.nedges)  # fmt: skip
        return lo, hi

    def system(self):
        """(A, c, e) of the current pieces (Model.linear_system)."""
        key = (tuple(self.side), tuple(self.k))
        if key not in self.systems:
            rows = np.arange(self.model.n)
            self.systems[key] = self.model.linear_system(
                self.side * self.intercepts[rows, self.k], self.slopes[rows, self.k]
            )
        return self.systems[key]

    def cross(self, i: int, going_up: bool) -> bool:
        """Move interface i to its next piece; whether the crossing is an impact."""
        return cross(i, going_up, self.side, self.k, self.pending, self.awaiting, self.rigid,
                     self.silent) == IMPACT  # fmt: skip


def _surfaces(pieces: _Pieces, argmap, cmap, c: float, n: int):
    """The event functions of the current pieces.

    Returns lo, hi (the pieces' bounds of the law arguments), `events` (4 per interface:
    law bound below and above, None where infinite, collapse on either side), `live` (the
    terminal ones, then one peak event per interface: a zero of a collapse quantity's
    rate) and the number of terminal events."""
    lo, hi = pieces.bounds()
    events = []
    for i in range(n):
        row = argmap[i]
        events.append(_event(row, -lo[i]) if np.isfinite(lo[i]) else None)
        events.append(_event(-row, hi[i]) if np.isfinite(hi[i]) else None)
        events.append(_event(-cmap[i], c))
        events.append(_event(cmap[i], c))
    live = [e for e in events if e is not None]
    n_terminal = len(live)
    for i in range(n):  # peaks: zero crossings of the collapse quantities' rates

        def peak_event(tt, yy, row=cmap[i]):
            return float(row @ yy[n:])

        live.append(peak_event)
    return lo, hi, events, live, n_terminal


def _rhs(motion: GroundMotion, n: int, A, cvec, evec, amp: float):
    """dy/dt of the current pieces, y = (theta [rad], rate [rad/s]); amp [m/s^2] is 0 in
    free motion."""

    def fun(tt, yy, A=A, cvec=cvec, evec=evec, amp=amp):
        g = amp * math.sin(motion.omega * tt + motion.phase) if amp else 0.0
        return np.concatenate([yy[n:], A @ yy[:n] + cvec + evec * g])

    return fun


def _solution_peak(sol, cmap, n: int, n_terminal: int, peak: float) -> float:
    """The peak collapse ratio updated from the solver's steps and its peak events."""
    peak = max(peak, float(np.max(np.abs(cmap @ sol.y[:n]))))
    for ye in sol.y_events[n_terminal:]:
        if ye.size:
            peak = max(peak, float(np.max(np.abs(ye[:, :n] @ cmap.T))))
    return peak


def _cross(model: Model, pieces: _Pieces, y, i: int, going_up: bool, bounds, arg_inv, rest_rate):
    """Put interface i's argument on the bound it crossed and move it to its next piece;
    at an impact apply the restitution and put a rigid block slower than rest_rate [rad/s]
    to rest. Returns the state and whether it rests."""
    n, argmap = model.n, model.arg_map
    lo, hi = bounds
    bound = hi[i] if going_up else lo[i]
    y[:n] += arg_inv[:, i] * (bound - float(argmap[i] @ y[:n]))
    if pieces.cross(i, going_up):
        if model.restitution < 1.0:
            y[n:] = model.impact_rates(y[n:], i)
        if model.uplift_level is not None and abs(y[n]) < rest_rate:
            return np.zeros(2 * n), True
    return y, False


def _outcome(status: str, t_collapse: float, peak: float, message: str = "") -> Outcome:
    """The baseline's Outcome: its status, collapse time [s] and largest collapse ratio
    (over all interfaces, in max_ratio[0]); it counts no steps or events."""
    out = Outcome(status=status, message=message, t_collapse=t_collapse)
    out.max_ratio = np.array([peak])
    return out


def baseline_run(model: Model, motion: GroundMotion, budget_s: float = 600.0) -> Outcome:
    """One run of the baseline (an Outcome, the one result type of the models). A run
    longer than budget_s [s] of wall time stops as 'failed'. Sine motions only (the
    benchmark's harmonic and half-sine)."""
    if motion.form != SINE:
        raise RbmError(f"the baseline integrates sine motions only, not {motion.kind!r}")
    start = time.perf_counter()
    n = model.n
    tu = model.column.rotation_capacity
    pieces = _Pieces(model)
    argmap = model.arg_map
    arg_inv = model.arg_inverse
    cmap = model.collapse_map / model.collapse_limit[:, None]
    c = model.collapse_ratio
    atol = BASELINE_ATOL * np.concatenate([np.full(n, tu.min()), np.full(n, 10 * tu.min())])
    uplift, rest_rate, _ = rest_levels(model)
    y = np.zeros(2 * n)
    t = 0.0
    at_rest = uplift is not None
    peak = 0.0
    status, t_col = "survived", math.nan
    for seg_start, seg_end in motion.segments():
        forced = motion.forced(seg_start)
        amp = motion.amplitude if forced else 0.0
        while t < seg_end:
            if at_rest:
                kind, t = motion.rest_end(t, seg_end, uplift, forced)
                if kind != "uplift":
                    break
                y = np.zeros(2 * n)
                pieces.side[0], pieces.k[0] = motion.uplift_side(t), 0
                at_rest = False
            if time.perf_counter() - start > budget_s:
                return _outcome("failed", math.nan, peak, "wall-time budget exceeded")
            A, cvec, evec = pieces.system()
            lo, hi, events, live, n_terminal = _surfaces(pieces, argmap, cmap, c, n)
            fun = _rhs(motion, n, A, cvec, evec, amp)
            sol = solve_ivp(
                fun, (t, seg_end), y, method="RK45", rtol=BASELINE_RTOL, atol=atol, events=live
            )
            peak = _solution_peak(sol, cmap, n, n_terminal, peak)
            if sol.status != 1:
                if sol.status < 0:
                    return _outcome("failed", math.nan, peak, "solve_ivp failed")
                t, y = seg_end, sol.y[:, -1]
                break
            hit = next(j for j, te in enumerate(sol.t_events[:n_terminal]) if te.size)
            t, y = float(sol.t_events[hit][0]), sol.y_events[hit][0].copy()
            i, which = divmod(events.index(live[hit]), 4)
            if which >= 2:
                status, t_col, peak = "collapsed", t, max(peak, c)
                return _outcome(status, t_col, peak)
            y, at_rest = _cross(model, pieces, y, i, which == 1, (lo, hi), arg_inv, rest_rate)
    return _outcome(status, t_col, peak)
