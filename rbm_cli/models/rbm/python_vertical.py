"""Vertical shaking in the readable integrator (rbm_cli.models.rbm.python): the smooth piece
under gam(t) = (g + a_v(t)) / g, for any law (rigid or elastic joints).

A law's piece is f = gam (a_k + bs_k x) + be_k x (Model.slope_parts): the weight part
scales with gam, the joint stiffness does not, so

    theta'' = gam(t) (Aw theta + c) + Ae theta + e a_g(t)      (Model.vertical_system)

and the kinks between an elastic and a weight line move: x_q(gam) = E_q m(gam; w_q),
m = gam / (1 + w (gam - 1)) (Model.edge_weight_shares). The event row of such a kink is the
two lines' signed difference divided by its positive slope in x, (x - x_q(gam(t))) /
theta_u, evaluated at gam(t); the compiled kernel's twin is kernel_vertical.
"""

from __future__ import annotations

import numpy as np

from rbm_cli.config.types import G
from rbm_cli.models.events import EVENT_EPS
from rbm_cli.models.rbm.python_steps import RunState, SmoothPiece


def _m(gam, w):
    """m(gam; w) and its first two derivatives in gam (kernel_vertical._m)."""
    den = 1.0 + w * (gam - 1.0)
    return gam / den, (1.0 - w) / den**2, -2.0 * w * (1.0 - w) / den**3


def moving_rows(run: RunState, h0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(mv_e, mv_w) of the law-bound rows (2n) of the active pieces, h0 of a moving row
    set to EVENT_EPS in place (kernel_vertical.moving_rows)."""
    model, pieces, n = run.model, run.pieces, run.n
    shares = model.edge_weight_shares
    mv_e, mv_w = np.zeros(2 * n), np.ones(2 * n)
    for i, law in enumerate(model.laws):
        k, ne = int(pieces.k[i]), len(law.edges)
        q_end = k if k < ne else -1
        if k == 0 and not pieces.zero_active(i):
            q_s, s_s = q_end, -1.0
        else:
            q_s, s_s = (-1, 1.0) if k == 0 else (k - 1, 1.0)
        if pieces.side[i] > 0:
            ends = ((q_s, s_s), (q_end, 1.0))
        else:
            ends = ((q_end, -1.0), (q_s, -s_s))
        for row, (q, sgn), outer in ((i, ends[0], -1.0), (n + i, ends[1], 1.0)):
            if q >= 0 and shares[i, q] != 1.0:
                mv_e[row] = outer * sgn * law.edges[q] / run.tu[i]
                mv_w[row] = shares[i, q]
                h0[row] = EVENT_EPS
    return mv_e, mv_w


def gam_rate(t: float, knots: np.ndarray, vertical: np.ndarray) -> float:
    """d gam / dt [1/s] on the record's straight piece a step from t [s] runs on (the first
    knot past t + 10 ulp ends it, kernel_ground._record_piece); 0 outside the record."""
    j = int(np.searchsorted(knots, t + 10.0 * abs(np.nextafter(t, np.inf) - t), side="right"))
    if 0 < j < knots.size:
        return float((vertical[j] - vertical[j - 1]) / ((knots[j] - knots[j - 1]) * G))
    return 0.0


class VerticalPiece(SmoothPiece):
    """SmoothPiece under a vertical record: theta'' = gam(t) (Aw theta + c) + Ae theta + e a_g,
    and event rows whose kinks move with gam(t) (module docstring)."""

    def __init__(self, run: RunState, ag, gam, vertical: np.ndarray):
        super().__init__(run, ag, gam)
        self.knots, self.vertical = run.knots, vertical
        self.tu = run.tu
        model, pieces = run.model, run.pieces
        self.Ae = None
        if not all(law.rigid for law in model.laws):
            weight, elastic = model.slope_parts
            idx = np.arange(self.n)
            a = np.array(
                [
                    s * law.intercepts[k]
                    for s, k, law in zip(pieces.side, pieces.k, model.laws, strict=True)
                ]
            )
            self.A, self.Ae, self.cvec, self.evec = model.vertical_system(
                a, weight[idx, pieces.k], elastic[idx, pieces.k])  # fmt: skip
        self.h0 = self.h0.copy()
        self.mv_e, self.mv_w = moving_rows(run, self.h0)
        self.moving = np.nonzero(self.mv_e)[0]

    def acc(self, tt, yy) -> np.ndarray:
        n = self.n
        weight = self.gam(tt) * (self.A @ yy[:n] + self.cvec)
        if self.Ae is None:
            return weight + self.evec * self.ag(tt)
        return weight + self.Ae @ yy[:n] + self.evec * self.ag(tt)  # the kernel's order

    def _parts(self, t: float, t_piece: float | None = None):
        """The moving rows' parts at t [s]: value, rate, second derivative (2n each); the
        rate of gam from the piece a step from t_piece (default t) runs on."""
        val, rate, curv = np.zeros((3, 2 * self.n))
        if self.moving.size:
            gp = gam_rate(t if t_piece is None else t_piece, self.knots, self.vertical)
            r = self.moving
            m, m1, m2 = _m(self.gam(t), self.mv_w[r])
            e = self.mv_e[r]
            val[r], rate[r], curv[r] = e * m, e * m1 * gp, e * m2 * gp * gp
        return val, rate, curv

    def distances(self, yy, t=None, t_piece=None):
        d, dd = super().distances(yy)
        if self.moving.size:
            val, rate, _ = self._parts(t, t_piece)
            d[: 2 * self.n] += val
            dd[: 2 * self.n] += rate
        return d, dd

    def curvature(self, acc, t=None, t_piece=None):
        d2 = self.g_rows @ acc
        if self.moving.size:
            d2[: 2 * self.n] += self._parts(t, t_piece)[2]
        return d2

    def dist(self, dense, ts):
        D, R = super().dist(dense, ts)
        if self.moving.size:
            t_piece = float(ts[0])
            for c, tt in enumerate(np.atleast_1d(ts)):
                val, rate, _ = self._parts(float(tt), t_piece)
                D[: 2 * self.n, c] += val
                R[: 2 * self.n, c] += rate
        return D, R

    def bound(self, i: int, going_up: bool, t: float) -> float:
        row = self.n + i if going_up else i
        if self.mv_e[row] == 0.0:
            return super().bound(i, going_up, t)
        m = _m(self.gam(t), self.mv_w[row])[0]
        return float((1.0 if going_up else -1.0) * self.mv_e[row] * m * self.tu[i])
