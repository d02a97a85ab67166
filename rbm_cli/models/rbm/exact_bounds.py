"""Bounds of the modes of a piece over an interval: what makes the exact integrator's
sampling certain (rbm_cli.models.rbm.exact_search).

For each mode q'' + lam q = f + g a_g(t) on [a, a + h], from its state (q_a, v_a) there:

- a majorant of the linear ODE: with k^2 = |lam| and F = max |f + g a_g|,
  |q| <= |q_a| C + |v_a| S + F S2 and |q'| <= |q_a| k^2 S + |v_a| C + F S (hyperbolic C,
  S, S2 of k at h), so |q''| <= |lam| max|q| + F and |q'''| <= |lam| max|q'| + max|g a_g'|;
- for lam > 0, the energy E = v^2 + lam q^2 grows at most as sqrt(E) <= sqrt(E_a) + h F,
  which bounds |q'| and |q| for any h (the smaller of the two bounds is kept; the
  hyperbolic one only while lam h^2 < HYPERBOLIC_LIMIT, beyond which it is the larger);
- for an oscillatory mode away from resonance (lam > 0, and for a harmonic forcing
  lam >= 4 omega^2: "eligible"), the free oscillation o = q - p, p the particular solution,
  has the constant amplitude R = sqrt(o^2 + o'^2 / lam) over the whole piece, so
  |q''| <= lam R + |p''| and |q'''| <= lam^1.5 R + |p'''|; and where lam h^2 > 8 ("fast")
  the row's oscillation in that mode is better bounded by its envelope |G_j| R than by
  its curvature: the row's slow part (the row minus the fast oscillations, known at both
  ends) is bounded by curvature, the fast part by sum_j |G_j| R_j.

Every bound is inflated by SAFETY against rounding.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rbm_cli.models.rbm.exact_modal import basis

#: Bounds are inflated by this relative margin against rounding.
SAFETY = 1.0 + 1e-9
#: A mode is treated by its envelope on an interval when lam h^2 exceeds this.
ENVELOPE_RATIO = 8.0
#: For lam > 0 the hyperbolic majorant is used only while lam h^2 is below this (beyond,
#: the energy bound is the smaller).
HYPERBOLIC_LIMIT = 4.0

# the search's settings (rbm_cli.models.rbm.exact_search)
#: Shortest interval the search splits down to, relative to max(1, t) [s].
MIN_STEP = 1e-13
#: Absolute tolerance of the root finding on event times and peak times [s].
ROOT_XTOL = 1e-15
#: Relative tolerance of the peaks (running maxima of |z|).
PEAK_RTOL = 1e-12
#: A root of z' closer than this fraction of its interval to an end is taken as that end;
#: a rate below this fraction of the interval's end rates is a stationary point.
STATIONARY_GAP = 1e-9
#: First interval tried at the start of a run and of a segment [s].
FIRST_STEP = 1e-3


@dataclass
class ModeBounds:
    """Bounds of the modes on one interval [a, a + h] (module docstring).

    curv : (n,) |q''| bound of the modes treated by curvature, |p''| of the fast ones
    full : (n,) |q''| bound of every mode (all by curvature)
    third : (n,) |q'''| bound of every mode
    fast : (n,) bool, the modes treated by their envelope
    env : (n,) envelope R of the fast modes (0 for the others)
    osc_a, osc_b, rate_a, rate_b : (n,) free oscillation o and o' of the fast modes at
        both ends (0 for the others)
    """

    curv: np.ndarray
    full: np.ndarray
    third: np.ndarray
    fast: np.ndarray
    env: np.ndarray
    osc_a: np.ndarray
    osc_b: np.ndarray
    rate_a: np.ndarray
    rate_b: np.ndarray


def eligible(lam: np.ndarray, forcing) -> np.ndarray:
    """Modes whose free oscillation may be bounded by its envelope (module docstring)."""
    ok = lam > 0.0
    if forcing.kind == "harmonic":
        ok &= lam >= 4.0 * forcing.omega * forcing.omega
    return ok


def particular(piece, t: float, tau: float) -> tuple[np.ndarray, np.ndarray]:
    """Particular solution p and p' of the eligible modes at t + tau [s] (0 elsewhere), for
    the piece's forcing seen from time t."""
    lam, fo, elig = piece.lam, piece.forcing, piece.elig
    safe = np.where(elig, lam, 1.0)
    p = piece.f / safe
    dp = np.zeros_like(p)
    if fo.kind == "harmonic" and fo.amplitude != 0.0:
        phase, _ = fo.local(t)
        amp = piece.g * fo.amplitude / (safe - fo.omega**2)
        p = p + amp * math.sin(fo.omega * tau + phase)
        dp = amp * fo.omega * math.cos(fo.omega * tau + phase)
    elif fo.kind == "linear":
        _, a0 = fo.local(t)
        p = p + piece.g * (a0 + fo.a1 * tau) / safe
        dp = piece.g * fo.a1 / safe
    return np.where(elig, p, 0.0), np.where(elig, dp, 0.0)


def forcing_bounds(piece, t: float, h: float):
    """On [t, t + h]: bounds of |f + g a_g| and |g a_g'| per mode, and |p''|, |p'''| of the
    eligible modes."""
    fo, f, g = piece.forcing, piece.f, piece.g
    p2 = np.zeros_like(f)
    if fo.kind == "linear":
        a0, a1 = fo.accel(t), fo.accel(t + h)
        big = np.maximum(np.abs(f + g * a0), np.abs(f + g * a1))
        dbig = np.abs(g * fo.a1)
    else:
        peak = fo.peak(t, h)
        big = np.abs(f) + np.abs(g) * peak
        dbig = np.abs(g) * (peak * fo.omega)
    if fo.kind == "harmonic" and fo.amplitude != 0.0:
        om2 = fo.omega**2
        safe = np.where(piece.elig, piece.lam, 2.0 * om2 + 1.0)
        p2 = np.where(piece.elig, om2 * np.abs(g * fo.amplitude / (safe - om2)), 0.0)
    return big, dbig, p2, p2 * fo.omega


def _majorants(lam, q, v, h, big):
    """Bounds of |q| and |q'| on [a, a + h] (module docstring)."""
    alam = np.abs(lam)
    with np.errstate(over="ignore", invalid="ignore"):
        c, s, s2, _ = basis(-alam, h)  # may overflow to inf for a long interval
        aq, av = np.abs(q), np.abs(v)
        qmax = np.nan_to_num(aq * c + av * s + big * s2, nan=np.inf)  # 0 * inf: no bound
        vmax = np.nan_to_num(aq * alam * s + av * c + big * s, nan=np.inf)
    pos = lam > 0.0
    far = pos & (lam * h * h >= HYPERBOLIC_LIMIT)
    qmax, vmax = np.where(far, np.inf, qmax), np.where(far, np.inf, vmax)
    energy = np.sqrt(v * v + np.maximum(lam, 0.0) * q * q) + h * big
    alt = np.minimum(aq + h * energy, energy / np.sqrt(np.where(pos, lam, 1.0)))
    return np.where(pos, np.minimum(qmax, alt), qmax), np.where(pos, np.minimum(vmax, energy), vmax)


def mode_bounds(piece, t: float, q, v, h: float, qb, vb) -> ModeBounds:
    """Bounds of the piece's modes on [t, t + h] (module docstring), from (q, v) at t and
    (qb, vb) at t + h."""
    lam, elig = piece.lam, piece.elig
    big, dbig, p2, p3 = forcing_bounds(piece, t, h)
    qmax, vmax = _majorants(lam, q, v, h, big)
    full = np.abs(lam) * qmax + big
    third = np.abs(lam) * vmax + dbig
    p_a, dp_a = particular(piece, t, 0.0)
    osc_a, rate_a = np.where(elig, q - p_a, 0.0), np.where(elig, v - dp_a, 0.0)
    env = np.where(elig, np.sqrt(osc_a**2 + (rate_a / piece.w) ** 2), 0.0) * SAFETY
    full = np.where(elig, np.minimum(full, lam * env + p2), full) * SAFETY
    third = np.where(elig, np.minimum(third, lam * piece.w * env + p3), third) * SAFETY
    fast = elig & (lam * h * h > ENVELOPE_RATIO)
    if not fast.any():
        zero = np.zeros_like(lam)
        return ModeBounds(full, full, third, fast, zero, zero, zero, zero, zero)
    p_b, dp_b = particular(piece, t, h)
    return ModeBounds(
        np.where(fast, p2 * SAFETY, full), full, third, fast, np.where(fast, env, 0.0),
        np.where(fast, osc_a, 0.0), np.where(fast, qb - p_b, 0.0),
        np.where(fast, rate_a, 0.0), np.where(fast, vb - dp_b, 0.0),
    )  # fmt: skip


def hermite_root(f0: float, d0: float, fh: float, dh: float, h: float) -> float:
    """Start for the root finding in [0, h] [s] of a function with values f0, fh (f0 fh < 0)
    and rates d0, dh at the ends: the root of their cubic Hermite interpolant (Newton on the
    cubic from the secant's root, kept inside the interval). Plain arithmetic, compiled as
    is by rbm_cli.models.rbm.exact_jit_search."""
    m0, m1 = d0 * h, dh * h
    s = f0 / (f0 - fh)
    for _ in range(6):
        s2 = s * s
        p = (2 * s2 * s - 3 * s2 + 1) * f0 + (s2 * s - 2 * s2 + s) * m0
        p += (-2 * s2 * s + 3 * s2) * fh + (s2 * s - s2) * m1
        dp = (6 * s2 - 6 * s) * f0 + (3 * s2 - 4 * s + 1) * m0
        dp += (-6 * s2 + 6 * s) * fh + (3 * s2 - 2 * s) * m1
        if dp == 0.0:
            break
        s_new = s - p / dp
        if not 0.0 < s_new < 1.0:
            break
        s = s_new
    return s * h
