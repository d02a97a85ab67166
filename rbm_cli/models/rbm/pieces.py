"""The law pieces of a column's interfaces, as the compiled integrators (step and exact) keep
them: which piece of its moment-rotation law each interface is on, the piece's bounds and
event rows, locating the pieces of a state and crossing to the next piece (uplift, kink,
impact), the silent impacts, and what both integrators compute from the pieces (an impact's
loss of rate, a law's potential and a state's energy, the friction demand: its peak and
the demand held for a duration, which the block's closed form and rbm-3d's kernel take
too).

A law is odd and piecewise linear (rbm_cli.structures.law): on x >= 0 its piece k is
f = a_k + b_k x on [x_k, x_{k+1}), the edges x_1 < x_2 < ... padded with inf
(rbm_cli.structures.law.law_arrays). Interface i's piece is its side s_i = +-1 (the sign of its
argument) and its index k_i; ``pending[i]`` marks an excursion beyond the elastic branch
(piece 0 is then bounded by 0: the next zero crossing is an impact), ``awaiting[i]`` an
interface back on piece 0 whose zero crossing is silent (counted, not stopped at:
Model.silent_impacts). An uplift is a closed interface opening; one that leaves its elastic
branch again before its zero crossing goes on with its excursion (no uplift), whether that
crossing would be silent or not. The arrays are changed in place.

tests/piece_oracle.py writes the same bookkeeping from the laws' objects, as a check.
"""

from __future__ import annotations

import math

import numpy as np

from rbm_cli.base.detmath import dot, matvec
from rbm_cli.base.events import BIG, EVENT_EPS
from rbm_cli.base.jit import jit

#: What crossing a bound of a piece is (cross returns it): leaving the elastic branch, another
#: piece of the same side, a zero crossing after an excursion (the side flips).
UPLIFT, KINK, IMPACT = 0, 1, 2


@jit(inline=True)
def n_below(edges, ne, x):
    """Number of the first ne edges [rad] at or below x [rad] (the index of x's piece)."""
    k = 0
    while k < ne and edges[k] <= x:
        k += 1
    return k


@jit(inline=True)
def zero_active(i, pending, rigid):
    """Whether interface i's piece 0 ends at x = 0 (a rigid law, or after an excursion)."""
    return rigid[i] or pending[i]


@jit(inline=True)
def piece_bounds(i, side, k, pending, rigid, edges, nedges):
    """(lo, hi) [rad]: the bounds of interface i's argument on its current piece."""
    ki = k[i]
    start = 0.0 if ki == 0 else edges[i, ki - 1]
    end = edges[i, ki] if ki < nedges[i] else np.inf
    if ki == 0 and not zero_active(i, pending, rigid):
        start = -end
    if side[i] > 0:
        return start, end
    return -end, -start


@jit
def bound_rows(side, k, pending, rigid, edges, nedges, tu, c_ratio, lo, hi, off):
    """The bounds lo, hi [rad] (n,) of the current pieces and the offsets off[:4n] [-] of the
    event rows, in their order: argument over theta_u above lo (x / tu + off[i]), below hi
    (-x / tu + off[n + i]), and the collapse ratio below c_ratio on either side (off[2n + i],
    off[3n + i]); each offset with EVENT_EPS, an infinite bound at BIG."""
    n = side.size
    for i in range(n):
        lo[i], hi[i] = piece_bounds(i, side, k, pending, rigid, edges, nedges)
        off[i] = min(-lo[i] / tu[i], BIG) + EVENT_EPS
        off[n + i] = min(hi[i] / tu[i], BIG) + EVENT_EPS
        off[2 * n + i] = c_ratio + EVENT_EPS
        off[3 * n + i] = c_ratio + EVENT_EPS


@jit
def locate(x, rate, side, k, pending, rigid, edges, nedges):
    """The pieces at law arguments x [rad] with rates rate [rad/s] (n,): the side of x (of
    the rate at x = 0), the piece holding |x|, pending beyond the elastic branch."""
    for i in range(x.size):
        if x[i] > 0.0:
            side[i] = 1
        elif x[i] < 0.0:
            side[i] = -1
        else:
            side[i] = 1 if rate[i] >= 0.0 else -1
        k[i] = n_below(edges[i], nedges[i], abs(x[i]))
        pending[i] = k[i] > 0 and not rigid[i]


@jit
def cross(i, going_up, side, k, pending, awaiting, rigid, silent):
    """Move interface i to its next piece as its argument crosses the current piece's upper
    (going_up) or lower bound.

    Returns
    -------
    int  UPLIFT (a closed interface opens), KINK or IMPACT. An interface awaiting a silent
        zero crossing that leaves its elastic branch again has not closed: its excursion
        goes on (a KINK), as with pending when e < 1.
    """
    s, ki = side[i], k[i]
    if ki == 0 and not zero_active(i, pending, rigid):
        reopened = awaiting[i]
        side[i] = 1 if going_up else -1
        k[i] = 1
        pending[i] = True
        awaiting[i] = False
        return KINK if reopened else UPLIFT
    if going_up == (s > 0):
        k[i] = ki + 1
        return KINK
    if ki > 0:
        k[i] = ki - 1
        if ki == 1 and silent[i]:
            pending[i] = False
            awaiting[i] = True
        return KINK
    side[i] = -s
    pending[i] = False
    return IMPACT


@jit(inline=True)
def silent_impact(i, side, awaiting):
    """Interface i's silent zero crossing: its side flips, it awaits no more."""
    side[i] = -side[i]
    awaiting[i] = False


@jit(inline=True)
def settle(awaiting, argmap, y, side):
    """Count the silent impacts up to the state y (rotations y[:n] [rad]): the interfaces
    awaiting one whose argument (argmap @ y[:n]) has changed sign, each a silent_impact.
    Returns how many."""
    hits = 0
    for i in range(side.size):
        if awaiting[i]:
            x_i = 0.0
            for j in range(argmap.shape[1]):
                x_i += argmap[i, j] * y[j]
            if side[i] * x_i < 0.0:
                silent_impact(i, side, awaiting)
                hits += 1
    return hits


@jit(inline=True)
def restitute(i, xdot, e_rest, impulse_dir, impulse_w, rate):
    """An impact at interface i with restitution e_rest [-] < 1: the rates rate [rad/s] (n,)
    take the impulse (e_rest - 1) xdot / w_i along direction i (the equations' impulse directions:
    impulse_dir (n, n), impulse_w (n,)), xdot [rad/s] the argument's rate at the impact;
    in place."""
    lam = (e_rest - 1.0) * xdot / impulse_w[i]
    for j in range(rate.size):
        rate[j] += impulse_dir[j, i] * lam


@jit
def law_potential(i, x, edges, nedges, intercepts, slopes):
    """F_i(x) [J]: interface i's law integrated from 0 to x [rad] (Law.potential)."""
    ax = abs(x)
    cum, start = 0.0, 0.0
    kk = n_below(edges[i], nedges[i], ax)
    for q in range(kk):
        end = edges[i, q]
        cum += intercepts[i, q] * (end - start) + 0.5 * slopes[i, q] * (end * end - start * start)
        start = end
    return cum + intercepts[i, kk] * (ax - start) + 0.5 * slopes[i, kk] * (ax * ax - start * start)


@jit
def energy(theta, rate, mass, argmap, gravity, edges, nedges, intercepts, slopes):
    """Energy [J] of one state (Model.energy): rotations theta [rad], rates rate [rad/s] (n,);
    kinetic, the laws' potential and, for `geometric`, gravity's."""
    n = theta.size
    e = 0.5 * dot(rate, matvec(mass, rate, np.empty(n))) - 0.5 * dot(
        theta, matvec(gravity, theta, np.empty(n))
    )
    x = matvec(argmap, theta, np.empty(argmap.shape[0]))
    for i in range(x.size):
        e += law_potential(i, x[i], edges, nedges, intercepts, slopes)
    return e


@jit
def below_barrier(theta, rate, mass, argmap, gravity, edges, nedges, intercepts, slopes, barrier):
    """Whether a state's energy (:func:`energy`) is below an energy barrier [J] by more
    than 1e-9 of it (NaN: no barrier, never): the test of both early stops of free motion,
    a monolith's at a peak (structures.arrays.rest_levels) and a column's certain survival
    (structures.arrays.survival_barrier)."""
    if barrier != barrier:
        return False
    en = energy(theta, rate, mass, argmap, gravity, edges, nedges, intercepts, slopes)
    return en < barrier * (1.0 - 1e-9)


@jit(inline=True)
def shear_ratios(ag, ag_y, gam, centre_map, acc, acc_y, masses, normal_forces, rx, ry, peak):
    """The friction demand of each interface at one instant: rx, ry (joints) get the shear
    T_i / (N_i gam) [-] (its x and y components; ry 0 in the plane), peak (joints) is raised
    to its magnitude |T_i| / (N_i gam). T_i [N] is the shear of the bodies above interface
    i (the drums above it, and a frame's beam share on the top node, the last body), from
    their absolute horizontal accelerations: the ground's (ag, ag_y) [m/s^2] +
    centre_map @ (acc, acc_y) (acc the drums' theta'' [rad/s^2]; acc_y empty in the
    plane), masses [kg] (a body each); N_i the normal force [N] at rest (normal_forces
    holds one per joint whose demand is reported, Model.friction_normals: body i lies on
    joint i, a frame's beam share on its beam joint, the last, even where a monolith folds
    that joint's law into the base's), gam = (g + a_v) / g [-] (1 without vertical
    motion)."""
    n = acc.size
    joints = normal_forces.size
    three = acc_y.size > 0
    sx, sy = 0.0, 0.0
    for i in range(masses.size - 1, -1, -1):
        bx, by = ag, ag_y
        for j in range(n):
            bx += centre_map[i, j] * acc[j]
            if three:
                by += centre_map[i, j] * acc_y[j]
        sx += bx * masses[i]
        sy += by * masses[i]
        if i >= joints:
            continue
        w = normal_forces[i] * gam
        rx[i], ry[i] = sx / w, sy / w
        d = math.sqrt(sx * sx + sy * sy) / w if three else abs(sx) / w
        if d > peak[i]:
            peak[i] = d


@jit(inline=True)
def first_over(friction, mu, t, slip):
    """Note (t [s], interface from 1) in slip where a friction demand first exceeds mu [-]
    (the largest of those over it)."""
    best = mu
    for i in range(friction.size):
        if friction[i] > best:
            best = friction[i]
            slip[0], slip[1] = t, i + 1.0


# ---- the friction demand held for a duration
#
# The RBM's normal force N_i is the weight above the joint: it has no vertical motion. That
# is the mean of the true normal force over times long against the joints' elastic
# periods, not its value at an instant of a joint's elastic phase or of a rattle of the
# drums (many joints open at once, in alternate directions): there the model's own
# kinematics lift the drums above an open joint at up to tens of g, and |T_i| / N_i (its
# largest, the peak) compares a shear of that instant with the weight. The demand a domain
# reports is the largest level |T_i| / N_i stays above, without its direction reversing,
# at every sample of a window of FRICTION_DURATION [s]: samples at
# t_k = k duration / HELD_SAMPLES, taken by every integrator at the same times (the step
# integrators on their steps' quintic Hermite interpolants of theta, the exact integrator
# and the block's closed form from their closed forms, a block at rest from a_g).

#: The duration [s] a friction demand of the RBM's joints is held for: longer than a
#: joint's elastic phase or a rattle of the drums (a few ms at k_n 5e9 Pa/m), a tenth of
#: the period of a 3.3 Hz shaking. The integrators take it as their default.
FRICTION_DURATION = 0.03
#: Sample intervals in a window of the held demand [-].
HELD_SAMPLES = 60
#: Columns of a held array's interface rows: the largest level held [-], the index of the
#: last sample whose shear reversed against the one before it, the last sample's shear
#: components [-], then the ring of the window's magnitudes (HELD_SAMPLES + 1).
HELD_LEVEL, HELD_REV, HELD_X, HELD_Y, HELD_RING = 0, 1, 2, 3, 4
#: Columns of its last row: the next sample's index and time [s], the sample spacing [s],
#: the window in samples (0: no held demand), the friction limit mu [-] and where the held
#: demand first exceeded it: the start of that window [s] and the interface (from 1; 0:
#: not).
HELD_NEXT, HELD_T_NEXT, HELD_DT, HELD_K, HELD_MU, HELD_T_SLIP, HELD_SLIP_IF = range(7)


def held_array(n: int, duration: float, mu: float = math.inf) -> np.ndarray:
    """A held demand's state for n interfaces, a window of duration [s] (0: none, the
    demand is the peak) and a friction limit mu [-] (inf: none); the integrators change it
    in place (:func:`held_push`)."""
    k = HELD_SAMPLES if duration > 0.0 else 0
    held = np.zeros((n + 1, max(HELD_RING + k + 1, 7)))
    last = held[n]
    last[HELD_T_NEXT] = 0.0 if k else math.inf
    last[HELD_DT] = duration / k if k else math.inf
    last[HELD_K] = k
    last[HELD_MU] = mu
    last[HELD_T_SLIP] = math.nan
    return held


@jit(inline=True)
def held_time(held):
    """The time of the next sample of a held demand [s] (inf: it takes none)."""
    return held[held.shape[0] - 1, HELD_T_NEXT]


@jit(borrow=True)
def held_push(held, rx, ry, peak):
    """Take the sample due (at :func:`held_time`): rx, ry (n) the shear ratios of each
    interface there (:func:`shear_ratios`). Each interface's held level is raised to the
    least magnitude over the window of the last HELD_SAMPLES + 1 samples where the shear
    did not reverse in it (no two consecutive samples with a dot product <= 0), peak (n)
    to the magnitude; the first window held above mu notes where it started."""
    n = held.shape[0] - 1
    last = held[n]
    k = last[HELD_NEXT]
    window = int(last[HELD_K])
    slot = HELD_RING + int(k) % (window + 1)
    best, where = last[HELD_MU], -1
    for i in range(n):
        row = held[i]
        x, y = rx[i], ry[i]
        if x * row[HELD_X] + y * row[HELD_Y] <= 0.0:
            row[HELD_REV] = k
        row[HELD_X], row[HELD_Y] = x, y
        size = abs(x) if y == 0.0 else math.sqrt(x * x + y * y)
        row[slot] = size
        if size > peak[i]:
            peak[i] = size
        if k - row[HELD_REV] >= window:
            level = row[HELD_RING]
            for j in range(1, window + 1):
                level = min(level, row[HELD_RING + j])
            if level > row[HELD_LEVEL]:
                row[HELD_LEVEL] = level
            if level > best:
                best, where = level, i
    if where >= 0 and last[HELD_SLIP_IF] == 0.0:
        last[HELD_T_SLIP] = (k - window) * last[HELD_DT]
        last[HELD_SLIP_IF] = where + 1.0
    last[HELD_NEXT] = k + 1.0
    last[HELD_T_NEXT] = (k + 1.0) * last[HELD_DT]


@jit(inline=True)
def hermite_accel(s, h, x0, v0, a0, x1, v1, a1):
    """x''(t0 + s h) [per s^2] of the quintic through x, x', x'' given at t0 (x0, v0, a0)
    and t0 + h (x1, v1, a1), 0 <= s <= 1, h > 0 [s]."""
    s2 = s * s
    s3 = s2 * s
    return (((x1 - x0) * (60.0 * s - 180.0 * s2 + 120.0 * s3)
             + h * (v0 * (-36.0 * s + 96.0 * s2 - 60.0 * s3)
                    + v1 * (-24.0 * s + 84.0 * s2 - 60.0 * s3))) / (h * h)
            + a0 * (1.0 - 9.0 * s + 18.0 * s2 - 10.0 * s3)
            + a1 * (3.0 * s - 12.0 * s2 + 10.0 * s3))  # fmt: skip


def held_result(held: np.ndarray, peak: np.ndarray, slip) -> tuple[np.ndarray, tuple | None]:
    """The friction demand (n) and its first exceedance of the limit ((t [s], interface)
    or None) a run reports: the held demand's with a window, else the peak's (slip: the
    integrator's (t, interface), interface 0 for none)."""
    n = held.shape[0] - 1
    last = held[n]
    if last[HELD_K] == 0.0:
        return peak.copy(), ((float(slip[0]), int(slip[1])) if slip[1] > 0 else None)
    where = int(last[HELD_SLIP_IF])
    return held[:n, HELD_LEVEL].copy(), ((float(last[HELD_T_SLIP]), where) if where else None)


__all__ = [
    "IMPACT",
    "KINK",
    "UPLIFT",
    "bound_rows",
    "cross",
    "energy",
    "first_over",
    "held_array",
    "held_push",
    "held_result",
    "held_time",
    "hermite_accel",
    "law_potential",
    "locate",
    "n_below",
    "piece_bounds",
    "restitute",
    "settle",
    "shear_ratios",
    "silent_impact",
    "zero_active",
]
