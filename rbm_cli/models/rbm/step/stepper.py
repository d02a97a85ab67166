"""The compiled stepper of the Rigid Beam Model (numba): one call runs a whole motion
(the algorithm: rbm_cli.models.rbm.step), from four typed records (step.inputs)."""

from __future__ import annotations

import numpy as np

from rbm_cli.base.copies import copy_into
from rbm_cli.base.detmath import matvec
from rbm_cli.base.jit import jit
from rbm_cli.config.types import G
from rbm_cli.inputs.ground import (
    gravity_factor,
    ground,
    ground_at,
    next_uplift,
    record_piece,
    rest_demand,
    rest_shear,
)
from rbm_cli.models.rbm.pieces import (
    IMPACT,
    UPLIFT,
    below_barrier,
    bound_rows,
    energy,
    first_over,
    held_push,
    held_time,
    hermite_accel,
    locate,
    settle,
    shear_ratios,
)
from rbm_cli.models.rbm.step.events import (
    CHECK_INTERVALS,
    affine,
    brentq,
    first_crossing,
    poly_val,
    row_poly,
    row_spans,
    surfaces,
    system,
    within_reach,
)
from rbm_cli.models.rbm.step.inputs import Excitation, RunTask, SolverSettings, motion_into
from rbm_cli.models.rbm.step.state import REST, switch
from rbm_cli.models.rbm.step.vertical import bound_now, moving_rows
from rbm_cli.models.rbm.step.work import PLANE
from rbm_cli.models.status import (
    COLLAPSED,
    GOING,
    SURVIVED,
)
from rbm_cli.numerics.loop import loop_for, loop_into
from rbm_cli.numerics.quadrature import GL_NODES, GL_WEIGHTS
from rbm_cli.numerics.records import new_record
from rbm_cli.numerics.rk import TAB_EST, dense_eval, emit, emit_rest, steps_for
from rbm_cli.structures.arrays import ColumnArrays, column_into
from rbm_cli.structures.rates import acc_of, rhs

#: The planar column's Runge-Kutta steps on its right-hand side (structures.rates.rhs).
initial_step, attempt_step, dense_prepare = steps_for("plane", rhs)


@jit(borrow=True)
def account_step(mc, t_old, t_new, h, y_old, F, gr, ground_load, argmap, damp, k, yq, ledger):
    """Add one step's work of the ground and the energy its damping took to ledger[2] and
    ledger[3] [J]: over [t_old, t_new] on the step's dense output (F, from y_old; its
    interpolant over h), the powers -a_g r . theta' (r the ground load) and
    sum_i c_i x_i'^2 (the joints on their elastic piece, k_i = 0) by Gauss-Legendre."""
    n = ground_load.size  # the drums; damp.size the joints
    dt = t_new - t_old
    for q in range(GL_NODES.size):
        tq = t_old + GL_NODES[q] * dt
        dense_eval(mc, tq, t_old, h, y_old, F, yq)
        ag = ground(tq, gr)
        p_in = 0.0
        for j in range(n):
            p_in -= ag * ground_load[j] * yq[n + j]
        p_d = 0.0
        for i in range(damp.size):
            if damp[i] != 0.0 and k[i] == 0:
                xd = 0.0
                for j in range(n):
                    xd += argmap[i, j] * yq[n + j]
                p_d += damp[i] * xd * xd
        ledger[2] += GL_WEIGHTS[q] * dt * p_in
        ledger[3] += GL_WEIGHTS[q] * dt * p_d


@jit
def rest_until(t, seg_end, last, uplift_level, amplitude, gr_full, knots, values, vertical,
               friction, held, rx, ry, slip, mu, record, samples, n_out, next_out, output_dt,
               y, side, k):  # fmt: skip
    """A rigid monolith at rest from t [s] in a forced segment (to seg_end [s]): its friction
    demand at rest (inputs.ground.rest_demand, exact; the held demand's samples; where it
    first exceeds mu), the same at every joint it is reported for (a monolithic frame's
    beam joint too: every body moves with the ground), its samples, and where it lifts (no
    later than last [s]).

    Returns
    -------
    (lifted, t, n_out, next_out)  lifted: the column lifts at t (its state zeroed, the
        lifting side's pieces set); else it rests to t = seg_end.
    """
    t_up = next_uplift(t, uplift_level, amplitude, gr_full, knots, values, vertical, last)
    t_rest = seg_end if t_up < 0.0 or t_up >= seg_end else t_up
    d_rest = rest_demand(t, t_rest, gr_full, knots, values, vertical)
    for i in range(friction.size):
        if d_rest > friction[i]:
            friction[i] = d_rest
    while held_time(held) <= t_rest:
        r = rest_shear(held_time(held), gr_full, knots, values, vertical)
        for i in range(rx.size):
            rx[i] = r
        held_push(held, rx, ry, friction)
    if slip[1] == 0.0 and d_rest > mu:
        slip[0] = next_uplift(t, mu * G, amplitude, gr_full, knots, values, vertical, t_rest)
        slip[1] = 1.0
    if t_up < 0.0 or t_up >= seg_end:
        if record:
            n_out, next_out = emit_rest(seg_end, samples, n_out, next_out, output_dt)
        return False, seg_end, n_out, next_out
    if record:
        n_out, next_out = emit_rest(t_up - 1e-15, samples, n_out, next_out, output_dt)
    t = t_up
    for i in range(y.size):
        y[i] = 0.0
    side[0] = -1 if ground_at(t, gr_full, knots, values) > 0.0 else 1
    k[0] = 0
    return True, t, n_out, next_out


@jit(inline=True)
def start(theta0, rate0, W, account):
    """The initial state y = (theta0, rate0), its pieces (pieces.locate) and its energy in
    the run's ledger; returns y and whether a rigid monolith starts at rest."""
    n = theta0.size
    y = np.empty(2 * n)
    copy_into(y, theta0)
    copy_into(y[n:], rate0)
    at_rest = W.uplift_level >= 0.0
    for i in range(2 * n):
        if y[i] != 0.0:
            at_rest = False
    m = W.argmap.shape[0]  # the joints
    x0 = matvec(W.argmap, y[:n], np.empty(m))
    r0 = matvec(W.argmap, y[n:], np.empty(m))
    locate(x0, r0, W.side, W.k, W.pending, W.rigid, W.edges, W.nedges)
    if account:
        ledger = W.ledger
        ledger[0] = energy(y[:n], y[n:], W.mass, W.argmap, W.gravity, W.edges, W.nedges,
                           W.intercepts, W.slopes)  # fmt: skip
        ledger[1] = ledger[0]
    return y, at_rest


@jit(inline=True)
def plane_record(model, motion, task, n, vert):
    """The run's record (step.work.PLANE) of a column of n drums (and m joints: n, or n + 1
    with a frame's beam joint): model its ColumnArrays, motion the Excitation, task the
    RunTask; vert: under a vertical record."""
    W = new_record(PLANE)
    column_into(W, model)
    motion_into(W, motion)
    m = model.argmap.shape[0]
    mf = model.normal_forces.size  # the joints whose friction demand is reported
    # max_ratio, friction, slip, swept (none), the energy account (run_kernel's Returns), the
    # top's peak
    W.max_ratio, W.friction, W.slip = np.zeros(m), np.zeros(mf), np.array([np.nan, 0.0])
    W.swept, W.ledger, W.top = np.zeros(0), np.zeros(5), np.zeros(1)
    nrow, nt, nv = 4 * m, m + 1, 2 * m if vert else 0
    W.side, W.k = np.ones(m, dtype=np.int64), np.zeros(m, dtype=np.int64)
    W.pending, W.awaiting = np.zeros(m, dtype=np.bool_), np.zeros(m, dtype=np.bool_)
    W.lo, W.hi, W.h0, W.mv_e, W.mv_w = (
        np.empty(m),
        np.empty(m),
        np.empty(4 * m),
        np.zeros(nv),
        np.ones(nv),
    )
    W.peaks, W.coef, W.zero_t, W.no_offset = np.zeros(nt), np.empty(7), np.zeros(nt), np.empty(0)
    W.z_old, W.z_new, W.z_prev = np.empty(nt), np.empty(nt), np.empty(nt)
    W.dz_old, W.dz_new, W.dz_prev = np.empty(nt), np.empty(nt), np.empty(nt)
    W.d_old, W.d_new, W.dd_old = np.empty(nrow), np.empty(nrow), np.empty(nrow)
    W.dd_new, W.d2_old, W.d2_new = np.empty(nrow), np.empty(nrow), np.empty(nrow)
    W.near = np.zeros(nrow, dtype=np.bool_)
    W.spans = np.empty((4, m), dtype=np.int64)
    row_spans(W.gx, W.gc, W.spans)
    W.Dq, W.Rq = np.empty((nrow, CHECK_INTERVALS + 1)), np.empty((nrow, CHECK_INTERVALS + 1))
    W.dc0, W.dc1, W.rc0, W.rc1 = np.empty(nrow), np.empty(nrow), np.empty(nrow), np.empty(nrow)
    W.CP, W.BP, W.CR, W.BR = (
        np.empty((nrow, 7)),
        np.empty(nrow),
        np.empty((nrow, 7)),
        np.empty(nrow),
    )
    W.acc, W.acc_old, W.acc_k = np.empty(n), np.empty(n), np.empty(n)
    W.rx, W.ry, W.between, W.ends = np.zeros(mf), np.zeros(mf), np.zeros(mf), np.zeros(2)
    W.samples, W.held, W.record = task.samples, task.held, task.record
    W.output_dt, W.mu, W.vert = task.output_dt, task.friction_limit, vert
    W.any_silent = model.silent.any()
    return W


@jit
def run_kernel(model, motion, solver, task):
    """Run one motion of one model.

    The four records come as plain tuples (their fields in order: tuple(record)) and
    are named here, at no cost: numba unboxes a named tuple argument about twice as
    slowly as a plain one (some 4 us a call for these four, measured).

    Parameters
    ----------
    model : tuple  A structures.arrays.ColumnArrays (step.inputs.prepare_kernel).
    motion : tuple  A step.inputs.Excitation: the ground motion.
    solver : tuple  A step.inputs.SolverSettings: method, tolerances, budgets, deadline.
    task : tuple  A step.inputs.RunTask: initial state, early stop, samples (in place).

    Returns
    -------
    RunEnd  (numerics.loop; azimuth nan and swept empty). friction: the largest |T_i / N_i|
        of each interface [-] (its peak), at rest (inputs.ground.rest_demand, exact) and at
        step ends in motion (the held demand's samples between them, on the step's
        interpolant, go to task.held only, changed in place: pieces.held_push); slip: where
        the peak first exceeded task.friction_limit, (t [s], interface from 1), (nan, 0) if
        not: at rest the exceedance time itself (inputs.ground.next_uplift at the limit), in
        motion the end of the first step whose demand exceeds it. ledger: the energy account
        of a recorded run without a vertical record [J] (zeros otherwise): the energy at the
        start and at the end (pieces.energy), the ground's work, the energy the joints'
        damping and the impacts took. Their balance: end - start = work - damping - impacts,
        to the integration's accuracy (the work and the damping are integrated over each
        step's dense output by Gauss-Legendre quadrature, the impacts counted exactly at
        each one).
    """
    model, motion = ColumnArrays(*model), Excitation(*motion)
    solver, task = SolverSettings(*solver), RunTask(*task)
    n = task.theta0.size
    vert = motion.vertical.size > 0  # a vertical record: kinks that move with it (step.vertical)
    W = plane_record(model, motion, task, n, vert)
    # the system's arrays: As[:, n:2n] the joints' stiffness, As[:, 2n:] their damping
    # (step.events.system), cs the rows' offsets, es the model's
    system = (np.empty((n, 3 * n if model.damped else 2 * n)), np.empty(n), model.es)
    account = task.record and not vert
    y, at_rest = start(task.theta0, task.rate0, W, account)
    last_forced = -1  # the last segment with forcing (solver.stop: outcome stops after it)
    for seg in range(motion.bounds.size - 1):
        if motion.forced[seg]:
            last_forced = seg
    outcome_bound = model.survival == model.survival and not vert  # a barrier that applies
    stops = (task.early_stop, last_forced, outcome_bound, n == 1)
    loop_into(W, y, system)
    return run_plane(W, motion, solver, n, at_rest, stops, account)


# ---- the planar column's part of the run loop (numerics.loop.run_motion): its
# run record (W: step.work.PLANE)


@jit
def enter_segment(W, free_seg):
    """Nothing to set at a segment's start."""
    return


@jit
def rest_to_end(W, t, t_end, mc, n_out, next_out):
    """At rest from t to t_end [s]: its samples; ends SURVIVED."""
    if W.record:
        n_out, next_out = emit_rest(t_end, W.samples, n_out, next_out, W.output_dt)
    return SURVIVED, n_out, next_out


@jit
def rest(W, t, seg_end, gr_full, mc, n_out, next_out):
    """A rigid monolith at rest in a forced segment (rest_until)."""
    return rest_until(t, seg_end, min(W.pulse_end, W.t_end), W.uplift_level,
                      W.amplitude, gr_full, W.knots, W.values, W.vertical,
                      W.friction, W.held, W.rx, W.ry, W.slip, W.mu, W.record, W.samples,
                      n_out, next_out, W.output_dt, W.y, W.side,
                      W.k)  # fmt: skip


@jit
def restart(W, t, seg_end, seg_gain, h_carry, gr, mc, rtol, atol):
    """A new stepper from (t, W.y): the system of the current pieces (step.events.system), the
    watched rows' bounds (and their moving parts), the rows and their distances at t, the
    first step's size (h_carry, the one proposed before an event, or numerics.rk's
    initial_step). Returns the step size [s], the right-hand side's calls and the ground."""
    vert = W.vert
    n = W.y.size // 2
    system(W.side, W.k, W.intercepts, W.slopes, W.slope_parts, vert, W.md,
           W.mg, W.argmap, W.damp, W.sys_A, W.sys_c)  # fmt: skip
    bound_rows(W.side, W.k, W.pending, W.rigid, W.edges, W.nedges, W.tu,
               W.c_ratio, W.lo, W.hi, W.h0)  # fmt: skip
    if vert:
        moving_rows(W.side, W.k, W.pending, W.rigid, W.edges, W.nedges,
                    W.edge_w, W.tu, W.h0, W.mv_e, W.mv_w)  # fmt: skip
    t_bound = seg_end
    if W.clipped:
        gr, t_bound = record_piece(t, W.knots, W.values, W.vertical, seg_gain,
                                   seg_end)  # fmt: skip
    rhs(t, W.y, n, W.sys_A, W.sys_c, W.sys_e, gr, W.f)
    if h_carry > 0.0:
        h_abs, calls = min(h_carry, seg_end - t), 1
    else:
        h_abs = initial_step(
            t, W.y, W.f, t_bound, TAB_EST[mc], rtol, atol, n, W.sys_A, W.sys_c, W.sys_e, gr, W.work
        )
        calls = 2
    affine(W.track, W.y, 0, W.no_offset, W.z_old)
    affine(W.track, W.y, n, W.no_offset, W.dz_old)
    acc_of(t, W.y, n, W.sys_A, W.sys_c, W.sys_e, gr, W.acc)
    surfaces(W.gx, W.gc, W.same, W.spans, W.y, W.acc, W.h0, W.d_old, W.dd_old, W.d2_old, t, gr,
             W.mv_e, W.mv_w)  # fmt: skip
    return h_abs, calls, gr


@jit
def ground_piece(W, t, seg_gain, seg_end):
    """A record's straight piece from t and the time a step ends at (record_piece)."""
    return record_piece(t, W.knots, W.values, W.vertical, seg_gain, seg_end)


@jit
def find_event(W, mc, t_old, t_new, h, gr):
    """The first watched row's crossing in the step [t_old, t_new] (step.events): theta''
    and the rows at the step's end, then, where a crossing may lie within reach, the step's
    dense output prepared and the crossing found on it. Returns (t_e, the row crossed or -1,
    the dense output ready, right-hand side calls)."""
    n = W.y.size // 2
    copy_into(W.acc_old, W.acc)
    W.ends[0], W.ends[1] = acc_of(t_new, W.y_new, n, W.sys_A, W.sys_c, W.sys_e, gr, W.acc)
    surfaces(W.gx, W.gc, W.same, W.spans, W.y_new, W.acc, W.h0, W.d_new, W.dd_new, W.d2_new,
             t_new, gr, W.mv_e, W.mv_w)  # fmt: skip
    if not within_reach(W.d_old, W.d_new, W.dd_old, W.dd_new, W.d2_old, W.d2_new, t_new - t_old,
                        W.near):  # fmt: skip
        return t_new, -1, False, 0
    calls = dense_prepare(
        mc, t_old, h, W.y, W.y_new, W.K, W.F, W.tmp, n, W.sys_A, W.sys_c, W.sys_e, gr
    )
    t_e, row = first_crossing(mc, t_old, t_new, W.y, W.F, W.gx, W.gc, W.same, W.spans, W.h0, n,
                              W.Dq, W.Rq, W.dc0, W.dc1, W.rc0, W.rc1, W.near, W.CP, W.BP, W.CR,
                              W.BR, gr, W.mv_e, W.mv_w)  # fmt: skip
    return t_e, row, True, calls


@jit
def step_figures(W, mc, t_old, t_new, h, gr, event, dense_ready, account, n_out, next_out):
    """The figures of the step [t_old, t_new] (cut at an event): samples, the energy account,
    silent impacts, the peaks of the tracked rows (at the root of a rate inside the step, on
    the dense output), the friction demand at the step's end and the held demand's samples
    inside it. Returns (right-hand side calls, n_out, next_out, impacts counted)."""
    n = W.y.size // 2
    calls, impacts = 0, 0
    if event:
        g_new, gam_new = acc_of(t_new, W.y_new, n, W.sys_A, W.sys_c, W.sys_e, gr, W.acc)
        if W.record:
            n_out, next_out = emit(mc, t_new, t_old, h, W.y, W.F, W.samples, n_out, next_out,
                                   W.output_dt)  # fmt: skip
    else:
        g_new, gam_new = W.ends[0], W.ends[1]
        if W.record:
            if not dense_ready:
                calls += dense_prepare(
                    mc, t_old, h, W.y, W.y_new, W.K, W.F, W.tmp, n, W.sys_A, W.sys_c, W.sys_e, gr
                )
                dense_ready = True
            n_out, next_out = emit(mc, t_new, t_old, h, W.y, W.F, W.samples, n_out, next_out,
                                   W.output_dt)  # fmt: skip
    if account:  # the step's dense output is ready (recorded runs always are)
        account_step(mc, t_old, t_new, h, W.y, W.F, gr, W.ground_load, W.argmap,
                     W.damp, W.k, W.yq, W.ledger)  # fmt: skip
        W.ledger[1] = energy(W.y_new[:n], W.y_new[n:], W.mass, W.argmap, W.gravity,
                           W.edges, W.nedges, W.intercepts, W.slopes)  # fmt: skip
    if W.any_silent:
        impacts += settle(W.awaiting, W.argmap, W.y_new, W.side)
    # peaks and friction demand over [t_old, t_new]
    affine(W.track, W.y_new, 0, W.no_offset, W.z_new)
    affine(W.track, W.y_new, n, W.no_offset, W.dz_new)
    # peaks inside the step: at the root of the rate, on the dense output
    m = W.side.size  # the joints: the tracked rows are their collapse ratios, then the top
    for r in range(m + 1):
        v = max(abs(W.z_old[r]), abs(W.z_new[r]))
        # a turn inside the step that may beat the running maximum: the step's cubic
        # Hermite exceeds its end values by at most 4/27 h (|rate0| + |rate1|); the margin
        # used is 1/2 (the dense output is of higher order than the Hermite)
        reach = v + 0.5 * (t_new - t_old) * (abs(W.dz_old[r]) + abs(W.dz_new[r]))
        if W.dz_old[r] * W.dz_new[r] < 0.0 and reach > W.peaks[r]:
            if not dense_ready:
                calls += dense_prepare(
                    mc, t_old, h, W.y, W.y_new, W.K, W.F, W.tmp, n, W.sys_A, W.sys_c, W.sys_e, gr
                )
                dense_ready = True
            base = row_poly(mc, W.F, W.y, W.track, r, W.zero_t, n, True, W.coef)
            t_pk = brentq(mc, t_old, t_new, t_old, h, W.coef, base, (0.0, 1.0, gr))
            base = row_poly(mc, W.F, W.y, W.track, r, W.zero_t, n, False, W.coef)
            v = max(v, abs(poly_val(mc, t_pk, t_old, h, W.coef, base)))
        if v > W.peaks[r]:
            W.peaks[r] = v
    for i in range(m):
        if W.peaks[i] > W.max_ratio[i]:
            W.max_ratio[i] = W.peaks[i]
    if W.peaks[m] > W.top[0]:
        W.top[0] = W.peaks[m]
    shear_ratios(g_new, 0.0, gam_new, W.centre_map, W.acc, W.no_offset, W.masses,
                 W.normal_forces, W.rx, W.ry, W.friction)  # fmt: skip
    if W.slip[1] == 0.0:
        first_over(W.friction, W.mu, t_new, W.slip)
    # the held demand's samples in (t_old, t_new]: theta'' on the step's quintic
    while held_time(W.held) <= t_new:
        t_k = held_time(W.held)
        h_k = t_new - t_old
        for j in range(n):
            W.acc_k[j] = W.acc[j] if h_k <= 0.0 else hermite_accel(
                (t_k - t_old) / h_k, h_k, W.y[j], W.y[n + j], W.acc_old[j], W.y_new[j],
                W.y_new[n + j], W.acc[j])  # fmt: skip
        shear_ratios(ground(t_k, gr), 0.0, gravity_factor(t_k, gr), W.centre_map, W.acc_k,
                     W.no_offset, W.masses, W.normal_forces, W.rx, W.ry,
                     W.between)  # fmt: skip
        held_push(W.held, W.rx, W.ry, W.between)
    # the step's end is the next step's start
    copy_into(W.z_prev, W.z_old)
    copy_into(W.z_old, W.z_new)
    copy_into(W.dz_prev, W.dz_old)
    copy_into(W.dz_old, W.dz_new)
    copy_into(W.d_old, W.d_new)
    copy_into(W.dd_old, W.dd_new)
    copy_into(W.d2_old, W.d2_new)
    return calls, n_out, next_out, impacts


@jit
def may_stop(W, can_stop, sure_stop):
    """Free motion below a barrier: a column's survival certain (sure_stop: solver.stop:
    outcome), or a monolith past a peak (can_stop; every figure final)."""
    n = W.y.size // 2
    peak = can_stop and W.z_prev[0] * W.dz_prev[0] > 0 >= W.z_old[0] * W.dz_old[0]
    return (sure_stop or peak) and below_barrier(
        W.y[:n], W.y[n:], W.mass, W.argmap, W.gravity, W.edges, W.nedges,
        W.intercepts, W.slopes, W.survival if sure_stop else W.barrier)  # fmt: skip


@jit
def at_event(W, row, t, gr, account):
    """The state change at the crossing of a watched row at (t, W.y): a collapse (its row's
    family 2: the column's collapse rows), else a joint's kink, uplift or impact (switch).
    Returns (GOING or COLLAPSED, uplifts, impacts, at rest, the collapsed interface from 1
    (-1: none), nan)."""
    n = W.y.size // 2
    m = W.side.size  # the joints: the rows are 4 of theirs
    i = row % m
    if row // m >= 2:
        if W.c_ratio > W.max_ratio[i]:
            W.max_ratio[i] = W.c_ratio
        return COLLAPSED, 0, 0, False, i + 1, np.nan
    going_up = row // m == 1
    bound = bound_now(i, going_up, m, W.lo, W.hi, W.tu, t, gr, W.mv_e, W.mv_w) if W.vert else (
        W.hi[i] if going_up else W.lo[i])  # fmt: skip
    what = switch(W, i, going_up, bound, W.y, W.side, W.k, W.pending, W.awaiting, W.rigid_mono)
    if account:
        after = energy(W.y[:n], W.y[n:], W.mass, W.argmap, W.gravity, W.edges,
                       W.nedges, W.intercepts, W.slopes)  # fmt: skip
        if what >= IMPACT:
            W.ledger[4] += W.ledger[1] - after
        W.ledger[1] = after
    if what == UPLIFT:
        return GOING, 1, 0, False, -1, np.nan
    if what >= IMPACT:
        return GOING, 0, 1, what == REST, -1, np.nan
    return GOING, 0, 0, False, -1, np.nan


#: The planar column's run loop (numerics.loop.run_motion with the functions above).
run_plane = loop_for("plane", globals())
