"""The law pieces of a column's interfaces, as the compiled integrators (step and exact) keep
them: which piece of its moment-rotation law each interface is on, the piece's bounds and
event rows, locating the pieces of a state and crossing to the next piece (uplift, kink,
impact), the silent impacts, and what both integrators compute from the pieces (an impact's
loss of rate, a law's potential and a state's energy, the friction demand).

A law is odd and piecewise linear (rbm_cli.physics.law): on x >= 0 its piece k is
f = a_k + b_k x on [x_k, x_{k+1}), the edges x_1 < x_2 < ... padded with inf
(rbm_cli.physics.law.law_arrays). Interface i's piece is its side s_i = +-1 (the sign of its
argument) and its index k_i; ``pending[i]`` marks an excursion beyond the elastic branch
(piece 0 is then bounded by 0: the next zero crossing is an impact), ``awaiting[i]`` an
interface back on piece 0 whose zero crossing is silent (counted, not stopped at:
Model.silent_impacts). An uplift is a closed interface opening; one that leaves its elastic
branch again before its zero crossing goes on with its excursion (no uplift), whether that
crossing would be silent or not. The arrays are changed in place.

tests/piece_oracle.py writes the same bookkeeping from the laws' objects, as a check.
"""

from __future__ import annotations

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
    n = side.size
    hits = 0
    for i in range(n):
        if awaiting[i]:
            x_i = 0.0
            for j in range(n):
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
    x = matvec(argmap, theta, np.empty(n))
    for i in range(n):
        e += law_potential(i, x[i], edges, nedges, intercepts, slopes)
    return e


@jit
def below_barrier(theta, rate, mass, argmap, gravity, edges, nedges, intercepts, slopes,
                  barrier):
    """Whether a state's energy (:func:`energy`) is below an energy barrier [J] by more
    than 1e-9 of it (NaN: no barrier, never): the test of both early stops of free motion,
    a monolith's at a peak (physics.arrays.rest_levels) and a column's certain survival
    (physics.arrays.survival_barrier)."""
    if barrier != barrier:
        return False
    en = energy(theta, rate, mass, argmap, gravity, edges, nedges, intercepts, slopes)
    return en < barrier * (1.0 - 1e-9)


@jit(inline=True)
def friction_demand(ag, gam, centre_map, acc, masses, normal_forces, out):
    """Raise out (n) to the friction demand |T_i| / (N_i gam) [-] of each interface: T_i the
    shear [N] of the drums above it, from their absolute accelerations ag [m/s^2] (the
    ground's) + centre_map @ acc (acc the drums' theta'' [rad/s^2]), masses [kg]; N_i the
    normal force [N] at rest, gam = (g + a_v) / g [-] (1 without vertical motion)."""
    n = acc.size
    shear = 0.0
    for i in range(n - 1, -1, -1):
        a_abs = ag
        for j in range(n):
            a_abs += centre_map[i, j] * acc[j]
        shear += a_abs * masses[i]
        fr = abs(shear) / (normal_forces[i] * gam)
        if fr > out[i]:
            out[i] = fr


@jit(inline=True)
def first_over(friction, mu, t, slip):
    """Note (t [s], interface from 1) in slip where a friction demand first exceeds mu [-]
    (the largest of those over it)."""
    best = mu
    for i in range(friction.size):
        if friction[i] > best:
            best = friction[i]
            slip[0], slip[1] = t, i + 1.0


__all__ = [
    "IMPACT",
    "KINK",
    "UPLIFT",
    "bound_rows",
    "cross",
    "energy",
    "first_over",
    "friction_demand",
    "law_potential",
    "locate",
    "n_below",
    "piece_bounds",
    "restitute",
    "settle",
    "silent_impact",
    "zero_active",
]
