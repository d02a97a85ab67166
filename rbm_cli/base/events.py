"""Event location shared by the integrators written in Python (Housner's block, the rigid
cylinder, the validation): the offsets of event surfaces, where the first event of a step
is, and cubic Hermite checks between points (peaks, grazing dips). Nothing here knows a
column: the rows are whatever distances a model watches."""

from __future__ import annotations

import numpy as np

#: Relative offset of event surfaces, so that a restart exactly on a surface
#: is not taken for a new crossing [fraction of theta_u].
EVENT_EPS = 1e-12
#: Energy margin of the early stop of free motion [fraction of the barrier].
STOP_MARGIN = 1e-9
#: Stand-in for an infinite bound in the event distances.
BIG = 1e30


def _lowest_dip(d0, d1, r0, r1, dt):
    """(time from the start, row) of the lowest interior minimum below zero of the
    cubic Hermite interpolants of the distances d, or None. Only rows turning
    inside the interval (rate < 0 at its start, > 0 at its end)."""
    rows = np.nonzero((r0 < 0.0) & (r1 > 0.0))[0]
    best, hit = 0.0, None
    for r in rows:
        p0, m0, p1, m1 = d0[r], dt * r0[r], d1[r], dt * r1[r]
        # quick reject: the distance cannot reach zero within the interval
        if min(p0, p1) > 0.5 * (abs(m0) + abs(m1)):
            continue
        a = 2 * p0 + m0 - 2 * p1 + m1
        b = -3 * p0 - 2 * m0 + 3 * p1 - m1
        roots = np.roots([3 * a, 2 * b, m0]) if abs(a) + abs(b) > 0 else []
        for s in np.real(roots[np.isreal(roots)]) if len(roots) else []:
            if 0.0 < s < 1.0:
                val = ((a * s + b) * s + m0) * s + p0
                if val < best:
                    best, hit = val, (s * dt, int(r))
    return hit


def hermite_dip(d0, d1, r0, r1, dt):
    """Time (from the step start) of the lowest interior minimum of the cubic
    Hermite interpolants of the distances d (values d0, d1, rates r0, r1),
    if one dips below zero; else None. Only rows turning inside the step."""
    hit = _lowest_dip(d0, d1, r0, r1, dt)
    return None if hit is None else hit[0]


#: Points per solver step at which the dense output is checked for a crossing.
CHECK_INTERVALS = 8


def first_crossing(dist, t0, t1, intervals=CHECK_INTERVALS, xtol=1e-14):
    """Earliest zero crossing, over all rows, of event distances inside [t0, t1].

    Parameters
    ----------
    dist : callable  ts (m,) -> (D, R), distances and their rates, (rows, m)
        (from the solver's dense output of the step)
    t0, t1 : float  The step [s]
    intervals : int  Sub-intervals checked in turn

    Returns
    -------
    (t, row) of the first crossing, or None.

    Notes
    -----
    The step is cut into `intervals` pieces; in the first piece where a row ends
    below zero, or where the cubic Hermite of the dense values and rates at the
    piece's ends dips below zero (confirmed on the dense output), each such row's
    own crossing is found by Brent's method and the earliest wins. Root finding on
    the minimum over rows instead can return a later root when one row dips below
    zero and back while another ends below zero: the first crossing is then lost
    (test_energy_jump_reproducer). The end-of-step cubic alone also misses
    dips of long steps, where the higher derivatives matter.
    """
    ts = np.linspace(t0, t1, intervals + 1)
    D, R = dist(ts)
    if D[:, 0].min() <= 0.0:
        return t0, int(np.argmin(D[:, 0]))

    def row_value(s, r):
        return float(dist(np.array([s]))[0][r, 0])

    # sub-intervals where a row ends below zero or may dip (the quick test of
    # _lowest_dip, vectorised); the others need no closer look
    ds = ts[1] - ts[0]
    ends_below = (D[:, 1:] < 0.0).any(axis=0)
    turning = (R[:, :-1] < 0.0) & (R[:, 1:] > 0.0)
    near = np.minimum(D[:, :-1], D[:, 1:]) <= 0.5 * ds * (np.abs(R[:, :-1]) + np.abs(R[:, 1:]))
    look = ends_below | (turning & near).any(axis=0)
    for j in np.nonzero(look)[0]:
        a, b = ts[j], ts[j + 1]
        cands = [(b, int(r)) for r in np.nonzero(D[:, j + 1] < 0.0)[0]]
        dip = _lowest_dip(D[:, j], D[:, j + 1], R[:, j], R[:, j + 1], b - a)
        if dip is not None and row_value(a + dip[0], dip[1]) < 0.0:
            cands.append((a + dip[0], dip[1]))
        if cands:
            # lazy: scipy.optimize loads only where needed (docs/architecture.md, Start-up)
            from scipy.optimize import brentq

            roots = [(brentq(row_value, a, hi, args=(r,), xtol=xtol), r) for hi, r in cands]
            return min(roots)
    return None
