"""The run loop of the rigid block's compiled closed form (numba): rest, uplift, pieces
of closed-form motion (closed_form_jit), impacts, collapse and the early stop of free
motion, in one compiled call per run; rbm_cli.models.housner_linear's algorithm.

Mutable scalars live in small arrays: st = [t, theta, rate, side, at rest, peak,
friction, next output time, samples written, t_collapse] (floats) and cnt = [uplifts,
impacts, pieces, evaluations, events] (ints). A motion is mo = [pulse or record (0/1),
amplitude, omega, phase, pulse_end, t_end] with its segments (start, end) and their
forcings (exact_jit_modal); settings are se = [max_steps (pieces), max_events, deadline
(time.monotonic) [s], early_stop, record, output_dt [s]] (as exact_jit_run's).
"""

from __future__ import annotations

import math

import numpy as np

from rbm_cli.base.jit import jit
from rbm_cli.models.housner_state import STOP_MARGIN
from rbm_cli.models.rbm.closed_form_jit import (
    A_EVALS,
    A_FRICTION,
    A_PEAK,
    A_TAU_PEAK,
    B_ALPHA,
    B_BARRIER,
    B_LIMIT,
    B_P,
    B_REST,
    B_REST_RATE,
    B_UPLIFT,
    COLLAPSE,
    IMPACT,
    NONE,
    PIECE_SIZE,
    point,
    scan_piece,
    start_piece,
)
from rbm_cli.models.rbm.exact.modal import LINEAR, ZERO, f_accel, linear_exceedance
from rbm_cli.models.rbm.kernel_ground import sine_exceedance
from rbm_cli.models.rbm.run_codes import (
    AT_REST_END,
    COLLAPSED,
    FAILED_EVENTS,
    FAILED_STEPS,
    GOING,
    POLL_PIECES,
    STOPPED_EARLY,
    SURVIVED,
    guard_code,
)

T, THETA, RATE, SIDE, AT_REST, PEAK, FRICTION, NEXT_OUT, N_OUT, T_COLLAPSE = range(10)
UPLIFTS, IMPACTS, PIECES, EVALS, EVENTS = range(5)


@jit
def energy(blk, theta, rate):
    """Energy per unit inertia [rad^2/s^2]: rate^2 / 2 + p^2 (alpha |theta| - theta^2 / 2)."""
    a = abs(theta)
    p = blk[B_P]
    return 0.5 * rate * rate + p * p * (blk[B_ALPHA] * a - 0.5 * a * a)


@jit
def _emit(pc, st, samples, t_stop, dt, rest):
    """Record the samples due up to t_stop [s], every dt [s]: the piece's, or zeros."""
    while st[NEXT_OUT] <= t_stop + 1e-12 and int(st[N_OUT]) < samples.shape[0]:
        row = int(st[N_OUT])
        samples[row, 0] = st[NEXT_OUT]
        if rest:
            samples[row, 1], samples[row, 2] = 0.0, 0.0
        else:
            f, g, _, _, _, _, _ = point(pc, st[NEXT_OUT] - pc[0])
            samples[row, 1], samples[row, 2] = pc[1] * f, pc[1] * g
        st[N_OUT] += 1.0
        st[NEXT_OUT] = (st[N_OUT]) * dt


@jit
def _leave_rest(blk, st, cnt, mo, seg_end, fc, pc, samples, dt):
    """The block at rest: 0 no ground motion left (rests to the end), 1 the segment ends
    first, 2 it lifts (a harmonic's exceedance from its formula, a line's from the line)
    on the side turning away from a_g."""
    t = st[T]
    kind_fc = int(fc[0])
    if kind_fc == ZERO:
        if mo[0] != 0.0 and t < mo[4]:  # rest before a record's first sample
            kind, t_stop = 1, seg_end
        else:
            kind, t_stop = 0, mo[5]
    else:
        if kind_fc == LINEAR:
            t_up = linear_exceedance(fc, t, blk[B_UPLIFT], seg_end)
        else:
            t_up = sine_exceedance(t, blk[B_UPLIFT], fc[1], fc[2], fc[3], min(mo[4], mo[5]))
        if t_up < 0.0 or t_up >= seg_end:  # -1: none
            kind, t_stop = 1, seg_end
        else:
            kind, t_stop = 2, t_up
    _emit(pc, st, samples, t_stop - (1e-15 if kind == 2 else 0.0), dt, True)
    st[T] = t_stop
    if kind != 2:
        return kind
    st[THETA], st[RATE], st[AT_REST] = 0.0, 0.0, 0.0
    st[SIDE] = -1.0 if f_accel(fc, t_stop) > 0.0 else 1.0
    cnt[UPLIFTS] += 1
    return kind


@jit
def _event(blk, st, cnt, kind, se):
    """Apply the event that ended a piece at st[T]. Returns a code."""
    cnt[EVENTS] += 1
    if kind == COLLAPSE:
        st[T_COLLAPSE] = st[T]
        st[PEAK] = max(st[PEAK], blk[B_LIMIT])
        return COLLAPSED
    if cnt[EVENTS] > se[1]:
        return FAILED_EVENTS
    cnt[IMPACTS] += 1
    st[THETA], st[RATE], st[SIDE] = 0.0, blk[B_REST] * st[RATE], -st[SIDE]
    if abs(st[RATE]) < blk[B_REST_RATE]:
        st[RATE], st[AT_REST] = 0.0, 1.0
    return GOING


@jit
def _piece(blk, st, cnt, fc, seg_end, can_stop, se, samples, pc, acc):
    """One piece from the current state up to its first event, a peak of free motion
    below the barrier (can_stop) or seg_end [s]. Returns a code."""
    t = st[T]
    start_piece(blk, t, st[THETA], st[RATE], st[SIDE], fc, pc)
    cnt[PIECES] += 1
    acc[A_PEAK], acc[A_TAU_PEAK], acc[A_EVALS], acc[A_FRICTION] = 0.0, -1.0, 0.0, st[FRICTION]
    kind, tau = scan_piece(pc, blk, seg_end - t, acc)
    cnt[EVALS] += int(acc[A_EVALS])
    stop_here = (
        can_stop
        and acc[A_TAU_PEAK] >= 0.0
        and energy(blk, st[THETA], st[RATE]) < blk[B_BARRIER] * (1.0 - STOP_MARGIN)
    )
    tau_end = acc[A_TAU_PEAK] if stop_here else tau
    t_new = seg_end if (kind == NONE and not stop_here) else t + tau_end
    if se[4] != 0.0:
        _emit(pc, st, samples, t_new, se[5], False)
    f, g, _, _, _, _, _ = point(pc, tau_end)
    st[THETA], st[RATE], st[T] = pc[1] * f, pc[1] * g, t_new
    st[PEAK], st[FRICTION] = max(st[PEAK], acc[A_PEAK]), acc[A_FRICTION]
    if stop_here:
        return STOPPED_EARLY
    if kind == IMPACT or kind == COLLAPSE:
        return _event(blk, st, cnt, kind, se)
    return GOING


@jit
def _segment(blk, st, cnt, mo, se, fc, seg_end, can_stop, samples, pc, acc):
    """Run up to seg_end [s] under the forcing fc. Returns a code."""
    while st[T] < seg_end:
        if st[AT_REST] != 0.0:
            kind = _leave_rest(blk, st, cnt, mo, seg_end, fc, pc, samples, se[5])
            if kind == 0:
                return AT_REST_END
            if kind == 1:
                return GOING
        if cnt[PIECES] >= se[0]:
            return FAILED_STEPS
        if cnt[PIECES] % POLL_PIECES == POLL_PIECES - 1:
            code = guard_code(se[2])
            if code != GOING:
                return code
        code = _piece(blk, st, cnt, fc, seg_end, can_stop, se, samples, pc, acc)
        if code != GOING:
            return code
    return GOING


@jit
def run_block(blk, seg_t, seg_fc, mo, se, theta0, rate0, samples):
    """One run from (theta0 [rad], rate0 [rad/s]) at t = 0. Returns (code, st, cnt)."""
    side = 1.0 if theta0 > 0.0 else -1.0 if theta0 < 0.0 else (-1.0 if rate0 < 0.0 else 1.0)
    at_rest = 1.0 if theta0 == 0.0 and rate0 == 0.0 else 0.0
    st = np.array([0.0, theta0, rate0, side, at_rest, abs(theta0), 0.0, 0.0, 0.0, math.nan])
    cnt = np.zeros(5, dtype=np.int64)
    pc, acc = np.zeros(PIECE_SIZE), np.zeros(4)
    if abs(theta0) >= blk[B_LIMIT]:
        st[T_COLLAPSE] = 0.0
        return COLLAPSED, st, cnt
    code = GOING
    for i in range(seg_t.shape[0]):
        if st[T] >= seg_t[i, 1]:
            continue
        free = int(seg_fc[i, 0]) == ZERO and seg_t[i, 0] >= mo[4]
        can_stop = se[3] != 0.0 and free and mo[0] != 0.0
        code = _segment(blk, st, cnt, mo, se, seg_fc[i], seg_t[i, 1], can_stop, samples, pc,
                        acc)  # fmt: skip
        if code != GOING:
            break
    if code == GOING:
        code = SURVIVED
    return code, st, cnt
