"""Event search for the compiled kernel (numba): the earliest crossing on the dense output
and cubic Hermite dips (as rbm_cli.base.events), the event distances of a state, and the
linear system and energy of the current law pieces (the pieces themselves:
rbm_cli.models.rbm.pieces); the moving kinks of a vertical record are step.vertical's (the
exact uplift time of a rigid block at rest is in inputs.ground, time-history sampling in
step.rk)."""

from __future__ import annotations

import math

import numpy as np

from rbm_cli.base.brent import brent_step
from rbm_cli.base.jit import jit
from rbm_cli.models.rbm.step.vertical import add_moving, moving_rate, moving_value
from rbm_cli.numerics.rk import TAB_NP


@jit(borrow=True)
def affine(event_rows, y, off, h0, out):
    """out = event_rows @ y[off:off + cols] (+ h0 if given): no allocation."""
    for r in range(event_rows.shape[0]):
        d = 0.0 if h0.size == 0 else h0[r]
        for j in range(event_rows.shape[1]):
            d += event_rows[r, j] * y[off + j]
        out[r] = d


@jit(borrow=True)
def row_poly(mc, F, y_old, event_rows, row, h0, n, rate, coef):
    """One row of the step's interpolant, projected: the distance event_rows[row] theta +
    h0[row] (or, rate, the rate event_rows[row] theta') as a polynomial in the step's
    fraction, with dense_eval's form. Fills coef, returns the constant term;
    poly_val evaluates it (a few flops instead of the whole state's interpolant)."""
    row_coef(mc, F, event_rows, row, 0, n, n, rate, coef)
    return row_base(y_old, event_rows, row, 1.0, 0.0 if rate else h0[row], 0, n, n, rate)


@jit(inline=True)
def row_coef(mc, F, rows, row, lo, hi, n, rate, coef):
    """The interpolant's coefficients of rows[row] theta (or theta', rate) into coef
    (row_poly without the constant term), over the row's columns lo..hi - 1 (the rest
    zeros: a sum from 0.0 is the same without them, to the bit)."""
    off = n if rate else 0
    for q in range(TAB_NP[mc]):
        v = 0.0
        for j in range(lo, hi):
            v += rows[row, j] * F[q, off + j]
        coef[q] = v


@jit(inline=True)
def row_base(y_old, rows, row, sign, start, lo, hi, n, rate):
    """The constant term of the row sign * rows[row] (row_poly): start (a distance's offset,
    0 for a rate) plus the row at the step's start, over its columns lo..hi - 1 (row_coef).
    sign is +-1: the negated row's terms are the same products, negated, added in the same
    order."""
    off = n if rate else 0
    base = start
    for j in range(lo, hi):
        base += (sign * rows[row, j]) * y_old[off + j]
    return base


@jit(inline=True)
def poly_part(mc, x, coef):
    """The interpolant's part beyond its constant term at the step's fraction x (poly_val
    is this plus the base). Of coefficients negated it is the value negated, to the bit:
    each operation is a sum or product, whose rounding is symmetric."""
    v = 0.0
    nq = TAB_NP[mc]
    if mc == 2:  # DOP853's nested form (dense_eval)
        for q in range(nq):
            v += coef[nq - 1 - q]
            v *= x if q % 2 == 0 else 1.0 - x
        return v
    p = 1.0
    for r in range(nq):
        p *= x
        v += coef[r] * p
    return v


@jit(borrow=True)
def poly_val(mc, t, t_old, h, coef, base):
    """A projected row (row_poly) at time t: dense_eval for one row."""
    return poly_part(mc, (t - t_old) / h, coef) + base


#: Tolerances of the root finding: scipy brentq's rtol (4 eps) and our xtol [s].
XTOL, RTOL, MAXITER = 1e-14, 8.881784197001252e-16, 100


@jit(inline=True)
def _row_val(mc, t, t_old, h, coef, base, mv):
    """A projected row at t, plus its moving part mv = (e, w, ground tuple) if e != 0
    (step.vertical: a kink moving with g + a_v(t))."""
    v = poly_val(mc, t, t_old, h, coef, base)
    if mv[0] != 0.0:
        v += moving_value(t, mv[2], mv[0], mv[1])
    return v


@jit(borrow=True)
def brentq(mc, xa, xb, t_old, h, coef, base, mv):
    """scipy's brentq (zeros.c) along a projected row of the step's interpolant (plus its
    moving part, _row_val)."""
    xpre, xcur = xa, xb
    xblk, fblk, spre, scur = 0.0, 0.0, 0.0, 0.0
    fpre = _row_val(mc, xpre, t_old, h, coef, base, mv)
    fcur = _row_val(mc, xcur, t_old, h, coef, base, mv)
    if fpre == 0.0:
        return xpre
    if fcur == 0.0:
        return xcur
    for _ in range(MAXITER):
        done, xpre, xcur, xblk, fpre, fblk, spre, scur = brent_step(
            xpre, xcur, xblk, fpre, fcur, fblk, spre, scur, XTOL, RTOL
        )
        if done:
            return xcur
        fcur = _row_val(mc, xcur, t_old, h, coef, base, mv)
    return xcur


@jit(inline=True)
def _quad_roots(qa, qb, qc):
    """Real roots of qa s^2 + qb s + qc (as np.roots: leading zeros dropped), a pair with
    nan for a root that is not."""
    if qa == 0.0:
        return (-qc / qb if qb != 0.0 else np.nan), np.nan
    disc = qb * qb - 4.0 * qa * qc
    if disc < 0.0:
        return np.nan, np.nan
    sq = math.sqrt(disc)
    q = -0.5 * (qb + sq if qb >= 0.0 else qb - sq)
    if q != 0.0:
        return q / qa, qc / q
    return 0.0, 0.0


@jit(borrow=True)
def _lowest_dip(d0, d1, r0, r1, dt):
    """events._lowest_dip: (time from the start, row) of the lowest interior minimum
    below zero of the cubic Hermite interpolants, or (-1, -1)."""
    best, t_best, row = 0.0, -1.0, -1
    for r in range(d0.size):
        if not (r0[r] < 0.0 and r1[r] > 0.0):
            continue
        p0, m0, p1, m1 = d0[r], dt * r0[r], d1[r], dt * r1[r]
        if min(p0, p1) > 0.5 * (abs(m0) + abs(m1)):
            continue
        a = 2 * p0 + m0 - 2 * p1 + m1
        b = -3 * p0 - 2 * m0 + 3 * p1 - m1
        if abs(a) + abs(b) == 0.0:
            continue
        roots = _quad_roots(3 * a, 2 * b, m0)
        for k in range(2):
            s = roots[k]
            if 0.0 < s < 1.0:
                val = ((a * s + b) * s + m0) * s + p0
                if val < best:
                    best, t_best, row = val, s * dt, r
    return t_best, row


@jit(inline=True)
def _mv(r, gr, mv_e, mv_w):
    """The moving part of row r as _row_val takes it ((0, 1, gr) for a fixed row)."""
    if r < mv_e.size:
        return (mv_e[r], mv_w[r], gr)
    return (0.0, 1.0, gr)


#: Sub-intervals of a step checked on the dense output (events.CHECK_INTERVALS).
CHECK_INTERVALS = 8


@jit(borrow=True)
def within_reach(d0, d1, r0, r1, a0, a1, dt, mask):
    """Whether an event distance may reach zero inside a step, judged from its values d,
    rates r and second derivatives a at both ends, with a wide margin; mask[r] marks the
    rows within reach (only they are searched in first_crossing).

    A row is within reach when min(d0, d1) <= dt (|r0| + |r1|) + dt^2 (|a0| + |a1|).
    The cubic Hermite of a step's end values moves at most 4/27 dt (|r0| + |r1|) below
    min(d0, d1), so the margin is several times that; it is not a proof (the interior of a
    long step is judged from its ends), which is why it is wide. Steps far from every
    surface (most of them) need no dense output."""
    anyrow = False
    for r in range(d0.size):
        reach = dt * (abs(r0[r]) + abs(r1[r])) + dt * dt * (abs(a0[r]) + abs(a1[r]))
        mask[r] = min(d0[r], d1[r]) <= reach
        anyrow = anyrow or mask[r]
    return anyrow


@jit(borrow=True)
def first_crossing(mc, t0, t1, y_old, F, gx, gc, same, spans, h0, n, D, R, dcol0, dcol1, rcol0,
                   rcol1, mask, CP, BP, CR, BR, gr, mv_e, mv_w):  # fmt: skip
    """events.first_crossing on the step's dense output, over the rows in `mask`:
    (t, row) of the earliest crossing of any event surface in [t0, t1], or (-1, -1).

    The 4m rows (m joints, n drums) are [gx; -gx; -gc; gc] theta + h0 (_event_rows), so
    their interpolants (polynomials in the step's fraction) are those of m rows (2m unless
    `same`), signed:
    each is projected once and evaluated once a check point (poly_part), each masked row
    adds its sign and its own constant term (CP, BP: its distance; CR, BR: its rate; the
    same numbers as row_poly's). Rows r < mv_e.size with mv_e[r] != 0 add their moving
    part (step.vertical) on the step's ground piece gr."""
    nseg = CHECK_INTERVALS
    h = t1 - t0
    m = gx.shape[0]  # the joints; n the drums
    nrow = 4 * m
    nq = TAB_NP[mc]
    for r in range(nrow):
        if not mask[r]:
            D[r, :], R[r, :] = np.inf, 0.0  # inert: never below zero, never turning
    for b in range(m if same else 2 * m):
        i = b % m
        rows = gx if b < m else gc
        lo, hi = (spans[0, i], spans[1, i]) if b < m else (spans[2, i], spans[3, i])
        # the rows built on rows[i], with their signs: the first is where its interpolant is
        # projected; the collapse pair too when same (-1: none)
        p = i if b < m else 3 * m + i
        signed = ((p, 1.0), (m + i if b < m else 2 * m + i, -1.0),
                  (3 * m + i if same else -1, 1.0), (2 * m + i if same else -1, -1.0))  # fmt: skip
        used = False
        for r, _ in signed:
            used = used or (r >= 0 and mask[r])
        if not used:
            continue
        row_coef(mc, F, rows, i, lo, hi, n, False, CP[p])
        row_coef(mc, F, rows, i, lo, hi, n, True, CR[p])
        for r, sign in signed:
            if r < 0 or not mask[r]:
                continue
            if r != p:
                for c in range(nq):
                    CP[r, c], CR[r, c] = sign * CP[p, c], sign * CR[p, c]
            BP[r] = row_base(y_old, rows, i, sign, h0[r], lo, hi, n, False)
            BR[r] = row_base(y_old, rows, i, sign, 0.0, lo, hi, n, True)
        for q in range(nseg + 1):
            tq = t0 + h * q / nseg if q < nseg else t1
            x = (tq - t0) / h
            vd, vr = poly_part(mc, x, CP[p]), poly_part(mc, x, CR[p])
            for r, sign in signed:
                if r < 0 or not mask[r]:
                    continue
                D[r, q] = sign * vd + BP[r]
                R[r, q] = sign * vr + BR[r]
                if r < mv_e.size and mv_e[r] != 0.0:
                    D[r, q] += moving_value(tq, gr, mv_e[r], mv_w[r])
                    R[r, q] += moving_rate(tq, gr, mv_e[r], mv_w[r])
    best, brow = np.inf, -1
    for r in range(nrow):
        if D[r, 0] < best:
            best, brow = D[r, 0], r
    if best <= 0.0:
        return t0, brow
    ds = h / nseg
    for q in range(nseg):
        a = t0 + h * q / nseg
        b = t0 + h * (q + 1) / nseg if q + 1 < nseg else t1
        look = False
        for r in range(nrow):
            if D[r, q + 1] < 0.0:
                look = True
            elif R[r, q] < 0.0 and R[r, q + 1] > 0.0:
                if min(D[r, q], D[r, q + 1]) <= 0.5 * ds * (abs(R[r, q]) + abs(R[r, q + 1])):
                    look = True
        if not look:
            continue
        t_first, r_first = np.inf, -1
        for r in range(nrow):
            dcol0[r], dcol1[r] = D[r, q], D[r, q + 1]
            rcol0[r], rcol1[r] = R[r, q], R[r, q + 1]
        for r in range(nrow):
            if D[r, q + 1] < 0.0:
                tr = brentq(mc, a, b, t0, h, CP[r], BP[r], _mv(r, gr, mv_e, mv_w))
                if tr < t_first:
                    t_first, r_first = tr, r
        s_dip, r_dip = _lowest_dip(dcol0, dcol1, rcol0, rcol1, b - a)
        if r_dip >= 0:
            mv = _mv(r_dip, gr, mv_e, mv_w)
            if _row_val(mc, a + s_dip, t0, h, CP[r_dip], BP[r_dip], mv) < 0.0:
                tr = brentq(mc, a, a + s_dip, t0, h, CP[r_dip], BP[r_dip], mv)
                if tr < t_first:
                    t_first, r_first = tr, r_dip
        if r_first >= 0:
            return t_first, r_first
    return -1.0, -1


# ---------------------------------------------------------------- the equations, the rows
@jit
def system(side, k, intercepts, slopes, parts, vert, md, mg, argmap, damp, As, cs):
    """(A, c) of theta'' = A theta + c + e a_g for the active pieces, in place into
    As[:, :n] and cs: A = M^-1 K_g - sum_i b_i (M^-1 D^T)[:, i] argmap[i, :],
    c = -(M^-1 D^T) a, with md = M^-1 D^T and mg = M^-1 K_g assembled once
    (Model.linear_system). With a vertical record (vert), b is the slopes' weight part
    parts[0] and As[:, n:2n] gets the elastic part parts[1] (Model.vertical_system):
    theta'' = gam (As[:, :n] theta + c) + As[:, n:2n] theta + e a_g. A damped column (As
    with 3n columns) gets -sum_i c_i (M^-1 D^T)[:, i] argmap[i, :] in As[:, 2n:], over the
    interfaces on their elastic piece (k_i = 0; Model.joint_damping c), read on the rates:
    theta'' += As[:, 2n:] theta'."""
    n = As.shape[0]  # the drums; side.size the joints
    damped = As.shape[1] > 2 * n
    for p in range(n):
        cs[p] = 0.0
        for q in range(n):
            As[p, q] = mg[p, q]
            As[p, n + q] = 0.0
            if damped:
                As[p, 2 * n + q] = 0.0
    # joint by joint, as the sums above say; within a joint, only the drums its argument
    # reads (argmap's nonzero columns, two in a column of drums): the work grows as the
    # drums squared, not cubed, and each entry takes the same terms in the same order
    for i in range(side.size):
        a = side[i] * intercepts[i, k[i]]
        b = parts[0, i, k[i]] if vert else slopes[i, k[i]]
        be = parts[1, i, k[i]] if vert else 0.0
        ci = damp[i] if damped and k[i] == 0 else 0.0
        for p in range(n):
            if md[p, i] != 0.0:
                cs[p] -= md[p, i] * a
        for q in range(n):
            g = argmap[i, q]
            if g == 0.0:
                continue
            for p in range(n):
                w = md[p, i]
                if w == 0.0:
                    continue
                As[p, q] -= w * b * g
                if be != 0.0:
                    As[p, n + q] -= w * be * g
                if ci != 0.0:
                    As[p, 2 * n + q] -= w * ci * g


@jit
def _event_rows(gx, gc, same, spans, v, off, h0, with_h0, out):
    """The event rows event_rows v[off:off + n] (+ h0) of the kernel (m joints, n drums),
    from their two distinct blocks: event_rows = [gx; -gx; -gc; gc] (gx = argmap / theta_u,
    gc the normalised collapse map; `same` when gc == gx, as for `relative`), each row
    over its nonzero columns (spans: row_spans)."""
    n = gx.shape[0]  # the joints (the rows' blocks); the drums: gx.shape[1]
    for i in range(n):
        a = 0.0
        for j in range(spans[0, i], spans[1, i]):
            a += gx[i, j] * v[off + j]
        c = a
        if not same:
            c = 0.0
            for j in range(spans[2, i], spans[3, i]):
                c += gc[i, j] * v[off + j]
        if with_h0:
            out[i], out[n + i] = a + h0[i], h0[n + i] - a
            out[2 * n + i], out[3 * n + i] = h0[2 * n + i] - c, c + h0[3 * n + i]
        else:
            out[i], out[n + i], out[2 * n + i], out[3 * n + i] = a, -a, -c, c


@jit(borrow=True)
def surfaces(gx, gc, same, spans, y, acc, h0, d, dd, d2, t, gr, mv_e, mv_w):
    """The event distances d, rates dd and second derivatives d2 at the state y (time t [s])
    with accelerations acc; with a vertical record (mv_e not empty) the moving kinks'
    parts added (step.vertical)."""
    n = gx.shape[1]  # the drums: the rates' offset in y
    _event_rows(gx, gc, same, spans, y, 0, h0, True, d)
    _event_rows(gx, gc, same, spans, y, n, h0, False, dd)
    _event_rows(gx, gc, same, spans, acc, 0, h0, False, d2)
    if mv_e.size > 0:
        add_moving(t, gr, mv_e, mv_w, d, dd, d2)


@jit
def row_spans(gx, gc, spans):
    """Each event row's nonzero columns, first and last + 1, into spans (4, m): gx's rows,
    then gc's (0, 0 for a row of zeros). A joint's argument reads the drums next to it
    (two columns of a column of drums), so the rows cost the same for any number of drums;
    the zeros left out change no sum (each starts from 0.0)."""
    for b in range(2):
        rows = gx if b == 0 else gc
        for i in range(rows.shape[0]):
            lo, hi = 0, 0
            for j in range(rows.shape[1]):
                if rows[i, j] != 0.0:
                    if hi == 0:
                        lo = j
                    hi = j + 1
            spans[2 * b, i], spans[2 * b + 1, i] = lo, hi
