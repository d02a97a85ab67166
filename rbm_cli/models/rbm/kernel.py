"""Compiled event-driven integrator of the Rigid Beam Model (numba).

The same algorithm as rbm_cli.models.rbm.python (which stays as the readable Python
reference and serves time histories): an explicit Runge-Kutta pair (scipy's
DOP853, RK45 or RK23 tableaux and step-size control, transcribed), stopped
exactly at every event (kink of a law, impact, collapse) by Brent's method
on the step's dense output. The whole run, piece changes, impacts, rest
phases of rigid blocks and the early stop of free motion included, runs in
one compiled call: no Python per step or per event.

The step sequence follows scipy's (same initial step, same error norm, same
controller; after an event both restart with the step size proposed before
it), so for non-chaotic runs the kernel reproduces the Python path to
round-off; the tests compare the two. Zero crossings that change nothing
(e = 1, a law linear through zero) are counted at step ends, not stopped at,
in both (events.Pieces.silent).
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
from numba import njit

from rbm_cli.base.detmath import matmul, matvec, pow_pos
from rbm_cli.models.rbm.kernel_events import (
    CHECK_INTERVALS,
    _affine,
    _bounds,
    _brentq,
    _emit,
    _emit_rest,
    _energy1,
    _event_rows,
    _first_crossing,
    _n_below,
    _next_exceedance,
    _poly_val,
    _row_poly,
    _system,
    _within_reach,
)
from rbm_cli.models.rbm.kernel_guard import GO_ON, PAST_DEADLINE, POLL_STEPS, arm, disarm, poll
from rbm_cli.models.rbm.kernel_rk import (
    _MAX_FACTOR,
    _MIN_FACTOR,
    _NS_MAX,
    _SAFETY,
    COLLAPSED,
    FAILED_EVENTS,
    FAILED_NONFINITE,
    FAILED_STEP,
    FAILED_STEPS,
    FAILED_WALL,
    INTERRUPTED,
    METHOD_CODES,
    STOPPED_EARLY,
    SURVIVED,
    TAB_EST,
    TAB_NS,
    _dense_eval,
    _dense_prepare,
    _error_norm,
    _ground,
    _initial_step,
    _rhs,
    _rk_attempt,
)
from rbm_cli.models.rbm.python import BIG, EVENT_EPS, REST_RATE, Outcome
from rbm_cli.physics.equations import Model
from rbm_cli.physics.excitation import GroundMotion


# ---------------------------------------------------------------- the run
@njit(cache=True)
def run_kernel(
    mc, rtol, atol, max_steps, max_events,
    mass, minv, diff, argmap, arg_inv, gravity, ground_load,
    edges, nedges, intercepts, slopes, rigid, silent,
    tu, cmap, top, c_ratio, e_rest, literal_impact, impulse_dir, impulse_w,
    centre_map, masses, normal_forces,
    kind, amplitude, omega, phase, pulse_end, t_end,
    uplift_level, rest_rate, barrier, early_stop, theta0, rate0, record, output_dt, samples,
    deadline,
):  # fmt: skip
    n = theta0.size
    n_out = 0
    next_out = 0.0
    m = 2 * n
    max_ratio = np.zeros(n)
    friction = np.zeros(n)
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
    G = np.empty((4 * n, n))
    for i in range(n):
        for j in range(n):
            G[i, j] = argmap[i, j] / tu[i]
            G[n + i, j] = -argmap[i, j] / tu[i]
            G[2 * n + i, j] = -cmap[i, j]
            G[3 * n + i, j] = cmap[i, j]
    gx, gc = G[:n], G[3 * n :]
    same = True
    for i in range(n):
        for j in range(n):
            same = same and gx[i, j] == gc[i, j]
    md = matmul(minv, diff.T.copy())
    mg = matmul(minv, gravity)
    nt = n + 1
    track = np.empty((nt, n))
    track[:n, :] = cmap
    track[n, :] = top
    es = -matvec(minv, ground_load, np.empty(n))
    peaks = np.zeros(nt)
    As, cs = np.empty((n, n)), np.empty(n)
    h0 = np.empty(4 * n)
    K = np.empty((_NS_MAX, m))
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
    no_offset = np.empty(0)
    y_new = np.empty(m)
    est_order = TAB_EST[mc]
    err_exp = -1.0 / (est_order + 1)
    ns = TAB_NS[mc]
    stage_rhs = ns  # rhs calls per attempt (stages 1..ns-1 and f_new)

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
    for i in range(n):
        s = 1 if x0[i] > 0 else (-1 if x0[i] < 0 else (1 if r0[i] >= 0 else -1))
        side[i] = s
        k[i] = _n_below(edges[i], nedges[i], abs(x0[i]))
        pending[i] = k[i] > 0 and not rigid[i]

    n_seg = 2 if (kind == 1 and pulse_end < t_end) else 1
    for seg in range(n_seg):
        seg_start = 0.0 if seg == 0 else pulse_end
        seg_end = t_end if (seg == n_seg - 1) else pulse_end
        if t >= seg_end:
            continue
        free_seg = amplitude == 0.0 or (kind == 1 and seg_start >= pulse_end)
        amp = 0.0 if free_seg else amplitude
        can_stop = early_stop and free_seg and kind == 1 and n == 1
        h_carry = -1.0  # the step size proposed before an event, carried over it
        while t < seg_end:
            if at_rest:
                if free_seg:
                    if record:
                        n_out, next_out = _emit_rest(t_end, samples, n_out, next_out, output_dt)
                    return (status, t_end, t_col, c_if, max_ratio, max_top, friction,
                            n_upl, n_imp, n_steps, n_rhs, n_ev, n_out)  # fmt: skip
                last = min(pulse_end, t_end)
                t_up = _next_exceedance(t, uplift_level, amplitude, omega, phase, last)
                if t_up < 0.0 or t_up >= seg_end:
                    if record:
                        n_out, next_out = _emit_rest(seg_end, samples, n_out, next_out, output_dt)
                    t = seg_end
                    break
                if record:
                    n_out, next_out = _emit_rest(t_up - 1e-15, samples, n_out, next_out, output_dt)
                t = t_up
                for i in range(m):
                    y[i] = 0.0
                side[0] = -1 if _ground(t, amplitude, omega, phase) > 0.0 else 1
                k[0] = 0
                at_rest = False
                n_upl += 1
                h_carry = -1.0

            _system(side, k, intercepts, slopes, md, mg, argmap, As, cs)
            for i in range(n):
                _bounds(i, side, k, pending, rigid, edges, nedges, lo, hi)
                h0[i] = min(-lo[i] / tu[i], BIG) + EVENT_EPS
                h0[n + i] = min(hi[i] / tu[i], BIG) + EVENT_EPS
                h0[2 * n + i] = c_ratio + EVENT_EPS
                h0[3 * n + i] = c_ratio + EVENT_EPS

            # a new stepper from (t, y)
            _rhs(t, y, n, As, cs, es, amp, omega, phase, f)
            if h_carry > 0.0:
                h_abs = min(h_carry, seg_end - t)
                n_rhs += 1
            else:
                h_abs = _initial_step(t, y, f, seg_end, est_order, rtol, atol, n, As, cs, es,
                                      amp, omega, phase, work)  # fmt: skip
                n_rhs += 2
            _affine(track, y, 0, no_offset, z_old)
            _affine(track, y, n, no_offset, dz_old)
            _event_rows(gx, gc, same, y, 0, h0, True, d_old)
            _event_rows(gx, gc, same, y, n, h0, False, dd_old)
            g0 = _ground(t, amp, omega, phase)
            _affine(As, y, 0, cs, acc)
            for i in range(n):
                acc[i] += es[i] * g0
            _event_rows(gx, gc, same, acc, 0, h0, False, d2_old)
            event = False
            running = True
            while running:
                # ---- one accepted step (scipy RungeKutta._step_impl)
                min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
                if h_abs < min_step:
                    h_abs = min_step
                rejected = False
                while True:
                    if not (h_abs >= min_step):  # also a NaN step or time: no endless loop
                        t_fail = t
                        return (FAILED_STEP, t_fail, t_col, c_if, max_ratio, max_top, friction,
                                n_upl, n_imp, n_steps, n_rhs, n_ev, n_out)  # fmt: skip
                    t_new = t + h_abs
                    if t_new - seg_end > 0:
                        t_new = seg_end
                    h = t_new - t
                    h_abs = abs(h)
                    _rk_attempt(mc, t, y, f, h, K, ynew, tmp, n, As, cs, es, amp, omega, phase)
                    n_rhs += stage_rhs
                    err = _error_norm(mc, K, h, y, ynew, atol, rtol, scale)
                    if not (err == err and abs(err) < math.inf):  # NaN or inf state
                        return (FAILED_NONFINITE, t, t_col, c_if, max_ratio, max_top, friction,
                                n_upl, n_imp, n_steps, n_rhs, n_ev, n_out)  # fmt: skip
                    if err < 1.0:
                        if err == 0.0:
                            factor = _MAX_FACTOR
                        else:
                            factor = min(_MAX_FACTOR, _SAFETY * pow_pos(err, err_exp))
                        if rejected:
                            factor = min(1.0, factor)
                        h_abs *= factor
                        break
                    h_abs *= max(_MIN_FACTOR, _SAFETY * pow_pos(err, err_exp))
                    rejected = True
                n_steps += 1
                if n_steps > max_steps:
                    return (FAILED_STEPS, t, t_col, c_if, max_ratio, max_top, friction,
                            n_upl, n_imp, n_steps, n_rhs, n_ev, n_out)  # fmt: skip
                if n_steps % POLL_STEPS == 0:  # the wall-clock budget and Ctrl-C
                    guard = poll(deadline)
                    if guard != GO_ON:
                        code = FAILED_WALL if guard == PAST_DEADLINE else INTERRUPTED
                        return (code, t, t_col, c_if, max_ratio, max_top, friction,
                                n_upl, n_imp, n_steps, n_rhs, n_ev, n_out)  # fmt: skip
                if t_new - seg_end >= 0:
                    running = False
                t_old = t
                y_old = y
                y_new[:] = ynew
                _event_rows(gx, gc, same, y_new, 0, h0, True, d_new)
                _event_rows(gx, gc, same, y_new, n, h0, False, dd_new)
                dense_ready = False
                g_new = _ground(t_new, amp, omega, phase)
                _affine(As, y_new, 0, cs, acc)
                for i in range(n):
                    acc[i] += es[i] * g_new
                _event_rows(gx, gc, same, acc, 0, h0, False, d2_new)
                event_row = -1
                t_e = t_new
                if _within_reach(d_old, d_new, dd_old, dd_new, d2_old, d2_new, t_new - t_old, near):
                    n_rhs += _dense_prepare(mc, t_old, h, y_old, y_new, K, F, tmp, n, As,
                                            cs, es, amp, omega, phase)  # fmt: skip
                    dense_ready = True
                    t_e, event_row = _first_crossing(mc, t_old, t_new, y_old, F, G, h0, n, Dq,
                                                     Rq, dc0, dc1, rc0, rc1, near, CP, BP, CR,
                                                     BR)  # fmt: skip
                if event_row >= 0:
                    _dense_eval(mc, t_e, t_old, h, y_old, F, y_new)
                    t_new = t_e
                    event = True
                    g_new = _ground(t_new, amp, omega, phase)
                    _affine(As, y_new, 0, cs, acc)
                    for i in range(n):
                        acc[i] += es[i] * g_new
                    if record:
                        n_out, next_out = _emit(mc, t_e, t_old, h, y_old, F, samples, n_out,
                                                next_out, output_dt)  # fmt: skip
                elif record:
                    if not dense_ready:
                        n_rhs += _dense_prepare(mc, t_old, h, y_old, y_new, K, F, tmp, n, As,
                                                cs, es, amp, omega, phase)  # fmt: skip
                        dense_ready = True
                    n_out, next_out = _emit(mc, t_new, t_old, h, y_old, F, samples, n_out,
                                            next_out, output_dt)  # fmt: skip
                if any_silent:
                    for i in range(n):
                        if awaiting[i]:
                            x_i = 0.0
                            for j in range(n):
                                x_i += argmap[i, j] * y_new[j]
                            if side[i] * x_i < 0.0:
                                side[i] = -side[i]
                                awaiting[i] = False
                                n_imp += 1
                # peaks and friction demand over [t_old, t_new]
                _affine(track, y_new, 0, no_offset, z_new)
                _affine(track, y_new, n, no_offset, dz_new)
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
                            n_rhs += _dense_prepare(mc, t_old, h, y_old, ynew, K, F, tmp, n,
                                                    As, cs, es, amp, omega, phase)  # fmt: skip
                            dense_ready = True
                        base = _row_poly(mc, F, y_old, track, r, zero_t, n, True, coef)
                        t_pk = _brentq(mc, t_old, t_new, t_old, h, coef, base)
                        base = _row_poly(mc, F, y_old, track, r, zero_t, n, False, coef)
                        v = max(v, abs(_poly_val(mc, t_pk, t_old, h, coef, base)))
                    if v > peaks[r]:
                        peaks[r] = v
                for i in range(n):
                    if peaks[i] > max_ratio[i]:
                        max_ratio[i] = peaks[i]
                if peaks[n] > max_top:
                    max_top = peaks[n]
                shear = 0.0
                for i in range(n - 1, -1, -1):
                    a_abs = g_new
                    for j in range(n):
                        a_abs += centre_map[i, j] * acc[j]
                    shear += a_abs * masses[i]
                    fr = abs(shear) / normal_forces[i]
                    if fr > friction[i]:
                        friction[i] = fr
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
                if can_stop and z_prev[0] * dz_prev[0] > 0 >= z_old[0] * dz_old[0]:
                    en = _energy1(y[:n], y[n:], mass, argmap, gravity, edges, nedges,
                                  intercepts, slopes)  # fmt: skip
                    if en < barrier * (1.0 - 1e-9):
                        return (STOPPED_EARLY, t, t_col, c_if, max_ratio, max_top, friction,
                                n_upl, n_imp, n_steps, n_rhs, n_ev, n_out)  # fmt: skip
            if not event:
                t = seg_end if not running else t
                continue

            # ---- the event at (t, y)
            h_carry = h_abs
            n_ev += 1
            if n_ev > max_events:
                return (FAILED_EVENTS, t, t_col, c_if, max_ratio, max_top, friction,
                        n_upl, n_imp, n_steps, n_rhs, n_ev, n_out)  # fmt: skip
            which, i = event_row // n, event_row % n
            if which >= 2:
                t_col, c_if = t, i + 1
                if c_ratio > max_ratio[i]:
                    max_ratio[i] = c_ratio
                return (COLLAPSED, t, t_col, c_if, max_ratio, max_top, friction,
                        n_upl, n_imp, n_steps, n_rhs, n_ev, n_out)  # fmt: skip
            going_up = which == 1
            bound = hi[i] if going_up else lo[i]
            x_i = 0.0
            for j in range(n):
                x_i += argmap[i, j] * y[j]
            for j in range(n):
                y[j] += arg_inv[j, i] * (bound - x_i)
            s, ki = side[i], k[i]
            outward = going_up == (s > 0)
            if ki == 0 and not (rigid[i] or pending[i]):
                side[i] = 1 if going_up else -1
                k[i] = 1
                pending[i] = True
                awaiting[i] = False
                n_upl += 1
            elif outward:
                k[i] = ki + 1
            elif ki > 0:
                k[i] = ki - 1
                if ki == 1 and silent[i]:
                    pending[i] = False
                    awaiting[i] = True
            else:
                n_imp += 1
                side[i] = -s
                pending[i] = False
                if e_rest < 1.0:
                    xdot = 0.0
                    for j in range(n):
                        xdot += argmap[i, j] * y[n + j]
                    if literal_impact:
                        for j in range(n):
                            y[n + j] += arg_inv[j, i] * (e_rest - 1.0) * xdot
                    else:
                        lam = (e_rest - 1.0) * xdot / impulse_w[i]
                        for j in range(n):
                            y[n + j] += impulse_dir[j, i] * lam
                if rigid_mono and abs(y[n]) < rest_rate:
                    for j in range(m):
                        y[j] = 0.0
                    at_rest = True
    return (status, t, t_col, c_if, max_ratio, max_top, friction,
            n_upl, n_imp, n_steps, n_rhs, n_ev, n_out)  # fmt: skip


# ---------------------------------------------------------------- Python side
def _pad_laws(model: Model):
    n = model.n
    ne = max(len(law.edges) for law in model.laws)
    edges = np.full((n, max(ne, 1)), np.inf)
    inter = np.zeros((n, ne + 1))
    slopes = np.zeros((n, ne + 1))
    nedges = np.zeros(n, dtype=np.int64)
    for i, law in enumerate(model.laws):
        m = len(law.edges)
        edges[i, :m] = law.edges
        inter[i, : m + 1] = law.intercepts
        slopes[i, : m + 1] = law.slopes
        nedges[i] = m
    rigid = np.array([law.rigid for law in model.laws], dtype=np.bool_)
    return edges, nedges, inter, slopes, rigid


def model_arrays(model: Model) -> tuple:
    """The model's arrays in the kernel's argument order (assembled once per column)."""
    col = model.column
    tu = col.rotation_capacity.astype(float)
    argmap = model.arg_map.astype(float)
    impulse_dir, impulse_w = model.impulse_directions
    edges, nedges, inter, slopes, rigid = _pad_laws(model)
    return (
        model.mass, model.mass_inv, model.diff.astype(float), argmap,
        model.arg_inverse, model.gravity, model.ground_load,
        edges, nedges, inter, slopes, rigid, model.silent_impacts,
        tu, model.collapse_map / model.collapse_limit[:, None], col.heights.astype(float),
        float(model.collapse_ratio), float(model.restitution), model.formulation == "absolute",
        impulse_dir, impulse_w, model.centre_map, col.masses.astype(float),
        col.normal_forces.astype(float),
    )  # fmt: skip


def _prepare(model: Model) -> tuple:
    """Everything of a model the kernel needs, once per model: its arrays, the
    scale of atol (theta_u for rotations, 10 theta_u for rates), the uplift
    level of a rigid monolith (-1: none), the rest rate and the energy barrier
    of the early stop (NaN unless n = 1); as rbm_cli.models.rbm.python computes them."""
    n = model.n
    tu = float(model.column.rotation_capacity.min())
    atol_scale = np.concatenate([np.full(n, tu), np.full(n, 10.0 * tu)])
    uplift = model.uplift_level
    barrier = math.nan
    if n == 1:
        theta_c = model.collapse_ratio * model.column.rotation_capacity
        barrier = float(model.energy(theta_c, np.zeros(1))[0])
    rest_rate = REST_RATE * model.rocking_p * tu
    return model_arrays(model), atol_scale, -1.0 if uplift is None else uplift, rest_rate, barrier


_KIND = {"harmonic": 0, "half-sine": 1, "free": 2}
#: The last model run and what _prepare made of it (a sweep runs one model many times).
_LAST: tuple = (None, ())


def integrate_compiled(
    model: Model,
    motion: GroundMotion,
    theta0: np.ndarray,
    rate0: np.ndarray,
    solver,
    record: bool = False,
    output_dt: float = 0.002,
    early_stop: bool = True,
) -> Outcome:
    """rbm_cli.models.rbm.python.integrate, compiled (same arguments and Outcome)."""
    n = model.n
    global _LAST
    last = _LAST  # one read: threads (Dask in-process, joblib threading) may swap it
    if last[0] is not model:
        last = (model, _prepare(model))
        _LAST = last
    arrays, atol_scale, uplift, rest_rate, barrier = last[1]
    n_max = int(math.floor(motion.t_end / output_dt + 1e-9)) + 2 if record else 0
    samples = np.zeros((n_max, 1 + 2 * n))
    deadline = time.monotonic() + float(solver.max_wall_time)
    armed = arm()  # Ctrl-C reaches the kernel through poll (kernel_guard)
    try:
        res = run_kernel(
            METHOD_CODES[solver.method], float(solver.rtol), solver.atol * atol_scale,
            int(solver.max_steps), int(solver.max_events), *arrays,
            _KIND[motion.kind], float(motion.amplitude), float(motion.omega), float(motion.phase),
            float(motion.pulse_end), float(motion.t_end), uplift, rest_rate, barrier,
            bool(early_stop), np.asarray(theta0, dtype=float), np.asarray(rate0, dtype=float),
            bool(record), float(output_dt), samples, deadline,
        )  # fmt: skip
    finally:
        disarm(armed)
    (code, t_end, t_col, c_if, max_ratio, max_top, friction,
     n_upl, n_imp, n_steps, n_rhs, n_ev, n_out) = res  # fmt: skip
    out = Outcome(
        t_end=float(t_end), max_ratio=max_ratio, max_top=float(max_top), friction=friction,
        n_uplifts=int(n_upl), n_impacts=int(n_imp), n_steps=int(n_steps), n_rhs=int(n_rhs),
        n_events=int(n_ev),
    )  # fmt: skip
    if record:
        out.samples = [
            (float(r[0]), r[1 : 1 + n].copy(), r[1 + n :].copy()) for r in samples[:n_out]
        ]
    if code == COLLAPSED:
        out.status = "collapsed"
        out.t_collapse = float(t_col)
        out.collapse_interface = int(c_if)
        out.message = f"interface {int(c_if)} reached its collapse limit"
    elif code == STOPPED_EARLY:
        out.message = "free motion below the collapse barrier: stopped early"
    elif code == FAILED_STEP:
        out.stop("failed", "integrator: Required step size is less than spacing between "
                 "numbers.", t_end)  # fmt: skip
    elif code == FAILED_STEPS:
        out.stop("failed", f"step budget exceeded ({solver.max_steps} steps)", t_end)
    elif code == FAILED_EVENTS:
        out.stop("failed", f"event budget exceeded ({solver.max_events} events)", t_end)
    elif code == FAILED_WALL:
        out.stop("failed", f"wall-clock budget exceeded ({solver.max_wall_time:g} s, "
                 "solver.max_wall_time)", t_end)  # fmt: skip
    elif code == FAILED_NONFINITE:
        out.stop("failed", "the state became NaN or infinite (non-finite arithmetic)", t_end)
    elif code == INTERRUPTED:  # pragma: no cover - disarm() raises first
        raise KeyboardInterrupt
    return out


def needs_compile() -> bool:
    """Whether the kernel has no on-disk cache yet: its first use then compiles it
    (about 15-20 s, once per installation). False if that cannot be told."""
    try:
        return not any(Path(run_kernel._cache.cache_path).glob("kernel.run_kernel-*.nbi"))
    except Exception:  # a numba without this attribute: no notice, nothing else changes
        return False


def warm_up() -> None:
    """Compile (or load from the cache) the kernel once, e.g. in a worker."""
    from rbm_cli.config.types import ColumnConfig, InterfaceConfig, SolverConfig
    from rbm_cli.physics.column import build_column
    from rbm_cli.physics.equations import build_model

    geometry = ColumnConfig(height=2.0, base_width=0.5, top_width=0.5, drum_heights=(2.0,))
    col = build_column(geometry, InterfaceConfig())
    model = build_model(col)
    motion = GroundMotion("harmonic", 5.0, 6.0, 0.0, 0.1, 0.1)
    integrate_compiled(model, motion, np.zeros(1), np.zeros(1), SolverConfig())
    poll(math.inf)  # its object-mode block loads on first use (~30 ms): not in a timed run


__all__ = ["integrate_compiled", "model_arrays", "needs_compile", "warm_up"]
