"""Closed-form solution of the piecewise-linear rocking equation, written for the tests.

    theta'' = p^2 (theta - s alpha) - p^2 a_g(t) / g,   s = sign(theta)

(Spanos and Koh 1984; the rigid RBM with n = 1 reduces to it with
alpha = B/H and p^2 = m g (H/2) / (I_G + m H^2/4)). Between events the
solution is s alpha + C sin(w t + phi) + c1 cosh(p tau) + c2 sinh(p tau), with
C = p^2 A / (p^2 + w^2) while the sine acts (A in g) and C = 0 after a pulse.
Events (uplift, theta = 0 impacts, |theta| = alpha collapse) are found by
scanning the closed form and refining with brentq. Nothing here uses rbm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq


@dataclass
class Piece:
    t0: float
    s: int
    c1: float
    c2: float
    forced: bool


@dataclass
class ClosedFormResult:
    collapsed: bool
    t_collapse: float
    peak_ratio: float  # max |theta| / alpha
    n_impacts: int


class LinearRocking:
    def __init__(self, alpha, p, amplitude_g, omega, phase, pulse_end, t_end, e=1.0):
        self.alpha, self.p = alpha, p
        self.A, self.w, self.phi = amplitude_g, omega, phase
        self.pulse_end, self.t_end, self.e = pulse_end, t_end, e
        self.C = p * p * amplitude_g / (p * p + omega * omega)

    def _make(self, t0, th0, v0, s, forced):
        C = self.C if forced else 0.0
        sn, cs = math.sin(self.w * t0 + self.phi), math.cos(self.w * t0 + self.phi)
        c1 = th0 - s * self.alpha - C * sn
        c2 = (v0 - C * self.w * cs) / self.p
        return Piece(t0, s, c1, c2, forced)

    def theta(self, pc, t):
        C = self.C if pc.forced else 0.0
        tau = np.asarray(t) - pc.t0
        return (
            pc.s * self.alpha
            + C * np.sin(self.w * np.asarray(t) + self.phi)
            + pc.c1 * np.cosh(self.p * tau)
            + pc.c2 * np.sinh(self.p * tau)
        )

    def rate(self, pc, t):
        C = self.C if pc.forced else 0.0
        tau = np.asarray(t) - pc.t0
        return (
            C * self.w * np.cos(self.w * np.asarray(t) + self.phi)
            + self.p * pc.c1 * np.sinh(self.p * tau)
            + self.p * pc.c2 * np.cosh(self.p * tau)
        )

    def _uplift_time(self, t0, t_stop):
        """First t in [t0, t_stop) with |A sin(w t + phi)| > alpha (scan + brentq)."""
        if self.A <= self.alpha:
            return None
        ts = np.arange(t0, t_stop, 1e-4)
        vals = np.abs(self.A * np.sin(self.w * ts + self.phi)) - self.alpha
        idx = np.nonzero(vals > 0)[0]
        if len(idx) == 0:
            return None
        k = idx[0]
        if k == 0:
            return t0
        return brentq(
            lambda t: abs(self.A * math.sin(self.w * t + self.phi)) - self.alpha,
            ts[k - 1],
            ts[k],
            xtol=1e-15,
        )

    def solve(self, dt=5e-4) -> ClosedFormResult:
        t = 0.0
        peak, impacts = 0.0, 0
        t_up = self._uplift_time(0.0, self.pulse_end)
        if t_up is None:
            return ClosedFormResult(False, math.nan, 0.0, 0)
        a_now = self.A * math.sin(self.w * t_up + self.phi)
        s = -1 if a_now > 0 else 1
        pc = self._make(t_up, 0.0, 0.0, s, t_up < self.pulse_end)
        t = t_up
        while t < self.t_end:
            stop = self.pulse_end if pc.forced else self.t_end
            stop = min(stop, self.t_end)
            ts = np.arange(t, stop, dt)
            ts = np.append(ts[1:], stop)
            th = self.theta(pc, ts)
            # impact: theta back to zero (from side s); collapse: |theta| = alpha
            gz = pc.s * th
            gc = self.alpha - np.abs(th)
            hit_z = np.nonzero(gz <= 0)[0]
            hit_c = np.nonzero(gc <= 0)[0]
            first = min(hit_z[0] if len(hit_z) else len(ts), hit_c[0] if len(hit_c) else len(ts))
            lo_t = t if first == 0 else ts[first - 1]
            # peak over the scanned part up to the event
            seg_ts = (
                np.concatenate([[t], ts[: first + 1]])
                if first < len(ts)
                else np.concatenate([[t], ts])
            )
            rates = self.rate(pc, seg_ts)
            for j in np.nonzero(rates[:-1] * rates[1:] < 0)[0]:
                tp = brentq(lambda x, pc=pc: self.rate(pc, x), seg_ts[j], seg_ts[j + 1], xtol=1e-15)
                peak = max(peak, abs(float(self.theta(pc, tp))) / self.alpha)
            if first == len(ts):  # no event before `stop`
                th_end = float(self.theta(pc, stop))
                v_end = float(self.rate(pc, stop))
                peak = max(peak, abs(th_end) / self.alpha)
                if stop >= self.t_end:
                    return ClosedFormResult(False, math.nan, peak, impacts)
                pc = self._make(stop, th_end, v_end, pc.s, False)
                t = stop
                continue
            is_collapse = len(hit_c) and hit_c[0] == first
            if is_collapse:
                tc = brentq(
                    lambda x, pc=pc: self.alpha - abs(float(self.theta(pc, x))),
                    lo_t,
                    ts[first],
                    xtol=1e-15,
                )
                return ClosedFormResult(True, tc, 1.0, impacts)
            ti = brentq(lambda x, pc=pc: float(self.theta(pc, x)), lo_t, ts[first], xtol=1e-15)
            v = float(self.rate(pc, ti)) * self.e
            impacts += 1
            pc = self._make(ti, 0.0, v, -pc.s, pc.forced and ti < self.pulse_end)
            t = ti
        return ClosedFormResult(False, math.nan, peak, impacts)
