"""Where the exact integrator samples a piece, and how it finds events and peaks that no
sampling can miss (numba).

An interval [a, b] of a piece is *certified* for an event row when a lower bound of the
row's distance over the whole interval is positive (rbm_cli.models.rbm.exact.bounds: a
slow part bounded by curvature, fast oscillations by their envelope):

    lower = max(min(s_a, s_b) - C h^2 / 8,                 (linear interpolation)
                min(s_a, s_a + s'_a h - C h^2 / 2),        (Taylor from a)
                min(s_b, s_b - s'_b h - C h^2 / 2)) - E    (Taylor from b)

with s the slow part, C the bound of its second derivative and E the envelope of the fast
modes (the same with every mode in C and E = 0 is also tried). No crossing can hide in a
certified interval. The integrator advances by certified intervals, doubling the interval
after a success and halving it after a failure; an interval where some rows end below zero
and every other row is certified holds the first event, provided each such row's distance
is monotone there (its rate cannot reach zero: d'_a + C_full h < 0 or d'_b + C_full h < 0,
so the root is unique), and a safeguarded Newton method finds it. Below MIN_STEP the
interval is taken as it is (a graze deeper than C MIN_STEP^2 cannot hide there).

Peaks of the tracked quantities (collapse ratios, top displacement) use the same bounds
from above: an interval whose upper bound of |z| does not exceed the running maximum is
done, and so is one where z' keeps its sign (a lower bound of +-z' from the ends' z', z''
and a bound of |z'''|): |z| peaks at an end. Otherwise the interval is split at the root
of z' (safeguarded Newton) when z' changes sign, else in halves.

Points live in a pool array (rbm_cli.models.rbm.exact.piece): slots 0-2 belong to the run
loop (the current point, the next one, a scratch point); the peak refinement takes its
points from the slots above, with reference counts.
"""

from __future__ import annotations

import math

from rbm_cli.base.jit import jit
from rbm_cli.models.rbm.exact.bounds import (
    family_bounds,
    lower2,
    mode_bounds,
    row_lower,
    track_upper,
)
from rbm_cli.models.rbm.exact.piece import eval_family, eval_point

#: Shortest interval the search splits down to, relative to max(1, t) [s].
MIN_STEP = 1e-13
#: Absolute tolerance of the root finding on event times and peak times [s].
ROOT_XTOL = 1e-15
#: Relative tolerance of the peaks (running maxima of |z|).
PEAK_RTOL = 1e-12
#: A root of z' closer than this fraction of its interval to an end is taken as that end;
#: a rate below this fraction of the interval's end rates is a stationary point.
STATIONARY_GAP = 1e-9

#: Slots of the point pool owned by the run loop.
RESERVED = 3
SCRATCH = 2


@jit(borrow=True)
def bounds_of(pc, pts, ia, ib, mb, fb):
    """Mode and family bounds of the interval between points ia and ib; any fast mode."""
    n = pc.n
    h = pts[ib, 0] - pts[ia, 0]
    fast = mode_bounds(pc.lam, pc.f, pc.g, pc.elig, pc.w, pc.fc, pts[ia, 0],
                       pts[ia, 1 : 1 + n], pts[ia, 1 + n : 1 + 2 * n], h,
                       pts[ib, 1 : 1 + n], pts[ib, 1 + n : 1 + 2 * n], mb)  # fmt: skip
    family_bounds(pc.gf, pc.absgf, mb, fast, fb)
    return fast


@jit(borrow=True)
def _value(pc, pts, ia, x, r, kind):
    """(value, derivative) at x [s] after point ia: of event row r (kind 0) or of the rate
    of family r (kind 1)."""
    if kind == 0:
        fv, dv, _ = eval_family(pc, pts, ia, x, pc.fam[r], False)
        return pc.sgn[r] * fv + pc.off[r], pc.sgn[r] * dv
    _, dv, ff = eval_family(pc, pts, ia, x, r, True)
    return dv, ff


@jit
def hermite_root(f0, d0, fh, dh, h):
    """Start for the root finding in [0, h] [s] of a function with values f0, fh (f0 fh < 0)
    and rates d0, dh at the ends: the root of their cubic Hermite interpolant (Newton on the
    cubic from the secant's root, kept inside the interval)."""
    m0, m1 = d0 * h, dh * h
    s = f0 / (f0 - fh)
    for _ in range(6):
        s2 = s * s
        p = (2 * s2 * s - 3 * s2 + 1) * f0 + (s2 * s - 2 * s2 + s) * m0
        p += (-2 * s2 * s + 3 * s2) * fh + (s2 * s - s2) * m1
        dp = (6 * s2 - 6 * s) * f0 + (3 * s2 - 4 * s + 1) * m0
        dp += (-6 * s2 + 6 * s) * fh + (3 * s2 - 2 * s) * m1
        if dp == 0.0:
            break
        s_new = s - p / dp
        if not 0.0 < s_new < 1.0:
            break
        s = s_new
    return s * h


@jit(borrow=True)
def _newton(pc, pts, ia, h, f0, fh, r, kind, x0):
    """Root in [0, h] [s] after point ia of event row r (kind 0) or of the rate of family
    r (kind 1), f0 fh < 0 the values at the ends, from x0 (NaN: the secant's root)
    (safeguarded Newton). Returns (root, evaluations)."""
    if f0 < 0.0:
        lo, hi = 0.0, h
    else:
        lo, hi = h, 0.0
    x = h * f0 / (f0 - fh) if math.isnan(x0) else x0
    step = step_old = h
    evals = 1
    f, df = _value(pc, pts, ia, x, r, kind)
    for _ in range(200):
        if f == 0.0:
            return x, evals
        if f < 0.0:
            lo = x
        else:
            hi = x
        if ((x - hi) * df - f) * ((x - lo) * df - f) > 0.0 or abs(2.0 * f) > abs(step_old * df):
            step_old, step = step, 0.5 * (hi - lo)
            x = lo + step
        else:
            step_old, step = step, f / df
            x -= step
        if abs(step) < ROOT_XTOL:
            return x, evals
        evals += 1
        f, df = _value(pc, pts, ia, x, r, kind)
    return x, evals


@jit(borrow=True)
def _check(pc, pts, ia, ib, fb, fast, h):
    """(any row uncertified, any crossed row, an uncertified row not crossed)."""
    of, nf = 1 + 2 * pc.n, pc.nf
    bad = crossed = other = False
    for r in range(pc.sgn.size):
        k, s, o = pc.fam[r], pc.sgn[r], pc.off[r]
        low = row_lower(s, o, k, pts[ia, of + k], pts[ib, of + k], pts[ia, of + nf + k],
                        pts[ib, of + nf + k], fb, fast, h)  # fmt: skip
        if not low > 0.0:
            bad = True
            if s * pts[ib, of + k] + o < 0.0:
                crossed = True
            else:
                other = True
    return bad, crossed, other


@jit(borrow=True)
def _first_root(pc, pts, ia, ib, fb, h, small):
    """(row, tau [s], evaluations) of the earliest crossing among the rows ending below
    zero at ib; row -1 when some such row is not monotone (and the interval not small)."""
    of, nf = 1 + 2 * pc.n, pc.nf
    for r in range(pc.sgn.size):
        k, s = pc.fam[r], pc.sgn[r]
        if s * pts[ib, of + k] + pc.off[r] < 0.0:
            cfull = fb[1, k] * h
            mono = s * pts[ia, of + nf + k] + cfull < 0.0 or s * pts[ib, of + nf + k] + cfull < 0.0
            if not (small or mono):
                return -1, 0.0, 0
    # the earliest root: a row still positive at the earliest root so far crosses later
    best, best_r, evals = h, -1, 0
    for r in range(pc.sgn.size):
        k, s = pc.fam[r], pc.sgn[r]
        if not s * pts[ib, of + k] + pc.off[r] < 0.0:
            continue
        if best_r < 0:
            f_best, d_best = s * pts[ib, of + k] + pc.off[r], s * pts[ib, of + nf + k]
        else:
            f_best, d_best = _value(pc, pts, ia, best, r, 0)
            evals += 1
            if f_best > 0.0:
                continue
        if f_best == 0.0:
            best_r = r
            continue
        f0, d0 = s * pts[ia, of + k] + pc.off[r], s * pts[ia, of + nf + k]
        start = hermite_root(f0, d0, f_best, d_best, best)
        best, ne = _newton(pc, pts, ia, best, f0, f_best, r, 0, start)
        best_r = r
        evals += ne
    return best_r, best, evals


@jit(borrow=True)
def next_point(pc, pts, h, t_stop, mb, fb):
    """From point 0: point 1 becomes the end of a certified interval of length <= h [s]
    (or t_stop), or the first event (module docstring). Returns (event row or -1,
    interval to try next [s], evaluations, whether mb and fb hold the bounds of [0, 1])."""
    ta = pts[0, 0]
    h_min = MIN_STEP * max(1.0, abs(ta))
    h = min(h, t_stop - ta)
    evals = 0
    first = True
    while True:
        at_stop = h >= t_stop - ta
        eval_point(pc, pts, 0, t_stop - ta if at_stop else h, 1)
        evals += 1
        if at_stop:
            pts[1, 0] = t_stop
        hh = pts[1, 0] - ta
        fast = bounds_of(pc, pts, 0, 1, mb, fb)
        bad, crossed, other = _check(pc, pts, 0, 1, fb, fast, hh)
        if not bad:
            return -1, 2.0 * h if first else h, evals, True
        small = h <= h_min
        if crossed and (small or not other):
            row, tau, ne = _first_root(pc, pts, 0, 1, fb, hh, small)
            evals += ne
            if row >= 0:
                eval_point(pc, pts, 0, tau, 1)
                return row, h, evals + 1, False
        if small:
            return -1, h, evals, True
        h = 0.5 * h
        first = False


@jit
def _monotone(pts, ia, ib, k, of, nf, third, slack, h):
    """Whether family k's rate keeps one sign between points ia and ib."""
    da, db = pts[ia, of + nf + k], pts[ib, of + nf + k]
    za, zb = pts[ia, of + 2 * nf + k], pts[ib, of + 2 * nf + k]
    if lower2(da, db, za, zb, third, h) >= -slack:
        return True
    return lower2(-da, -db, -za, -zb, third, h) >= -slack


@jit
def _split_point(pc, pts, a, b, rows, c):
    """Make point c where [a, b] is split for the rows still open: the root of the first
    open row whose rate changes sign (its rate and those of the rows stationary there set
    to 0), else the midpoint. Returns the evaluations."""
    m, of, nf = pc.m, 1 + 2 * pc.n, pc.nf
    h = pts[b, 0] - pts[a, 0]
    for i in range(m + 1):
        k = m + i
        if rows[i] and pts[a, of + nf + k] * pts[b, of + nf + k] < 0.0:
            tau, evals = _newton(pc, pts, a, h, pts[a, of + nf + k], pts[b, of + nf + k], k, 1,
                                 math.nan)  # fmt: skip
            if not STATIONARY_GAP * h < tau < (1.0 - STATIONARY_GAP) * h:
                tau = 0.5 * h
            eval_point(pc, pts, a, tau, c)
            for j in range(m + 1):
                kj = m + j
                gap = STATIONARY_GAP * (abs(pts[a, of + nf + kj]) + abs(pts[b, of + nf + kj]))
                if abs(pts[c, of + nf + kj]) <= gap:
                    pts[c, of + nf + kj] = 0.0
            pts[c, of + nf + k] = 0.0
            return evals + 1
    eval_point(pc, pts, a, 0.5 * h, c)
    return 1


@jit
def _open_rows(pc, pts, a, b, maxima, rows, mb, fb, fresh):
    """Narrow rows (bool, m + 1: the joints' collapse ratios, the top) to those whose peak
    may still exceed its running maximum on [a, b] (module docstring); returns whether any
    is left. fresh: mb and fb hold the bounds of [a, b] already."""
    n, m, of, nf = pc.n, pc.m, 1 + 2 * pc.n, pc.nf
    for i in range(m + 1):
        maxima[i] = max(maxima[i], abs(pts[a, of + m + i]), abs(pts[b, of + m + i]))
    h = pts[b, 0] - pts[a, 0]
    if fresh:
        fast = False
        for j in range(n):
            fast = fast or mb[3, j] != 0.0
    else:
        fast = bounds_of(pc, pts, a, b, mb, fb)
    left = False
    for i in range(m + 1):
        k = m + i
        if rows[i]:
            up = track_upper(k, pts[a, of + k], pts[b, of + k], pts[a, of + nf + k],
                             pts[b, of + nf + k], fb, fast, h)  # fmt: skip
            rows[i] = not up <= maxima[i]
            left = left or rows[i]
    if not left or h <= MIN_STEP * max(1.0, abs(pts[a, 0])):
        return False
    left = False
    for i in range(m + 1):
        if rows[i]:
            k = m + i
            slack = PEAK_RTOL * maxima[i] / h
            rows[i] = not _monotone(pts, a, b, k, of, nf, fb[2, k], slack, h)
            left = left or rows[i]
    return left


@jit
def refine_peaks(pc, pts, maxima, mb, fb, refs, free, st_ab, st_rows, fresh):
    """Raise the running maxima (m + 1) to the peaks between points 0 and 1 (module
    docstring). refs, free: reference counts and free list of the pool's slots; st_ab,
    st_rows: the stack; fresh: mb and fb hold the bounds of [0, 1]. Returns the
    evaluations."""
    m, of = pc.m, 1 + 2 * pc.n
    n_free = free.size
    for i in range(free.size):
        free[i] = pts.shape[0] - 1 - i
    refs[:] = 0
    refs[0] = refs[1] = 1 << 30  # the run loop's points are never freed
    st_ab[0, 0], st_ab[0, 1] = 0, 1
    st_rows[0, :] = True
    top, evals = 1, 0
    while top > 0:
        top -= 1
        a, b = st_ab[top, 0], st_ab[top, 1]
        rows = st_rows[top].copy()
        opened = _open_rows(pc, pts, a, b, maxima, rows, mb, fb, fresh)
        fresh = False
        if opened and n_free > 0 and top + 2 < st_ab.shape[0]:
            n_free -= 1
            c = free[n_free]
            evals += _split_point(pc, pts, a, b, rows, c)
            for i in range(m + 1):
                maxima[i] = max(maxima[i], abs(pts[c, of + m + i]))
            st_ab[top, 0], st_ab[top, 1] = c, b
            st_rows[top, :] = rows
            st_ab[top + 1, 0], st_ab[top + 1, 1] = a, c
            st_rows[top + 1, :] = rows
            top += 2
            refs[c] += 2
            refs[a] += 1
            refs[b] += 1
        for p in (a, b):
            refs[p] -= 1
            if refs[p] == 0:
                free[n_free] = p
                n_free += 1
    return evals
