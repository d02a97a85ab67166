"""The Rigid Beam Model in two horizontal directions (for `rbm-3d`): a column of circular
drums whose nodes move in x and y, each drum's small rotation a vector.

A drum's rotation is the pair (theta_x, theta_y): theta_x the small rotation that moves its
top along +x, theta_y along +y (so a planar run along x has theta_y = 0 and theta_x the
planar theta). The kinematics of the planar model hold in each direction on its own: the
nodes' displacements are node_map @ theta_x and node_map @ theta_y, the drums' centres
centre_map @ theta_x and @ theta_y, and the mass matrix M (a drum of circular section has
the same inertia I_G about every horizontal axis) is the planar one for both. The two
directions meet only in the joints. A circular joint of diameter D carries the same
capacity M_u = (D / 2) N in every direction, so its moment is the planar law f applied to
the magnitude of its relative rotation vector phi_i (the law's argument, D theta or theta
for `absolute`, in each direction), along that vector:

    m_i = -f(|phi_i|) phi_i / |phi_i|        (the moment restoring the joint),

and with it, per direction d = x, y (as the planar equations, rbm_cli.structures.equations),

    M theta_d'' = D^T m_d + gam K_g theta_d - r a_d(t) - D^T (c phi_d')  (elastic joints),

gam = (g + a_v) / g the vertical record's factor on the laws' weight parts and on gravity's
term K_g of `geometric` (the elastic parts K_M do not scale), c the joints' damping on their
elastic branch (Model.joint_damping). On the elastic branch f = K_M |phi| and the moment is
-K_M phi: the column is linear and the two directions do not meet at all.

Near a closed joint of a rigid law (f jumps at 0: a rigid monolith) the direction of phi is
not defined at phi = 0 and turns without bound as phi passes closure ever nearer; within a
pinned distance of closure the law reads the component x = phi . c of phi along a pinned
direction c (the side the joint rocks onto), as a base flat to that side, and m = -f(x) c
(rbm_cli.models.rbm3d says when: that distance is the integrator's absolute tolerance of
the rotation, solver.atol theta_u).

The equations are compiled (numba) as the planar kernel's are, in the same slots as its
right-hand side's (rbm_cli.structures.rates.rhs), on a state of 4n values
(:func:`beam_rates`, this column's right-hand side):

- ``As`` (n, 3n): [M^-1 D^T | M^-1 K_g | the argument map];
- ``cs`` (9n): per joint, the piece it is on: intercept, weight slope, elastic slope, its
  damping (0 off the elastic branch), pinned (0.0, 1.0, or 2.0: at phi = 0 alone), the
  pinned direction (x, y), then 2n of scratch for the moments (:func:`pack_pieces` fills
  it);
- ``es`` (n + 10): -M^-1 r, the motion's direction in plan (cos, sin), then the second
  horizontal component (flag, gain, omega, phase, centre, gamma: a record pair's straight
  piece, a_{k+1} - a_k, a_k, t_k, t_{k+1} - t_k, or an analytic component's formula; flag
  0 for one component), then 1.0 if K_g is not zero, then the second component's form
  (inputs.ground: LINE for a record pair's piece, or SINE, RICKER, MP).
"""

from __future__ import annotations

import math

from rbm_cli.base.jit import jit
from rbm_cli.inputs.ground import LINE, gravity_factor, ground, shape_at

#: Entries of ``es`` after the n loads: the direction, the second component's piece or
#: formula, whether gravity's term K_g is there (`geometric`), and the second component's
#: form.
ES_EXTRA = 10
#: Entries per joint of ``cs`` (pieces, pinned direction, scratch).
CS_PER_JOINT = 9


@jit(inline=True)
def second_component(t, es, n):
    """a_y(t) [m/s^2] of a pair's second component: a record's on its current straight
    piece, or an analytic one's formula (0 without)."""
    if es[n + 2] == 0.0 or es[n + 3] == 0.0:
        return 0.0
    if es[n + 9] == LINE:
        v = es[n + 5] + es[n + 4] * ((t - es[n + 6]) / es[n + 7])
        return v if es[n + 3] == 1.0 else es[n + 3] * v
    return shape_at(t, int(es[n + 9]), es[n + 3], es[n + 4], es[n + 5], es[n + 6], es[n + 7])


@jit(inline=True)
def horizontal(t, es, n, gr):
    """(a_x, a_y) [m/s^2]: the motion along its direction, plus a pair's second component
    across it."""
    ag, ay = ground(t, gr), second_component(t, es, n)
    d0, d1 = es[n], es[n + 1]
    return ag * d0 - ay * d1, ag * d1 + ay * d0


@jit(inline=True)
def beam_rates(t, y, n, As, cs, es, gr, out):
    """y' of the state y = (theta_x, theta_y, theta_x', theta_y') (4n,) into out, the
    pieces and pinned directions in cs (:func:`pack_pieces`)."""
    ax, ay = horizontal(t, es, n, gr)
    gam = gravity_factor(t, gr)
    for i in range(n):
        px, py, vx, vy = 0.0, 0.0, 0.0, 0.0
        for j in range(n):
            a = As[i, 2 * n + j]
            px += a * y[j]
            py += a * y[n + j]
            vx += a * y[2 * n + j]
            vy += a * y[3 * n + j]
        a0 = gam * cs[i]
        slope = gam * cs[n + i] + cs[2 * n + i]
        r = math.sqrt(px * px + py * py)
        pin = cs[4 * n + i]
        if pin == 1.0 or (pin == 2.0 and r == 0.0):  # pinned: the law along c
            cx, cy = cs[5 * n + i], cs[6 * n + i]
            along = a0 + slope * (px * cx + py * cy)
            mx, my = -along * cx, -along * cy
        else:
            k = (a0 / r if r > 0.0 else 0.0) + slope
            mx, my = -k * px, -k * py
        damp = cs[3 * n + i]
        if damp != 0.0:
            mx -= damp * vx
            my -= damp * vy
        cs[7 * n + i], cs[8 * n + i] = mx, my
    for i in range(n):
        out[i] = y[2 * n + i]
        out[n + i] = y[3 * n + i]
        sx, sy = es[i] * ax, es[i] * ay
        for j in range(n):
            sx += As[i, j] * cs[7 * n + j]
            sy += As[i, j] * cs[8 * n + j]
        if es[n + 8] != 0.0:  # gravity's term (`geometric`)
            for j in range(n):
                sx += gam * As[i, n + j] * y[j]
                sy += gam * As[i, n + j] * y[n + j]
        out[2 * n + i] = sx
        out[3 * n + i] = sy


@jit
def pack_pieces(k, pinned, c, intercepts, weight, elastic, damp, rigid, cs):
    """cs's pieces (beam_rates) of joints on pieces k (n,) of their laws, pinned (n,) along
    c (n, 2 or more: the direction in its first two columns; 0 free, 1 pinned, 2 pinned
    where phi = 0 exactly, its own direction elsewhere): each piece's intercept and slopes,
    the damping of an elastic joint on its elastic branch."""
    n = k.size
    for i in range(n):
        q = k[i]
        cs[i] = intercepts[i, q]
        cs[n + i] = weight[i, q]
        cs[2 * n + i] = elastic[i, q]
        cs[3 * n + i] = damp[i] if (q == 0 and not rigid[i]) else 0.0
        cs[4 * n + i] = float(pinned[i])
        cs[5 * n + i] = c[i, 0]
        cs[6 * n + i] = c[i, 1]
