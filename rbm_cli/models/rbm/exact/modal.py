"""Closed-form motion of one modal coordinate of a linear piece (numba), one mode at a time.

Inside one set of active law pieces the column's equations are linear with constant
coefficients, M theta'' + K theta = -F0 - r a_g(t). With the M-orthonormal modes of the
pencil (K, M) (rbm_cli.models.rbm.exact.piece), each modal coordinate obeys

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

A forcing is a float array fc of FORCING_SIZE entries: [kind, amplitude [m/s^2],
omega [rad/s], phase [rad], t0 [s], a0 [m/s^2], a1 [m/s^3]], kind ZERO, HARMONIC
(a_g = amplitude sin(omega t + phase), absolute t) or LINEAR (a_g = a0 + a1 (t - t0)).
"""

from __future__ import annotations

import math

import numpy as np

from rbm_cli.base.jit import jit
from rbm_cli.inputs.ground import sine_exceedance, sine_peak

#: Terms of the power series of C, S, S2, S3 tabulated (used for |lam| tau^2 < 1: the
#: last term is below 1e-26 of the first; _terms takes as many as a given |z| needs).
SERIES_TERMS = 14
#: The harmonic response uses its resonance-stable form for modes with
#: |w - omega| < RESONANCE_BAND omega, the plain particular-solution form elsewhere.
RESONANCE_BAND = 0.5

ZERO, HARMONIC, LINEAR = 0, 1, 2
FORCING_SIZE = 7


@jit(borrow=True)
def f_accel(fc, t):
    """a_g(t) [m/s^2]."""
    kind = int(fc[0])
    if kind == HARMONIC:
        return fc[1] * math.sin(fc[2] * t + fc[3])
    if kind == LINEAR:
        return fc[5] + fc[6] * (t - fc[4])
    return 0.0


@jit
def linear_exceedance(fc, t0, level, t_stop):
    """First t in [t0, t_stop) with |a_g(t)| > level [m/s^2] under a linear forcing fc:
    t0 when already above, else where |a_g| reaches level (-1 if not before t_stop [s])."""
    a = f_accel(fc, t0)
    if abs(a) > level:
        return t0
    slope = fc[6]
    if slope == 0.0:
        return -1.0
    target = level if slope > 0.0 else -level
    t = t0 + (target - a) / slope
    return t if t < t_stop else -1.0


@jit
def f_peak_on(fc, t0, t1):
    """max over [t0, t1] of |a_g| [m/s^2]: a harmonic's crest or ends (sine_peak), a line's
    ends."""
    kind = int(fc[0])
    if kind == HARMONIC:
        return sine_peak(t0, t1, fc[1], fc[2], fc[3])
    if kind == LINEAR:
        return max(abs(f_accel(fc, t0)), abs(f_accel(fc, t1)))
    return 0.0


@jit
def f_exceedance(fc, t0, level, t_stop):
    """First t in [t0, t_stop) with |a_g(t)| > level [m/s^2] (-1: none)."""
    kind = int(fc[0])
    if kind == HARMONIC:
        return sine_exceedance(t0, level, fc[1], fc[2], fc[3], t_stop)
    if kind == LINEAR:
        return linear_exceedance(fc, t0, level, t_stop)
    return -1.0


@jit(borrow=True)
def f_peak(fc, t, h):
    """Bound of |a_g| on [t, t + h] [m/s^2]."""
    kind = int(fc[0])
    if kind == HARMONIC:
        return abs(fc[1])
    if kind == LINEAR:
        return max(abs(f_accel(fc, t)), abs(f_accel(fc, t + h)))
    return 0.0


@jit(borrow=True)
def f_phase(fc, t):
    """Phase [rad] of a harmonic forcing seen from t: a_g(t + tau) = A sin(om tau + phase)."""
    return np.fmod(fc[2] * t + fc[3], 2.0 * math.pi)  # exact, as math.fmod


#: 1 / (2k + first)!, rows first = 0..3, k < SERIES_TERMS (Horner coefficients).
_INV_FACT = np.array(
    [[1.0 / math.factorial(2 * k + first) for k in range(SERIES_TERMS)] for first in range(4)]
)


@jit
def _terms(az):
    """Terms of the series enough for |z| = az <= 1 (the next one below 1e-17 relative)."""
    if az < 1e-6:
        return 3
    if az < 1e-3:
        return 5
    if az < 0.1:
        return 7
    return 10


@jit
def _series(z, first, terms):
    """sum_k (-z)^k / (2k + first)!, k < terms (Horner)."""
    out = _INV_FACT[first, terms - 1]
    for k in range(terms - 2, -1, -1):
        out = _INV_FACT[first, k] - z * out
    return out


@jit
def basis1(lam, tau):
    """(C, S, S2, S3) of one mode at tau [s] (equation (1) of the module docstring)."""
    z = lam * tau * tau
    if abs(z) < 1.0:
        m = _terms(abs(z))
        return (_series(z, 0, m), tau * _series(z, 1, m), tau * tau * _series(z, 2, m),
                tau * tau * tau * _series(z, 3, m))  # fmt: skip
    if lam > 0.0:
        w = math.sqrt(lam)
        c = math.cos(w * tau)
        s = math.sin(w * tau) / w
        return c, s, (1.0 - c) / lam, (tau - s) / lam
    k = math.sqrt(-lam)
    c = math.cosh(k * tau)
    s = math.sinh(k * tau) / k
    return c, s, (c - 1.0) / (k * k), (s - tau) / (k * k)


@jit
def near_resonance(lam, om):
    """Whether a mode takes the resonance-stable form of the harmonic response."""
    return lam > 0.0 and abs(math.sqrt(lam) - om) < RESONANCE_BAND * om


@jit
def harmonic_near(lam, tau, om, phase, c, s):
    """(Y, Y') of q'' + lam q = sin(om tau + phase) from rest, resonance-stable form (module
    docstring), given C = c and S = s of the same tau."""
    w = math.sqrt(lam)
    sig, dlt = w + om, w - om
    arg = 0.5 * sig * tau + phase
    half = 0.5 * dlt * tau
    sinc = math.sin(half) / half if half != 0.0 else 1.0
    ca, sa = math.cos(arg), math.sin(arg)
    cph = math.cos(phase)
    y = (cph * s - tau * ca * sinc) / sig
    dy = (cph * c + sig * sa * 0.5 * tau * sinc - ca * math.cos(half)) / sig
    return y, dy


@jit(borrow=True)
def advance(lam, q, v, f, g, fc, t, tau, qn, vn):
    """Modal coordinates and rates (q, v) at t + tau [s] from (q, v) at t, exactly, into
    (qn, vn) (equation (1) of the module docstring, the forcing fc read from absolute time
    t; lam [1/s^2], f and g per mode)."""
    kind = int(fc[0])
    harmonic = kind == HARMONIC and fc[1] != 0.0
    om = fc[2]
    sph = cph = sw = cw = a0 = phase = 0.0
    if harmonic:  # the forcing's sines, shared by the modes
        phase = f_phase(fc, t)
        sph, cph = math.sin(phase), math.cos(phase)
        sw, cw = math.sin(om * tau + phase), math.cos(om * tau + phase)
    elif kind == LINEAR:
        a0 = f_accel(fc, t)
    for j in range(lam.size):
        lj = lam[j]
        c, s, s2, s3 = basis1(lj, tau)
        qj = q[j] * c + v[j] * s + f[j] * s2
        vj = v[j] * c - lj * q[j] * s + f[j] * s
        if harmonic:
            if near_resonance(lj, om):
                y, dy = harmonic_near(lj, tau, om, phase, c, s)
            else:
                den = lj - om * om
                y = (sw - sph * c - om * cph * s) / den
                dy = (om * cw + lj * sph * s - om * cph * c) / den
            qj += g[j] * fc[1] * y
            vj += g[j] * fc[1] * dy
        elif kind == LINEAR:
            qj += g[j] * (a0 * s2 + fc[6] * s3)
            vj += g[j] * (a0 * s + fc[6] * s2)
        qn[j] = qj
        vn[j] = vj
