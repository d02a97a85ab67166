"""One piece of the rigid block's closed form (numba-compatible; rbm_cli.base.jit): the
motion on one side between two events, its events found by a scan that cannot miss one,
refined by Brent's method to round-off. The run loop is block.run; block.closed_form runs
it.

On side s = +-1, between two events, the block obeys

    theta'' = p^2 gam (theta - s alpha) + e a_g(t),

(Spanos and Koh's block: e = -p^2 / g; the rigid RBM monolith: e = -m (H/2) / I_0,
closed_form.rbm_block; gam = (g + a_v) / g under a vertical record, taken constant on the
piece, else 1), solved exactly for a forcing of the exact integrator's kinds
(rbm_cli.models.rbm.exact.modal: zero, harmonic, or linear between two samples of a record). With
p_g = p sqrt(gam):

    theta(tau) = s alpha + C sin(omega tau + phi0) + q0 + q1 tau + c1 e^(p_g tau)
                 + c2 e^(-p_g tau)

with C = -e A / (p^2 + omega^2) under a_g = A sin(omega t + phase), and q0 + q1 tau =
-(e / p_g^2) a_g(t0 + tau) under a straight-line a_g.

Events (impact: s theta back to 0; collapse: s theta reaches the limit) and maxima are
bracketed on intervals [a, b] on which s theta' has at most one zero, which is proved, not
assumed: if s theta' had two zeros in [a, b], theta'' would vanish between them and
|theta'| <= M3 (b - a)^2 at both ends, M3 a bound of |theta'''| on [a, b] (the sine's
|C| omega^3 plus p^3 (|c1| e^(p b) + |c2| e^(-p a))). On such an interval s theta is
monotone, or has one extremum (the rate changes sign: located by Brent on the rate), so
its crossings are seen from the end values and that extremum. Where the rate is round-off (the first
microseconds of a grazing uplift, theta = theta' = theta'' = 0 to rounding) a second
certificate holds instead: the Taylor envelope at a, |s theta - s theta(a)| <= w |theta'| +
w^2 |theta''| / 2 + M3 w^3 / 6 on [a, a + w], below the event offset eps (no event, the
peak to eps). An interval that neither certifies is halved.
"""

from __future__ import annotations

import math

from rbm_cli.base.brent import brent_step
from rbm_cli.base.jit import jit
from rbm_cli.models.rbm.exact.modal import HARMONIC, LINEAR, f_phase

#: A piece: start time t0 [s], side s, C [rad], omega [rad/s], phi0 [rad], q0 [rad],
#: q1 [rad/s], c1, c2 [rad], alpha [rad], p_g [rad/s]; the ground acceleration on it,
#: a_g(t0 + tau) = A sin(omega tau + phi0) + g0 + g1 tau (A [m/s^2], g0 [m/s^2],
#: g1 [m/s^3]); the friction factors fa [s^2/m], fb [1/rad] of the ground joint and fa2,
#: fb2 of a monolithic frame's beam joint (0: none; a joint's pair is FA + 2 row, FB + 2 row).
T0, SIDE, AMP, OM, PHI, Q0, Q1, C1, C2, ALPHA, P, GA, G0, G1, FA, FB, FA2, FB2 = range(18)
PIECE_SIZE = 18
#: The block: p [rad/s], alpha [rad], e [rad/s^2 per m/s^2], collapse limit [rad],
#: restitution [-], rest rate [rad/s], uplift level [m/s^2], energy barrier of the early
#: stop [rad^2/s^2], event offset eps [rad], friction factors fa [s^2/m] and fb [1/rad]
#: (NaN: no friction demand), where an impact is placed (0: s theta = -eps, the RBM's
#: convention; 1: theta = 0, housner-linear's; impact_time), and the friction factors
#: fa2, fb2 of a monolithic frame's beam joint (NaN: none; closed_form.rbm_block).
(B_P, B_ALPHA, B_E, B_LIMIT, B_REST, B_REST_RATE, B_UPLIFT, B_BARRIER, B_EPS, B_FA,
 B_FB, B_AT_ZERO, B_FA2, B_FB2) = range(14)  # fmt: skip
BLOCK_SIZE = 14
#: What the scan of a piece keeps: the largest s theta [rad], the time of the interior
#: maximum holding it [s] (-1: none), the evaluations made, the friction demand [-]; and,
#: for a friction limit mu [-] (inf: none) it is given, the first time in the piece its
#: |demand| exceeds mu [s] (-1: none); then the beam joint's demand and first exceedance.
A_PEAK, A_TAU_PEAK, A_EVALS, A_FRICTION, A_MU, A_SLIP, A_FRICTION2, A_SLIP2 = range(8)
ACC_SIZE = 8
#: Events of a piece.
NONE, IMPACT, COLLAPSE = 0, 1, 2
#: Longest scanning interval, in units of the shorter of 1/p and 1/omega [-] (the bound
#: halves the intervals it does not certify).
SCAN_STEP = 1.0
#: Brent's tolerances (scipy.optimize.brentq's xtol 1e-15 s and rtol 4 eps).
XTOL, RTOL = 1e-15, 4.0 * 2.220446049250313e-16
#: Halvings of an interval that neither bound certifies, before it is taken as is, and the
#: shortest interval [fraction of the longest] (neither is met in the tests' runs).
MAX_HALVINGS = 40
MIN_WIDTH = 1e-12


@jit
def start_piece(blk, t, theta, rate, side, fc, gam, pc):
    """Fill pc with the piece through (theta [rad], rate [rad/s]) at t [s] on side s
    under the forcing fc (exact.modal), the weights scaled by gam = (g + a_v) / g [-]
    (1: no vertical motion)."""
    p, alpha, e = blk[B_P] * math.sqrt(gam), blk[B_ALPHA], blk[B_E]
    p2 = p * p
    kind = int(fc[0])
    amp, om, phi, q0, q1, ga, g0, g1 = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    if kind == HARMONIC and fc[1] != 0.0:
        om, ga = fc[2], fc[1]
        amp = -e * ga / (p2 + om * om)
        phi = f_phase(fc, t)
    elif kind == LINEAR:
        g0, g1 = fc[5] + fc[6] * (t - fc[4]), fc[6]
        q0, q1 = -e * g0 / p2, -e * g1 / p2
    x0 = theta - side * alpha - amp * math.sin(phi) - q0
    v0 = rate - amp * om * math.cos(phi) - q1
    pc[T0], pc[SIDE], pc[AMP], pc[OM], pc[PHI] = t, side, amp, om, phi
    pc[Q0], pc[Q1], pc[ALPHA], pc[P] = q0, q1, alpha, p
    pc[C1], pc[C2] = 0.5 * (x0 + v0 / p), 0.5 * (x0 - v0 / p)
    pc[GA], pc[G0], pc[G1] = ga, g0, g1
    friction = not math.isnan(blk[B_FA])
    pc[FA], pc[FB] = (blk[B_FA], blk[B_FB]) if friction else (0.0, 0.0)
    beam = not math.isnan(blk[B_FA2])
    pc[FA2], pc[FB2] = (blk[B_FA2], blk[B_FB2]) if beam else (0.0, 0.0)


@jit
def _motion(pc, tau):
    """At t0 + tau: c1 e^(p tau), c2 e^(-p tau), the sine of the forcing's phase,
    theta - s alpha [rad], theta' [rad/s], a_g [m/s^2] and a_g' [m/s^3]."""
    p = pc[P]
    e1 = pc[C1] * math.exp(p * tau) if pc[C1] != 0.0 else 0.0
    e2 = pc[C2] * math.exp(-p * tau) if pc[C2] != 0.0 else 0.0
    arg = pc[OM] * tau + pc[PHI]
    sn, cs = math.sin(arg), math.cos(arg)
    dev = pc[AMP] * sn + pc[Q0] + pc[Q1] * tau + e1 + e2  # theta - s alpha
    rate = pc[AMP] * pc[OM] * cs + pc[Q1] + p * (e1 - e2)
    ag = pc[GA] * sn + pc[G0] + pc[G1] * tau
    ag_rate = pc[GA] * pc[OM] * cs + pc[G1]
    return e1, e2, sn, dev, rate, ag, ag_rate


@jit(inline=True)
def _demand(pc, row, dev, rate, ag, ag_rate):
    """A joint's friction demand from the motion at an instant (_motion's dev, rate, a_g,
    a_g'): fa a_g + fb (theta - s alpha) [-] with the row's factors (row 0 the ground
    joint's, 1 a monolithic frame's beam joint's; 0 without factors) and its rate [1/s]."""
    fa, fb = pc[FA + 2 * row], pc[FB + 2 * row]
    return fa * ag + fb * dev, fa * ag_rate + fb * rate


@jit(inline=True)
def _point_of(pc, motion):
    """point's figures from the motion at the instant (_motion's tuple)."""
    e1, e2, sn, dev, rate, ag, ag_rate = motion
    demand, demand_rate = _demand(pc, 0, dev, rate, ag, ag_rate)
    s, p = pc[SIDE], pc[P]
    accel = p * p * (e1 + e2) - pc[AMP] * pc[OM] * pc[OM] * sn
    return pc[ALPHA] + s * dev, s * rate, e1, e2, demand, demand_rate, s * accel


@jit
def point(pc, tau):
    """At t0 + tau: s theta [rad], s theta' [rad/s], c1 e^(p tau), c2 e^(-p tau), the
    friction demand's signed value fa a_g + fb (theta - s alpha) [-] (the shear ratio of
    the RBM's equations, n = 1; 0 without friction factors), its rate [1/s] and s theta''
    [rad/s^2]."""
    return _point_of(pc, _motion(pc, tau))


@jit
def point_and_beam(pc, tau):
    """:func:`point` at t0 + tau and a monolithic frame's beam joint's friction demand and
    its rate (0 without a beam), from one evaluation of the motion (scan_piece's)."""
    motion = _motion(pc, tau)
    _, _, _, dev, rate, ag, ag_rate = motion
    beam, beam_rate = _demand(pc, 1, dev, rate, ag, ag_rate)
    f, g, e1, e2, demand, demand_rate, accel = _point_of(pc, motion)
    return f, g, e1, e2, demand, demand_rate, accel, beam, beam_rate


@jit
def joint_demand(pc, tau, row):
    """The friction demand of a joint (row 0: the ground's, :func:`point`'s; 1: a monolithic
    frame's beam joint, the beam share's shear ratio) at t0 + tau: its signed value
    fa a_g + fb (theta - s alpha) [-] with the row's factors, and its rate [1/s]."""
    _, _, _, dev, rate, ag, ag_rate = _motion(pc, tau)
    return _demand(pc, row, dev, rate, ag, ag_rate)


@jit
def _value(pc, which, shift, tau):
    """s theta + shift (which 0), s theta' (which 1) at t0 + tau, or a joint's friction
    demand's rate (which 2 + 2 row) or demand + shift (which 3 + 2 row; row 0 the ground
    joint's, 1 a monolithic frame's beam joint's)."""
    if which >= 2:
        d, dr = joint_demand(pc, tau, (which - 2) // 2)
        return d + shift if which % 2 == 1 else dr
    f, g, _, _, _, _, _ = point(pc, tau)
    return f + shift if which == 0 else g


@jit
def brent(pc, which, shift, xa, xb, acc):
    """Root in [xa, xb] of _value(pc, which, shift, .), which changes sign there (scipy's
    brentq, Brent 1973, xtol XTOL and rtol RTOL); evaluations counted in acc."""
    xpre, xcur = xa, xb
    fpre, fcur = _value(pc, which, shift, xpre), _value(pc, which, shift, xcur)
    acc[A_EVALS] += 2
    if fpre == 0.0:
        return xpre
    if fcur == 0.0:
        return xcur
    xblk, fblk, spre, scur = 0.0, 0.0, 0.0, 0.0
    for _ in range(200):
        done, xpre, xcur, xblk, fpre, fblk, spre, scur = brent_step(
            xpre, xcur, xblk, fpre, fcur, fblk, spre, scur, XTOL, RTOL
        )
        if done:
            return xcur
        fcur = _value(pc, which, shift, xcur)
        acc[A_EVALS] += 1
    return xcur


@jit
def impact_time(pc, blk, a, b, fa, acc):
    """The impact time in [a, b], s theta(b) + eps <= 0 < s theta(a) + eps. The RBM's
    convention (blk[B_AT_ZERO] 0, the step kernel's and the exact integrator's): where s
    theta reaches -eps (the state is then projected onto theta = 0). housner-linear's: the
    root of s theta if s theta(a) > eps, else (s theta(a) within round-off of 0, as at a
    restart from theta = 0, where the sign of s theta is round-off: a root of s theta
    itself could be one of its sign changes next to a) of s theta + eps, then two Newton
    steps to s theta = 0."""
    eps = blk[B_EPS]
    if blk[B_AT_ZERO] == 0.0:
        return brent(pc, 0, eps, a, b, acc)
    if fa > eps:
        return brent(pc, 0, 0.0, a, b, acc)
    tau = brent(pc, 0, eps, a, b, acc)
    for _ in range(2):
        f, g, _, _, _, _, _ = point(pc, tau)
        acc[A_EVALS] += 1
        if g >= 0.0:
            break
        tau = min(max(tau - f / g, a), b)
    return tau


@jit
def _interval(pc, blk, a, b, fa, ga, fb, gb, acc):
    """The first event in a certified interval [a, b] (at most one zero of the rate),
    from its end values (s theta, s theta') and its extremum; the peak kept in acc.
    Returns (kind, tau)."""
    limit, eps = blk[B_LIMIT], blk[B_EPS]
    if ga * gb < 0.0:
        tm = brent(pc, 1, 0.0, a, b, acc)
        fm, _, _, _, _, _, _ = point(pc, tm)
        acc[A_EVALS] += 1
        if ga > 0.0:  # a maximum
            if fm >= limit:
                return COLLAPSE, brent(pc, 0, -limit, a, tm, acc)
            if fm > acc[A_PEAK]:
                acc[A_PEAK], acc[A_TAU_PEAK] = fm, tm
            if fb + eps <= 0.0:
                return IMPACT, impact_time(pc, blk, tm, b, fm, acc)
        else:  # a minimum
            if fm + eps <= 0.0:
                return IMPACT, impact_time(pc, blk, a, tm, fa, acc)
            if fb >= limit:
                return COLLAPSE, brent(pc, 0, -limit, tm, b, acc)
    else:  # monotone
        if fb >= limit:
            return COLLAPSE, brent(pc, 0, -limit, a, b, acc)
        if fb + eps <= 0.0:
            return IMPACT, impact_time(pc, blk, a, b, fa, acc)
    if fb > acc[A_PEAK]:
        acc[A_PEAK] = fb
    return NONE, b


@jit
def _first_over(pc, a, b, da, db, tm, dm, mu, acc, row):
    """The first time in [a, b] where |demand| of a row (0: the ground joint's, 1: the beam
    joint's) exceeds mu, the demand being monotone on [a, tm] and [tm, b] (tm < 0: on
    [a, b]) with its ends da, dm, db: Brent on demand = +-mu on the first monotone part
    whose end is past it."""
    if abs(da) > mu:
        return a
    lo = a
    which = 3 + 2 * row
    if tm >= 0.0:
        if abs(dm) > mu:
            return brent(pc, which, -mu if dm > 0.0 else mu, a, tm, acc)
        lo = tm
    return brent(pc, which, -mu if db > 0.0 else mu, lo, b, acc)


@jit
def _friction(pc, a, b, da, db, dra, drb, acc, row):
    """Raise acc's friction demand of a row (0: the ground joint's, 1: the beam joint's) to
    the largest |demand| on [a, b]: its ends' (da, db) and, where its rate (dra, drb)
    changes sign, the extremum's (Brent on the rate)."""
    fr, sl = (A_FRICTION, A_SLIP) if row == 0 else (A_FRICTION2, A_SLIP2)
    best = max(abs(da), abs(db))
    tm, dm = -1.0, 0.0
    if dra * drb < 0.0:
        tm = brent(pc, 2 + 2 * row, 0.0, a, b, acc)
        dm, _ = joint_demand(pc, tm, row)
        acc[A_EVALS] += 1
        best = max(best, abs(dm))
    if best > acc[A_MU] and acc[sl] < 0.0:
        acc[sl] = _first_over(pc, a, b, da, db, tm, dm, acc[A_MU], acc, row)
    if best > acc[fr]:
        acc[fr] = best


@jit
def scan_piece(pc, blk, tau_max, acc):
    """The piece's first event before tau_max [s] (from its start), or its end:
    (kind, tau). acc gets the peak (the largest s theta on [0, tau], with the time of an
    interior maximum holding it), the evaluations and the friction demand."""
    om = pc[OM] if pc[AMP] != 0.0 else 0.0
    h_max = SCAN_STEP / max(pc[P], om)
    m3_sine = abs(pc[AMP]) * om * om * om
    p3 = pc[P] * pc[P] * pc[P]
    friction = pc[FA] != 0.0 or pc[FB] != 0.0
    beam = pc[FA2] != 0.0 or pc[FB2] != 0.0  # a monolithic frame's beam joint
    a = 0.0
    fa, ga, _, e2a, da, dra, f2a, ba, bra = point_and_beam(pc, 0.0)
    acc[A_EVALS] += 1
    if fa > acc[A_PEAK]:
        acc[A_PEAK] = fa
    limit, eps = blk[B_LIMIT], blk[B_EPS]
    h, halvings = h_max, 0
    while a < tau_max:
        b = min(a + h, tau_max)
        fb, gb, e1b, e2b, db, drb, f2b, bb, brb = point_and_beam(pc, b)
        acc[A_EVALS] += 1
        w = b - a
        m3 = m3_sine + p3 * (abs(e1b) + abs(e2a))  # bound of the third derivative on [a, b]
        one_turn = max(abs(ga), abs(gb)) > m3 * w * w  # at most one zero of the rate
        # or a Taylor envelope at a, |s theta - fa| <= reach <= eps on [a, b]: no event,
        # no peak above fa + eps (a grazing uplift's start, where the rate is round-off)
        reach = w * (abs(ga) + w * (0.5 * abs(f2a) + m3 * w / 6.0))
        still = reach <= eps and fa - reach > -eps and fa + reach < limit
        if not (one_turn or still) and halvings < MAX_HALVINGS and w > MIN_WIDTH * h_max:
            h, halvings = 0.5 * w, halvings + 1
            continue
        if one_turn or not still:
            kind, tau = _interval(pc, blk, a, b, fa, ga, fb, gb, acc)
        else:
            kind, tau = NONE, b
            acc[A_PEAK] = max(acc[A_PEAK], fb)
        if kind != NONE:
            if friction or beam:
                _, _, _, _, db, drb, _, bb, brb = point_and_beam(pc, tau)
            if friction:
                _friction(pc, a, tau, da, db, dra, drb, acc, 0)
            if beam:
                _friction(pc, a, tau, ba, bb, bra, brb, acc, 1)
            return kind, tau
        if friction:
            _friction(pc, a, b, da, db, dra, drb, acc, 0)
        if beam:
            _friction(pc, a, b, ba, bb, bra, brb, acc, 1)
        a, fa, ga, e2a, da, dra, f2a = b, fb, gb, e2b, db, drb, f2b
        ba, bra = bb, brb
        h, halvings = min(2.0 * h, h_max), 0
    return NONE, tau_max
