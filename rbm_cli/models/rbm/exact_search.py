"""Where the exact integrator samples a piece, and how it finds events and peaks that no
sampling can miss.

An interval [a, b] of a piece is *certified* for an event row when a lower bound of the
row's distance over the whole interval is positive (rbm_cli.models.rbm.exact_piece
module docstring: a slow part bounded by curvature, fast oscillations by their envelope):

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
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rbm_cli.models.rbm.exact_bounds import (
    MIN_STEP,
    PEAK_RTOL,
    ROOT_XTOL,
    STATIONARY_GAP,
    ModeBounds,
    hermite_root,
    mode_bounds,
)
from rbm_cli.models.rbm.exact_piece import LinearPiece


@dataclass
class Point:
    """The piece's state at time t [s]: modal (q, v), event distances d and rates dd,
    tracked quantities z and their first and second derivatives dz, zz."""

    t: float
    q: np.ndarray
    v: np.ndarray
    d: np.ndarray
    dd: np.ndarray
    z: np.ndarray
    dz: np.ndarray
    zz: np.ndarray


class Evaluator:
    """Evaluations of a piece, counted (n_evals)."""

    def __init__(self, piece: LinearPiece) -> None:
        self.piece = piece
        self.n_evals = 0

    def start(self, t: float, q: np.ndarray, v: np.ndarray) -> Point:
        d, dd = self.piece.distances(q, v)
        z, dz = self.piece.peaks(q, v)
        zz = self.piece.track @ self.piece.modal_accel(t, q)
        return Point(t, q, v, d, dd, z, dz, zz)

    def point(self, a: Point, tau: float) -> Point:
        """The point tau [s] after a."""
        self.n_evals += 1
        q, v = self.piece.at(a.t, a.q, a.v, tau)
        return self.start(a.t + tau, q, v)

    def bounds(self, a: Point, b: Point) -> ModeBounds:
        return mode_bounds(self.piece, a.t, a.q, a.v, b.t - a.t, b.q, b.v)


def _lower(vals_a, vals_b, rate_a, rate_b, curv, h):
    """Lower bound over the interval of functions with these end values and rates and
    |second derivative| <= curv."""
    interp = np.minimum(vals_a, vals_b) - curv * (h * h / 8.0)
    left = np.minimum(vals_a, vals_a + rate_a * h - curv * (h * h / 2.0))
    right = np.minimum(vals_b, vals_b - rate_b * h - curv * (h * h / 2.0))
    return np.maximum(interp, np.maximum(left, right))


def _upper_abs(vals_a, vals_b, rate_a, rate_b, curv, h):
    """Upper bound of |value| over the interval (same data as _lower)."""
    ends = np.maximum(np.abs(vals_a), np.abs(vals_b))
    interp = ends + curv * (h * h / 8.0)
    left = np.maximum(np.abs(vals_a), np.abs(vals_a + rate_a * h)) + curv * (h * h / 2.0)
    right = np.maximum(np.abs(vals_b), np.abs(vals_b - rate_b * h)) + curv * (h * h / 2.0)
    return np.minimum(interp, np.minimum(left, right))


def _slow(rows, mb: ModeBounds, a: Point, b: Point, va, vb, ra, rb):
    """End values and rates of the rows' slow parts (the fast oscillations taken out)."""
    if not mb.fast.any():
        return va, vb, ra, rb
    return va - rows @ mb.osc_a, vb - rows @ mb.osc_b, ra - rows @ mb.rate_a, rb - rows @ mb.rate_b


def row_lower(piece: LinearPiece, a: Point, b: Point, mb: ModeBounds) -> np.ndarray:
    """Lower bounds of the event distances over [a.t, b.t]."""
    h = b.t - a.t
    rows, absr = piece.rows, piece.abs_rows
    full = _lower(a.d, b.d, a.dd, b.dd, absr @ mb.full, h)
    if not mb.fast.any():
        return full
    sa, sb, ra, rb = _slow(rows, mb, a, b, a.d, b.d, a.dd, b.dd)
    split = _lower(sa, sb, ra, rb, absr @ mb.curv, h) - absr @ mb.env
    return np.maximum(full, split)


def track_upper(piece: LinearPiece, a: Point, b: Point, mb: ModeBounds) -> np.ndarray:
    """Upper bounds of |z| (tracked quantities) over [a.t, b.t]."""
    h = b.t - a.t
    rows, absr = piece.track, piece.abs_track
    full = _upper_abs(a.z, b.z, a.dz, b.dz, absr @ mb.full, h)
    if not mb.fast.any():
        return full
    sa, sb, ra, rb = _slow(rows, mb, a, b, a.z, b.z, a.dz, b.dz)
    split = _upper_abs(sa, sb, ra, rb, absr @ mb.curv, h) + absr @ mb.env
    return np.minimum(full, split)


def _safe_newton(fun, h: float, f0: float, fh: float, x0: float | None = None) -> float:
    """Root in [0, h] [s] of fun (tau -> (value, derivative)), f0 fh < 0 the values at the
    ends (not evaluated again: a re-evaluation may round to the other sign): Newton's
    method from x0 (default: the secant's root) kept inside the bracket, bisecting when a
    Newton step would leave it or converge slowly (rtsafe), to ROOT_XTOL."""
    lo, hi = (0.0, h) if f0 < 0.0 else (h, 0.0)  # fun(lo) < 0 < fun(hi)
    x = h * f0 / (f0 - fh) if x0 is None else x0
    step = step_old = h
    f, df = fun(x)
    for _ in range(200):
        if f == 0.0:
            return x
        if f < 0.0:
            lo = x
        else:
            hi = x
        newton_out = ((x - hi) * df - f) * ((x - lo) * df - f) > 0.0
        if newton_out or abs(2.0 * f) > abs(step_old * df):
            step_old, step = step, 0.5 * (hi - lo)
            x = lo + step
        else:
            step_old, step = step, f / df
            x -= step
        if abs(step) < ROOT_XTOL:
            return x
        f, df = fun(x)
    return x


def _earliest(ev: Evaluator, a: Point, b: Point, rows: np.ndarray) -> tuple[float, int]:
    """(time after a [s], row) of the earliest root among rows, each crossing zero once in
    (0, b.t - a.t]: a row whose distance is still positive at the earliest root so far
    crosses later and is not solved."""
    piece = ev.piece
    best, best_r, f_best, d_best = b.t - a.t, -1, 0.0, 0.0
    for r in rows:

        def dist(tau, r=r):
            ev.n_evals += 1
            q, v = piece.at(a.t, a.q, a.v, tau)
            return float(piece.rows[r] @ q + piece.h0[r]), float(piece.rows[r] @ v)

        if best_r < 0:
            f_best, d_best = float(b.d[r]), float(b.dd[r])
        else:
            f_best, d_best = dist(best)
            if f_best > 0.0:
                continue
        if f_best == 0.0:
            best_r = int(r)
            continue
        start = hermite_root(float(a.d[r]), float(a.dd[r]), f_best, d_best, best)
        best, best_r = _safe_newton(dist, best, float(a.d[r]), f_best, start), int(r)
    return best, best_r


def next_point(ev: Evaluator, a: Point, h: float, t_stop: float) -> tuple[Point, int | None, float]:
    """The next sample point after a: the end of a certified interval of length <= h
    [s] (or t_stop), or the first event. Returns (point, event row or None, the
    interval length to try next [s]: twice the certified one if certified at the first
    try, else the same)."""
    piece = ev.piece
    h_min = MIN_STEP * max(1.0, abs(a.t))
    h = min(h, t_stop - a.t)
    first = True
    while True:
        at_stop = h >= t_stop - a.t
        b = ev.point(a, t_stop - a.t if at_stop else h)
        if at_stop:
            b.t = t_stop
        mb = ev.bounds(a, b)
        bad = ~(row_lower(piece, a, b, mb) > 0.0)  # NaN: no bound
        if not bad.any():
            return b, None, 2.0 * h if first else h
        crossed = b.d < 0.0
        small = h <= h_min
        if crossed.any() and (small or not (bad & ~crossed).any()):
            rows = np.nonzero(crossed)[0]
            cfull = piece.abs_rows[rows] @ mb.full * (b.t - a.t)
            mono = (a.dd[rows] + cfull < 0.0) | (b.dd[rows] + cfull < 0.0)
            if small or mono.all():
                tau, r = _earliest(ev, a, b, rows)
                return ev.point(a, tau), r, h
        if small:
            return b, None, h
        h = 0.5 * h
        first = False


def refine_peaks(ev: Evaluator, a: Point, b: Point, maxima: np.ndarray) -> None:
    """Raise the running maxima of |z| to the peaks inside [a.t, b.t]: split the interval
    at roots of z' and in halves until, for every row, each part is below the
    running maximum or has a monotone z (module docstring)."""
    piece = ev.piece
    stack = [(a, b, None)]
    while stack:
        a, b, need = stack.pop()
        np.maximum(maxima, np.maximum(np.abs(a.z), np.abs(b.z)), out=maxima)
        h = b.t - a.t
        mb = ev.bounds(a, b)
        rows = ~(track_upper(piece, a, b, mb) <= maxima)  # NaN: no bound
        if need is not None:
            rows &= need
        if not rows.any() or h <= MIN_STEP * max(1.0, abs(a.t)):
            continue
        rows &= ~_monotone(a, b, piece.abs_track @ mb.third, PEAK_RTOL * maxima / h)
        if not rows.any():
            continue
        flips = np.nonzero(rows & (a.dz * b.dz < 0.0))[0]
        if flips.size:
            r = int(flips[0])

            def rate(tau, a=a, r=r):
                ev.n_evals += 1
                q, v = piece.at(a.t, a.q, a.v, tau)
                return float(piece.track[r] @ v), float(
                    piece.track[r] @ piece.modal_accel(a.t + tau, q)
                )

            tau = _safe_newton(rate, h, float(a.dz[r]), float(b.dz[r]))
            if not STATIONARY_GAP * h < tau < (1.0 - STATIONARY_GAP) * h:
                tau = 0.5 * h  # an end is stationary already: split in halves
            c = ev.point(a, tau)
            # stationary rows at c (r, and rows proportional to it): no sign change there
            still = np.abs(c.dz) <= STATIONARY_GAP * (np.abs(a.dz) + np.abs(b.dz))
            c.dz[r] = 0.0
            c.dz[still] = 0.0
        else:
            c = ev.point(a, 0.5 * h)
        np.maximum(maxima, np.abs(c.z), out=maxima)
        stack += [(c, b, rows), (a, c, rows)]


def _monotone(a: Point, b: Point, third: np.ndarray, slack: np.ndarray) -> np.ndarray:
    """Rows whose z' keeps one sign on [a.t, b.t], so |z| peaks at an end: a lower bound of
    s z' (s = +-1) over the interval, from the ends' z' and z'' and the bound `third` of
    the third derivative, is above -slack (a computed root of z' is not exactly zero)."""
    h = b.t - a.t
    up = _lower(a.dz, b.dz, a.zz, b.zz, third, h) >= -slack
    down = _lower(-a.dz, -b.dz, -a.zz, -b.zz, third, h) >= -slack
    return up | down
