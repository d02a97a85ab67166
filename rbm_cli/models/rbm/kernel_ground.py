"""The ground acceleration in the compiled kernel (numba): the forms of
rbm_cli.physics.ground_forms, evaluated with the same operations, the exact first
exceedance of an uplift level on their monotone pieces, and the knot a step must end at.

The kernel carries the ground as one tuple ``gr = (form, gain, omega, phase, center,
gamma, knots, values)`` (see kernel_inputs.ground); gain = 0 is a free segment. A cosine
is sin(y + pi/2) here and in the Python forms alike (detmath has no cosine).
"""

from __future__ import annotations

import math

from numba import njit

from rbm_cli.base.detmath import asin as dasin
from rbm_cli.base.detmath import exp as dexp
from rbm_cli.base.detmath import sin as dsin
from rbm_cli.physics.ground_forms import BISECTION_STEPS, MP, RICKER, SINE

_HALF_PI = 0.5 * math.pi


@njit(cache=True)
def _sampled(t, knots, values):
    """ground_forms.sampled_value: linear between samples, 0 outside them."""
    n = knots.size
    if t < knots[0] or t > knots[n - 1]:
        return 0.0
    lo, hi = 0, n
    while lo < hi:  # the number of knots <= t (np.searchsorted, side='right')
        mid = (lo + hi) >> 1
        if knots[mid] <= t:
            lo = mid + 1
        else:
            hi = mid
    k = lo - 1
    if k >= n - 1:
        return values[n - 1]
    t0 = knots[k]
    return values[k] + (values[k + 1] - values[k]) * ((t - t0) / (knots[k + 1] - t0))


@njit(cache=True)
def _ground_other(t, gr):
    """a_g of the forms other than the sine [m/s^2]."""
    form, amp, om, ph, c, gamma, knots, values = gr
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
    v = _sampled(t, knots, values)
    return v if amp == 1.0 else amp * v


@njit(cache=True, inline="always")
def _ground(t, gr):
    """a_g(t) [m/s^2] of the ground tuple gr (0 on a free segment: gain 0)."""
    # the tuple is indexed, not unpacked: binding its arrays to names would count
    # references on every call (the sine's cost grew by a tenth)
    amp = gr[1]
    if amp == 0.0:
        return 0.0
    if gr[0] == SINE:
        return amp * dsin(gr[2] * t + gr[3])
    return _ground_other(t, gr)


@njit(cache=True)
def _next_exceedance(t0, level, amp, om, ph, last):
    """GroundMotion.next_exceedance; -1 for none before `last`."""
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


@njit(cache=True)
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


@njit(cache=True)
def _next_knot(knots, x, bound):
    """The first knot > x if it is before bound, else bound [s] (a record's steps end at
    every sample: x = t + the smallest step)."""
    k = _first_after(knots, x)
    if k < knots.size and knots[k] < bound:
        return knots[k]
    return bound


@njit(cache=True)
def _solve_piece(gr, tl, tr, target):
    """ground_forms._solve_piece: bisection for a_g = target on a monotone piece."""
    s = 1.0 if target > 0.0 else -1.0
    lo, hi = tl, tr
    for _ in range(BISECTION_STEPS):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if s * (_ground(mid, gr) - target) > 0.0:
            hi = mid
        else:
            lo = mid
    return hi


@njit(cache=True)
def _exceedance_pieces(t0, level, last, gr, sampled):
    """ground_forms.exceedance_on_pieces; -1 for none before `last`."""
    knots, values = gr[6], gr[7]
    if abs(_ground(t0, gr)) > level:
        return t0
    k = _first_after(knots, t0)
    tl = t0
    while True:
        tr = min(knots[k] if k < knots.size else last, last)
        ar = _ground(tr, gr)
        if abs(ar) > level:
            target = level if ar > 0.0 else -level
            if not sampled:
                t = _solve_piece(gr, tl, tr, target)
            elif k == 0:
                t = tr
            else:
                t_a, t_b = knots[k - 1], knots[k]
                a_a, a_b = values[k - 1], values[k]
                t = t_a + (target - a_a) * ((t_b - t_a) / (a_b - a_a))
                t = min(max(t, tl), tr)
            return t if t < last else -1.0
        if tr >= last:
            return -1.0
        tl = tr
        k += 1


@njit(cache=True)
def _next_uplift(t0, level, peak, gr, last):
    """GroundMotion.next_exceedance: the first time >= t0 with |a_g| > level [m/s^2]
    (peak = max |a_g|); -1 for none before `last`."""
    if gr[0] == SINE:
        return _next_exceedance(t0, level, gr[1], gr[2], gr[3], last)
    if peak <= level or t0 >= last:
        return -1.0
    return _exceedance_pieces(t0, level, last, gr, gr[0] != RICKER and gr[0] != MP)
