"""One linear piece of the exact integrator: the modes of the active law pieces, the
closed-form motion from a point, and its event and peak rows.

The modes (Decomposition) solve the symmetric pencil K phi = lam M phi (scipy.linalg.eigh:
M symmetric positive definite in the `relative` and `geometric` formulations, K symmetric,
possibly indefinite or singular), M-orthonormal: Phi^T M Phi = I, so q = Phi^T M theta.
They depend only on the slopes of the active pieces, so they are cached by the pieces'
indices; the intercepts (which side) only move the constant load f.

Rows: every event surface and every tracked peak quantity is linear in theta, so in modal
coordinates a row is d(t) = G q(t) + h0 (event distances, >= 0 inside the piece) or
z(t) = T q(t) (peaks). Bounds on them: rbm_cli.models.rbm.exact_bounds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import eigh

from rbm_cli.models.events import BIG, EVENT_EPS, Pieces
from rbm_cli.models.rbm.exact_bounds import eligible
from rbm_cli.models.rbm.exact_modal import Forcing, advance
from rbm_cli.physics.equations import Model


@dataclass(frozen=True)
class Decomposition:
    """Modes of one set of active slopes.

    lam : (n,) eigenvalues of K phi = lam M phi [1/s^2]
    phi : (n, n) M-orthonormal modes (columns) [rad per unit q]
    to_modal : (n, n) Phi^T M, theta -> q
    g : (n,) modal ground load -Phi^T r [per m/s^2]
    """

    lam: np.ndarray
    phi: np.ndarray
    to_modal: np.ndarray
    g: np.ndarray


class ModalSystem:
    """The column's fixed matrices for the exact integrator and the cache of its modes."""

    def __init__(self, model: Model) -> None:
        if model.formulation == "absolute":
            raise ValueError("the exact integrator needs a symmetric stiffness")
        n = model.n
        self.model = model
        self.n = n
        tu = model.column.rotation_capacity
        self.tu = tu
        cmap = model.collapse_map / model.collapse_limit[:, None]
        self.g_rows = np.vstack(
            [model.arg_map / tu[:, None], -model.arg_map / tu[:, None], -cmap, cmap]
        )
        self.track = np.vstack([cmap, model.column.heights[None, :]])
        self.c_vec = np.full(n, model.collapse_ratio)
        self._cache: dict = {}

    def modes(self, k: np.ndarray) -> Decomposition:
        """The modes of the pieces of indices k (one per interface), cached."""
        key = tuple(int(x) for x in k)
        dec = self._cache.get(key)
        if dec is None:
            model = self.model
            slopes = np.array([law.slopes[kk] for kk, law in zip(key, model.laws, strict=True)])
            stiff = model.stiffness(slopes)
            stiff = 0.5 * (stiff + stiff.T)
            lam, phi = eigh(stiff, model.mass)
            to_modal = phi.T @ model.mass
            dec = Decomposition(lam, phi, to_modal, -(phi.T @ model.ground_load))
            self._cache[key] = dec
        return dec


class LinearPiece:
    """The motion inside one set of active law pieces under one forcing, from a point.

    The integrator advances it from its latest point (t, q, v): the closed form is exact
    from any point, and advancing from the latest one keeps the arguments of the
    trigonometric and exponential functions small. (t0, q0, v0) is where it starts.
    """

    def __init__(
        self,
        system: ModalSystem,
        pieces: Pieces,
        forcing: Forcing,
        t: float,
        theta: np.ndarray,
        rate: np.ndarray,
    ) -> None:
        model = system.model
        dec = system.modes(pieces.k)
        self.system, self.dec, self.forcing = system, dec, forcing
        self.lam, self.phi = dec.lam, dec.phi
        sides = zip(pieces.side, pieces.k, model.laws, strict=True)
        a = np.array([s * law.intercepts[k] for s, k, law in sides])
        self.f = -(dec.phi.T @ (model.diff.T @ a))
        self.g = dec.g
        self.t0 = t
        self.q0 = dec.to_modal @ theta
        self.v0 = dec.to_modal @ rate
        self._rows(system, pieces)
        self._eligible()

    def _rows(self, system: ModalSystem, pieces: Pieces) -> None:
        """Event rows (law bounds, collapse; then silent zero crossings) and peak rows."""
        lo, hi = pieces.bounds()
        tu = system.tu
        h0 = (
            np.concatenate(
                [np.minimum(-lo / tu, BIG), np.minimum(hi / tu, BIG), system.c_vec, system.c_vec]
            )
            + EVENT_EPS
        )
        rows = system.g_rows
        silent = np.nonzero(pieces.awaiting)[0]
        if silent.size:
            srows = (pieces.side[silent] / tu[silent])[:, None] * system.model.arg_map[silent]
            rows = np.vstack([rows, srows])
            h0 = np.concatenate([h0, np.zeros(silent.size)])
        self.silent = silent
        self.rows = rows @ self.phi
        self.abs_rows = np.abs(self.rows)
        self.h0 = h0
        self.track = system.track @ self.phi
        self.abs_track = np.abs(self.track)

    def _eligible(self) -> None:
        """Modes whose free oscillation may be bounded by its envelope (exact_bounds)."""
        self.elig = eligible(self.lam, self.forcing)
        self.w = np.sqrt(np.where(self.elig, self.lam, 1.0))

    # ------------------------------------------------------------------ motion
    def at(self, t: float, q: np.ndarray, v: np.ndarray, tau: float):
        """(q, v) at t + tau [s] from (q, v) at t [s]."""
        return advance(self.lam, q, v, self.f, self.g, self.forcing, t, tau)

    def theta(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Drum rotations [rad] and rates [rad/s] of modal (q, v)."""
        return self.phi @ q, self.phi @ v

    def distances(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Event distances d and rates d' of modal (q, v)."""
        return self.rows @ q + self.h0, self.rows @ v

    def peaks(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Tracked quantities z (collapse ratios, top displacement) and rates."""
        return self.track @ q, self.track @ v

    def modal_accel(self, t: float, q: np.ndarray) -> np.ndarray:
        """q'' at time t [s]."""
        return -self.lam * q + self.f + self.g * self.forcing.accel(t)
