"""Event bookkeeping of the integrator: which law piece each interface is on,
where the first event of a step is, and cubic Hermite checks between points
(peaks, grazing dips)."""

from __future__ import annotations

import numpy as np

from rbm_cli.physics.equations import Model

#: Relative offset of event surfaces, so that a restart exactly on a surface
#: is not taken for a new crossing [fraction of theta_u].
EVENT_EPS = 1e-12
#: A rigid block whose post-impact rate is below REST_RATE * p * theta_u is
#: put to rest [assumption]: its next excursion would stay below
#: (REST_RATE^2 / 2) theta_u = 5e-7 theta_u. This ends Zeno impact sequences
#: (e < 1) and micro-chatter (e = 1, demand just above uplift) in finite work.
REST_RATE = 1e-3
#: Energy margin of the early stop of free motion [fraction of the barrier].
STOP_MARGIN = 1e-9
#: Stand-in for an infinite bound in the event distances.
BIG = 1e30


class Pieces:
    """Which piece of its law each interface is on: side s = +-1 and index k."""

    def __init__(self, model: Model, silent: bool = False):
        self.model = model
        n = model.n
        self.side = np.ones(n, dtype=int)
        self.k = np.zeros(n, dtype=int)
        self.pending = np.zeros(n, dtype=bool)  # excursion beyond elastic branch
        self.rigid = np.array([law.rigid for law in model.laws])
        # silent impacts (`silent`, Model.silent_impacts): a zero crossing that changes
        # neither the state nor the equations is no event; `settle` counts it instead
        self.silent = model.silent_impacts & silent
        self.awaiting = np.zeros(n, dtype=bool)  # back on piece 0, zero not crossed yet
        self.tu = model.column.rotation_capacity
        self._cache: dict = {}

    def locate(self, x: np.ndarray, rate: np.ndarray) -> None:
        for i, law in enumerate(self.model.laws):
            s = 1 if x[i] > 0 else -1 if x[i] < 0 else (1 if rate[i] >= 0 else -1)
            self.side[i] = s
            self.k[i] = int(np.searchsorted(law.edges, abs(x[i]), side="right"))
            self.pending[i] = self.k[i] > 0 and not law.rigid

    def zero_active(self, i: int) -> bool:
        return bool(self.rigid[i] or self.pending[i])

    def cross(self, i: int, going_up: bool) -> str:
        """Move interface i to its next piece as its argument crosses the current
        piece's upper (going_up) or lower bound. Returns what the crossing is:
        'uplift' (leaving the elastic branch), 'kink' (another piece of the same
        side) or 'impact' (a zero crossing after an excursion: the side flips)."""
        s, k = self.side[i], self.k[i]
        if k == 0 and not self.zero_active(i):
            self.side[i], self.k[i], self.pending[i] = (1 if going_up else -1), 1, True
            self.awaiting[i] = False
            return "uplift"
        if going_up == (s > 0):
            self.k[i] = k + 1
            return "kink"
        if k > 0:
            self.k[i] = k - 1
            if k == 1 and self.silent[i]:
                self.pending[i], self.awaiting[i] = False, True
            return "kink"
        self.side[i], self.pending[i] = -s, False
        return "impact"

    def settle(self, x: np.ndarray) -> int:
        """Count the silent impacts up to a point where the law arguments are x:
        interfaces back on their first piece whose argument has changed sign
        (checked at every step's end, so a crossing and return inside one step
        is not counted). Returns how many."""
        hits = self.awaiting & (self.side * x < 0.0)
        if hits.any():
            self.side[hits] *= -1
            self.awaiting[hits] = False
        return int(hits.sum())

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        n = self.model.n
        lo, hi = np.empty(n), np.empty(n)
        for i, law in enumerate(self.model.laws):
            e = law.edges
            k, s = self.k[i], self.side[i]
            start = 0.0 if k == 0 else e[k - 1]
            end = e[k] if k < len(e) else np.inf
            if k == 0 and not self.zero_active(i):
                start = -end
            if s > 0:
                lo[i], hi[i] = start, end
            else:
                lo[i], hi[i] = -end, -start
        return lo, hi

    def system(self):
        key = (tuple(self.side), tuple(self.k))
        sys_ = self._cache.get(key)
        if sys_ is None:
            laws = self.model.laws
            a = np.array(
                [s * law.intercepts[k] for s, k, law in zip(self.side, self.k, laws, strict=True)]
            )
            b = np.array([law.slopes[k] for k, law in zip(self.k, laws, strict=True)])
            sys_ = self.model.linear_system(a, b)
            self._cache[key] = sys_
        return sys_


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


#: Points per solver step at which the dense output is checked for a crossing,
#: when a surface is within reach of the step (see within_reach).
CHECK_INTERVALS = 8


def within_reach(d0, d1, r0, r1, a0, a1, dt) -> bool:
    """Whether an event distance may reach zero inside a step, judged from its
    values d, rates r and second derivatives a at both ends, with a wide margin.

    A row is within reach when min(d0, d1) <= dt (|r0| + |r1|) + dt^2 (|a0| + |a1|).
    The cubic Hermite of a step's end values moves at most 4/27 dt (|r0| + |r1|)
    below min(d0, d1), so the margin is several times that; it is not a proof (the
    interior of a long step is judged from its ends), which is why it is wide.
    Steps far from every surface (most of them) need no dense output."""
    reach = dt * (np.abs(r0) + np.abs(r1)) + dt * dt * (np.abs(a0) + np.abs(a1))
    return bool(np.any(np.minimum(d0, d1) <= reach))


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
            from scipy.optimize import brentq  # here: no scipy at import (a shorter start-up)

            roots = [(brentq(row_value, a, hi, args=(r,), xtol=xtol), r) for hi, r in cands]
            return min(roots)
    return None
