"""The closed-form pieces of the piecewise-linear rocking block (`housner-linear`,
rbm_cli.models.housner_linear): the motion on one side between two events, what the scan
of a piece (housner_linear.scan_piece) finds, and the root finding it refines events with.

References
----------
.. [1] P. D. Spanos and A.-S. Koh (1984). Rocking of rigid blocks due to
   harmonic shaking. Journal of Engineering Mechanics 110(11), 1627-1642.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq


@dataclass(frozen=True)
class LinearPiece:
    """Closed-form motion on side s between two events, from time t0 [s].

    theta(tau) = s alpha + C sin(omega tau + phi0) + c1 exp(p tau) + c2 exp(-p tau),
    tau = t - t0 [s]; C = p^2 A / (p^2 + omega^2), A the ground amplitude in g
    (C = 0 in free motion). Under a straight-line ground acceleration (a record between
    two samples), a_g / g = q0 + q1 tau, the particular solution is the line itself:
    theta(tau) = s alpha + q0 + q1 tau + c1 exp(p tau) + c2 exp(-p tau) (C = 0).
    """

    t0: float
    side: int
    alpha: float
    p: float
    forced_amplitude: float  # C [rad]
    omega: float
    phi0: float
    c1: float
    c2: float
    q0: float = 0.0  # a_g / g at t0 of a straight-line ground acceleration [-]
    q1: float = 0.0  # its slope [1/s]

    @classmethod
    def start(cls, t0, theta0, rate0, side, alpha, p, amplitude_g, omega, phase):
        """The piece through (theta0 [rad], rate0 [rad/s]) at t0 [s]; amplitude_g = A [g]."""
        c = p * p * amplitude_g / (p * p + omega * omega) if amplitude_g else 0.0
        phi0 = math.fmod(omega * t0 + phase, 2.0 * math.pi) if c else 0.0
        x0 = theta0 - side * alpha - c * math.sin(phi0)
        v0 = rate0 - c * omega * math.cos(phi0)
        return cls(t0, side, alpha, p, c, omega, phi0, 0.5 * (x0 + v0 / p), 0.5 * (x0 - v0 / p))

    @classmethod
    def start_line(cls, t0, theta0, rate0, side, alpha, p, q0, q1):
        """The piece through (theta0 [rad], rate0 [rad/s]) at t0 [s] under the ground
        acceleration a_g / g = q0 + q1 (t - t0) [-]."""
        x0 = theta0 - side * alpha - q0
        v0 = rate0 - q1
        c1, c2 = 0.5 * (x0 + v0 / p), 0.5 * (x0 - v0 / p)
        return cls(t0, side, alpha, p, 0.0, 0.0, 0.0, c1, c2, q0, q1)

    def _exps(self, tau):
        tau = np.asarray(tau, dtype=float)
        with np.errstate(divide="ignore", over="ignore"):
            # c * exp(x) as sign(c) exp(log|c| + x): no 0 * inf when c = 0
            e1 = np.sign(self.c1) * np.exp(np.log(abs(self.c1)) + self.p * tau)
            e2 = np.sign(self.c2) * np.exp(np.log(abs(self.c2)) - self.p * tau)
        return tau, e1, e2

    def theta(self, tau):
        """Rotation theta(t0 + tau) [rad]."""
        tau, e1, e2 = self._exps(tau)
        forced = self.forced_amplitude * np.sin(self.omega * tau + self.phi0)
        if self.q0 != 0.0 or self.q1 != 0.0:
            forced = forced + (self.q0 + self.q1 * tau)
        return self.side * self.alpha + forced + e1 + e2

    def rate(self, tau):
        """Rate theta'(t0 + tau) [rad/s]."""
        tau, e1, e2 = self._exps(tau)
        forced = self.forced_amplitude * self.omega * np.cos(self.omega * tau + self.phi0)
        if self.q1 != 0.0:
            forced = forced + self.q1
        return forced + self.p * (e1 - e2)


@dataclass
class Scan:
    """What a piece does up to its first event (times from the piece start) [s]."""

    tau: float  # end of the piece: the event, or the end of the segment
    kind: str | None  # 'impact', 'collapse' or None
    peak: float  # largest s theta on [0, tau] [rad]
    tau_peak: float | None  # time of an interior maximum (theta' = 0) holding the peak
    n_evals: int


class PieceScanner:
    """s theta and s theta' of a piece (evaluations counted in n_evals) and the roots of
    its events: impact (s theta + eps = 0, then s theta = 0) and collapse (s theta = limit)."""

    def __init__(self, piece: LinearPiece, eps: float, limit: float):
        self.piece = piece
        self.s = piece.side
        self.eps = eps
        self.limit = limit
        self.n_evals = 0

    def f(self, x):
        self.n_evals += 1
        return self.s * float(self.piece.theta(x))

    def df(self, x):
        self.n_evals += 1
        return self.s * float(self.piece.rate(x))

    @staticmethod
    def root(fun, a, b):
        return brentq(fun, a, b, xtol=1e-15)

    def impact(self, a, b):
        """The impact time in [a, b]: f(a) > eps, f(b) <= 0: the root of f; else (f(a) within
        eps of 0, as at a restart from theta = 0, where f's round-off has either sign) the
        root of f + eps, then Newton to f = 0. A root of f itself from such an f(a) could be
        a sign change of the round-off next to a (three impacts within 3e-14 s, then a
        million: tests/test_housner_linear.py)."""
        f, df, root, eps = self.f, self.df, self.root, self.eps
        if f(a) > eps:
            return root(f, a, b)
        tau = root(lambda x: f(x) + eps, a, b)
        for _ in range(2):
            v = df(tau)
            if v >= 0.0:
                break
            tau = min(max(tau - f(tau) / v, a), b)
        return tau

    def collapse(self, a, b):
        """The time in [a, b] where s theta reaches the limit."""
        return self.root(lambda x: self.f(x) - self.limit, a, b)
