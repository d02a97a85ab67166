"""Runge-Kutta pairs as data and their steps, for the compiled engine: scipy's DOP853, RK45
and RK23 tableaux, initial step, error norm, step-size control and dense output,
transcribed so that a run's step sequence is the one scipy's steppers would take.

Model-agnostic: the steps that call a right-hand side (initial_step, rk_attempt,
attempt_step, dense_prepare) are templates; a structure gets its own compiled copies, whose
``rhs(t, y, n, As, cs, es, gr, out)`` is its own (:func:`steps_for`)."""

from __future__ import annotations

import math

import numpy as np

import rbm_cli.base.rk_tableaux as _tb
from rbm_cli.base.copies import copy_into
from rbm_cli.base.detmath import pow_pos
from rbm_cli.base.jit import jit
from rbm_cli.numerics.binding import bind

#: method name -> code in the kernel
METHOD_CODES = {"RK23": 0, "RK45": 1, "DOP853": 2}

# ---- Butcher tableaux (scipy's, written out in rbm_cli.base.rk_tableaux), padded to one shape:
# (A, B, C, E, P, n_stages, est_order)
NS_MAX = _tb.DOP853_N_STAGES_EXTENDED


def _fill(out: np.ndarray, rows) -> np.ndarray:
    """out with each row (or entry) of rows at its start, the rest left as it was (zeros)."""
    if out.ndim == 1:
        out[: len(rows)] = rows
        return out
    for i, row in enumerate(rows):
        out[i, : len(row)] = row
    return out


def _tableau(method: str):
    A = np.zeros((NS_MAX, NS_MAX))
    C = np.zeros(NS_MAX)
    B = np.zeros(NS_MAX)
    E = np.zeros(NS_MAX)
    E3 = np.zeros(NS_MAX)
    P = np.zeros((NS_MAX, 8))
    if method == "DOP853":
        _fill(A, _tb.DOP853_A)
        _fill(C, _tb.DOP853_C)
        _fill(B, _tb.DOP853_B)
        _fill(E, _tb.DOP853_E5)
        _fill(E3, _tb.DOP853_E3)
        # dense output: D (4 x 16) stored transposed in P[:, :4]
        D = _fill(np.zeros((4, NS_MAX)), _tb.DOP853_D)
        P[:, :4] = D.T
        return A, B, C, E, E3, P, _tb.DOP853_N_STAGES, 7
    name = "RK45" if method == "RK45" else "RK23"
    _fill(A, getattr(_tb, f"{name}_A"))
    _fill(C, getattr(_tb, f"{name}_C"))
    _fill(B, getattr(_tb, f"{name}_B"))
    _fill(E, getattr(_tb, f"{name}_E"))
    _fill(P, getattr(_tb, f"{name}_P"))
    return (
        A,
        B,
        C,
        E,
        E3,
        P,
        getattr(_tb, f"{name}_N_STAGES"),
        getattr(_tb, f"{name}_ERROR_ESTIMATOR_ORDER"),
    )


_TAB = [_tableau(m) for m in ("RK23", "RK45", "DOP853")]
TAB_A = np.stack([t[0] for t in _TAB])
TAB_B = np.stack([t[1] for t in _TAB])
TAB_C = np.stack([t[2] for t in _TAB])
TAB_E = np.stack([t[3] for t in _TAB])
TAB_E3 = np.stack([t[4] for t in _TAB])
TAB_P = np.stack([t[5] for t in _TAB])
TAB_NS = np.array([t[6] for t in _TAB], dtype=np.int64)
TAB_EST = np.array([t[7] for t in _TAB], dtype=np.int64)
TAB_NP = np.array([3, 4, 7], dtype=np.int64)  # interpolant order of RK23 / RK45 / DOP853

#: Step-size control (scipy's): the safety factor and the least and greatest change of h.
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0


# ---------------------------------------------------------------- small pieces
@jit
def _rms(v):
    s = 0.0
    for x in v:
        s += x * x
    return math.sqrt(s / v.size)


def initial_step(t0, y0, f0, t_bound, order, rtol, atol, n, As, cs, es, gr, work):
    """scipy.integrate._ivp.common.select_initial_step (max_step = inf)."""
    interval = abs(t_bound - t0)
    if interval == 0.0:
        return 0.0
    m = y0.size
    scale = atol + np.abs(y0) * rtol
    d0 = _rms(y0 / scale)
    d1 = _rms(f0 / scale)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, interval)
    y1 = np.empty(m)
    for i in range(m):
        y1[i] = y0[i] + h0 * f0[i]
    rhs(t0 + h0, y1, n, As, cs, es, gr, work)  # noqa: F821 (the structure's: steps_for)
    d2 = _rms((work - f0) / scale) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = pow_pos(0.01 / max(d1, d2), 1.0 / (order + 1))
    return min(100.0 * h0, h1, interval)


@jit(inline=True)
def _combine(w, K, count, y, h, out):
    """out[i] = y[i] + h sum_j w[j] K[j, i] over the first count stages (the sum in j's
    order)."""
    m = out.size
    m4 = m - m % 4
    for i in range(0, m4, 4):
        a0 = a1 = a2 = a3 = 0.0
        for j in range(count):
            c = w[j]
            a0 += c * K[j, i]
            a1 += c * K[j, i + 1]
            a2 += c * K[j, i + 2]
            a3 += c * K[j, i + 3]
        out[i], out[i + 1] = y[i] + h * a0, y[i + 1] + h * a1
        out[i + 2], out[i + 3] = y[i + 2] + h * a2, y[i + 3] + h * a3
    for i in range(m4, m):
        acc = 0.0
        for j in range(count):
            acc += w[j] * K[j, i]
        out[i] = y[i] + h * acc


def _stage(mc, s, t, y, h, K, tmp, n, As, cs, es, gr):
    """Stage s from the stages before it: K[s] = f(t + c_s h, y + h sum_j a_sj K_j).
    Inlined into the borrowed steps that call it (RHS_STEPS), as is the right-hand side:
    neither counts a reference to the arrays it takes (base.jit), 12 times a step."""
    A = TAB_A[mc]
    _combine(A[s], K, s, y, h, tmp)
    rhs(t + TAB_C[mc][s] * h, tmp, n, As, cs, es, gr, K[s])  # noqa: F821


def rk_attempt(mc, t, y, f, h, K, ynew, tmp, n, As, cs, es, gr):
    """One Runge-Kutta step of size h; stages in K (row ns = f(t + h, y_new))."""
    B = TAB_B[mc]
    ns = TAB_NS[mc]
    copy_into(K[0], f)
    for s in range(1, ns):
        _stage(mc, s, t, y, h, K, tmp, n, As, cs, es, gr)
    _combine(B, K, ns, y, h, ynew)
    rhs(t + h, ynew, n, As, cs, es, gr, K[ns])  # noqa: F821


@jit(borrow=True)
def error_norm(mc, K, h, y, ynew, atol, rtol, scale):
    ns = TAB_NS[mc]
    E = TAB_E[mc]
    m = scale.size
    for i in range(m):
        scale[i] = atol[i] + max(abs(y[i]), abs(ynew[i])) * rtol
    if mc == 2:
        E3 = TAB_E3[mc]
        e5, e3 = 0.0, 0.0
        for i in range(m):
            a5, a3 = 0.0, 0.0
            for j in range(ns + 1):
                a5 += E[j] * K[j, i]
                a3 += E3[j] * K[j, i]
            a5 /= scale[i]
            a3 /= scale[i]
            e5 += a5 * a5
            e3 += a3 * a3
        if e5 == 0.0 and e3 == 0.0:
            return 0.0
        return abs(h) * e5 / math.sqrt((e5 + 0.01 * e3) * m)
    s = 0.0
    for i in range(m):
        a = 0.0
        for j in range(ns + 1):
            a += E[j] * K[j, i]
        a = a * h / scale[i]
        s += a * a
    return math.sqrt(s / m)


#: How :func:`attempt_step` ends: a step taken, a step below the spacing of the numbers at
#: t, a state that became NaN or infinite.
STEP_TAKEN, STEP_TOO_SMALL, STEP_NONFINITE = 0, 1, 2


def attempt_step(mc, t, y, f, h_abs, bound, K, ynew, tmp, n, As, cs, es, gr, atol, rtol,
                 scale, err_exp):  # fmt: skip
    """One accepted step from (t, y) (scipy's RungeKutta._step_impl): a step of h_abs [s]
    (at least 10 ulp of t, cut at bound), shrunk until its error norm is below 1. The new
    state in ynew, the stages in K.

    Returns
    -------
    (code, t_new, h, h_abs, calls)  STEP_TAKEN (else the failure, at t), the step's end and
        size [s], the size proposed for the next step [s], and the right-hand side's calls.
    """
    min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
    if h_abs < min_step:
        h_abs = min_step
    calls = 0
    rejected = False
    while True:
        if not (h_abs >= min_step):  # also a NaN step or time: no endless loop
            return STEP_TOO_SMALL, t, 0.0, h_abs, calls
        t_new = t + h_abs
        if t_new - bound > 0:
            t_new = bound
        h = t_new - t
        h_abs = abs(h)
        rk_attempt(mc, t, y, f, h, K, ynew, tmp, n, As, cs, es, gr)
        calls += TAB_NS[mc]
        err = error_norm(mc, K, h, y, ynew, atol, rtol, scale)
        if not (err == err and abs(err) < math.inf):  # NaN or inf state
            return STEP_NONFINITE, t, h, h_abs, calls
        if err < 1.0:
            if err == 0.0:
                factor = MAX_FACTOR
            else:
                factor = min(MAX_FACTOR, SAFETY * pow_pos(err, err_exp))
            if rejected:
                factor = min(1.0, factor)
            return STEP_TAKEN, t_new, h, h_abs * factor, calls
        h_abs *= max(MIN_FACTOR, SAFETY * pow_pos(err, err_exp))
        rejected = True


def dense_prepare(mc, t_old, h, y_old, y_new, K, F, tmp, n, As, cs, es, gr):
    """Coefficients F of the step's interpolant (DOP853: extra stages)."""
    m = y_old.size
    ns = TAB_NS[mc]
    P = TAB_P[mc]
    if mc == 2:
        for s in range(ns + 1, NS_MAX):
            _stage(mc, s, t_old, y_old, h, K, tmp, n, As, cs, es, gr)
        for i in range(m):
            dy = y_new[i] - y_old[i]
            F[0, i] = dy
            F[1, i] = h * K[0, i] - dy
            F[2, i] = 2.0 * dy - h * (K[ns, i] + K[0, i])
            a0 = a1 = a2 = a3 = 0.0  # the four sums side by side (one per r)
            for j in range(NS_MAX):
                kj = K[j, i]
                a0 += P[j, 0] * kj
                a1 += P[j, 1] * kj
                a2 += P[j, 2] * kj
                a3 += P[j, 3] * kj
            F[3, i], F[4, i], F[5, i], F[6, i] = h * a0, h * a1, h * a2, h * a3
        return NS_MAX - ns - 1
    order = TAB_NP[mc]
    for i in range(m):
        for r in range(order):
            acc = 0.0
            for j in range(ns + 1):
                acc += K[j, i] * P[j, r]
            F[r, i] = h * acc
    return 0


@jit(borrow=True)
def dense_eval(mc, t, t_old, h, y_old, F, out):
    x = (t - t_old) / h
    m = y_old.size
    if mc == 2:
        for i in range(m):
            v = 0.0
            for k in range(7):
                v += F[6 - k, i]
                v *= x if k % 2 == 0 else 1.0 - x
            out[i] = v + y_old[i]
        return
    order = TAB_NP[mc]
    for i in range(m):
        v = 0.0
        p = 1.0
        for r in range(order):
            p *= x
            v += F[r, i] * p
        out[i] = y_old[i] + v


@jit
def emit_rest(t_stop, samples, n_out, next_out, dt):
    while next_out <= t_stop + 1e-12 and n_out < samples.shape[0]:
        samples[n_out, 0] = next_out
        samples[n_out, 1:] = 0.0
        n_out += 1
        next_out += dt
    return n_out, next_out


@jit(borrow=True)
def emit(mc, t_stop, t_old, h, y_old, F, samples, n_out, next_out, dt):
    while next_out <= t_stop + 1e-12 and n_out < samples.shape[0]:
        samples[n_out, 0] = next_out
        dense_eval(mc, next_out, t_old, h, y_old, F, samples[n_out, 1:])
        n_out += 1
        next_out += dt
    return n_out, next_out


#: The steps that call the right-hand side, with how each is compiled (base.jit.jit;
#: :func:`steps_for` copies them per structure): borrowed, the steps a run takes every step
#: (no reference counts, base.jit), with the stage inlined into them; the first step's size
#: (once a stepper) allocates and counts.
RHS_STEPS = {
    "initial_step": (initial_step, {}),
    "_stage": (_stage, {"inline": True}),
    "rk_attempt": (rk_attempt, {"borrow": True}),
    "attempt_step": (attempt_step, {"borrow": True}),
    "dense_prepare": (dense_prepare, {"borrow": True}),
}


def steps_for(name: str, rhs) -> tuple:
    """A structure's compiled steps on its right-hand side ``rhs(t, y, n, As, cs, es, gr,
    out)`` (a function compiled with base.jit.jit): (initial_step, attempt_step,
    dense_prepare), named ``<step>_<name>``."""
    steps = bind(RHS_STEPS, {"rhs": rhs}, name)
    return steps["initial_step"], steps["attempt_step"], steps["dense_prepare"]
