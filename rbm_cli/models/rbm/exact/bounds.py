"""Bounds of the modes of a piece over an interval (numba), and their use on rows: lower
bounds of event distances, upper bounds of |tracked quantities|. They make the exact
integrator's sampling certain (rbm_cli.models.rbm.exact.search).

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
  |q''| <= lam R + |p''| and |q'''| <= lam^1.5 R + |p'''|; and where lam h^2 >
  ENVELOPE_RATIO ("fast") the row's oscillation in that mode is better bounded by its
  envelope |G_j| R than by its curvature: the row's slow part (the row minus the fast
  oscillations, known at both ends) is bounded by curvature, the fast part by
  sum_j |G_j| R_j.

Every bound is inflated by SAFETY against rounding.

Mode bounds of an interval go into an (MB_ROWS, n) array: CURV (|q''| of the modes treated
by curvature, |p''| of the fast ones), FULL (|q''| of every mode, all by curvature), THIRD
(|q'''|), FAST (1.0 for the modes treated by their envelope), ENV (their envelope R), OSC_A,
OSC_B, RATE_A, RATE_B (their free oscillation o and o' at both ends). Row bounds work on
*families*: every event or peak row is sign * F[fam] + off, F = Gf q the family values (law
arguments over theta_u, collapse ratios, top displacement), so a family's bound serves every
row built on it.
"""

from __future__ import annotations

import math

import numpy as np

from rbm_cli.base.jit import jit
from rbm_cli.models.rbm.exact.modal import HARMONIC, LINEAR, basis1, f_accel, f_peak, f_phase

#: Bounds are inflated by this relative margin against rounding.
SAFETY = 1.0 + 1e-9
#: A mode is treated by its envelope on an interval when lam h^2 exceeds this.
ENVELOPE_RATIO = 8.0
#: For lam > 0 the hyperbolic majorant is used only while lam h^2 is below this (beyond,
#: the energy bound is the smaller).
HYPERBOLIC_LIMIT = 4.0

CURV, FULL, THIRD, FAST, ENV, OSC_A, OSC_B, RATE_A, RATE_B = range(9)
MB_ROWS = 9


@jit(borrow=True)
def _particular(lam, f, g, fc, ag_a, ag_b, sin_a, cos_a, sin_b, cos_b):
    """(p, p') of an eligible mode at both ends of an interval (module docstring),
    from the forcing's sines at both ends (harmonic) or its values ag_a, ag_b (linear)."""
    kind = int(fc[0])
    p_a = p_b = f / lam
    dp_a = dp_b = 0.0
    if kind == HARMONIC and fc[1] != 0.0:
        amp = g * fc[1] / (lam - fc[2] * fc[2])
        p_a += amp * sin_a
        p_b += amp * sin_b
        dp_a = amp * fc[2] * cos_a
        dp_b = amp * fc[2] * cos_b
    elif kind == LINEAR:
        p_a += g * ag_a / lam
        p_b += g * ag_b / lam
        dp_a = dp_b = g * fc[6] / lam
    return p_a, dp_a, p_b, dp_b


@jit
def _mode(lam, q, v, big, dbig, h):
    """(bound of |q''|, bound of |q'''|) of one mode on [a, a + h] by its majorants:
    hyperbolic (lam <= 0, or lam h^2 < HYPERBOLIC_LIMIT) and, for lam > 0, the energy's."""
    alam = abs(lam)
    aq, av = abs(q), abs(v)
    qmax = vmax = math.inf
    if lam <= 0.0 or lam * h * h < HYPERBOLIC_LIMIT:
        c, s, s2, _ = basis1(-alam, h)
        qmax = aq * c + av * s + big * s2  # inf for a long interval; NaN (0 * inf): none
        vmax = aq * alam * s + av * c + big * s
        if math.isnan(qmax):
            qmax = math.inf
        if math.isnan(vmax):
            vmax = math.inf
    if lam > 0.0:
        energy = math.sqrt(v * v + lam * q * q) + h * big
        qmax = min(qmax, aq + h * energy, energy / math.sqrt(lam))
        vmax = min(vmax, energy)
    return alam * qmax + big, alam * vmax + dbig


@jit(borrow=True)
def mode_bounds(lam, f, g, elig, w, fc, t, q, v, h, qb, vb, mb):
    """Fill mb (MB_ROWS, n) with the modes' bounds on [t, t + h] (module docstring)
    from (q, v) at t and (qb, vb) at t + h. Returns whether some mode is fast."""
    kind = int(fc[0])
    peak = f_peak(fc, t, h)
    om = fc[2]
    ag_a, ag_b = f_accel(fc, t), f_accel(fc, t + h)
    sin_a = cos_a = sin_b = cos_b = 0.0
    if kind == HARMONIC:
        phase = f_phase(fc, t)
        sin_a, cos_a = math.sin(phase), math.cos(phase)
        sin_b, cos_b = math.sin(om * h + phase), math.cos(om * h + phase)
    any_fast = False
    for j in range(lam.size):
        if kind == LINEAR:
            big = max(abs(f[j] + g[j] * ag_a), abs(f[j] + g[j] * ag_b))
            dbig = abs(g[j] * fc[6])
        else:
            big = abs(f[j]) + abs(g[j]) * peak
            dbig = abs(g[j]) * peak * om
        full, third = _mode(lam[j], q[j], v[j], big, dbig, h)
        fast = False
        p2 = 0.0
        if elig[j]:
            if kind == HARMONIC and fc[1] != 0.0:
                p2 = om * om * abs(g[j] * fc[1] / (lam[j] - om * om))
            p_a, dp_a, p_b, dp_b = _particular(lam[j], f[j], g[j], fc, ag_a, ag_b, sin_a,
                                               cos_a, sin_b, cos_b)  # fmt: skip
            osc, rate = q[j] - p_a, v[j] - dp_a
            env = math.sqrt(osc * osc + (rate / w[j]) ** 2) * SAFETY
            full = min(full, lam[j] * env + p2)
            third = min(third, lam[j] * w[j] * env + p2 * om)
            fast = lam[j] * h * h > ENVELOPE_RATIO
            if fast:
                mb[ENV, j], mb[OSC_A, j], mb[RATE_A, j] = env, osc, rate
                mb[OSC_B, j], mb[RATE_B, j] = qb[j] - p_b, vb[j] - dp_b
        if not fast:
            for row in (ENV, OSC_A, OSC_B, RATE_A, RATE_B):
                mb[row, j] = 0.0
        mb[FULL, j] = full * SAFETY
        mb[THIRD, j] = third * SAFETY
        mb[CURV, j] = p2 * SAFETY if fast else full * SAFETY
        mb[FAST, j] = 1.0 if fast else 0.0
        any_fast = any_fast or fast
    return any_fast


@jit(borrow=True)
def family_bounds(gf, absgf, mb, any_fast, fb):
    """Family-level bounds into fb (8, families): |Gf| @ CURV (FULL when no mode is fast),
    FULL, THIRD, ENV, and the fast oscillations Gf @ OSC_A, OSC_B, RATE_A, RATE_B (a row's
    slow part: its values and rates minus these)."""
    nf, n = gf.shape
    for k in range(nf):
        cv = fu = th = en = oa = ob = ra = rb = 0.0
        for j in range(n):
            a = absgf[k, j]
            fu += a * mb[FULL, j]
            th += a * mb[THIRD, j]
            if any_fast:
                cv += a * mb[CURV, j]
                en += a * mb[ENV, j]
                oa += gf[k, j] * mb[OSC_A, j]
                ob += gf[k, j] * mb[OSC_B, j]
                ra += gf[k, j] * mb[RATE_A, j]
                rb += gf[k, j] * mb[RATE_B, j]
        fb[0, k], fb[1, k], fb[2, k] = (cv if any_fast else fu), fu, th
        fb[3, k], fb[4, k], fb[5, k], fb[6, k], fb[7, k] = en, oa, ob, ra, rb


@jit
def lower2(va, vb, ra, rb, curv, h):
    """Lower bound over [0, h] of a function with end values va, vb, end rates ra, rb and
    |second derivative| <= curv (rbm_cli.models.rbm.exact.search)."""
    interp = min(va, vb) - curv * (h * h / 8.0)
    left = min(va, va + ra * h - curv * (h * h / 2.0))
    right = min(vb, vb - rb * h - curv * (h * h / 2.0))
    return max(interp, max(left, right))


@jit
def upper_abs2(va, vb, ra, rb, curv, h):
    """Upper bound of |value| over [0, h] (rbm_cli.models.rbm.exact.search)."""
    interp = max(abs(va), abs(vb)) + curv * (h * h / 8.0)
    left = max(abs(va), abs(va + ra * h)) + curv * (h * h / 2.0)
    right = max(abs(vb), abs(vb - rb * h)) + curv * (h * h / 2.0)
    return min(interp, min(left, right))


@jit(borrow=True)
def row_lower(sgn, off, k, fa, fb_, da, db, fb, any_fast, h):
    """Lower bound on [a, b] of the event row sgn * F[k] + off, from the family values fa,
    fb_ and rates da, db at both ends and the family bounds fb (NaN counts as no bound)."""
    full = lower2(sgn * fa + off, sgn * fb_ + off, sgn * da, sgn * db, fb[1, k], h)
    if any_fast:
        split = lower2(sgn * (fa - fb[4, k]) + off, sgn * (fb_ - fb[5, k]) + off,
                       sgn * (da - fb[6, k]), sgn * (db - fb[7, k]), fb[0, k], h)  # fmt: skip
        split -= fb[3, k]
        if math.isnan(split) or math.isnan(full):
            return math.nan  # as numpy's maximum: no bound
        full = max(full, split)
    return full


@jit(borrow=True)
def track_upper(k, fa, fb_, da, db, fb, any_fast, h):
    """Upper bound of |F[k]| on [a, b] (a tracked quantity)."""
    full = upper_abs2(fa, fb_, da, db, fb[1, k], h)
    if any_fast:
        split = upper_abs2(fa - fb[4, k], fb_ - fb[5, k], da - fb[6, k], db - fb[7, k],
                           fb[0, k], h) + fb[3, k]  # fmt: skip
        if math.isnan(split) or math.isnan(full):
            return math.nan
        full = min(full, split)
    return full


def empty_bounds(n: int, families: int) -> tuple[np.ndarray, np.ndarray]:
    """Work arrays (mb, fb) for n modes and this many families."""
    return np.zeros((MB_ROWS, n)), np.zeros((8, families))
