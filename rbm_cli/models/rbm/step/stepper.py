"""The compiled stepper of the Rigid Beam Model (numba): one call runs a whole motion
(the algorithm: rbm_cli.models.rbm.step), from four typed records (step.inputs)."""

from __future__ import annotations

import numpy as np

from rbm_cli.base.detmath import matvec
from rbm_cli.base.guard import POLL_STEPS
from rbm_cli.base.jit import jit
from rbm_cli.config.types import G
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
    surfaces,
    system,
    within_reach,
)
from rbm_cli.models.rbm.step.inputs import Excitation, RunTask, SolverSettings
from rbm_cli.models.rbm.step.rk import (
    NS_MAX,
    STEP_TAKEN,
    STEP_TOO_SMALL,
    TAB_EST,
    TAB_NS,
    acc_of,
    attempt_step,
    dense_eval,
    dense_prepare,
    emit,
    emit_rest,
    initial_step,
    rhs,
)
from rbm_cli.models.rbm.step.state import REST, switch
from rbm_cli.models.rbm.step.vertical import bound_now, moving_rows
from rbm_cli.models.status import (
    COLLAPSED,
    FAILED_EVENTS,
    FAILED_NONFINITE,
    FAILED_STEP,
    FAILED_STEPS,
    GOING,
    STOP_NEVER,
    STOP_OUTCOME,
    STOPPED_EARLY,
    SURVIVED,
    guard_code,
)
from rbm_cli.physics.arrays import ColumnArrays
from rbm_cli.physics.ground import (
    gravity_factor,
    ground,
    ground_at,
    next_uplift,
    record_piece,
    rest_demand,
    rest_shear,
)

#: Gauss-Legendre nodes on [0, 1] and weights (5 points: exact for polynomials of degree 9).
GL_NODES = np.array([0.04691007703066802, 0.23076534494715845, 0.5, 0.7692346550528415,
                     0.9530899229693319])  # fmt: skip
GL_WEIGHTS = np.array([0.11846344252809454, 0.23931433524968324, 0.28444444444444444,
                       0.23931433524968324, 0.11846344252809454])  # fmt: skip


@jit
def account_step(mc, t_old, t_new, h, y_old, F, gr, ground_load, argmap, damp, k, yq, ledger):
    """Add one step's work of the ground and the energy its damping took to ledger[2] and
    ledger[3] [J]: over [t_old, t_new] on the step's dense output (F, from y_old; its
    interpolant over h), the powers -a_g r . theta' (r the ground load) and
    sum_i c_i x_i'^2 (the joints on their elastic piece, k_i = 0) by Gauss-Legendre."""
    n = damp.size
    dt = t_new - t_old
    for q in range(GL_NODES.size):
        tq = t_old + GL_NODES[q] * dt
        dense_eval(mc, tq, t_old, h, y_old, F, yq)
        ag = ground(tq, gr)
        p_in = 0.0
        for j in range(n):
            p_in -= ag * ground_load[j] * yq[n + j]
        p_d = 0.0
        for i in range(n):
            if damp[i] != 0.0 and k[i] == 0:
                xd = 0.0
                for j in range(n):
                    xd += argmap[i, j] * yq[n + j]
                p_d += damp[i] * xd * xd
        ledger[2] += GL_WEIGHTS[q] * dt * p_in
        ledger[3] += GL_WEIGHTS[q] * dt * p_d


@jit
def run_kernel(model, motion, solver, task):
    """Run one motion of one model.

    The four records come as plain tuples (their fields in order: tuple(record)) and
    are named here, at no cost: numba unboxes a named tuple argument about twice as
    slowly as a plain one (some 4 us a call for these four, measured).

    Parameters
    ----------
    model : tuple  A physics.arrays.ColumnArrays (step.inputs.prepare_kernel).
    motion : tuple  A step.inputs.Excitation: the ground motion.
    solver : tuple  A step.inputs.SolverSettings: method, tolerances, budgets, deadline.
    task : tuple  A step.inputs.RunTask: initial state, early stop, samples (in place).

    Returns
    -------
    tuple  (status code (rbm_cli.models.status), t_end [s], t_collapse [s], collapsed interface,
        max_ratio (n,), max_top, friction (n,), slip (2,), n_uplifts, n_impacts, n_steps,
        n_rhs, n_events, n_samples, ledger). friction: the largest |T_i / N_i| of each
        interface [-] (its peak), at rest (physics.ground.rest_demand, exact) and at step
        ends in motion (the held demand's samples between them, on the step's interpolant,
        go to task.held only, changed in place: pieces.held_push); slip: where the peak
        first exceeded task.friction_limit, (t [s], interface from 1),
        (nan, 0) if not: at rest the exceedance time itself (physics.ground.next_uplift at the
        limit), in motion the end of the first step whose demand exceeds it. ledger: the
        energy account of a recorded run without a vertical record [J] (zeros otherwise): the
        energy at the start and at the end (pieces.energy), the ground's work, the energy the
        joints' damping and the impacts took. Their balance: end - start = work - damping -
        impacts, to the integration's accuracy (the work and the damping are integrated over
        each step's dense output by Gauss-Legendre quadrature, the impacts counted exactly at
        each one).
    """
    model, motion = ColumnArrays(*model), Excitation(*motion)
    solver, task = SolverSettings(*solver), RunTask(*task)
    mass, argmap, gravity = model.mass, model.argmap, model.gravity
    edges, nedges, intercepts, slopes = model.edges, model.nedges, model.intercepts, model.slopes
    parts, edge_w = model.slope_parts, model.edge_w
    damp, ground_load = model.damp, model.ground_load
    rigid, silent, tu, c_ratio = model.rigid, model.silent, model.tu, model.c_ratio
    centre_map, masses, normal_forces = model.centre_map, model.masses, model.normal_forces
    uplift_level, barrier, survival = model.uplift_level, model.barrier, model.survival
    amplitude, pulse_end, t_end = motion.amplitude, motion.pulse_end, motion.t_end
    knots, values, vertical, clipped = motion.knots, motion.values, motion.vertical, motion.clipped
    bounds, forced = motion.bounds, motion.forced
    # the ground (rbm_cli.physics.ground): of the motion, and nothing (a free segment); a record
    # one straight piece a step (record_piece)
    gr_full = (motion.form, motion.gain, motion.omega, motion.phase, motion.center,
               motion.gamma, 0.0, 0.0, 0.0)  # fmt: skip
    gr_free = (motion.form, 0.0, motion.omega, motion.phase, motion.center, motion.gamma,
               0.0, 0.0, 0.0)  # fmt: skip
    mc, rtol, atol, deadline = solver.mc, solver.rtol, solver.atol, solver.deadline
    max_steps, max_events = solver.max_steps, solver.max_events
    theta0, rate0, early_stop = task.theta0, task.rate0, task.early_stop
    record, output_dt, samples = task.record, task.output_dt, task.samples
    mu = task.friction_limit
    held = task.held

    n = theta0.size
    n_out = 0
    next_out = 0.0
    m = 2 * n
    max_ratio = np.zeros(n)
    friction = np.zeros(n)
    slip = np.array([np.nan, 0.0])
    max_top = 0.0
    n_upl, n_imp, n_steps, n_rhs, n_ev = 0, 0, 0, 0, 0
    status = SURVIVED
    t_col, c_if = np.nan, -1

    side = np.ones(n, dtype=np.int64)
    k = np.zeros(n, dtype=np.int64)
    pending = np.zeros(n, dtype=np.bool_)
    # silent impacts (Model.silent_impacts): counted at step ends, not stopped at
    any_silent = silent.any()
    awaiting = np.zeros(n, dtype=np.bool_)
    lo, hi = np.empty(n), np.empty(n)
    nt = n + 1
    gx, gc, same = model.gx, model.gc, model.same
    md, mg, track, es = model.md, model.mg, model.track, model.es
    peaks = np.zeros(nt)
    # As[:, n:2n]: the joints' stiffness, As[:, 2n:]: their damping (step.events.system)
    As, cs = np.empty((n, 3 * n if model.damped else 2 * n)), np.empty(n)
    vert = vertical.size > 0  # a vertical record: kinks that move with it (step.vertical)
    # the energy account of a recorded run (see Returns): start, end, work, damping, impacts
    account = record and not vert
    ledger = np.zeros(5)
    yq = np.empty(2 * n)
    mv_e, mv_w = np.zeros(2 * n if vert else 0), np.ones(2 * n if vert else 0)
    h0 = np.empty(4 * n)
    K = np.empty((NS_MAX, m))
    F = np.empty((8, m))
    f = np.empty(m)
    ynew = np.empty(m)
    tmp = np.empty(m)
    work = np.empty(m)
    scale = np.empty(m)
    nrow = 4 * n
    d_old, d_new = np.empty(nrow), np.empty(nrow)
    dd_old, dd_new = np.empty(nrow), np.empty(nrow)
    d2_old, d2_new = np.empty(nrow), np.empty(nrow)
    Dq, Rq = np.empty((nrow, CHECK_INTERVALS + 1)), np.empty((nrow, CHECK_INTERVALS + 1))
    dc0, dc1, rc0, rc1 = np.empty(nrow), np.empty(nrow), np.empty(nrow), np.empty(nrow)
    near = np.zeros(nrow, dtype=np.bool_)
    CP, CR = np.empty((nrow, 7)), np.empty((nrow, 7))
    BP, BR = np.empty(nrow), np.empty(nrow)
    coef = np.empty(7)
    zero_t = np.zeros(nt)
    z_old, z_new, z_prev = np.empty(nt), np.empty(nt), np.empty(nt)
    dz_old, dz_new, dz_prev = np.empty(nt), np.empty(nt), np.empty(nt)
    acc = np.empty(n)
    acc_old, acc_k = np.empty(n), np.empty(n)  # theta'' at a step's start, at a sample
    rx, ry = np.zeros(n), np.zeros(n)  # the shear ratios at a sample of the held demand
    between = np.zeros(n)  # their peak between step ends (interpolated: not the run's peak)
    no_offset = np.empty(0)
    y_new = np.empty(m)
    est_order = TAB_EST[mc]
    err_exp = -1.0 / (est_order + 1)
    ns = TAB_NS[mc]

    t = 0.0
    y = np.empty(m)
    y[:n] = theta0
    y[n:] = rate0
    rigid_mono = uplift_level >= 0.0
    at_rest = rigid_mono
    for i in range(m):
        if y[i] != 0.0:
            at_rest = False
    x0 = matvec(argmap, y[:n], np.empty(n))
    r0 = matvec(argmap, y[n:], np.empty(n))
    locate(x0, r0, side, k, pending, rigid, edges, nedges)
    if account:
        ledger[0] = energy(y[:n], y[n:], mass, argmap, gravity, edges, nedges, intercepts,
                           slopes)  # fmt: skip
        ledger[1] = ledger[0]

    last_forced = -1  # the last segment with forcing (solver.stop: outcome stops after it)
    for seg in range(bounds.size - 1):
        if forced[seg]:
            last_forced = seg
    outcome_bound = survival == survival and not vert  # a survival barrier that applies
    for seg in range(bounds.size - 1):
        seg_end = bounds[seg + 1]
        if t >= seg_end:
            continue
        free_seg = not forced[seg]
        gr = gr_free if free_seg else gr_full
        seg_gain = gr[1]
        can_stop = early_stop != STOP_NEVER and free_seg and motion.pulse and n == 1
        # solver.stop: outcome: free motion from here to the end, below the survival barrier
        sure_stop = early_stop == STOP_OUTCOME and seg > last_forced and outcome_bound
        h_carry = -1.0  # the step size proposed before an event, carried over it
        while t < seg_end:
            if at_rest:
                if free_seg:
                    if record:
                        n_out, next_out = emit_rest(t_end, samples, n_out, next_out, output_dt)
                    return (status, t_end, t_col, c_if, max_ratio, max_top, friction, slip,
                            n_upl, n_imp, n_steps, n_rhs, n_ev, n_out, ledger)  # fmt: skip
                last = min(pulse_end, t_end)
                t_up = next_uplift(t, uplift_level, amplitude, gr_full, knots, values, vertical,
                                    last)  # fmt: skip
                t_rest = seg_end if t_up < 0.0 or t_up >= seg_end else t_up
                d_rest = rest_demand(t, t_rest, gr_full, knots, values, vertical)
                if d_rest > friction[0]:
                    friction[0] = d_rest
                while held_time(held) <= t_rest:
                    rx[0] = rest_shear(held_time(held), gr_full, knots, values, vertical)
                    held_push(held, rx, ry, friction)
                if slip[1] == 0.0 and d_rest > mu:
                    slip[0] = next_uplift(t, mu * G, amplitude, gr_full, knots, values,
                                          vertical, t_rest)  # fmt: skip
                    slip[1] = 1.0
                if t_up < 0.0 or t_up >= seg_end:
                    if record:
                        n_out, next_out = emit_rest(seg_end, samples, n_out, next_out, output_dt)
                    t = seg_end
                    break
                if record:
                    n_out, next_out = emit_rest(t_up - 1e-15, samples, n_out, next_out, output_dt)
                t = t_up
                for i in range(m):
                    y[i] = 0.0
                side[0] = -1 if ground_at(t, gr_full, knots, values) > 0.0 else 1
                k[0] = 0
                at_rest = False
                n_upl += 1
                h_carry = -1.0

            system(side, k, intercepts, slopes, parts, vert, md, mg, argmap, damp, As, cs)
            bound_rows(side, k, pending, rigid, edges, nedges, tu, c_ratio, lo, hi, h0)
            if vert:
                moving_rows(side, k, pending, rigid, edges, nedges, edge_w, tu, h0, mv_e, mv_w)

            # a new stepper from (t, y)
            t_bound = seg_end
            if clipped:
                gr, t_bound = record_piece(t, knots, values, vertical, seg_gain, seg_end)
            rhs(t, y, n, As, cs, es, gr, f)
            if h_carry > 0.0:
                h_abs = min(h_carry, seg_end - t)
                n_rhs += 1
            else:
                h_abs = initial_step(t, y, f, t_bound, est_order, rtol, atol, n, As, cs, es,
                                      gr, work)  # fmt: skip
                n_rhs += 2
            affine(track, y, 0, no_offset, z_old)
            affine(track, y, n, no_offset, dz_old)
            acc_of(t, y, n, As, cs, es, gr, acc)
            surfaces(gx, gc, same, y, acc, h0, d_old, dd_old, d2_old, t, gr, mv_e, mv_w)
            event = False
            running = True
            while running:
                # ---- one accepted step (scipy RungeKutta._step_impl)
                bound = seg_end  # a record's steps end at its samples (python.Stepper's)
                if clipped:
                    gr, bound = record_piece(t, knots, values, vertical, seg_gain, seg_end)
                taken, t_new, h, h_abs, calls = attempt_step(
                    mc, t, y, f, h_abs, bound, K, ynew, tmp, n, As, cs, es, gr, atol, rtol,
                    scale, err_exp)  # fmt: skip
                n_rhs += calls
                if taken != STEP_TAKEN:
                    code = FAILED_STEP if taken == STEP_TOO_SMALL else FAILED_NONFINITE
                    return (code, t, t_col, c_if, max_ratio, max_top, friction, slip, n_upl,
                            n_imp, n_steps, n_rhs, n_ev, n_out, ledger)  # fmt: skip
                n_steps += 1
                if n_steps > max_steps:
                    return (FAILED_STEPS, t, t_col, c_if, max_ratio, max_top, friction, slip,
                            n_upl, n_imp, n_steps, n_rhs, n_ev, n_out, ledger)  # fmt: skip
                if n_steps % POLL_STEPS == 0:  # the wall-clock budget and Ctrl-C
                    code = guard_code(deadline)
                    if code != GOING:
                        return (code, t, t_col, c_if, max_ratio, max_top, friction, slip,
                                n_upl, n_imp, n_steps, n_rhs, n_ev, n_out, ledger)  # fmt: skip
                if t_new - seg_end >= 0:
                    running = False
                t_old = t
                y_old = y
                y_new[:] = ynew
                dense_ready = False
                acc_old[:] = acc
                g_new, gam_new = acc_of(t_new, y_new, n, As, cs, es, gr, acc)
                surfaces(gx, gc, same, y_new, acc, h0, d_new, dd_new, d2_new, t_new, gr, mv_e,
                          mv_w)  # fmt: skip
                event_row = -1
                t_e = t_new
                if within_reach(d_old, d_new, dd_old, dd_new, d2_old, d2_new, t_new - t_old, near):
                    n_rhs += dense_prepare(mc, t_old, h, y_old, y_new, K, F, tmp, n, As,
                                            cs, es, gr)  # fmt: skip
                    dense_ready = True
                    t_e, event_row = first_crossing(mc, t_old, t_new, y_old, F, gx, gc, same,
                                                     h0, n, Dq, Rq, dc0, dc1, rc0, rc1, near,
                                                     CP, BP, CR, BR, gr, mv_e, mv_w)  # fmt: skip
                if event_row >= 0:
                    dense_eval(mc, t_e, t_old, h, y_old, F, y_new)
                    t_new = t_e
                    event = True
                    g_new, gam_new = acc_of(t_new, y_new, n, As, cs, es, gr, acc)
                    if record:
                        n_out, next_out = emit(mc, t_e, t_old, h, y_old, F, samples, n_out,
                                                next_out, output_dt)  # fmt: skip
                elif record:
                    if not dense_ready:
                        n_rhs += dense_prepare(mc, t_old, h, y_old, y_new, K, F, tmp, n, As,
                                                cs, es, gr)  # fmt: skip
                        dense_ready = True
                    n_out, next_out = emit(mc, t_new, t_old, h, y_old, F, samples, n_out,
                                            next_out, output_dt)  # fmt: skip
                if account:  # the step's dense output is ready (recorded runs always are)
                    account_step(mc, t_old, t_new, h, y_old, F, gr, ground_load, argmap, damp,
                                 k, yq, ledger)  # fmt: skip
                    ledger[1] = energy(y_new[:n], y_new[n:], mass, argmap, gravity, edges,
                                       nedges, intercepts, slopes)  # fmt: skip
                if any_silent:
                    n_imp += settle(awaiting, argmap, y_new, side)
                # peaks and friction demand over [t_old, t_new]
                affine(track, y_new, 0, no_offset, z_new)
                affine(track, y_new, n, no_offset, dz_new)
                # peaks inside the step: at the root of the rate, on the dense output
                for r in range(nt):
                    v = max(abs(z_old[r]), abs(z_new[r]))
                    # a turn inside the step that may beat the running maximum: the
                    # step's cubic Hermite exceeds its end values by at most
                    # 4/27 h (|rate0| + |rate1|); the margin used is 1/2 (the dense
                    # output is of higher order than the Hermite)
                    reach = v + 0.5 * (t_new - t_old) * (abs(dz_old[r]) + abs(dz_new[r]))
                    if dz_old[r] * dz_new[r] < 0.0 and reach > peaks[r]:
                        if not dense_ready:
                            n_rhs += dense_prepare(mc, t_old, h, y_old, ynew, K, F, tmp, n,
                                                    As, cs, es, gr)  # fmt: skip
                            dense_ready = True
                        base = row_poly(mc, F, y_old, track, r, zero_t, n, True, coef)
                        t_pk = brentq(mc, t_old, t_new, t_old, h, coef, base, (0.0, 1.0, gr))
                        base = row_poly(mc, F, y_old, track, r, zero_t, n, False, coef)
                        v = max(v, abs(poly_val(mc, t_pk, t_old, h, coef, base)))
                    if v > peaks[r]:
                        peaks[r] = v
                for i in range(n):
                    if peaks[i] > max_ratio[i]:
                        max_ratio[i] = peaks[i]
                if peaks[n] > max_top:
                    max_top = peaks[n]
                shear_ratios(g_new, 0.0, gam_new, centre_map, acc, no_offset, masses,
                             normal_forces, rx, ry, friction)  # fmt: skip
                if slip[1] == 0.0:
                    first_over(friction, mu, t_new, slip)
                # the held demand's samples in (t_old, t_new]: theta'' on the step's quintic
                while held_time(held) <= t_new:
                    t_k = held_time(held)
                    h_k = t_new - t_old
                    for j in range(n):
                        acc_k[j] = acc[j] if h_k <= 0.0 else hermite_accel(
                            (t_k - t_old) / h_k, h_k, y_old[j], y_old[n + j], acc_old[j],
                            y_new[j], y_new[n + j], acc[j])  # fmt: skip
                    shear_ratios(ground(t_k, gr), 0.0, gravity_factor(t_k, gr), centre_map,
                                 acc_k, no_offset, masses, normal_forces, rx, ry,
                                 between)  # fmt: skip
                    held_push(held, rx, ry, between)
                z_prev, z_old, z_new = z_old, z_new, z_prev
                dz_prev, dz_old, dz_new = dz_old, dz_new, dz_prev
                d_old, d_new = d_new, d_old
                dd_old, dd_new = dd_new, dd_old
                d2_old, d2_new = d2_new, d2_old
                t = t_new
                y, y_new = y_new, y
                f[:] = K[ns]
                if event:
                    break
                # free motion below a barrier: a column's survival certain (solver.stop:
                # outcome), or a monolith past a peak (every figure final)
                peak = can_stop and z_prev[0] * dz_prev[0] > 0 >= z_old[0] * dz_old[0]
                if (sure_stop or peak) and below_barrier(
                        y[:n], y[n:], mass, argmap, gravity, edges, nedges, intercepts, slopes,
                        survival if sure_stop else barrier):  # fmt: skip
                    return (STOPPED_EARLY, t, t_col, c_if, max_ratio, max_top, friction, slip,
                            n_upl, n_imp, n_steps, n_rhs, n_ev, n_out, ledger)  # fmt: skip
            if not event:
                t = seg_end if not running else t
                continue

            # ---- the event at (t, y)
            h_carry = h_abs
            n_ev += 1
            if n_ev > max_events:
                return (FAILED_EVENTS, t, t_col, c_if, max_ratio, max_top, friction, slip,
                        n_upl, n_imp, n_steps, n_rhs, n_ev, n_out, ledger)  # fmt: skip
            which, i = event_row // n, event_row % n
            if which >= 2:
                t_col, c_if = t, i + 1
                if c_ratio > max_ratio[i]:
                    max_ratio[i] = c_ratio
                return (COLLAPSED, t, t_col, c_if, max_ratio, max_top, friction, slip,
                        n_upl, n_imp, n_steps, n_rhs, n_ev, n_out, ledger)  # fmt: skip
            going_up = which == 1
            bound = bound_now(i, going_up, n, lo, hi, tu, t, gr, mv_e, mv_w) if vert else (
                hi[i] if going_up else lo[i])  # fmt: skip
            what = switch(model, i, going_up, bound, y, side, k, pending, awaiting, rigid_mono)
            if account:
                after = energy(y[:n], y[n:], mass, argmap, gravity, edges, nedges, intercepts,
                               slopes)  # fmt: skip
                if what >= IMPACT:
                    ledger[4] += ledger[1] - after
                ledger[1] = after
            if what == UPLIFT:
                n_upl += 1
            elif what >= IMPACT:
                n_imp += 1
                at_rest = what == REST
    return (status, t, t_col, c_if, max_ratio, max_top, friction, slip,
            n_upl, n_imp, n_steps, n_rhs, n_ev, n_out, ledger)  # fmt: skip
