"""The ground acceleration a_g(t) [m/s^2] as every integrator evaluates it (numba).

A :class:`~rbm_cli.inputs.motion.GroundMotion` is one of four forms, each a formula of
time with a few numbers (``gain`` [m/s^2], ``omega`` [rad/s], ``phase`` [rad], ``center``
[s], ``gamma`` [-]) or a table of samples:

- ``SINE``: gain sin(omega t + phase) (harmonic, half-sine, one-sine, cycloidal);
- ``RICKER``: gain (1 - 2 u^2) exp(-u^2), u = (omega / 2)(t - center) (omega = 2 pi f_p);
- ``MP``: the Mavroeidis-Papageorgiou acceleration, x = omega (t - center),
  gain (-pi / gamma) [sin(x / gamma) cos(x + phase) + gamma sin(x + phase)(1 + cos(x / gamma))]
  (a cosine is sin(y + pi/2): detmath has no cosine);
- ``SAMPLED``: linear between samples (times, values), 0 before the first and after the last.

Between consecutive ``knots`` a_g is monotone (the samples of a record; the extrema of a
Ricker or MP pulse), which makes the search for the first time |a_g| exceeds a level
(:func:`next_uplift`) exact: linear for samples, bisection to the last bit for a formula.

The functions are compiled (rbm_cli.base.jit) with detmath's sin, asin and exp, so the
same bits come out on every machine; the Python integrators (Housner's block, the scipy
baseline) call the same functions through GroundMotion (``scalar``, ``next_exceedance``,
``gravity``). The compiled integrators see the ground as a tuple of nine numbers,
``gr = (form, gain, omega, phase, center, gamma, vflag, va, vd)`` (gain 0: a free segment;
vflag 1 with a vertical record, whose piece is va + vd (t - center) / gamma), never as
arrays: an array passed down to them costs reference counts at every call (a tuple
holding a record's samples made harmonic runs 5-10 % slower). A record reaches them one
straight piece at a time: its steps end at every sample (the kinks of a_g), so inside a
step a_g is the line through two samples, ``(LINE, gain, a_{k+1} - a_k, a_k, t_k,
t_{k+1} - t_k)`` (:func:`record_piece` picks it).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from rbm_cli.base.detmath import asin as dasin
from rbm_cli.base.detmath import exp as dexp
from rbm_cli.base.detmath import sin as dsin
from rbm_cli.base.jit import jit
from rbm_cli.config.types import G
from rbm_cli.inputs.pulses import mp_shape

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

#: Bisection steps of the search for an exceedance on a formula (more than a double has).
BISECTION_STEPS = 200

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


@jit
def ground(t, gr):
    """a_g(t) [m/s^2] of the ground tuple gr (0 on a free segment: gain 0).

    Compiled on its own, not inlined into the right-hand sides (it takes numbers only, so
    a call costs no reference count): inlined, each of its twelve callers compiled its
    own copy of the sine (base.detmath.sin), 5 s of a first use of about 55 s, for no
    measurable speed (the 8-drum band's CPU within 1 %, five paired runs)."""
    form, amp, om, ph, c, gamma = gr[0], gr[1], gr[2], gr[3], gr[4], gr[5]
    if amp == 0.0:
        return 0.0
    if form == SINE:
        return amp * dsin(om * t + ph)
    return _ground_other(t, form, amp, om, ph, c, gamma)


@jit
def shape_at(t, form, amp, om, ph, c, gamma):
    """a(t) [m/s^2] of a form's formula (SINE, RICKER, MP, or a record's straight piece,
    LINE), its numbers given one by one (a pair's second component, structures.column3d)."""
    if form == SINE:
        return amp * dsin(om * t + ph)
    return _ground_other(t, form, amp, om, ph, c, gamma)


@jit(inline=True)
def gravity_factor(t, gr):
    """(g + a_v(t)) / g [-] of the ground tuple gr (1 with no vertical record)."""
    if gr[6] == 0.0:
        return 1.0
    return 1.0 + (gr[7] + gr[8] * ((t - gr[4]) / gr[5])) / G


@jit(borrow=True)
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


@jit(borrow=True)
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


@jit(borrow=True)
def _sampled_at(t, knots, values):
    """a_g(t) of samples (knots [s], values): linear between them, 0 outside them;
    a_k + (a_{k+1} - a_k) ((t - t_k) / (t_{k+1} - t_k))."""
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
def vertical_factor(t, knots, vertical):
    """(g + a_v(t)) / g [-] of an upward ground acceleration sampled at the knots (1 before
    the first and after the last sample, and with no vertical record: empty)."""
    if vertical.size == 0:
        return 1.0
    return 1.0 + _sampled_at(t, knots, vertical) / G


@jit
def _level_at(t, level, knots, vertical):
    """The uplift level at t [m/s^2]: level (g + a_v(t)) / g with a vertical record."""
    if vertical.size == 0:
        return level
    return level * vertical_factor(t, knots, vertical)


@jit
def sine_exceedance(t0, level, amp, om, ph, last):
    """The first time >= t0 with |amp sin(om t + ph)| > level, -1 for none before `last`:
    |sin(psi)| > s, s = level / amp, holds on (asin(s) + k pi, pi - asin(s) + k pi); the time
    returned is where |a_g| = level and rising (t0 itself when already above)."""
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
def sine_peak(t0, t1, amp, om, ph):
    """max over [t0, t1] of |amp sin(om t + ph)| [its unit]: |amp| when a crest (om t + ph =
    pi/2 + k pi) lies in the interval, else the larger of its ends (the sine is monotone
    between crests)."""
    if t1 < t0 or amp == 0.0:
        return 0.0
    psi0 = om * t0 + ph
    kk = math.ceil((psi0 - _HALF_PI) / math.pi)
    crest = _HALF_PI + kk * math.pi
    if om > 0.0 and (crest - ph) / om <= t1:
        return abs(amp)
    return max(abs(amp * dsin(psi0)), abs(amp * dsin(om * t1 + ph)))


@jit
def rest_demand(t0, t1, gr, knots, values, vertical):
    """The friction demand max |T / N| = max |a_g| / (g + a_v) [-] of a column at rest on
    the ground over [t0, t1] [s] (T = m a_g, N = m (g + a_v)): a sine's crest or ends
    (sine_peak); for the other forms the ends and the knots between them, where a_g is
    monotone between knots (a record's samples, a pulse's extrema), and so is a_g / (g + a_v)
    under a vertical record (both straight between samples, g + a_v > 0)."""
    if gr[1] == 0.0 or t1 < t0:
        return 0.0
    if gr[0] == SINE:
        return sine_peak(t0, t1, gr[1], gr[2], gr[3]) / G
    best = 0.0
    k = _first_after(knots, t0)
    tt = t0
    while True:
        d = abs(ground_at(tt, gr, knots, values)) / (G * vertical_factor(tt, knots, vertical))
        if d > best:
            best = d
        if tt >= t1:
            return best
        tt = min(knots[k], t1) if k < knots.size else t1
        k += 1


@jit
def rest_shear(t, gr, knots, values, vertical):
    """The shear ratio T / N = a_g / (g + a_v) [-] of a column at rest on the ground at t
    [s], with its sign (T = m a_g, N = m (g + a_v)): a sample of its held friction demand."""
    return ground_at(t, gr, knots, values) / (G * vertical_factor(t, knots, vertical))


@jit
def _solve_piece(gr, tl, tr, target):
    """Bisection for a_g = target on [tl, tr], a_g monotone with s (a_g(tl) - target) <= 0 <
    s (a_g(tr) - target), s = sign(target): the earliest float past the crossing."""
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
    """The first time in [t0, last) with |a_g| > level [m/s^2] (times (g + a_v) / g with a
    vertical record), -1 for none: on each monotone piece between knots, solved on the
    straight line between two samples (a jump, at knots[0] or a knot written twice, is met
    there), by bisection for a formula; t0 itself when already above."""
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
def _first_positive(qa, qb, qc, s_lo):
    """The first s in [s_lo, 1] where qa s^2 + qb s + qc > 0 (where it is 0 and rising, or
    s_lo itself when already above), or -1."""
    if (qa * s_lo + qb) * s_lo + qc > 0.0:
        return s_lo
    r0, r1 = math.inf, math.inf
    if qa == 0.0:
        if qb != 0.0:
            r0 = -qc / qb
    else:
        disc = qb * qb - 4.0 * qa * qc
        if disc >= 0.0:
            q = -0.5 * (qb + math.copysign(math.sqrt(disc), qb))
            r0 = q / qa
            if q != 0.0:
                r1 = qc / q
    for s in (min(r0, r1), max(r0, r1)):
        if s_lo <= s <= 1.0 and (2.0 * qa * s + qb) > 0.0:
            return s
    return -1.0


@jit
def pair_exceedance(t0, ratio, last, knots, ax, ay, av):
    """A pair of records (ax, ay at the knots; av the vertical's, or empty): the first
    time t in [t0, last) where the horizontal acceleration's magnitude exceeds ratio
    (g + a_v(t)) [m/s^2], or -1. Both components and a_v are linear between the knots, so
    on each interval the excess |a|^2 - (ratio (g + a_v))^2 is a quadratic in time, solved
    exactly."""
    i0 = max(_first_after(knots, t0) - 1, 0)
    for i in range(i0, knots.size - 1):
        ta, tb = knots[i], knots[i + 1]
        if ta >= last:
            return -1.0
        if tb <= ta:
            continue
        lo = max(t0, ta)
        # on [ta, tb]: a(s) = a0 + s da, s = (t - ta) / (tb - ta)
        x0, dx = ax[i], ax[i + 1] - ax[i]
        y0, dy = ay[i], ay[i + 1] - ay[i]
        v0, dv = (av[i], av[i + 1] - av[i]) if av.size > 0 else (0.0, 0.0)
        w0, dw = ratio * (G + v0), ratio * dv
        qa, qb = dx * dx + dy * dy - dw * dw, 2.0 * (x0 * dx + y0 * dy - w0 * dw)
        qc = x0 * x0 + y0 * y0 - w0 * w0
        s = _first_positive(qa, qb, qc, (lo - ta) / (tb - ta))
        if s >= 0.0:
            t = ta + s * (tb - ta)
            return t if t < last else -1.0
    return -1.0


@jit
def _turn(c, d):
    """The angle [rad] whose cosine and sine are c / hypot(c, d) and d / hypot(c, d) (up to
    a whole turn), by detmath's asin on its well-conditioned half (no atan2: the C
    library's differs in the last bit from one CPU to another)."""
    r = math.sqrt(c * c + d * d)
    if abs(d) <= abs(c):
        b = dasin(d / r)
        return b if c > 0.0 else math.pi - b
    b = _HALF_PI - dasin(c / r)
    return b if d > 0.0 else -b


@jit
def _sine_pair_exceedance(t0, level, last, gr, gy):
    """The first time in [t0, last) where |(a_x, a_y)| > level [m/s^2], -1 for none: two
    sines of one frequency, a_x = g_x sin(psi), a_y = g_y sin(psi + delta), psi = om t +
    ph_x. In closed form: |a|^2 = (g_x^2 + g_y^2) / 2 - (R / 2) cos(2 psi + beta), with
    g_x^2 cos 2 psi + g_y^2 cos(2 psi + 2 delta) = R cos(2 psi + beta), so |a| > level
    where sin(chi) > s, chi = 2 psi + beta - pi / 2, s = (2 level^2 - g_x^2 - g_y^2) / R;
    the time returned is where |a| = level and rising (t0 itself when already above)."""
    if t0 >= last:
        return -1.0
    om, gx, gyy = gr[2], gr[1], gy[1]
    d2 = 2.0 * (gy[3] - gr[3])
    gx2, gy2 = gx * gx, gyy * gyy
    c = gx2 + gy2 * dsin(d2 + _HALF_PI)
    d = gy2 * dsin(d2)
    r = math.sqrt(c * c + d * d)
    over = 2.0 * level * level - gx2 - gy2
    if r == 0.0:  # a circle: |a| constant
        return t0 if over < 0.0 else -1.0
    s = over / r
    if s >= 1.0:
        return -1.0
    ph = 2.0 * gr[3] + _turn(c, d) - _HALF_PI
    chi0 = 2.0 * om * t0 + ph
    if s < -1.0 or dsin(chi0) > s:
        return t0
    lo = dasin(s)
    kk = math.ceil((chi0 - lo) / (2.0 * math.pi))
    chi = lo + kk * 2.0 * math.pi
    if chi < chi0:
        chi += 2.0 * math.pi
    t = (chi - ph) / (2.0 * om)
    return t if t < last else -1.0


#: Depth of the interval search of a pair of formulas (more halvings than a double has
#: between two knots but near t = 0; deeper, an interval is taken as a point).
PAIR_DEPTH = 128


@jit
def _pair_first_above(a, b, l2, gr, gy):
    """The first time in (a, b] where a_x^2 + a_y^2 > l2, -1 for none, with a_x and a_y
    each monotone on [a, b] (between knots of both): on an interval, a_x^2 + a_y^2 is at
    most the larger of a_x^2 at its ends plus the larger of a_y^2 there, so an interval
    whose bound is at most l2 holds no crossing; the others are halved, the earlier half
    first, down to the last bit (the earliest float past the crossing)."""
    los, his = np.empty(PAIR_DEPTH + 1), np.empty(PAIR_DEPTH + 1)
    los[0], his[0] = a, b
    top = 1
    while top > 0:
        top -= 1
        lo, hi = los[top], his[top]
        xl, yl = ground(lo, gr), ground(lo, gy)
        xh, yh = ground(hi, gr), ground(hi, gy)
        if max(xl * xl, xh * xh) + max(yl * yl, yh * yh) <= l2:
            continue
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi or top + 2 > PAIR_DEPTH:
            if xh * xh + yh * yh > l2:
                return hi
            continue
        los[top], his[top] = mid, hi
        los[top + 1], his[top + 1] = lo, mid
        top += 2
    return -1.0


@jit
def _formula_pair_exceedance(t0, level, last, gr, gy, knots, knots_y):
    """The first time in [t0, last) where |(a_x, a_y)| > level [m/s^2], -1 for none: two
    formulas (a Ricker or MP pulse and its second component), each monotone between its
    knots, searched on the intervals between the knots of both (_pair_first_above); t0
    itself when already above."""
    if t0 >= last:
        return -1.0
    l2 = level * level
    x0, y0 = ground(t0, gr), ground(t0, gy)
    if x0 * x0 + y0 * y0 > l2:
        return t0
    i, j = _first_after(knots, t0), _first_after(knots_y, t0)
    tl = t0
    while True:
        tx = knots[i] if i < knots.size else last
        ty = knots_y[j] if j < knots_y.size else last
        tr = min(tx, ty, last)
        if tr > tl:
            t = _pair_first_above(tl, tr, l2, gr, gy)
            if t >= 0.0:
                return t if t < last else -1.0
        if tr >= last:
            return -1.0
        if tx == tr:
            i += 1
        if ty == tr:
            j += 1
        tl = tr


@jit
def pair_uplift(t0, ratio, last, gr, gy, knots, values, values_y, knots_y, vertical):
    """The first time t in [t0, last) where a pair's horizontal acceleration's magnitude
    exceeds ratio (g + a_v(t)) [m/s^2], -1 for none: a pair of records (values_y not
    empty: :func:`pair_exceedance`), or a formula gr and its second component gy (ground
    tuples; knots_y gy's knots): two sines in closed form, the other forms by halving
    intervals between both knots to the last bit."""
    if values_y.size > 0:
        return pair_exceedance(t0, ratio, last, knots, values, values_y, vertical)
    if gr[0] == SINE:
        return _sine_pair_exceedance(t0, ratio * G, last, gr, gy)
    return _formula_pair_exceedance(t0, ratio * G, last, gr, gy, knots, knots_y)


@jit
def next_uplift(t0, level, peak, gr, knots, values, vertical, last):
    """The first time >= t0 with |a_g| > level [m/s^2]
    (times (g + a_v) / g with a vertical record; peak = max |a_g|); -1 for none before
    `last`."""
    if gr[0] == SINE:
        return sine_exceedance(t0, level, gr[1], gr[2], gr[3], last)
    if (peak <= level and vertical.size == 0) or t0 >= last:
        return -1.0
    return _exceedance_pieces(t0, level, last, gr, knots, values, vertical)


def form_function(gr, knots, values):
    """a_g(t) [m/s^2] of a motion's ground tuple gr (its form, gain, omega, phase, center,
    gamma) and samples (float64 arrays, empty for none) as a function of a float t [s], for
    the Python integrators: the compiled :func:`ground_at` (no support window: they call it
    only inside the forced segments of the motion)."""
    gain = gr[1]
    if gain == 0.0:
        return lambda tt: 0.0
    if gr[0] == SAMPLED and gain != 1.0:
        return lambda tt: gain * ground_at(tt, gr, knots, values)
    return lambda tt: ground_at(tt, gr, knots, values)


def as_samples(x) -> np.ndarray:
    """A writable float64 copy of samples (empty for None), as the compiled functions take
    them (numba types read-only arrays apart: one more compile)."""
    return np.array(() if x is None else x, dtype=np.float64)


def ricker_knots(omega: float, center: float) -> np.ndarray:
    """Ends of the monotone pieces of a Ricker wavelet on [0, 2 center] [s]: its extrema at
    u = 0 and u = +-sqrt(3/2), u = (omega / 2)(t - center)."""
    d = math.sqrt(1.5) / (0.5 * omega)
    return np.array([0.0, center - d, center, center + d, 2.0 * center])


@lru_cache(maxsize=256)
def _mp_extrema(gamma: float, nu: float) -> tuple[float, ...]:
    """Extrema of the MP shape (pulses.mp_shape) over s in [-gamma/2, gamma/2] [cycles]:
    sign changes of its slope on 400 points a cycle, each refined by Brent's method."""
    # lazy: scipy.optimize loads only where needed (docs/architecture.md, Start-up)
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
