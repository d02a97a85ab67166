"""The forms a ground acceleration a_g(t) [m/s^2] takes, as the integrators evaluate them.

A :class:`~rbm_cli.physics.excitation.GroundMotion` is one of four forms, each a formula of
time with a few numbers (``gain`` [m/s^2], ``omega`` [rad/s], ``phase`` [rad], ``center``
[s], ``gamma`` [-]) or a table of samples:

- ``SINE``: gain sin(omega t + phase) (harmonic, half-sine, one-sine, cycloidal);
- ``RICKER``: gain (1 - 2 u^2) exp(-u^2), u = (omega / 2)(t - center) (omega = 2 pi f_p);
- ``MP``: the Mavroeidis-Papageorgiou acceleration, x = omega (t - center),
  gain (-pi / gamma) [sin(x / gamma) cos(x + phase) + gamma sin(x + phase)(1 + cos(x / gamma))]
  (a cosine computed as sin(y + pi/2), as the kernel does);
- ``SAMPLED``: linear between samples (times, values), 0 before the first and after the last.

The compiled kernel evaluates the same formulas (rbm_cli.models.ground), in the
same order of operations. Between consecutive ``knots`` a_g is monotone (the samples of a
record; the extrema of a Ricker or MP pulse), which makes the search for the first time
|a_g| exceeds a level (:func:`exceedance_on_pieces`) exact: linear for samples, bisection
to the last bit for a formula.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import lru_cache

import numpy as np

from rbm_cli.config.types import G
from rbm_cli.physics.pulses import mp_shape

SINE, RICKER, MP, SAMPLED = 0, 1, 2, 3

#: excitation kind -> form
FORM_OF_KIND = {
    "harmonic": SINE,
    "half-sine": SINE,
    "free": SINE,
    "one-sine": SINE,
    "cycloidal": SINE,
    "ricker": RICKER,
    "mavroeidis-papageorgiou": MP,
    "record": SAMPLED,
}

#: Bisection steps of :func:`exceedance_on_pieces` on a formula (more than a double has).
BISECTION_STEPS = 200


def sampled_value(t: float, times: np.ndarray, values: np.ndarray) -> float:
    """Linear interpolation of (times [s], values) at t [s]; 0 outside [times[0], times[-1]].

    a_k + (a_{k+1} - a_k) ((t - t_k) / (t_{k+1} - t_k)), the kernel's operations."""
    n = times.size
    if t < times[0] or t > times[n - 1]:
        return 0.0
    k = int(np.searchsorted(times, t, side="right")) - 1
    if k >= n - 1:
        return float(values[n - 1])
    t0 = times[k]
    return float(values[k] + (values[k + 1] - values[k]) * ((t - t0) / (times[k + 1] - t0)))


def scalar_form(
    form: int,
    gain: float,
    omega: float,
    phase: float,
    center: float,
    gamma: float,
    times: np.ndarray | None,
    values: np.ndarray | None,
) -> Callable[[float], float]:
    """a_g(t) [m/s^2] of a form, as a function of a float t [s] (no support window: the
    integrators call it only inside the forced segments of the motion)."""
    if gain == 0.0:
        return lambda tt: 0.0
    if form == SINE:
        return lambda tt, amp=gain, om=omega, ph=phase: amp * math.sin(om * tt + ph)
    if form == RICKER:
        half = 0.5 * omega

        def ricker(tt):
            u = half * (tt - center)
            u2 = u * u
            return gain * (1.0 - 2.0 * u2) * math.exp(-u2)

        return ricker
    if form == MP:
        k = -(math.pi / gamma)
        half_pi = 0.5 * math.pi  # cos(y) as sin(y + pi/2), as the kernel computes it

        def mp(tt):
            x = omega * (tt - center)
            xg = x / gamma
            return (
                gain
                * k
                * (
                    math.sin(xg) * math.sin(x + phase + half_pi)
                    + gamma * math.sin(x + phase) * (1.0 + math.sin(xg + half_pi))
                )
            )

        return mp
    if form == SAMPLED:
        if gain == 1.0:
            return lambda tt: sampled_value(tt, times, values)
        return lambda tt: gain * sampled_value(tt, times, values)
    raise ValueError(f"unknown ground form {form}")


def _solve_piece(a, tl: float, tr: float, target: float) -> float:
    """Bisection for a(t) = target on [tl, tr], a monotone with s (a(tl) - target) <= 0 <
    s (a(tr) - target), s = sign(target): the earliest float past the crossing."""
    s = 1.0 if target > 0.0 else -1.0
    lo, hi = tl, tr
    for _ in range(BISECTION_STEPS):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if s * (a(mid) - target) > 0.0:
            hi = mid
        else:
            lo = mid
    return hi


def gravity_factor(t: float, knots: np.ndarray, vertical: np.ndarray) -> float:
    """(g + a_v(t)) / g [-] of an upward ground acceleration sampled at the knots (1 before
    the first and after the last sample), as the kernel computes it."""
    return 1.0 + sampled_value(t, knots, vertical) / G


def exceedance_on_pieces(
    a,
    knots: np.ndarray,
    t0: float,
    level: float,
    last: float,
    values: np.ndarray | None = None,
    vertical: np.ndarray | None = None,
) -> float | None:
    """First time t in [t0, last) with |a(t)| > level [m/s^2], or None.

    a_g must be monotone between consecutive knots [s] (and 0 before knots[0] and after
    knots[-1]). With ``values`` (a_g at the knots: a sampled form) the crossing is solved
    on the straight line between two samples, and a jump (at knots[0], or a knot written
    twice) is met there; otherwise by bisection. With ``vertical`` (a_v at the knots
    [m/s^2], a sampled form only) the level is level (g + a_v(t)) / g, a line too. The
    time returned is where |a_g| reaches the level (t0 itself when already above).
    """
    if t0 >= last:
        return None

    def lev(t):
        return level if vertical is None else level * gravity_factor(t, knots, vertical)

    if abs(a(t0)) > lev(t0):
        return t0
    k = int(np.searchsorted(knots, t0, side="right"))
    tl = t0
    while True:
        tr = min(float(knots[k]) if k < knots.size else last, last)
        ar = a(tr)
        if abs(ar) > lev(tr):
            target = level if ar > 0.0 else -level
            if values is None:
                t = _solve_piece(a, tl, tr, target)
            elif k == 0 or knots[k] == knots[k - 1]:
                t = tr  # a jump: from rest to the first sample, or a knot written twice
            else:
                t = _line_crossing(knots, values, vertical, k, target)
                t = min(max(t, tl), tr)
            return t if t < last else None
        if tr >= last:
            return None
        tl = tr
        k += 1


def _line_crossing(knots, values, vertical, k: int, target: float) -> float:
    """Where a_g = target (g + a_v) / g on the straight piece [knots[k-1], knots[k]]."""
    t_a, t_b = float(knots[k - 1]), float(knots[k])
    a_a, a_b = float(values[k - 1]), float(values[k])
    if vertical is None:
        return t_a + (target - a_a) * ((t_b - t_a) / (a_b - a_a))
    f_a = a_a - target * (1.0 + float(vertical[k - 1]) / G)
    f_b = a_b - target * (1.0 + float(vertical[k]) / G)
    return t_a + (t_b - t_a) * (f_a / (f_a - f_b))


def ricker_knots(omega: float, center: float) -> np.ndarray:
    """Ends of the monotone pieces of a Ricker wavelet on [0, 2 center] [s]: its extrema at
    u = 0 and u = +-sqrt(3/2), u = (omega / 2)(t - center)."""
    d = math.sqrt(1.5) / (0.5 * omega)
    return np.array([0.0, center - d, center, center + d, 2.0 * center])


@lru_cache(maxsize=256)
def _mp_extrema(gamma: float, nu: float) -> tuple[float, ...]:
    """Extrema of the MP shape (pulses.mp_shape) over s in [-gamma/2, gamma/2] [cycles]:
    sign changes of its slope on 400 points a cycle, each refined by Brent's method."""
    from scipy.optimize import minimize_scalar  # here: no scipy at import (a shorter start-up)

    half = gamma / 2.0
    s = np.linspace(-half, half, int(400 * gamma) + 1)
    v = mp_shape(s, gamma, nu)
    slope = np.diff(v)
    out = []
    for i in np.nonzero(slope[:-1] * slope[1:] < 0.0)[0]:
        sign = 1.0 if slope[i] > 0.0 else -1.0  # rising then falling: a maximum
        best = minimize_scalar(
            lambda x, sign=sign: -sign * float(mp_shape(x, gamma, nu)),
            bounds=(s[i], s[i + 2]),
            method="bounded",
            options={"xatol": 1e-13 * max(1.0, gamma)},
        )
        out.append(float(best.x))
    return tuple(out)


def mp_knots(frequency_hz: float, gamma: float, nu: float) -> np.ndarray:
    """Ends of the monotone pieces of the MP pulse on [0, gamma / f_p] [s]."""
    center = gamma / (2.0 * frequency_hz)
    inner = [center + s / frequency_hz for s in _mp_extrema(float(gamma), float(nu))]
    return np.array([0.0, *inner, 2.0 * center])


def sampled_displacement(times: np.ndarray, values: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Ground displacement [m] from rest of the piecewise-linear acceleration (times [s],
    values [m/s^2]), exact (cubic between samples; a time written twice is a jump);
    after the last sample the ground keeps its velocity (the acceleration is 0 there)."""
    t = np.asarray(t, dtype=float)
    h = np.diff(times)
    a0, a1 = values[:-1], values[1:]
    v = np.concatenate([[0.0], np.cumsum(h * (a0 + a1) / 2.0)])
    u = np.concatenate([[0.0], np.cumsum(v[:-1] * h + h * h * (2.0 * a0 + a1) / 6.0)])
    k = np.clip(np.searchsorted(times, t, side="right") - 1, 0, times.size - 2)
    tau = np.clip(t - times[k], 0.0, None)
    slopes = np.divide(np.diff(values), h, out=np.zeros_like(h), where=h > 0.0)  # jumps: h = 0
    slope = slopes[k]
    inside = u[k] + v[k] * tau + values[k] * tau**2 / 2.0 + slope * tau**3 / 6.0
    after = u[-1] + v[-1] * (t - times[-1])
    out = np.where(t > times[-1], after, inside)
    return np.where(t < times[0], 0.0, out)
