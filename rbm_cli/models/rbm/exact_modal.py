"""Closed-form motion of one modal coordinate of a linear piece (the exact integrator).

Inside one set of active law pieces the column's equations are linear with constant
coefficients, M theta'' + K theta = -F0 - r a_g(t). With the M-orthonormal modes of the
pencil (K, M) (rbm_cli.models.rbm.exact_piece), each modal coordinate obeys

    q'' + lam q = f + g a_g(t)                                             (1)

lam [1/s^2] of either sign (rising law pieces give lam > 0, oscillatory; descending ones
lam < 0, exponential; a flat piece lam = 0), f and g constants. Its solution from
(q0, v0) at tau = 0 is

    q(tau) = q0 C(tau) + v0 S(tau) + f S2(tau) + g Y(tau)

with the fundamental functions, continuous in lam through lam = 0,

    C  = cos(w tau)  | cosh(k tau)          (w = sqrt(lam), k = sqrt(-lam))
    S  = int_0^tau C = sin(w tau) / w | sinh(k tau) / k
    S2 = int_0^tau S = (1 - C) / lam      (tau^2 / 2 at lam = 0)
    S3 = int_0^tau S2 = (tau - S) / lam   (tau^3 / 6 at lam = 0)

(power series for |lam| tau^2 < 1, so no cancellation near lam = 0; beyond it the
differences lose at most an absolute eps / |lam|), and Y the response
from rest to the ground acceleration:

- harmonic, a_g = A sin(Om tau + phi): Y = A [sin(Om tau + phi) - sin(phi) C
  - Om cos(phi) S] / (lam - Om^2), except near resonance (lam > 0, |w - Om| <
  RESONANCE_BAND Om), where the same function is written
  Y = A [cos(phi) S - tau cos(sig tau / 2 + phi) sinc(del tau / 2)] / (w + Om),
  sig = w + Om, del = w - Om: exact at resonance (w = Om gives the tau cos term) and
  without cancellation near it;
- piecewise linear, a_g = a0 + a1 tau (a sampled record, exact on each sample interval
  as in Nigam and Jennings' response spectra): Y = a0 S2 + a1 S3.

All functions take arrays of lam (one per mode) and a scalar tau [s].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Terms of the power series of C, S, S2, S3 (used for |lam| tau^2 < 1: the last term is
#: below 1e-26 of the first).
SERIES_TERMS = 14
#: The harmonic response uses its resonance-stable form for modes with
#: |w - omega| < RESONANCE_BAND omega, the plain particular-solution form elsewhere.
RESONANCE_BAND = 0.5


@dataclass(frozen=True)
class Forcing:
    """The ground acceleration on a segment of the motion, from absolute time t [s].

    kind : str  'harmonic' (a_g = amplitude sin(omega t + phase)), 'linear'
        (a_g = a0 + a1 (t - t0), t0 the segment's start) or 'zero'
    amplitude [m/s^2], omega [rad/s], phase [rad]: the harmonic's
    t0 [s], a0 [m/s^2], a1 [m/s^3]: the linear piece's
    """

    kind: str
    amplitude: float = 0.0
    omega: float = 0.0
    phase: float = 0.0
    t0: float = 0.0
    a0: float = 0.0
    a1: float = 0.0

    def accel(self, t: float) -> float:
        """a_g(t) [m/s^2]."""
        if self.kind == "harmonic":
            return self.amplitude * math.sin(self.omega * t + self.phase)
        if self.kind == "linear":
            return self.a0 + self.a1 * (t - self.t0)
        return 0.0

    def peak(self, t: float, h: float) -> float:
        """Bound of |a_g| on [t, t + h] [m/s^2]."""
        if self.kind == "harmonic":
            return abs(self.amplitude)
        if self.kind == "linear":
            return max(abs(self.accel(t)), abs(self.accel(t + h)))
        return 0.0

    def local(self, t: float) -> tuple[float, float]:
        """(phase [rad], a0 [m/s^2]) of the forcing seen from time t: a_g(t + tau) =
        amplitude sin(omega tau + phase) (harmonic) or a0 + a1 tau (linear)."""
        if self.kind == "harmonic":
            return math.fmod(self.omega * t + self.phase, 2.0 * math.pi), 0.0
        return 0.0, self.accel(t)


def _series_all(z: np.ndarray, first: int) -> np.ndarray:
    """sum_k (-z)^k / (2k + first)! by Horner on the ratio of consecutive terms."""
    out = np.ones_like(z)
    for k in range(SERIES_TERMS - 1, 0, -1):
        # term_k / term_{k-1} = -z / ((2k + first - 1)(2k + first))
        out = 1.0 - z * out / ((2 * k + first - 1) * (2 * k + first))
    return out / math.factorial(first)


def basis(lam: np.ndarray, tau: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(C, S, S2, S3) of every mode at tau [s] (module docstring); lam [1/s^2]."""
    z = lam * (tau * tau)
    small = np.abs(z) < 1.0
    c = np.empty_like(lam)
    s = np.empty_like(lam)
    s2 = np.empty_like(lam)
    s3 = np.empty_like(lam)
    if small.any():
        zs = z[small]
        c[small] = _series_all(zs, 0)
        s[small] = tau * _series_all(zs, 1)
        s2[small] = tau * tau * _series_all(zs, 2)
        s3[small] = tau * tau * tau * _series_all(zs, 3)
    pos = ~small & (lam > 0.0)
    if pos.any():
        w = np.sqrt(lam[pos])
        c[pos] = np.cos(w * tau)
        s[pos] = np.sin(w * tau) / w
        s2[pos] = (1.0 - c[pos]) / lam[pos]
        s3[pos] = (tau - s[pos]) / lam[pos]
    neg = ~small & (lam < 0.0)
    if neg.any():
        k = np.sqrt(-lam[neg])
        c[neg] = np.cosh(k * tau)
        s[neg] = np.sinh(k * tau) / k
        s2[neg] = (c[neg] - 1.0) / (k * k)
        s3[neg] = (s[neg] - tau) / (k * k)
    return c, s, s2, s3


def harmonic_response(
    lam: np.ndarray, tau: float, omega: float, phase: float, c: np.ndarray, s: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(Y, Y') [s^2, s] of q'' + lam q = sin(omega tau + phase) from rest (unit amplitude),
    given C and S of the same tau (basis). Exact at resonance, stable near it."""
    y = np.empty_like(lam)
    dy = np.empty_like(lam)
    near = (lam > 0.0) & (np.abs(np.sqrt(np.abs(lam)) - omega) < RESONANCE_BAND * omega)
    if near.any():
        w = np.sqrt(lam[near])
        sig, dlt = w + omega, w - omega
        arg = 0.5 * sig * tau + phase
        half = 0.5 * dlt * tau
        sinc = np.sinc(half / math.pi)  # sin(half) / half
        ca, sa = np.cos(arg), np.sin(arg)
        cph = math.cos(phase)
        y[near] = (cph * s[near] - tau * ca * sinc) / sig
        dy[near] = (cph * c[near] + sig * sa * 0.5 * tau * sinc - ca * np.cos(half)) / sig
    far = ~near
    if far.any():
        den = lam[far] - omega * omega
        sph, cph = math.sin(phase), math.cos(phase)
        sw, cw = math.sin(omega * tau + phase), math.cos(omega * tau + phase)
        y[far] = (sw - sph * c[far] - omega * cph * s[far]) / den
        dy[far] = (omega * cw + lam[far] * sph * s[far] - omega * cph * c[far]) / den
    return y, dy


def advance(
    lam: np.ndarray,
    q: np.ndarray,
    v: np.ndarray,
    f: np.ndarray,
    g: np.ndarray,
    forcing: Forcing,
    t: float,
    tau: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Modal coordinates and rates (q, v) at t + tau [s] from (q, v) at t, exactly
    (equation (1) of the module docstring, the forcing read from absolute time t)."""
    c, s, s2, s3 = basis(lam, tau)
    qn = q * c + v * s + f * s2
    vn = v * c - lam * q * s + f * s
    if forcing.kind == "harmonic" and forcing.amplitude != 0.0:
        phase, _ = forcing.local(t)
        y, dy = harmonic_response(lam, tau, forcing.omega, phase, c, s)
        qn = qn + (g * forcing.amplitude) * y
        vn = vn + (g * forcing.amplitude) * dy
    elif forcing.kind == "linear":
        _, a0 = forcing.local(t)
        qn = qn + g * (a0 * s2 + forcing.a1 * s3)
        vn = vn + g * (a0 * s + forcing.a1 * s2)
    return qn, vn


def accel(lam: np.ndarray, q: np.ndarray, f: np.ndarray, g: np.ndarray, ag: float) -> np.ndarray:
    """Modal accelerations q'' [1/s^2 x q] for the ground acceleration ag [m/s^2]."""
    return -lam * q + f + g * ag
