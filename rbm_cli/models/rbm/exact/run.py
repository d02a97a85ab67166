"""The run loop of the exact integrator (numba): one call per run, from piece to piece
(rbm_cli.models.rbm.exact, the package docstring, says what it does).

Mutable scalars live in small arrays: st = [t, h, next_out, t_collapse, at_rest, n_out,
t_slip, slip interface] (floats; the slip: where the friction demand first exceeded the
limit se[6], nan and 0 if not) and cnt = [n_uplifts, n_impacts, n_steps, n_rhs, n_events,
collapse interface, the part of n_rhs spent on peaks, the current segment] (ints). A motion
is mo = [pulse or record (0/1), amplitude, omega, phase, pulse_end, t_end] and its segments
(start, end) with their forcings (exact.modal); settings are
se = [max_steps, max_events, deadline, early_stop, record, output_dt, friction limit,
until_open] (until_open: stop at the first event of a joint, with status.OPENED).

The friction demand's peak is the largest |T_i / N_i| at the points of the march (the step
integrators' step ends) and, at rest, over the rest (exact: the forcing's crest or ends,
T = m a_g, N = m g); its first exceedance of the limit is the point where the running
maximum first passes it, at rest the time |a_g| reaches limit g. The held demand
(models.rbm.pieces.held_push) takes its samples from the pieces' closed form, at rest from
a_g.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from rbm_cli.base.jit import jit
from rbm_cli.config.types import G
from rbm_cli.inputs.ground import sine_exceedance
from rbm_cli.models.rbm.exact.modal import (
    LINEAR,
    ZERO,
    f_accel,
    f_exceedance,
    f_peak_on,
    linear_exceedance,
)
from rbm_cli.models.rbm.exact.peaks import (
    NOTES,
    may_exceed,
    new_notes,
    note_interval,
    settle_peaks,
)
from rbm_cli.models.rbm.exact.piece import eval_point, make_piece, row_at, set_point
from rbm_cli.models.rbm.exact.search import SCRATCH, next_point
from rbm_cli.models.rbm.pieces import (
    IMPACT,
    UPLIFT,
    below_barrier,
    cross,
    first_over,
    held_push,
    held_time,
    locate,
    piece_bounds,
    restitute,
    shear_ratios,
    silent_impact,
)
from rbm_cli.models.status import (
    AT_REST_END,
    COLLAPSED,
    FAILED_EVENTS,
    FAILED_STEPS,
    GOING,
    OPENED,
    POLL_PIECES,
    STOP_NEVER,
    STOP_OUTCOME,
    STOPPED_EARLY,
    SURVIVED,
    guard_code,
)

T, H, NEXT_OUT, T_COLLAPSE, AT_REST, N_OUT, T_SLIP, SLIP_IF = range(8)
UPLIFTS, IMPACTS, STEPS, RHS, EVENTS, COLLAPSE_IF, RHS_PEAKS, SEG = range(8)

#: First interval tried at the start of a run and of a segment [s].
FIRST_STEP = 1e-3

#: Work arrays of a run: the point pool, mode and family bounds, the peak refinement's
#: reference counts, free list and stack, and the noted intervals (exact.peaks).
Work = namedtuple("Work", "pts mb fb refs free st_ab st_rows notes up")
#: The moving state: rotations, rates, law pieces (side, k, pending, awaiting), maxima of
#: the tracked quantities, friction demand (its peak; the held demand, pieces.held_array,
#: and the shear ratios of a sample).
State = namedtuple(
    "State", "theta rate side k pending awaiting maxima fric st cnt held rx ry modal_acc"
)


@jit
def _emit(pc, pts, s, samples, t_stop, dt):
    """Record the samples due up to t_stop [s], every dt [s], from point 0 of the piece."""
    n = s.theta.size
    while s.st[NEXT_OUT] <= t_stop + 1e-12 and int(s.st[N_OUT]) < samples.shape[0]:
        row = int(s.st[N_OUT])
        samples[row, 0] = s.st[NEXT_OUT]
        eval_point(pc, pts, 0, s.st[NEXT_OUT] - pts[0, 0], SCRATCH)
        samples[row, 1 : 1 + n] = pc.phi @ pts[SCRATCH, 1 : 1 + n]
        samples[row, 1 + n : 1 + 2 * n] = pc.phi @ pts[SCRATCH, 1 + n : 1 + 2 * n]
        s.st[N_OUT] += 1
        s.st[NEXT_OUT] += dt


@jit
def _emit_rest(s, samples, t_stop, dt):
    """Record zeros (a rigid block at rest) for the samples due up to t_stop [s]."""
    while s.st[NEXT_OUT] <= t_stop + 1e-12 and int(s.st[N_OUT]) < samples.shape[0]:
        row = int(s.st[N_OUT])
        samples[row, 0] = s.st[NEXT_OUT]
        samples[row, 1:] = 0.0
        s.st[N_OUT] += 1
        s.st[NEXT_OUT] += dt


@jit(borrow=True)
def _accel_and_friction(mdl, pc, pts, i, s):
    """The shear ratios (s.rx) of the state at point i (at its time pts[i, 0]); the peak
    s.fric raised to them. The bodies' accelerations are (centre_map Phi) q'', the modal
    accelerations q'' mapped by the piece's cphi."""
    n = pc.n
    from_modes = s.modal_acc
    ag = f_accel(pc.fc, pts[i, 0])
    for j in range(n):
        from_modes[j] = -pc.lam[j] * pts[i, 1 + j] + pc.f[j] + pc.g[j] * ag
    shear_ratios(ag, 0.0, 1.0, pc.cphi, from_modes, s.ry[:0], mdl.masses,
                 mdl.normal_forces, s.rx, s.ry, s.fric)  # fmt: skip


@jit(borrow=True)
def _held_samples(mdl, pc, pts, s):
    """The held demand's samples due up to point 1, from the piece's closed form at point 0."""
    while held_time(s.held) <= pts[1, 0]:
        t_k = held_time(s.held)
        eval_point(pc, pts, 0, t_k - pts[0, 0], SCRATCH)
        pts[SCRATCH, 0] = t_k
        _accel_and_friction(mdl, pc, pts, SCRATCH, s)
        held_push(s.held, s.rx, s.ry, s.fric)


@jit
def _passed_peak(mdl, pc, pts):
    """Early stop of free motion between points 0 and 1: a monolith past a peak of its collapse
    ratio with less energy than the collapse barrier."""
    if math.isnan(mdl.barrier):
        return False
    k = 1 + 2 * pc.n + pc.m  # collapse ratio of interface 1
    dk = k + pc.nf
    if not pts[0, k] * pts[0, dk] > 0.0:
        return False
    if not (pts[1, k] * pts[1, dk] <= 0.0 or pts[1, dk] * pts[0, dk] < 0.0):
        return False
    theta, rate = np.empty(1), np.empty(1)
    theta[0] = pc.phi[0, 0] * pts[1, 1]
    rate[0] = pc.phi[0, 0] * pts[1, 2]
    return below_barrier(theta, rate, mdl.mass, mdl.argmap, mdl.gravity, mdl.edges,
                         mdl.nedges, mdl.intercepts, mdl.slopes, mdl.barrier)  # fmt: skip


@jit
def _survives(mdl, pc, pts):
    """solver.stop: outcome in free motion: the state at point 1 certain to survive, below
    the survival barrier (pieces.below_barrier)."""
    n = pc.n
    theta = pc.phi @ pts[1, 1 : 1 + n]
    rate = pc.phi @ pts[1, 1 + n : 1 + 2 * n]
    return below_barrier(theta, rate, mdl.mass, mdl.argmap, mdl.gravity, mdl.edges,
                         mdl.nedges, mdl.intercepts, mdl.slopes, mdl.survival)  # fmt: skip


@jit(borrow=True)
def _budget(cnt, se):
    """A failure code when a budget is exceeded, else GOING (cnt: the State's counts)."""
    if cnt[STEPS] > se[0]:
        return FAILED_STEPS
    if cnt[STEPS] % POLL_PIECES == 0:
        return guard_code(se[2])
    return GOING


@jit
def _march(mdl, pc, wk, s, se, seg_end, can_stop, sure_stop, samples):
    """Advance through the piece to its first event or seg_end [s].
    Returns the event row, -1 at seg_end, or -(a terminal code)."""
    pts = wk.pts
    best, row = math.inf, -1
    for r in range(pc.sgn.size):
        d, _ = row_at(pc, pts, 0, r)
        if d < best:
            best, row = d, r
    if best <= 0.0:
        return row
    row = -1
    while pts[0, 0] < seg_end and row < 0:
        s.cnt[STEPS] += 1
        code = _budget(s.cnt, se)
        if code != GOING:
            s.st[T] = pts[0, 0]
            return -code
        row, s.st[H], ev, fresh = next_point(pc, pts, s.st[H], seg_end, wk.mb, wk.fb)
        s.cnt[RHS] += ev
        if may_exceed(pc, pts, s.maxima, wk.mb, wk.fb, fresh, wk.up):
            ev = note_interval(pc, pts, s.maxima, wk.mb, wk.fb, wk.notes, s.side, s.k,
                               s.cnt[SEG], wk)  # fmt: skip
            s.cnt[RHS] += ev
            s.cnt[RHS_PEAKS] += ev
        if se[4] != 0.0:
            _emit(pc, pts, s, samples, pts[1, 0], se[5])
        _accel_and_friction(mdl, pc, pts, 1, s)
        if s.st[SLIP_IF] == 0.0:
            first_over(s.fric, se[6], pts[1, 0], s.st[T_SLIP : SLIP_IF + 1])
        if held_time(s.held) <= pts[1, 0]:
            _held_samples(mdl, pc, pts, s)
        if can_stop and _passed_peak(mdl, pc, pts):
            s.st[T] = pts[1, 0]
            return -STOPPED_EARLY
        if sure_stop and _survives(mdl, pc, pts):
            s.st[T] = pts[1, 0]
            return -STOPPED_EARLY
        pts[0, :] = pts[1, :]
    n = pc.n
    s.st[T] = pts[0, 0]
    s.theta[:] = pc.phi @ pts[0, 1 : 1 + n]
    s.rate[:] = pc.phi @ pts[0, 1 + n : 1 + 2 * n]
    return row


@jit
def _handle(mdl, pc, row, s, se):
    """Apply the event of a row at the state. Returns a code (OPENED, the state left as it
    is, when the run stops at a joint's first event: se[7]). The rows are the m joints'
    (exact.piece), a frame's beam joint the last."""
    m = s.side.size
    if row >= 4 * m:
        silent_impact(pc.silent[row - 4 * m], s.side, s.awaiting)
        s.cnt[IMPACTS] += 1
        return GOING
    if se[7] != 0.0:
        return OPENED
    s.cnt[EVENTS] += 1
    if s.cnt[EVENTS] > se[1]:
        return FAILED_EVENTS
    which, i = row // m, row % m
    if which >= 2:
        s.st[T_COLLAPSE] = s.st[T]
        s.cnt[COLLAPSE_IF] = i + 1
        s.maxima[i] = max(s.maxima[i], mdl.c_ratio)
        return COLLAPSED
    going_up = which == 1
    lo, hi = piece_bounds(i, s.side, s.k, s.pending, mdl.rigid, mdl.edges, mdl.nedges)
    bound = hi if going_up else lo
    x_i = mdl.argmap[i] @ s.theta
    s.theta[:] += mdl.arg_inv[:, i] * (bound - x_i)
    kind = cross(i, going_up, s.side, s.k, s.pending, s.awaiting, mdl.rigid, mdl.silent)
    if kind == UPLIFT:
        s.cnt[UPLIFTS] += 1
    elif kind == IMPACT:
        s.cnt[IMPACTS] += 1
        if mdl.e_rest < 1.0:
            xdot = mdl.argmap[i] @ s.rate
            restitute(i, xdot, mdl.e_rest, mdl.impulse_dir, mdl.impulse_w, s.rate)
        if mdl.rigid_mono and abs(s.rate[0]) < mdl.rest_rate:
            s.theta[:] = 0.0
            s.rate[:] = 0.0
            s.st[AT_REST] = 1.0
    return GOING


@jit
def _rest_friction(s, fc, t0, t1, mu):
    """The friction demand of a monolith at rest on [t0, t1] [s]: |a_g| / g (T = m a_g,
    N = m g), at every joint it is reported for (a monolithic frame's beam joint too); where
    it first exceeds mu, the time |a_g| reaches mu g."""
    d = f_peak_on(fc, t0, t1) / G
    for i in range(s.fric.size):
        if d > s.fric[i]:
            s.fric[i] = d
    if s.st[SLIP_IF] == 0.0 and d > mu:
        s.st[T_SLIP] = f_exceedance(fc, t0, mu * G, t1)
        s.st[SLIP_IF] = 1.0
    while held_time(s.held) <= t1:
        r = f_accel(fc, held_time(s.held)) / G
        for i in range(s.rx.size):
            s.rx[i] = r
        held_push(s.held, s.rx, s.ry, s.fric)


@jit
def _leave_rest(mdl, s, mo, seg_end, fc, samples, dt, mu):
    """A rigid monolith at rest: 0 no ground motion left (rests to
    the end), 1 the segment ends first, 2 it lifts (a harmonic's exceedance from its
    formula, a linear piece's from its line)."""
    t = s.st[T]
    kind_fc = int(fc[0])
    if kind_fc == ZERO:
        if mo[0] != 0.0 and t < mo[4]:  # rest before a record's first sample
            kind, t_stop = 1, seg_end
        else:
            kind, t_stop = 0, mo[5]
    else:
        if kind_fc == LINEAR:
            t_up = linear_exceedance(fc, t, mdl.uplift_level, seg_end)
        else:
            t_up = sine_exceedance(t, mdl.uplift_level, fc[1], fc[2], fc[3], min(mo[4], mo[5]))
        if t_up < 0.0 or t_up >= seg_end:  # -1: none
            kind, t_stop = 1, seg_end
        else:
            kind, t_stop = 2, t_up
    _rest_friction(s, fc, t, t_stop, mu)
    _emit_rest(s, samples, t_stop - (1e-15 if kind == 2 else 0.0), dt)
    s.st[T] = t_stop
    if kind != 2:
        return kind
    s.theta[:] = 0.0
    s.rate[:] = 0.0
    s.side[0] = -1 if f_accel(fc, t_stop) > 0.0 else 1
    s.k[0] = 0
    s.st[AT_REST] = 0.0
    s.cnt[UPLIFTS] += 1
    return kind


@jit
def _segment(mdl, cache, wk, s, mo, se, fc, seg_end, can_stop, sure_stop, samples):
    """Run up to seg_end [s] under the forcing fc. Returns a code."""
    while s.st[T] < seg_end:
        if s.st[AT_REST] != 0.0:
            kind = _leave_rest(mdl, s, mo, seg_end, fc, samples, se[5], se[6])
            if kind == 0:
                return AT_REST_END
            if kind == 1:
                return GOING
        pc = make_piece(mdl, cache, s.side, s.k, s.pending, s.awaiting, fc)
        set_point(pc, wk.pts, 0, s.st[T], pc.tom @ s.theta, pc.tom @ s.rate)
        row = _march(mdl, pc, wk, s, se, seg_end, can_stop, sure_stop, samples)
        if row < -1:
            return -row
        if row >= 0:
            code = _handle(mdl, pc, row, s, se)
            if code != GOING:
                return code
    return GOING


@jit
def run_exact(mdl, cache, seg_t, seg_fc, mo, se, theta0, rate0, samples, pool, stack, held):
    """One run (exact.integrate.integrate_exact) of a column of n drums (theta0, rate0)
    and m joints (mdl.argmap's rows: n, or n + 1 with a frame's beam joint); held: the held
    friction demand (pieces.held_array), changed in place. Returns (code, st, cnt, maxima:
    the m joints' collapse ratios and the top's displacement, friction: its peak at the
    joints it is reported for, mdl.normal_forces')."""
    n = theta0.size
    m = mdl.argmap.shape[0]
    mf = mdl.normal_forces.size
    side = np.ones(m, dtype=np.int64)
    k = np.zeros(m, dtype=np.int64)
    pending = np.zeros(m, dtype=np.bool_)
    awaiting = np.zeros(m, dtype=np.bool_)
    theta, rate = theta0.copy(), rate0.copy()
    locate(mdl.argmap @ theta, mdl.argmap @ rate, side, k, pending, mdl.rigid, mdl.edges,
           mdl.nedges)  # fmt: skip
    st = np.array([0.0, FIRST_STEP, 0.0, math.nan, 0.0, 0.0, math.nan, 0.0])
    if mdl.rigid_mono and not (np.any(theta != 0.0) or np.any(rate != 0.0)):
        st[AT_REST] = 1.0
    s = State(theta, rate, side, k, pending, awaiting, np.zeros(m + 1), np.zeros(mf), st,
              np.zeros(8, dtype=np.int64), held, np.zeros(mf), np.zeros(mf),
              np.zeros(n))  # fmt: skip
    nf = 2 * m + 1
    wk = Work(np.zeros((pool, 1 + 2 * n + 3 * nf)), np.zeros((9, n)), np.zeros((8, nf)),
              np.zeros(pool, dtype=np.int64), np.zeros(pool - 3, dtype=np.int64),
              np.zeros((stack, 2), dtype=np.int64),
              np.zeros((stack, m + 1), dtype=np.bool_), new_notes(n, m, NOTES),
              np.zeros(m + 1))  # fmt: skip
    code = GOING
    for i in range(seg_t.shape[0]):
        if s.st[T] >= seg_t[i, 1]:
            continue
        if not (i > 0 and int(seg_fc[i, 0]) == LINEAR and int(seg_fc[i - 1, 0]) == LINEAR):
            s.st[H] = min(s.st[H], FIRST_STEP)  # a record's next sample keeps its step
        free = int(seg_fc[i, 0]) == ZERO and seg_t[i, 0] >= mo[4]
        can_stop = se[3] != STOP_NEVER and free and mo[0] != 0.0
        sure_stop = se[3] == STOP_OUTCOME and free  # solver.stop: outcome
        s.cnt[SEG] = i
        code = _segment(mdl, cache, wk, s, mo, se, seg_fc[i], seg_t[i, 1], can_stop, sure_stop,
                        samples)  # fmt: skip
        if code != GOING:
            break
    if code == GOING:
        code = SURVIVED
    if code != OPENED:  # a run stopped where a joint opened is run again by another method
        ev = settle_peaks(mdl, cache, wk.notes, seg_fc, s.maxima, wk)
        s.cnt[RHS] += ev
        s.cnt[RHS_PEAKS] += ev
    return code, s.st, s.cnt, s.maxima, s.fric
