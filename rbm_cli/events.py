"""Event bookkeeping of the integrator: which law piece each interface is on,
and cubic Hermite checks between solver steps (peaks, grazing dips)."""

from __future__ import annotations

import numpy as np

from .model import Model


class Pieces:
    """Which piece of its law each interface is on: side s = +-1 and index k."""

    def __init__(self, model: Model):
        self.model = model
        n = model.n
        self.side = np.ones(n, dtype=int)
        self.k = np.zeros(n, dtype=int)
        self.pending = np.zeros(n, dtype=bool)  # excursion beyond elastic branch
        self.rigid = np.array([law.rigid for law in model.laws])
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


def hermite_peaks(z0, z1, d0, d1, dt):
    """Largest |z| inside [0, dt] of the cubic Hermite interpolant, per row,
    for rows whose derivative changes sign (else the end values bound it)."""
    out = np.maximum(np.abs(z0), np.abs(z1))
    rows = np.nonzero(d0 * d1 < 0)[0]
    for r in rows:
        # z(s) = h00 z0 + h10 dt d0 + h01 z1 + h11 dt d1, s in [0, 1]
        p0, m0, p1, m1 = z0[r], dt * d0[r], z1[r], dt * d1[r]
        # derivative coefficients of the cubic a s^3 + b s^2 + c s + d
        a = 2 * p0 + m0 - 2 * p1 + m1
        b = -3 * p0 - 2 * m0 + 3 * p1 - m1
        c = m0
        roots = np.roots([3 * a, 2 * b, c]) if abs(a) + abs(b) > 0 else []
        for s in np.real(roots[np.isreal(roots)]) if len(roots) else []:
            if 0.0 < s < 1.0:
                val = ((a * s + b) * s + c) * s + p0
                out[r] = max(out[r], abs(val))
    return out


def hermite_dip(d0, d1, r0, r1, dt):
    """Time (from the step start) of the lowest interior minimum of the cubic
    Hermite interpolants of the distances d (values d0, d1, rates r0, r1),
    if one dips below zero; else None. Only rows turning inside the step."""
    rows = np.nonzero((r0 < 0.0) & (r1 > 0.0))[0]
    best, t_best = 0.0, None
    for r in rows:
        p0, m0, p1, m1 = d0[r], dt * r0[r], d1[r], dt * r1[r]
        # quick reject: the distance cannot reach zero within the step
        if min(p0, p1) > 0.5 * (abs(m0) + abs(m1)):
            continue
        a = 2 * p0 + m0 - 2 * p1 + m1
        b = -3 * p0 - 2 * m0 + 3 * p1 - m1
        roots = np.roots([3 * a, 2 * b, m0]) if abs(a) + abs(b) > 0 else []
        for s in np.real(roots[np.isreal(roots)]) if len(roots) else []:
            if 0.0 < s < 1.0:
                val = ((a * s + b) * s + m0) * s + p0
                if val < best:
                    best, t_best = val, s * dt
    return t_best
