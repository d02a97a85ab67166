"""The Python bookkeeping of law pieces the compiled one (rbm_cli.models.rbm.pieces) is
checked against (tests/test_pieces.py): which piece of its law each interface is on,
written from the laws' objects (Law.edges, intercepts, slopes) and numpy, one interface at a
time."""

from __future__ import annotations

import numpy as np

from rbm_cli.structures.equations import Model


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
        'uplift' (a closed interface leaving the elastic branch), 'kink' (another piece
        of the same side, or leaving the elastic branch again before the silent zero
        crossing it awaited: the excursion goes on) or 'impact' (a zero crossing after
        an excursion: the side flips)."""
        s, k = self.side[i], self.k[i]
        if k == 0 and not self.zero_active(i):
            reopened = bool(self.awaiting[i])
            self.side[i], self.k[i], self.pending[i] = (1 if going_up else -1), 1, True
            self.awaiting[i] = False
            return "kink" if reopened else "uplift"
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
