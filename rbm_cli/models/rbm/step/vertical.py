"""Vertical shaking with elastic joints in the compiled kernel (numba): the kinks of a law
that move with gam(t) = (g + a_v(t)) / g.

Under g + a_v(t) a piece of a law is f = gam (a_k + bs_k x) + be_k x (the weight part
scales, the joint stiffness does not: Model.slope_parts), so a kink between two lines whose
slopes differ in their non-weight part moves: x_q(gam) = E_q m(gam; w_q) with
m(gam; w) = gam / (1 + w (gam - 1)), E_q the kink at gam = 1 and w_q the weight share of
the two lines' slope difference (Model.edge_weight_shares; w = 1: a fixed kink). x_q(gam) is
where the two lines cross, so the event row of a moving kink, (x - x_q(gam(t))) / theta_u, is
their signed difference divided by its (positive) slope in x: it vanishes where the lines
meet, at gam(t), not at the kink of gam = 1. Inside a step gam is one straight line (a
record's steps end at its samples), so the row is the dense output's polynomial plus
E m(gam(t)) / theta_u, evaluated exactly.

The event rows' bookkeeping: mv_e[r] (0 for a fixed row) and mv_w[r] describe the moving
part of rows r < 2n (the law bounds, rbm_cli.models.rbm.pieces.piece_bounds): row i (lower
bound) is x_i / theta_u - lo_i / theta_u, row n + i (upper) is hi_i / theta_u - x_i / theta_u;
the moving part is mv_e m(gam; mv_w), and the row's h0 keeps only EVENT_EPS.
"""

from __future__ import annotations

from rbm_cli.base.events import EVENT_EPS
from rbm_cli.base.jit import jit
from rbm_cli.config.types import G
from rbm_cli.inputs.ground import gravity_factor


@jit(inline=True)
def _m(gam, w):
    """m(gam; w) = gam / (1 + w (gam - 1)) [-]: a kink's position over its position at
    gam = 1 (1 exactly when w = 1, a fixed kink)."""
    if w == 1.0:
        return 1.0
    return gam / (1.0 + w * (gam - 1.0))


@jit(inline=True)
def _gam_rate(gr):
    """d gam / dt [1/s] on the record's straight piece gr (rbm_cli.inputs.ground)."""
    if gr[6] == 0.0:
        return 0.0
    return gr[8] / (gr[5] * G)


@jit(inline=True)
def moving_value(t, gr, e, w):
    """The moving part e m(gam(t); w) of an event row at t [s] (0 for a fixed row)."""
    if e == 0.0:
        return 0.0
    return e * _m(gravity_factor(t, gr), w)


@jit(inline=True)
def moving_rate(t, gr, e, w):
    """d/dt of moving_value [1/s]."""
    if e == 0.0:
        return 0.0
    gam = gravity_factor(t, gr)
    den = 1.0 + w * (gam - 1.0)
    return e * (1.0 - w) / (den * den) * _gam_rate(gr)


@jit
def add_moving(t, gr, mv_e, mv_w, d, dd, d2):
    """Add the moving parts of the rows (and their first and second time derivatives) at
    t [s] to the event distances d, their rates dd and second derivatives d2 (rows < 2n)."""
    gp = _gam_rate(gr)
    for r in range(mv_e.size):
        e = mv_e[r]
        if e == 0.0:
            continue
        w = mv_w[r]
        gam = gravity_factor(t, gr)
        den = 1.0 + w * (gam - 1.0)
        d[r] += e * _m(gam, w)
        dd[r] += e * (1.0 - w) / (den * den) * gp
        d2[r] += -2.0 * e * w * (1.0 - w) / (den * den * den) * gp * gp


@jit
def _end(i, k, ne, rigid, pending):
    """(edge, sign) of the start and end of interface i's piece k (pieces.piece_bounds):
    edge -1 for 0 or infinity."""
    q_end = k if k < ne else -1
    if k == 0 and not (rigid or pending):
        return q_end, -1.0, q_end, 1.0
    if k == 0:
        return -1, 1.0, q_end, 1.0
    return k - 1, 1.0, q_end, 1.0


@jit
def moving_rows(side, k, pending, rigid, edges, nedges, edge_w, tu, h0, mv_e, mv_w):
    """mv_e, mv_w of the law-bound rows of the active pieces (module docstring); h0 of a
    moving row keeps EVENT_EPS only."""
    n = side.size
    for i in range(n):
        q_s, s_s, q_e, s_e = _end(i, k[i], nedges[i], rigid[i], pending[i])
        # lo, hi = (start, end) on side +1, (-end, -start) on side -1
        if side[i] > 0:
            q_lo, s_lo, q_hi, s_hi = q_s, s_s, q_e, s_e
        else:
            q_lo, s_lo, q_hi, s_hi = q_e, -s_e, q_s, -s_s
        mv_e[i], mv_w[i] = 0.0, 1.0
        mv_e[n + i], mv_w[n + i] = 0.0, 1.0
        if q_lo >= 0 and edge_w[i, q_lo] != 1.0:
            mv_e[i] = -s_lo * edges[i, q_lo] / tu[i]
            mv_w[i] = edge_w[i, q_lo]
            h0[i] = EVENT_EPS
        if q_hi >= 0 and edge_w[i, q_hi] != 1.0:
            mv_e[n + i] = s_hi * edges[i, q_hi] / tu[i]
            mv_w[n + i] = edge_w[i, q_hi]
            h0[n + i] = EVENT_EPS


@jit
def bound_now(i, going_up, n, lo, hi, tu, t, gr, mv_e, mv_w):
    """The bound [rad] interface i's argument reached at its event at t [s]: the kink where
    the two lines meet at gam(t) for a moving one, else lo[i] or hi[i]."""
    if going_up:
        e = mv_e[n + i]
        return hi[i] if e == 0.0 else moving_value(t, gr, e, mv_w[n + i]) * tu[i]
    e = mv_e[i]
    return lo[i] if e == 0.0 else -moving_value(t, gr, e, mv_w[i]) * tu[i]
