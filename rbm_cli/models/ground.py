"""The ground acceleration in the compiled kernel (numba): the forms of
rbm_cli.physics.ground_forms, evaluated with the same operations, the exact first
exceedance of an uplift level on their monotone pieces, and a record's straight pieces.

The Runge-Kutta routines see the ground as a tuple of nine numbers,
``gr = (form, gain, omega, phase, center, gamma, vflag, va, vd)`` (gain 0: a free segment;
vflag 1 with a vertical record, whose piece is va + vd (t - center) / gamma), never as
arrays: an array passed down to them costs reference counts at every call (a tuple
holding a record's samples made harmonic runs 5-10 % slower). A record reaches them one
straight piece at a time: its steps end at every sample (the kinks of a_g), so inside a
step a_g is the line through two samples, ``(LINE, gain, a_{k+1} - a_k, a_k, t_k,
t_{k+1} - t_k)``, evaluated as ground_forms.sampled_value does (:func:`record_piece`
picks it). A cosine is sin(y + pi/2) here and in the Python forms alike (detmath has
no cosine).
"""

from __future__ import annotations

import math

import numpy as np

from rbm_cli.base.detmath import asin as dasin
from rbm_cli.base.detmath import exp as dexp
from rbm_cli.base.detmath import sin as dsin
from rbm_cli.base.jit import jit
from rbm_cli.config.types import G
from rbm_cli.physics.ground_forms import BISECTION_STEPS, MP, RICKER, SAMPLED, SINE

#: A straight piece of a record (a form of the kernel's only).
LINE = 4
_HALF_PI = 0.5 * math.pi


@jit
def _ground_other(t, form, amp, om, ph, c, gamma):
    """a_g of the forms other than the sine [m/s^2]."""
    if form == RICKER:
        u = 0.5 * om * (t - c)
        u2 = u * u
        return amp * (1.0 - 2.0 * u2) * dexp(-u2)
    if form == MP:
        x = om * (t - c)
        xg = x / gamma
        k = -(math.pi / gamma)
        return (
            amp
            * k
            * (
                dsin(xg) * dsin(x + ph + _HALF_PI)
                + gamma * dsin(x + ph) * (1.0 + dsin(xg + _HALF_PI))
            )
        )
    # LINE: om = a_{k+1} - a_k, ph = a_k, c = t_k, gamma = t_{k+1} - t_k
    v = ph + om * ((t - c) / gamma)
    return v if amp == 1.0 else amp * v


@jit(inline=True)
def ground(t, gr):
    """a_g(t) [m/s^2] of the ground tuple gr (0 on a free segment: gain 0)."""
    form, amp, om, ph, c, gamma = gr[0], gr[1], gr[2], gr[3], gr[4], gr[5]
    if amp == 0.0:
        return 0.0
    if form == SINE:
        return amp * dsin(om * t + ph)
    return _ground_other(t, form, amp, om, ph, c, gamma)


@jit(inline=True)
def gravity_factor(t, gr):
    """(g + a_v(t)) / g [-] of the ground tuple gr (1 with no vertical record)."""
    if gr[6] == 0.0:
        return 1.0
    return 1.0 + (gr[7] + gr[8] * ((t - gr[4]) / gr[5])) / G


@jit
def _first_after(knots, x):
    """Index of the first knot > x (np.searchsorted(knots, x, side='right'))."""
    lo, hi = 0, knots.size
    while lo < hi:
        mid = (lo + hi) >> 1
        if knots[mid] <= x:
            lo = mid + 1
        else:
            hi = mid
    return lo


@jit
def record_piece(t, knots, values, vertical, gain, seg_end):
    """The straight piece of a record a step from t [s] runs on, as a ground tuple, and
    the time that step ends at: the first sample past t + the smallest step (10 ulp of
    t, as python.Stepper takes it), or seg_end if sooner. Before the first sample and
    after the last the ground rests (gain 0). vertical: a_v at the knots (or empty; if not,
    the tuple says so even where a_v = 0, since the laws are then split, rhs)."""
    min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
    j = _first_after(knots, t + min_step)
    n = knots.size
    bound = knots[j] if j < n and knots[j] < seg_end else seg_end
    if 0 < j < n:
        vf, va, vd = 0.0, 0.0, 0.0
        if vertical.size > 0:
            vf, va, vd = 1.0, vertical[j - 1], vertical[j] - vertical[j - 1]
        gr = (LINE, gain, values[j] - values[j - 1], values[j - 1], knots[j - 1],
              knots[j] - knots[j - 1], vf, va, vd)  # fmt: skip
    else:  # with a vertical record, a_v = 0 still read as one (its split laws: step.vertical)
        gr = (LINE, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0 if vertical.size > 0 else 0.0, 0.0, 0.0)
    return gr, bound


@jit
def _sampled_at(t, knots, values):
    """ground_forms.sampled_value: linear between samples, 0 outside them."""
    n = knots.size
    if t < knots[0] or t > knots[n - 1]:
        return 0.0
    if t == knots[n - 1]:
        return values[n - 1]
    k = _first_after(knots, t)  # piece [knots[k - 1], knots[k]] holds t
    t0 = knots[k - 1]
    return values[k - 1] + (values[k] - values[k - 1]) * ((t - t0) / (knots[k] - t0))


@jit
def ground_at(t, gr, knots, values):
    """a_g(t) [m/s^2] of the motion (gr its formula, or a record's samples, gain 1)."""
    if gr[0] != SAMPLED:
        return ground(t, gr)
    return _sampled_at(t, knots, values)


@jit
def _level_at(t, level, knots, vertical):
    """The uplift level at t [m/s^2]: level (g + a_v(t)) / g with a vertical record."""
    if vertical.size == 0:
        return level
    return level * (1.0 + _sampled_at(t, knots, vertical) / G)


@jit
def sine_exceedance(t0, level, amp, om, ph, last):
    """GroundMotion.next_exceedance of a sine; -1 for none before `last`."""
    if amp <= level or t0 >= last:
        return -1.0
    s = level / amp
    psi0 = om * t0 + ph
    if abs(dsin(psi0)) > s:
        return t0
    lo = dasin(s)
    kk = math.ceil((psi0 - lo) / math.pi)
    psi = lo + kk * math.pi
    if psi < psi0:
        psi += math.pi
    t = (psi - ph) / om
    if t >= last:
        return -1.0
    return t


@jit
def _solve_piece(gr, tl, tr, target):
    """ground_forms._solve_piece: bisection for a_g = target on a monotone piece."""
    s = 1.0 if target > 0.0 else -1.0
    lo, hi = tl, tr
    for _ in range(BISECTION_STEPS):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if s * (ground(mid, gr) - target) > 0.0:
            hi = mid
        else:
            lo = mid
    return hi


@jit
def _exceedance_pieces(t0, level, last, gr, knots, values, vertical):
    """ground_forms.exceedance_on_pieces; -1 for none before `last`."""
    sampled = gr[0] == SAMPLED
    if abs(ground_at(t0, gr, knots, values)) > _level_at(t0, level, knots, vertical):
        return t0
    k = _first_after(knots, t0)
    tl = t0
    while True:
        tr = min(knots[k] if k < knots.size else last, last)
        ar = ground_at(tr, gr, knots, values)
        if abs(ar) > _level_at(tr, level, knots, vertical):
            target = level if ar > 0.0 else -level
            if not sampled:
                t = _solve_piece(gr, tl, tr, target)
            elif k == 0 or knots[k] == knots[k - 1]:
                t = tr
            else:
                t_a, t_b = knots[k - 1], knots[k]
                a_a, a_b = values[k - 1], values[k]
                if vertical.size == 0:
                    t = t_a + (target - a_a) * ((t_b - t_a) / (a_b - a_a))
                else:
                    f_a = a_a - target * (1.0 + vertical[k - 1] / G)
                    f_b = a_b - target * (1.0 + vertical[k] / G)
                    t = t_a + (t_b - t_a) * (f_a / (f_a - f_b))
                t = min(max(t, tl), tr)
            return t if t < last else -1.0
        if tr >= last:
            return -1.0
        tl = tr
        k += 1


@jit
def next_uplift(t0, level, peak, gr, knots, values, vertical, last):
    """GroundMotion.next_exceedance: the first time >= t0 with |a_g| > level [m/s^2]
    (times (g + a_v) / g with a vertical record; peak = max |a_g|); -1 for none before
    `last`."""
    if gr[0] == SINE:
        return sine_exceedance(t0, level, gr[1], gr[2], gr[3], last)
    if (peak <= level and vertical.size == 0) or t0 >= last:
        return -1.0
    return _exceedance_pieces(t0, level, last, gr, knots, values, vertical)
