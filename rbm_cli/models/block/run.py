"""The run loop of the rigid block's closed form (numba-compatible; rbm_cli.base.jit):
rest, uplift, pieces of closed-form motion (block.piece), impacts, collapse and the early
stop of free motion, in one call per run.

Mutable scalars live in small arrays: st = [t, theta, rate, side, at rest, peak,
friction, next output time, samples written, t_collapse, events logged, t_slip, the beam
joint's friction, slip joint] (floats; t_slip: where the friction demand first exceeded
the limit se[6], nan if not, at the slip joint: 1 the ground's, 2 a monolithic frame's
beam joint) and
cnt = [uplifts, impacts, pieces, evaluations, events] (ints). A motion is mo = [pulse or
record (0/1), amplitude, omega, phase, pulse_end, t_end] with its segments (start, end),
their forcings (exact.modal) and, under a vertical record, the upward acceleration
on each segment, seg_v = [a_v at the forcing's t0 [m/s^2], its slope [m/s^3]] (no rows:
no vertical motion); settings are se = [max_steps (pieces), max_events, deadline
(time.monotonic) [s], early_stop, record, output_dt [s], friction limit [-] (inf: none)]
(as exact.run's).

The friction demand |T / N| of the RBM block (block.closed_form.rbm_block derives it) is
exact: at rest |a_g| / (g + a_v) over the rest (T = m a_g, N = m (g + a_v); a harmonic's
crest or a line's ends), in motion the piece's largest |demand| (block.piece._friction),
and so is its first exceedance of the limit (the exceedance of |a_g| at rest, Brent on the
piece's demand in motion): its peak. The demand held for a duration
(models.rbm.pieces.held_push, the step and exact integrators' too) takes its samples from
a_g at rest and from the piece's closed form in motion (block.piece.point). A monolithic
frame's beam joint (its friction factors in the block: block.piece.joint_demand) has its
own demand, the same way: a_g / g at rest, where every body moves with the ground.

A vertical record makes the weights act as under g + a_v: on a piece the block obeys
theta'' = p^2 gam (theta - s alpha) + e a_g with gam = (g + a_v) / g taken at the middle
of the piece (a piece under a record ends at the next sample: exact for a_v constant
between samples, second order in the sample step otherwise), and it lifts when |a_g|
exceeds the uplift level times (g + a_v) / g.
"""

from __future__ import annotations

import math

import numpy as np

from rbm_cli.base.events import STOP_MARGIN
from rbm_cli.base.jit import jit
from rbm_cli.config.types import G
from rbm_cli.inputs.ground import sine_exceedance
from rbm_cli.models.block.piece import (
    A_EVALS,
    A_FRICTION,
    A_FRICTION2,
    A_MU,
    A_PEAK,
    A_SLIP,
    A_SLIP2,
    A_TAU_PEAK,
    ACC_SIZE,
    B_ALPHA,
    B_BARRIER,
    B_FA,
    B_LIMIT,
    B_P,
    B_REST,
    B_REST_RATE,
    B_UPLIFT,
    COLLAPSE,
    IMPACT,
    NONE,
    PIECE_SIZE,
    joint_demand,
    point,
    scan_piece,
    start_piece,
)
from rbm_cli.models.rbm.exact.modal import (
    LINEAR,
    ZERO,
    f_accel,
    f_exceedance,
    f_peak_on,
    linear_exceedance,
)
from rbm_cli.models.rbm.pieces import held_push, held_time
from rbm_cli.models.status import (
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

(T, THETA, RATE, SIDE, AT_REST, PEAK, FRICTION, NEXT_OUT, N_OUT, T_COLLAPSE, N_LOG, T_SLIP,
 FRICTION2, SLIP_IF) = range(14)  # fmt: skip
UPLIFTS, IMPACTS, PIECES, EVALS, EVENTS = range(5)
#: The kinds of the event log's rows (t [s], kind).
LOG_UPLIFT, LOG_IMPACT, LOG_REST, LOG_COLLAPSE = 1, 2, 3, 4


@jit
def energy(blk, theta, rate):
    """Energy per unit inertia [rad^2/s^2]: rate^2 / 2 + p^2 (alpha |theta| - theta^2 / 2)."""
    a = abs(theta)
    p = blk[B_P]
    return 0.5 * rate * rate + p * p * (blk[B_ALPHA] * a - 0.5 * a * a)


@jit
def _note(st, log, kind):
    """Log (t, kind) of an event at st[T] while the log has room."""
    row = int(st[N_LOG])
    if row < log.shape[0]:
        log[row, 0], log[row, 1] = st[T], kind
        st[N_LOG] += 1.0


@jit
def gravity_factor(fc, fv, t):
    """(g + a_v(t)) / g [-] on a segment with the upward acceleration line fv (a_v =
    fv[0] + fv[1] (t - t0), t0 the forcing's fc[4])."""
    return 1.0 + (fv[0] + fv[1] * (t - fc[4])) / G


@jit
def vertical_exceedance(fc, fv, t0, level, t_stop):
    """First t in [t0, t_stop) with |a_g(t)| > level (g + a_v(t)) / g under a linear
    forcing fc and the upward line fv: t0 when already above, else where a_g meets
    +-level (g + a_v) / g (both lines; -1 if not before t_stop [s])."""
    a = f_accel(fc, t0)
    if abs(a) > level * gravity_factor(fc, fv, t0):
        return t0
    b = f_accel(fc, t_stop)
    if not abs(b) > level * gravity_factor(fc, fv, t_stop):
        return -1.0
    target = level if b > 0.0 else -level
    f_a = a - target * gravity_factor(fc, fv, t0)
    f_b = b - target * gravity_factor(fc, fv, t_stop)
    t = min(max(t0 + (t_stop - t0) * (f_a / (f_a - f_b)), t0), t_stop)
    return t if t < t_stop else -1.0


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
def _held_rest(fc, fv, t1, held, hw):
    """The held demand's samples due up to t1 [s] of the block at rest: a_g / (g + a_v)
    (0 where no forcing acts) at every joint. hw: the sample's shear ratios (x, y) and a
    peak they raise, rows of one value per joint."""
    while held_time(held) <= t1:
        t_k = held_time(held)
        a = 0.0 if int(fc[0]) == ZERO else f_accel(fc, t_k)
        if fv.size > 0:
            a /= gravity_factor(fc, fv, t_k)
        hw[0, :] = a / G
        held_push(held, hw[0], hw[1], hw[2])


@jit
def _rest_friction(st, fc, fv, t0, t1, mu):
    """The friction demand of the block at rest on [t0, t1] [s], |a_g| / (g + a_v) (a_g
    and a_v straight on a record's piece: their ratio is monotone, its ends hold the
    largest), and where it first exceeds mu: the time |a_g| reaches mu (g + a_v)."""
    if fv.size > 0:
        d = max(abs(f_accel(fc, t0)) / gravity_factor(fc, fv, t0),
                abs(f_accel(fc, t1)) / gravity_factor(fc, fv, t1)) / G  # fmt: skip
    else:
        d = f_peak_on(fc, t0, t1) / G
    if d > st[FRICTION]:
        st[FRICTION] = d
    if d > st[FRICTION2]:  # a monolithic frame's beam joint (unused otherwise)
        st[FRICTION2] = d
    if math.isnan(st[T_SLIP]) and d > mu:
        st[SLIP_IF] = 1.0
        if fv.size > 0:
            st[T_SLIP] = vertical_exceedance(fc, fv, t0, mu * G, t1)
        else:
            st[T_SLIP] = f_exceedance(fc, t0, mu * G, t1)


@jit
def _leave_rest(blk, st, cnt, mo, seg_end, fc, fv, pc, samples, dt, log, mu, held, hw):
    """The block at rest: 0 no ground motion left (rests to the end), 1 the segment ends
    first, 2 it lifts (a harmonic's exceedance from its formula, a line's from the line,
    under a vertical record (fv: its line, else empty) against the level times
    (g + a_v) / g) on the side turning away from a_g."""
    t = st[T]
    kind_fc = int(fc[0])
    if kind_fc == ZERO:
        if mo[0] != 0.0 and t < mo[4]:  # rest before a record's first sample
            kind, t_stop = 1, seg_end
        else:
            kind, t_stop = 0, mo[5]
    else:
        if kind_fc == LINEAR and fv.size > 0:
            t_up = vertical_exceedance(fc, fv, t, blk[B_UPLIFT], seg_end)
        elif kind_fc == LINEAR:
            t_up = linear_exceedance(fc, t, blk[B_UPLIFT], seg_end)
        else:
            t_up = sine_exceedance(t, blk[B_UPLIFT], fc[1], fc[2], fc[3], min(mo[4], mo[5]))
        if t_up < 0.0 or t_up >= seg_end:  # -1: none
            kind, t_stop = 1, seg_end
        else:
            kind, t_stop = 2, t_up
    if not math.isnan(blk[B_FA]) and kind_fc != ZERO:
        _rest_friction(st, fc, fv, t, t_stop, mu)
    _held_rest(fc, fv, t_stop, held, hw)
    _emit(pc, st, samples, t_stop - (1e-15 if kind == 2 else 0.0), dt, True)
    st[T] = t_stop
    if kind != 2:
        return kind
    st[THETA], st[RATE], st[AT_REST] = 0.0, 0.0, 0.0
    st[SIDE] = -1.0 if f_accel(fc, t_stop) > 0.0 else 1.0
    cnt[UPLIFTS] += 1
    _note(st, log, LOG_UPLIFT)
    return kind


@jit
def _event(blk, st, cnt, kind, se, log):
    """Apply the event that ended a piece at st[T] (logged). Returns a code."""
    cnt[EVENTS] += 1
    if kind == COLLAPSE:
        st[T_COLLAPSE] = st[T]
        st[PEAK] = max(st[PEAK], blk[B_LIMIT])
        _note(st, log, LOG_COLLAPSE)
        return COLLAPSED
    if cnt[EVENTS] > se[1]:
        return FAILED_EVENTS
    cnt[IMPACTS] += 1
    _note(st, log, LOG_IMPACT)
    st[THETA], st[RATE], st[SIDE] = 0.0, blk[B_REST] * st[RATE], -st[SIDE]
    if abs(st[RATE]) < blk[B_REST_RATE]:
        st[RATE], st[AT_REST] = 0.0, 1.0
        _note(st, log, LOG_REST)
    return GOING


@jit
def _piece(blk, st, cnt, fc, fv, seg_end, can_stop, se, samples, pc, acc, log, held, hw):
    """One piece from the current state up to its first event, a peak of free motion
    below the barrier (can_stop) or seg_end [s]; under a vertical record (fv not empty) and
    a linear forcing, with gam = (g + a_v) / g at the piece's middle; the held demand's
    samples on it (hw: as _held_rest's). Returns a code."""
    t = st[T]
    gam = 1.0
    if fv.size > 0 and int(fc[0]) == LINEAR:
        gam = gravity_factor(fc, fv, 0.5 * (t + seg_end))
    start_piece(blk, t, st[THETA], st[RATE], st[SIDE], fc, gam, pc)
    cnt[PIECES] += 1
    acc[A_PEAK], acc[A_TAU_PEAK], acc[A_EVALS], acc[A_FRICTION] = 0.0, -1.0, 0.0, st[FRICTION]
    acc[A_MU] = se[6] if math.isnan(st[T_SLIP]) else math.inf
    acc[A_SLIP], acc[A_FRICTION2], acc[A_SLIP2] = -1.0, st[FRICTION2], -1.0
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
    while held_time(held) <= t_new:
        for row in range(hw.shape[1]):  # the ground joint, a monolithic frame's beam joint
            hw[0, row], _ = joint_demand(pc, held_time(held) - t, row)
        held_push(held, hw[0], hw[1], hw[2])
    f, g, _, _, _, _, _ = point(pc, tau_end)
    st[THETA], st[RATE], st[T] = pc[1] * f, pc[1] * g, t_new
    st[PEAK], st[FRICTION] = max(st[PEAK], acc[A_PEAK]), acc[A_FRICTION]
    st[FRICTION2] = acc[A_FRICTION2]
    if acc[A_SLIP] >= 0.0 and not 0.0 <= acc[A_SLIP2] < acc[A_SLIP]:
        st[T_SLIP], st[SLIP_IF] = t + acc[A_SLIP], 1.0
    elif acc[A_SLIP2] >= 0.0:
        st[T_SLIP], st[SLIP_IF] = t + acc[A_SLIP2], 2.0
    if stop_here:
        return STOPPED_EARLY
    if kind == IMPACT or kind == COLLAPSE:
        return _event(blk, st, cnt, kind, se, log)
    return GOING


@jit
def _segment(blk, st, cnt, mo, se, fc, fv, seg_end, can_stop, samples, pc, acc, log, held, hw):
    """Run up to seg_end [s] under the forcing fc (and the upward line fv). Returns a
    code."""
    while st[T] < seg_end:
        if st[AT_REST] != 0.0:
            kind = _leave_rest(blk, st, cnt, mo, seg_end, fc, fv, pc, samples, se[5], log,
                               se[6], held, hw)  # fmt: skip
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
        code = _piece(blk, st, cnt, fc, fv, seg_end, can_stop, se, samples, pc, acc, log,
                      held, hw)  # fmt: skip
        if code != GOING:
            return code
    return GOING


@jit
def run_block(blk, seg_t, seg_fc, seg_v, mo, se, theta0, rate0, samples, log, held):
    """One run from (theta0 [rad], rate0 [rad/s]) at t = 0: samples (rows t, theta, rate)
    written when se asks for them, events (rows t [s], kind LOG_*) logged while log has
    rows, the held friction demand's samples taken into held (models.rbm.pieces.held_array,
    a row per joint: the ground's, and a monolithic frame's beam joint's; one with no window
    takes none). Returns (code, st, cnt)."""
    side = 1.0 if theta0 > 0.0 else -1.0 if theta0 < 0.0 else (-1.0 if rate0 < 0.0 else 1.0)
    at_rest = 1.0 if theta0 == 0.0 and rate0 == 0.0 else 0.0
    st = np.array([0.0, theta0, rate0, side, at_rest, abs(theta0), 0.0, 0.0, 0.0, math.nan,
                   0.0, math.nan, 0.0, 0.0])  # fmt: skip
    no_v = np.zeros(0)
    cnt = np.zeros(5, dtype=np.int64)
    pc, acc = np.zeros(PIECE_SIZE), np.zeros(ACC_SIZE)
    # a held demand's sample (x, y) and the peak it raises (not the block's), a value a joint
    hw = np.zeros((3, held.shape[0] - 1))
    if abs(theta0) >= blk[B_LIMIT]:
        st[T_COLLAPSE] = 0.0
        return COLLAPSED, st, cnt
    code = GOING
    for i in range(seg_t.shape[0]):
        if st[T] >= seg_t[i, 1]:
            continue
        free = int(seg_fc[i, 0]) == ZERO and seg_t[i, 0] >= mo[4]
        can_stop = se[3] != 0.0 and free and mo[0] != 0.0
        fv = seg_v[i] if seg_v.shape[0] > 0 else no_v
        code = _segment(blk, st, cnt, mo, se, seg_fc[i], fv, seg_t[i, 1], can_stop, samples,
                        pc, acc, log, held, hw)  # fmt: skip
        if code != GOING:
            break
    if code == GOING:
        code = SURVIVED
    return code, st, cnt
