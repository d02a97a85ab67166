"""The compiled run of `rbm-3d` (numba; the rules: rbm_cli.models.rbm3d.runner).

One call runs a whole motion. The Runge-Kutta steps are the planar step kernel's
(rbm_cli.numerics.rk: scipy's tableaux, error norm, step control and dense output, this
column's copies on its own right-hand side, structures.column3d.beam_rates); the
events are located on each step's dense output: the watched distances are evaluated at
CHECK_INTERVALS + 1 points of the step, and in the first sub-interval where one ends below
zero, or where its cubic Hermite dips below zero (confirmed on the dense output), each
such row's crossing is found by Brent's method (base.brent) and the earliest wins.
"""

from __future__ import annotations

import math

import numpy as np

from rbm_cli.base.brent import brent_step
from rbm_cli.base.copies import copy_into
from rbm_cli.base.events import EVENT_EPS
from rbm_cli.base.jit import jit
from rbm_cli.config.types import G
from rbm_cli.inputs.ground import (
    LINE,
    gravity_factor,
    ground_at,
    next_uplift,
    pair_uplift,
    record_piece,
    rest_demand,
    rest_shear,
    vertical_factor,
)
from rbm_cli.models.outcome import WOBBLE_LEVEL
from rbm_cli.models.rbm.pieces import (
    below_barrier,
    held_push,
    held_time,
    hermite_accel,
    law_potential,
    shear_ratios,
)
from rbm_cli.models.rbm.step.inputs import Excitation, SolverSettings, motion_into
from rbm_cli.models.rbm3d.work import COLUMN3D
from rbm_cli.models.status import (
    COLLAPSED,
    GOING,
)
from rbm_cli.numerics.loop import RunEnd, loop_for, loop_into
from rbm_cli.numerics.quadrature import GL_NODES, GL_WEIGHTS
from rbm_cli.numerics.records import new_record
from rbm_cli.numerics.rk import TAB_EST, TAB_NS, dense_eval, steps_for
from rbm_cli.structures.arrays import ColumnArrays, column_into
from rbm_cli.structures.column3d import CS_PER_JOINT, ES_EXTRA, beam_rates, horizontal, pack_pieces

#: A rigid joint's direction is pinned within a distance of closure (c[i, 2], solver.atol
#: theta_u: the runner's notes) and after an uplift or an impact, until LEAVE_FACTOR times
#: that distance.
LEAVE_FACTOR = 2.0
#: A joint's phase: free (its own direction), leaving or approaching closure (pinned).
FREE, LEAVING, APPROACH = 0, 1, 2
#: The events watched: a kink up or down, near closure, left it, across the pinned line,
#: turned away near closure, collapse.
UP, DOWN, NEAR, LEFT, ACROSS, TURNED, COLLAPSE = 0, 1, 2, 3, 4, 5, 6
#: Points of a step at which the watched distances are checked (sub-intervals).
CHECK_INTERVALS = 8
#: Brent's tolerances (scipy's rtol, 4 eps; xtol [s]) and iterations.
XTOL, RTOL, MAXITER = 1e-15, 8.881784197001252e-16, 100
#: The run ended at rest in the free motion after the ground motion.
AT_REST = 11

#: The column's Runge-Kutta steps on its right-hand side (structures.column3d.beam_rates).
initial_step, attempt_step, dense_prepare = steps_for("column3d", beam_rates)


@jit(inline=True)
def _phi(i, y, n, argmap):
    """Joint i's rotation vector (x, y) [rad] and its rate [rad/s]."""
    px, py, vx, vy = 0.0, 0.0, 0.0, 0.0
    for j in range(n):
        a = argmap[i, j]
        px += a * y[j]
        py += a * y[n + j]
        vx += a * y[2 * n + j]
        vy += a * y[3 * n + j]
    return px, py, vx, vy


@jit(inline=True)
def _magnitude(row, y, n):
    """|(row @ theta_x, row @ theta_y)| and its rate."""
    px, py, vx, vy = 0.0, 0.0, 0.0, 0.0
    for j in range(n):
        px += row[j] * y[j]
        py += row[j] * y[n + j]
        vx += row[j] * y[2 * n + j]
        vy += row[j] * y[3 * n + j]
    m = math.sqrt(px * px + py * py)
    return m, ((px * vx + py * vy) / m if m > 0.0 else 0.0)


@jit(inline=True)
def _edge(i, q, gam, edges, nedges, edge_w):
    """Joint i's kink q [rad] under gam = (g + a_v) / g (inf past the last)."""
    if q >= nedges[i]:
        return np.inf
    return edges[i, q] * gam / (1.0 + edge_w[i, q] * (gam - 1.0))


@jit(inline=True)
def distance(kind, i, y, n, col, k, c, gam):
    """A watched event's distance [-] and its rate [-/s] at state y (c: each joint's pinned
    direction and pinned distance, run3d's notes)."""
    if kind == COLLAPSE:
        m, dm = _magnitude(col.families[n + i], y, n)
        return col.c_ratio + EVENT_EPS - m, -dm
    px, py, vx, vy = _phi(i, y, n, col.argmap)
    r = math.sqrt(px * px + py * py)
    dr = (px * vx + py * vy) / r if r > 0.0 else 0.0
    tu = col.tu[i]
    if kind == UP:
        e = _edge(i, k[i], gam, col.edges, col.nedges, col.edge_w)
        return (e - r) / tu + EVENT_EPS, -dr / tu
    if kind == DOWN:
        e = _edge(i, k[i] - 1, gam, col.edges, col.nedges, col.edge_w)
        return (r - e) / tu + EVENT_EPS, dr / tu
    pin = c[i, 2]
    if kind == NEAR:  # the square, smooth through closure: a dip within pin is seen
        return (r * r - pin * pin) / (tu * tu), 2.0 * (px * vx + py * vy) / (tu * tu)
    if kind == LEFT:
        return (LEAVE_FACTOR * pin - r) / tu, -dr / tu
    if kind == ACROSS:
        return (px * c[i, 0] + py * c[i, 1]) / tu + EVENT_EPS, (vx * c[i, 0] + vy * c[i, 1]) / tu
    return -dr / tu, 0.0  # TURNED


@jit
def watch(n, k, phase, pending, col, kinds, joints):
    """The events (kinds, joints) of the current pieces and phases; returns how many."""
    m = 0
    quiet = col.e_rest == 1.0  # an elastic joint's closure changes nothing: counted only
    for i in range(n):
        if k[i] < col.nedges[i]:
            kinds[m], joints[m] = UP, i
            m += 1
        if k[i] > 0:
            kinds[m], joints[m] = DOWN, i
            m += 1
        if col.rigid[i]:
            if phase[i] == FREE and k[i] == 0:
                kinds[m], joints[m] = NEAR, i
                m += 1
            elif phase[i] == LEAVING:
                kinds[m], joints[m], kinds[m + 1], joints[m + 1] = LEFT, i, ACROSS, i
                m += 2
            elif phase[i] == APPROACH:
                kinds[m], joints[m], kinds[m + 1], joints[m + 1] = ACROSS, i, TURNED, i
                m += 2
        elif phase[i] == APPROACH and pending[i] and not quiet:
            kinds[m], joints[m] = ACROSS, i
            m += 1
        kinds[m], joints[m] = COLLAPSE, i
        m += 1
    return m


@jit
def rows_at(y, gam, n, col, k, c, kinds, joints, m, dist, rate):
    """Every watched distance and its rate at state y (gam = (g + a_v) / g there)."""
    for r in range(m):
        dist[r], rate[r] = distance(kinds[r], joints[r], y, n, col, k, c, gam)


@jit(borrow=True)
def within_reach(d0, r0, d1, r1, dt, kinds, m, near):
    """The watched distances that may cross zero inside a step of dt [s], from their values
    and rates at both ends, into near (m,) bool; returns whether any may: it ends below
    zero, or its smaller end is within dt (|r0| + |r1|) of zero (some seven times the
    largest dip of the ends' cubic Hermite, 4/27 dt (|r0| + |r1|)); a turn near closure
    (TURNED, whose rate is not watched) always."""
    found = False
    for r in range(m):
        near[r] = (d1[r] < 0.0 or kinds[r] == TURNED
                   or min(d0[r], d1[r]) <= dt * (abs(r0[r]) + abs(r1[r])))  # fmt: skip
        found = found or near[r]
    return found


@jit
def _row_at(t, r, mc, t_old, h, y_old, F, yq, n, col, k, c, gr, kinds, joints):
    dense_eval(mc, t, t_old, h, y_old, F, yq)
    return distance(kinds[r], joints[r], yq, n, col, k, c, gravity_factor(t, gr))[0]


@jit
def _root(a, b, r, mc, t_old, h, y_old, F, yq, n, col, k, c, gr, kinds, joints):
    """Brent's root of row r on [a, b] (its value > 0 at a, < 0 at b)."""
    xpre, xcur = a, b
    xblk, fblk, spre, scur = 0.0, 0.0, 0.0, 0.0
    fpre = _row_at(xpre, r, mc, t_old, h, y_old, F, yq, n, col, k, c, gr, kinds, joints)
    fcur = _row_at(xcur, r, mc, t_old, h, y_old, F, yq, n, col, k, c, gr, kinds, joints)
    if fpre == 0.0:
        return xpre
    if fcur == 0.0:
        return xcur
    for _ in range(MAXITER):
        done, xpre, xcur, xblk, fpre, fblk, spre, scur = brent_step(
            xpre, xcur, xblk, fpre, fcur, fblk, spre, scur, XTOL, RTOL
        )
        if done:
            return xcur
        fcur = _row_at(xcur, r, mc, t_old, h, y_old, F, yq, n, col, k, c, gr, kinds, joints)
    return xcur


@jit(borrow=True)
def _hermite_min(p0, p1, m0, m1):
    """s in (0, 1) of the lowest interior minimum of the cubic Hermite of values p0, p1 and
    slopes m0, m1 (per unit s), with its value; (-1, 0) if none."""
    a = 2.0 * p0 + m0 - 2.0 * p1 + m1
    b = -3.0 * p0 - 2.0 * m0 + 3.0 * p1 - m1
    qa, qb, qc = 3.0 * a, 2.0 * b, m0
    best_s, best = -1.0, 0.0
    r0, r1 = np.nan, np.nan
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
    for s in (r0, r1):
        if 0.0 < s < 1.0:
            v = ((a * s + b) * s + m0) * s + p0
            if best_s < 0.0 or v < best:
                best_s, best = s, v
    return best_s, best


@jit
def first_event(mc, t_old, t_new, h, y_old, F, yq, n, col, k, c, gr, kinds, joints, m, D, R,
                near):  # fmt: skip
    """(t, row) of the earliest crossing of a watched distance near (within_reach) in
    [t_old, t_new], or (-1, -1) (the module's scan)."""
    ts = np.empty(CHECK_INTERVALS + 1)
    for j in range(CHECK_INTERVALS + 1):
        ts[j] = t_old + (t_new - t_old) * (j / CHECK_INTERVALS) if j < CHECK_INTERVALS else t_new
        dense_eval(mc, ts[j], t_old, h, y_old, F, yq)
        gam = gravity_factor(ts[j], gr)
        for r in range(m):
            if near[r]:
                D[r, j], R[r, j] = distance(kinds[r], joints[r], yq, n, col, k, c, gam)
    for r in range(m):
        if near[r] and D[r, 0] <= 0.0:
            return t_old, r
    for j in range(CHECK_INTERVALS):
        a, b = ts[j], ts[j + 1]
        ds = b - a
        best_t, best_r = np.inf, -1
        for r in range(m):
            if not near[r]:
                continue
            hi = -1.0
            if D[r, j + 1] < 0.0:
                hi = b
            elif R[r, j] < 0.0 < R[r, j + 1]:
                if min(D[r, j], D[r, j + 1]) <= 0.5 * ds * (abs(R[r, j]) + abs(R[r, j + 1])):
                    s, v = _hermite_min(D[r, j], D[r, j + 1], ds * R[r, j], ds * R[r, j + 1])
                    if s > 0.0 and v < 0.0:
                        tm = a + s * ds
                        if _row_at(tm, r, mc, t_old, h, y_old, F, yq, n, col, k, c, gr, kinds,
                                   joints) < 0.0:  # fmt: skip
                            hi = tm
            if hi > 0.0:
                root = _root(a, hi, r, mc, t_old, h, y_old, F, yq, n, col, k, c, gr, kinds,
                             joints)  # fmt: skip
                if root < best_t:
                    best_t, best_r = root, r
        if best_r >= 0:
            return best_t, best_r
    return -1.0, -1


@jit(borrow=True)
def _rate_at(t, row, mc, t_old, h, y_old, F, yq, n):
    dense_eval(mc, t, t_old, h, y_old, F, yq)
    return _magnitude(row, yq, n)[1]


@jit(borrow=True)
def _peak_in(row, a, b, mc, t_old, h, y_old, F, yq, n):
    """The magnitude of row where its rate turns from rising to falling in [a, b]."""
    xpre, xcur = a, b
    xblk, fblk, spre, scur = 0.0, 0.0, 0.0, 0.0
    fpre = _rate_at(xpre, row, mc, t_old, h, y_old, F, yq, n)
    fcur = _rate_at(xcur, row, mc, t_old, h, y_old, F, yq, n)
    if fpre != 0.0 and fcur != 0.0:
        for _ in range(MAXITER):
            done, xpre, xcur, xblk, fpre, fblk, spre, scur = brent_step(
                xpre, xcur, xblk, fpre, fcur, fblk, spre, scur, XTOL, RTOL
            )
            if done:
                break
            fcur = _rate_at(xcur, row, mc, t_old, h, y_old, F, yq, n)
    dense_eval(mc, xcur if fpre != 0.0 else xpre, t_old, h, y_old, F, yq)
    return _magnitude(row, yq, n)[0]


@jit
def _move(i, y, n, arg_inv, dx, dy):
    """Move joint i's rotation vector by (dx, dy) [rad], in place."""
    for j in range(n):
        y[j] += arg_inv[j, i] * dx
        y[n + j] += arg_inv[j, i] * dy


@jit
def _friction(t, f, n, col, es, gr, friction, rx, ry):
    """The shear ratios (rx, ry: pieces.shear_ratios) of y' = f at t [s], the peak friction
    raised to their magnitudes |T_i| / (N_i gam); returns the largest of those."""
    ax, ay = horizontal(t, es, n, gr)
    shear_ratios(ax, ay, gravity_factor(t, gr), col.centre_map, f[2 * n : 3 * n],
                 f[3 * n : 4 * n], col.masses, col.normal_forces, rx, ry, friction)  # fmt: skip
    top = 0.0
    for i in range(n):
        top = max(top, math.sqrt(rx[i] * rx[i] + ry[i] * ry[i]))
    return top


@jit
def _emit(mc, t_stop, t_old, h, y_old, F, yq, samples, n_out, next_out, dt, n, d0, d1, col):
    """Samples (t, theta and rate seen in the motion's plane, the top in plan, theta seen
    across it) up to t_stop;
    F None-like (h = 0): the state y_old itself."""
    top = col.families[2 * n]
    while next_out <= t_stop + 1e-12 and n_out < samples.shape[0]:
        if h > 0.0:
            dense_eval(mc, next_out, t_old, h, y_old, F, yq)
        else:
            copy_into(yq, y_old)
        row = samples[n_out]
        row[0] = next_out
        tx, ty = 0.0, 0.0
        for j in range(n):
            row[1 + j] = yq[j] * d0 + yq[n + j] * d1
            row[1 + n + j] = yq[2 * n + j] * d0 + yq[3 * n + j] * d1
            tx += top[j] * yq[j]
            ty += top[j] * yq[n + j]
        row[1 + 2 * n], row[2 + 2 * n] = tx, ty
        for j in range(n):  # seen across the motion's plane (its direction turned +90 deg)
            row[3 + 2 * n + j] = -yq[j] * d1 + yq[n + j] * d0
        n_out += 1
        next_out += dt
    return n_out, next_out


@jit(borrow=True)
def _pieces(t, knots, values, values_y, vertical, gain, seg_end, es):
    """A record's straight piece from t (inputs.ground.record_piece) and the time its step
    ends at; a pair's second record's piece written into es (structures.column3d)."""
    gr, bound = record_piece(t, knots, values, vertical, gain, seg_end)
    if values_y.size > 0:
        n = es.size - ES_EXTRA
        gy, _ = record_piece(t, knots, values_y, vertical, gain, seg_end)
        es[n + 2], es[n + 3], es[n + 4] = 1.0, gy[1], gy[2]
        es[n + 5], es[n + 6], es[n + 7] = gy[3], gy[4], gy[5]
    return gr, bound


@jit
def energy3d(y, n, col):
    """Energy [J] of a state y (4n,) (structures.column3d): the kinetic energy of both
    directions, gravity's for `geometric` and the laws' potential of |phi_i|
    (pieces.law_potential), as the planar Model.energy in each direction."""
    e = 0.0
    for i in range(n):
        for j in range(n):
            e += 0.5 * col.mass[i, j] * (y[2 * n + i] * y[2 * n + j] + y[3 * n + i] * y[3 * n + j])
            e -= 0.5 * col.gravity[i, j] * (y[i] * y[j] + y[n + i] * y[n + j])
    for i in range(n):
        px, py, _, _ = _phi(i, y, n, col.argmap)
        e += law_potential(i, math.sqrt(px * px + py * py), col.edges, col.nedges,
                           col.intercepts, col.slopes)  # fmt: skip
    return e


@jit
def account_step3d(mc, t_old, t_new, h, y_old, F, yq, n, col, k, es, gr, ledger):
    """Add one step's work of the ground and the energy its damping took to ledger[2] and
    ledger[3] [J] (as the planar stepper.account_step): over [t_old, t_new] on the step's
    dense output, the power -(a_x r . theta_x' + a_y r . theta_y') (r the ground load) and
    sum_i c_i |phi_i'|^2 (the joints on their elastic piece) by Gauss-Legendre."""
    dt = t_new - t_old
    for q in range(GL_NODES.size):
        tq = t_old + GL_NODES[q] * dt
        dense_eval(mc, tq, t_old, h, y_old, F, yq)
        ax, ay = horizontal(tq, es, n, gr)
        p_in = 0.0
        for j in range(n):
            p_in -= col.ground_load[j] * (ax * yq[2 * n + j] + ay * yq[3 * n + j])
        p_d = 0.0
        for i in range(n):
            if col.damp[i] != 0.0 and k[i] == 0:
                _, _, vx, vy = _phi(i, yq, n, col.argmap)
                p_d += col.damp[i] * (vx * vx + vy * vy)
        ledger[2] += GL_WEIGHTS[q] * dt * p_in
        ledger[3] += GL_WEIGHTS[q] * dt * p_d


@jit
def pair_rest_demand(t0, t1, gr, gy, knots, values, values_y, knots_y, vertical):
    """The friction demand max |a_h| / (g + a_v) [-] of a column at rest under a pair over
    [t0, t1] [s], a_h = (a_x, a_y). A pair of records: both components and a_v are straight
    between samples, where |a_h| / (g + a_v) has no interior maximum (its sublevel sets
    are convex), so the ends and the samples between them hold it. A formula and its
    second component (gy): the largest ratio that inputs.ground.pair_uplift finds
    exceeded on [t0, t1), by halving to the last bit (closed-form exceedance times)."""
    if gr[1] == 0.0 or t1 < t0:
        return 0.0
    if values_y.size == 0:
        lo, hi = 0.0, 1.0
        while pair_uplift(t0, hi, t1, gr, gy, knots, values, values_y, knots_y, vertical) >= 0.0:
            lo, hi = hi, 2.0 * hi
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if mid <= lo or mid >= hi:
                break
            if pair_uplift(t0, mid, t1, gr, gy, knots, values, values_y, knots_y,
                           vertical) >= 0.0:  # fmt: skip
                lo = mid
            else:
                hi = mid
        return lo
    best = 0.0
    for j in range(knots.size + 2):
        tt = t0 if j == 0 else (t1 if j == 1 else knots[j - 2])
        if tt < t0 or tt > t1:
            continue
        ax = ground_at(tt, gr, knots, values)
        ay = ground_at(tt, gr, knots, values_y)
        d = math.sqrt(ax * ax + ay * ay) / (G * vertical_factor(tt, knots, vertical))
        if d > best:
            best = d
    return best


@jit
def in_plane(y, n):
    """Whether the state y (4n,) lies in the motion's vertical plane to the bit: nothing
    across it (theta_y and its rate all zero)."""
    for j in range(n):
        if y[n + j] != 0.0 or y[3 * n + j] != 0.0:
            return False
    return True


@jit(inline=True)
def system3d(col, n, d0, d1, values_y, gy):
    """The column's system in two directions (structures.column3d): As (n, 3n) of its mass,
    stiffness and argument maps, cs (the current pieces' constants, packed at each restart)
    and es (the ground's factors, the motion's direction (d0, d1) and its second component's
    formula)."""
    As = np.empty((n, 3 * n))
    for i in range(n):
        for j in range(n):
            As[i, j] = col.md[i, j]
            As[i, n + j] = col.mg[i, j]
            As[i, 2 * n + j] = col.argmap[i, j]
    cs = np.zeros(CS_PER_JOINT * n)
    es = np.zeros(n + ES_EXTRA)
    copy_into(es, col.es)
    es[n], es[n + 1] = d0, d1
    es[n + 8] = 1.0 if np.any(col.mg != 0.0) else 0.0
    es[n + 9] = LINE if values_y.size > 0 else gy[0]
    return As, cs, es


@jit
def start3d(y, n, col, k, pending, phase, c):
    """The pieces and phases of the initial state y (4n,); returns whether a rigid monolith
    starts at rest."""
    for i in range(n):
        px, py, vx, vy = _phi(i, y, n, col.argmap)
        r = math.sqrt(px * px + py * py)
        q = 0
        while q < col.nedges[i] and col.edges[i, q] <= r:
            q += 1
        k[i] = q
        pending[i] = q > 0 and not col.rigid[i]
    at_rest = False
    if col.rigid_mono:
        at_rest = True
        for j in range(4 * n):
            if y[j] != 0.0:
                at_rest = False
        px, py, vx, vy = _phi(0, y, n, col.argmap)
        r = math.sqrt(px * px + py * py)
        if not at_rest and r <= LEAVE_FACTOR * c[0, 2]:
            if r > 0.0:
                c[0, 0], c[0, 1] = px / r, py / r
            else:
                s = math.sqrt(vx * vx + vy * vy)
                c[0, 0], c[0, 1] = vx / s, vy / s
            phase[0] = LEAVING
    return at_rest


@jit
def lean_azimuth(i, y, n, col):
    """Where joint i's collapse quantity points [rad from the motion's direction]."""
    vx_, vy_ = 0.0, 0.0
    for j in range(n):
        vx_ += col.families[n + i, j] * y[j]
        vy_ += col.families[n + i, j] * y[n + j]
    return math.atan2(vy_, vx_)


@jit
def rest3d(t, seg_end, last, col, amplitude, gr_full, pair_args, friction, held, rx, ry, slip,
           mu, sampling, n_out, next_out, y, c, phase, rising):  # fmt: skip
    """A rigid monolith at rest from t [s] in a forced segment (to seg_end [s]): its friction
    demand at rest (under a pair: pair_rest_demand), the held demand's samples, where it
    first exceeds mu, its samples, and where it lifts (no later than last [s]), leaving
    closure along the ground's acceleration then.

    Returns
    -------
    (lifted, t, n_out, next_out)  lifted: the column lifts at t; else it rests to seg_end.
    """
    gy, knots, values, values_y, knots_y, vertical, pair_on, d0, d1 = pair_args
    record, mc, F, yq, samples, output_dt = sampling
    n = y.size // 4
    if pair_on:
        t_up = pair_uplift(t, col.uplift_level / G, min(last, seg_end), gr_full, gy, knots,
                           values, values_y, knots_y, vertical)  # fmt: skip
    else:
        t_up = next_uplift(t, col.uplift_level, amplitude, gr_full, knots, values, vertical,
                           last)  # fmt: skip
    # the friction demand at rest (as the planar kernel), and where it first exceeds the limit
    t_rest = seg_end if t_up < 0.0 or t_up >= seg_end else t_up
    if pair_on:
        d_rest = pair_rest_demand(t, t_rest, gr_full, gy, knots, values, values_y, knots_y,
                                  vertical)  # fmt: skip
    else:
        d_rest = rest_demand(t, t_rest, gr_full, knots, values, vertical)
    if d_rest > friction[0]:
        friction[0] = d_rest
    while held_time(held) <= t_rest:
        t_k = held_time(held)
        rx[0] = rest_shear(t_k, gr_full, knots, values, vertical)
        ry[0] = rest_shear(t_k, gy, knots, values_y, vertical) if pair_on else 0.0
        held_push(held, rx, ry, friction)
    if slip[1] == 0.0 and d_rest > mu:
        if pair_on:
            slip[0] = pair_uplift(t, mu, t_rest, gr_full, gy, knots, values, values_y, knots_y,
                                  vertical)  # fmt: skip
        else:
            slip[0] = next_uplift(t, mu * G, amplitude, gr_full, knots, values, vertical, t_rest)
        slip[1] = 1.0
    if t_up < 0.0 or t_up >= seg_end:
        if record:
            n_out, next_out = _emit(mc, seg_end, t, 0.0, y, F, yq, samples, n_out, next_out,
                                    output_dt, n, d0, d1, col)  # fmt: skip
        return False, seg_end, n_out, next_out
    if record:
        n_out, next_out = _emit(mc, t_up - 1e-15, t, 0.0, y, F, yq, samples, n_out, next_out,
                                output_dt, n, d0, d1, col)  # fmt: skip
    t = t_up
    y[:] = 0.0
    a_d = ground_at(t, gr_full, knots, values)
    a_y = ground_at(t, gy, knots, values_y) if pair_on else 0.0
    ax, ay = a_d * d0 - a_y * d1, a_d * d1 + a_y * d0
    size = math.sqrt(ax * ax + ay * ay)
    c[0, 0], c[0, 1] = -ax / size, -ay / size
    phase[0], rising[0] = LEAVING, True
    return True, t, n_out, next_out


@jit
def event3d(kind, i, t, y, n, col, gr, pieces, account, ledger):
    """The state change at a watched event of joint i at (t, y) (the module's notes): at a
    kink its piece, near closure its pinned direction, at closure the impact (a rigid
    monolith slow enough comes to rest). Returns (uplifts, impacts, at rest) of it."""
    k, pending, phase, rising, c = pieces
    n_upl, n_imp, at_rest = 0, 0, False
    px, py, vx, vy = _phi(i, y, n, col.argmap)
    r = math.sqrt(px * px + py * py)
    if kind == UP or kind == DOWN:
        q = k[i] if kind == UP else k[i] - 1
        e = _edge(i, q, gravity_factor(t, gr), col.edges, col.nedges, col.edge_w)
        if r > 0.0:
            _move(i, y, n, col.arg_inv, px * (e / r - 1.0), py * (e / r - 1.0))
        if kind == UP:
            # an uplift: a closed joint opens; one back on its elastic branch that
            # opens again before it closed goes on with its excursion
            if k[i] == 0 and not col.rigid[i] and not pending[i] and phase[i] != APPROACH:
                n_upl += 1
            if not col.rigid[i]:
                pending[i] = True
                if phase[i] == APPROACH:
                    phase[i] = FREE
            k[i] += 1
        else:
            k[i] -= 1
            if k[i] == 0 and pending[i]:
                phase[i] = APPROACH
                c[i, 0], c[i, 1] = px / r, py / r
                # a silent closure (e = 1) is counted, not stopped at: back on its
                # elastic branch the joint is closed, as in the plane
                pending[i] = col.e_rest != 1.0
    elif kind == NEAR:
        phase[i] = APPROACH
        c[i, 0], c[i, 1] = px / r, py / r
    elif kind == LEFT:
        phase[i], rising[i] = FREE, False
    else:  # ACROSS or TURNED: the joint closes
        rising[i] = False
        cx, cy = c[i, 0], c[i, 1]
        if col.rigid[i]:
            _move(i, y, n, col.arg_inv, -px, -py)
        else:
            along = px * cx + py * cy
            _move(i, y, n, col.arg_inv, -along * cx, -along * cy)
        xdot = vx * cx + vy * cy
        e_rest = col.e_rest
        for j in range(n):
            if col.literal_impact:
                dv = col.arg_inv[j, i] * (e_rest - 1.0) * xdot
            else:
                dv = col.impulse_dir[j, i] * ((e_rest - 1.0) * xdot / col.impulse_w[i])
            y[2 * n + j] += dv * cx
            y[3 * n + j] += dv * cy
        n_imp += 1
        pending[i], phase[i] = False, FREE
        if col.rigid[i]:
            _, _, vx, vy = _phi(i, y, n, col.argmap)
            speed = math.sqrt(vx * vx + vy * vy)
            if col.rigid_mono and speed < col.rest_rate:
                y[:] = 0.0
                at_rest = True
            else:
                phase[i] = LEAVING
                if speed > 0.0:
                    c[i, 0], c[i, 1] = vx / speed, vy / speed
    if account:
        after = energy3d(y, n, col)
        if kind == ACROSS or kind == TURNED:
            ledger[4] += ledger[1] - after
        ledger[1] = after
    return n_upl, n_imp, at_rest


@jit
def run3d(col, motion, solver, task, pair):
    """Run one motion of one column in two directions.

    Parameters
    ----------
    col : ColumnArrays  The column (structures.arrays), as the planar kernel reads it
    motion : Excitation  The motion along its direction (step.inputs)
    solver : SolverSettings  atol of 4n entries
    task : tuple  (y0 (4n), record, output_dt, samples (rows, 3 + 3n), friction_limit,
        early stop (models.status.stop_level), pin: a rigid joint's pinned distance of
        closure over its theta_u [-], held: the held friction demand, pieces.held_array);
        y0 and held are changed in place: the state where the run ended, the samples of
        the demand held
    pair : tuple  (d0, d1, values_y: a second record's samples, or empty; gy: the second
        component's ground tuple, inputs.ground, gain 0 for none; knots_y: its knots)

    Returns
    -------
    RunEnd  (numerics.loop; the collapsed joint from 0, -1 for none; azimuth [rad], swept
        (n) [rad]). ledger: the energy account of a recorded run without a vertical record
        [J] (zeros otherwise), as the planar kernel's: the energy at the start and at the end
        (energy3d), the ground's work, the energy the joints' damping and the impacts took.
    """
    col, motion, solver = ColumnArrays(*col), Excitation(*motion), SolverSettings(*solver)
    account = task[1] and motion.vertical.size == 0  # the energy account (see Returns)
    n = col.tu.size
    W = column3d_record(col, motion, task, pair)
    y = task[0]  # the state, in place: the caller reads where the run ended
    at_rest = start3d(y, n, W, W.k, W.pending, W.phase, W.c)
    max_ratio = W.max_ratio
    for i in range(n):
        v, _ = _magnitude(col.families[n + i], y, n)
        max_ratio[i] = v
        if v >= col.c_ratio:
            max_ratio[i] = max(v, col.c_ratio)
            return RunEnd(COLLAPSED, 0.0, 0.0, i, max_ratio, 0.0, W.friction, W.slip, 0, 0,
                          0, 0, 0, 0, lean_azimuth(i, y, n, W), W.swept, W.ledger)  # fmt: skip
    if account:
        W.ledger[0] = energy3d(y, n, W)
        W.ledger[1] = W.ledger[0]
    W.top[0] = _magnitude(col.families[2 * n], y, n)[0]
    stops = (task[5], -1, False, n == 1)
    loop_into(W, y, system3d(W, n, W.d0, W.d1, W.values_y, W.gy))
    return run_3d(W, motion, solver, n, at_rest, stops, account)


@jit(inline=True)
def column3d_record(col, motion, task, pair):
    """The run's record (rbm3d.work.COLUMN3D) of a column col (ColumnArrays) under motion
    (Excitation), with run3d's task and pair."""
    W = new_record(COLUMN3D)
    column_into(W, col)
    motion_into(W, motion)
    n = col.tu.size
    nrow_max = 5 * n
    # max_ratio, friction, slip, swept, the energy account (run3d's Returns), the top's peak
    W.max_ratio, W.friction, W.slip = np.zeros(n), np.zeros(n), np.array([np.nan, 0.0])
    W.swept, W.ledger, W.top = np.zeros(n), np.zeros(5), np.zeros(1)
    W.k, W.pending = np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.bool_)
    W.phase = np.zeros(n, dtype=np.int64)
    # leaving closure from phi = 0 exactly (an uplift from rest): pinned at phi = 0 alone
    W.rising, W.c = np.zeros(n, dtype=np.bool_), np.zeros((n, 3))
    W.kinds, W.joints = np.zeros(nrow_max, dtype=np.int64), np.zeros(nrow_max, dtype=np.int64)
    W.count = np.zeros(1, dtype=np.int64)
    W.d_old, W.r_old, W.d_new, W.r_new = (
        np.empty(nrow_max),
        np.empty(nrow_max),
        np.empty(nrow_max),
        np.empty(nrow_max),
    )
    W.near = np.zeros(nrow_max, dtype=np.bool_)
    W.D, W.R = np.empty((nrow_max, CHECK_INTERVALS + 1)), np.empty((nrow_max, CHECK_INTERVALS + 1))
    W.rx, W.ry, W.acc_k, W.between = np.zeros(n), np.zeros(n), np.zeros(2 * n), np.zeros(n)
    W.turned = np.zeros(1, dtype=np.bool_)
    W.samples, W.held, W.record, W.output_dt, W.mu = task[3], task[7], task[1], task[2], task[4]
    d0, d1, values_y, gy, knots_y = pair
    W.d0, W.d1, W.values_y, W.gy, W.knots_y = d0, d1, values_y, gy, knots_y
    pair_on = values_y.size > 0 or gy[1] != 0.0
    formula_y = values_y.size == 0 and gy[1] != 0.0
    W.pair_on, W.formula_y = pair_on, formula_y
    c, pin = W.c, task[6]  # the pieces' direction: the motion's; the pinned distance
    for i in range(n):
        c[i, 0], c[i, 1], c[i, 2] = d0, d1, pin * col.tu[i]
    return W


# ---- the column in two directions' part of the run loop (numerics.loop.run_motion): its
# run record (W: rbm3d.work.COLUMN3D)


@jit
def enter_segment(W, free_seg):
    """A formula's second component: its form in W.sys_e, 0 on a free segment."""
    if W.formula_y:
        gy = W.gy
        n = W.sys_e.size - ES_EXTRA
        W.sys_e[n + 2], W.sys_e[n + 3], W.sys_e[n + 4] = 1.0, 0.0 if free_seg else gy[1], gy[2]
        W.sys_e[n + 5], W.sys_e[n + 6], W.sys_e[n + 7] = gy[3], gy[4], gy[5]


@jit
def rest_to_end(W, t, t_end, mc, n_out, next_out):
    """At rest from t to t_end [s] (no ground motion from here on): its samples; ends
    AT_REST."""
    if W.record:
        n_out, next_out = _emit(mc, t_end, t, 0.0, W.y, W.F, W.yq, W.samples, n_out, next_out,
                                W.output_dt, W.tu.size, W.d0, W.d1, W)  # fmt: skip
    return AT_REST, n_out, next_out


@jit
def rest(W, t, seg_end, gr_full, mc, n_out, next_out):
    """A rigid monolith at rest in a forced segment (rest3d)."""
    pair_args = (W.gy, W.knots, W.values, W.values_y, W.knots_y, W.vertical,
                 W.pair_on, W.d0, W.d1)  # fmt: skip
    return rest3d(t, seg_end, min(W.pulse_end, W.t_end), W, W.amplitude, gr_full, pair_args,
                  W.friction, W.held, W.rx, W.ry, W.slip, W.mu,
                  (W.record, mc, W.F, W.yq, W.samples, W.output_dt), n_out, next_out, W.y, W.c,
                  W.phase, W.rising)  # fmt: skip


@jit
def restart(W, t, seg_end, seg_gain, h_carry, gr, mc, rtol, atol):
    """A new stepper from (t, W.y): the current pieces packed
    (structures.column3d.pack_pieces), the watched events (watch) and their distances at
    t, the first step's size (h_carry, the one proposed before an event, or the column's
    initial_step). Returns the step size [s], the right-hand side's calls and the ground."""
    values_y = W.values_y
    k, phase, rising, c = W.k, W.phase, W.rising, W.c
    n = k.size
    pinned = np.zeros(n, dtype=np.int64)  # structures.column3d.pack_pieces
    for i in range(n):
        if phase[i] != FREE and W.rigid[i]:
            pinned[i] = 2 if rising[i] else 1
    pack_pieces(k, pinned, c, W.intercepts, W.slope_parts[0], W.slope_parts[1], W.damp,
                W.rigid, W.sys_c)  # fmt: skip
    m = watch(n, k, phase, W.pending, W, W.kinds, W.joints)
    W.count[0] = m
    t_bound = seg_end
    if W.clipped:
        gr, t_bound = _pieces(t, W.knots, W.values, values_y, W.vertical,
                              seg_gain, seg_end, W.sys_e)  # fmt: skip
    rows_at(W.y, gravity_factor(t, gr), n, W, k, c, W.kinds, W.joints, m, W.d_old, W.r_old)
    beam_rates(t, W.y, n, W.sys_A, W.sys_c, W.sys_e, gr, W.f)
    if h_carry > 0.0:
        return min(h_carry, seg_end - t), 1, gr
    h_abs = initial_step(
        t, W.y, W.f, t_bound, TAB_EST[mc], rtol, atol, n, W.sys_A, W.sys_c, W.sys_e, gr, W.work
    )
    return h_abs, 2, gr


@jit
def ground_piece(W, t, seg_gain, seg_end):
    """A record's straight piece from t and the time a step ends at, a pair's second record's
    in W.sys_e (_pieces)."""
    return _pieces(t, W.knots, W.values, W.values_y, W.vertical, seg_gain,
                   seg_end, W.sys_e)  # fmt: skip


@jit
def find_event(W, mc, t_old, t_new, h, gr):
    """The first watched event in the step [t_old, t_new]: the rows at the step's end, then,
    where one may cross within reach, the step's dense output prepared and the crossing found
    on it (first_event). Returns (t_e, the row crossed or -1, the dense output ready,
    right-hand side calls)."""
    n, m = W.k.size, W.count[0]
    rows_at(W.y_new, gravity_factor(t_new, gr), n, W, W.k, W.c, W.kinds, W.joints, m, W.d_new,
            W.r_new)  # fmt: skip
    if not within_reach(W.d_old, W.r_old, W.d_new, W.r_new, t_new - t_old, W.kinds, m, W.near):
        return t_new, -1, False, 0
    calls = dense_prepare(
        mc, t_old, h, W.y, W.y_new, W.K, W.F, W.tmp, n, W.sys_A, W.sys_c, W.sys_e, gr
    )
    t_e, hit = first_event(mc, t_old, t_new, h, W.y, W.F, W.yq, n, W, W.k, W.c, gr, W.kinds,
                           W.joints, m, W.D, W.R, W.near)  # fmt: skip
    return t_e, hit, True, calls


@jit
def step_figures(W, mc, t_old, t_new, h, gr, event, dense_ready, account, n_out, next_out):
    """The figures of the step [t_old, t_new] (cut at an event): the friction demand at its
    end and the held demand's samples inside it, samples, the energy account, the peaks (at
    the end, and where a magnitude's rate turns inside the step), the angle each joint's lean
    turned, silent closures. Returns (right-hand side calls, n_out, next_out, impacts
    counted)."""
    record, held = W.record, W.held
    friction, slip = W.friction, W.slip
    n = W.k.size
    ns = TAB_NS[mc]
    calls, impacts = 0, 0
    if record and not dense_ready:
        calls += dense_prepare(
            mc, t_old, h, W.y, W.y_new, W.K, W.F, W.tmp, n, W.sys_A, W.sys_c, W.sys_e, gr
        )
        dense_ready = True
    if event:
        beam_rates(t_new, W.y_new, n, W.sys_A, W.sys_c, W.sys_e, gr, W.work)
        calls += 1
        f_new = W.work
    else:
        f_new = W.K[ns]
    fr = _friction(t_new, f_new, n, W, W.sys_e, gr, friction, W.rx, W.ry)
    if slip[1] == 0.0 and fr > W.mu:
        best = 0
        for i in range(n):
            if friction[i] > friction[best]:
                best = i
        slip[0], slip[1] = t_new, best + 1.0
    # the held demand's samples in (t_old, t_new]: theta'' on the step's quintic
    acc_k = W.acc_k
    while held_time(held) <= t_new:
        t_k = held_time(held)
        h_k = t_new - t_old
        for j in range(2 * n):
            q = 2 * n + j
            acc_k[j] = f_new[q] if h_k <= 0.0 else hermite_accel(
                (t_k - t_old) / h_k, h_k, W.y[j], W.y[q], W.f[q], W.y_new[j], W.y_new[q],
                f_new[q])  # fmt: skip
        ax_k, ay_k = horizontal(t_k, W.sys_e, n, gr)
        shear_ratios(ax_k, ay_k, gravity_factor(t_k, gr), W.centre_map, acc_k[:n], acc_k[n:],
                     W.masses, W.normal_forces, W.rx, W.ry, W.between)  # fmt: skip
        held_push(held, W.rx, W.ry, W.between)
    if record:
        n_out, next_out = _emit(mc, t_new, t_old, h, W.y, W.F, W.yq, W.samples, n_out, next_out,
                                W.output_dt, n, W.d0, W.d1, W)  # fmt: skip
    if account:  # the step's dense output is ready (recorded runs always are)
        account_step3d(mc, t_old, t_new, h, W.y, W.F, W.yq, n, W, W.k, W.sys_e, gr, W.ledger)
        W.ledger[1] = energy3d(W.y_new, n, W)
    # peaks: at the end, and where a magnitude's rate turns inside the step
    top_row, max_ratio, top, swept = W.families[2 * n], W.max_ratio, W.top, W.swept
    for i in range(n + 1):
        row = W.families[n + i] if i < n else top_row
        v1, r1 = _magnitude(row, W.y_new, n)
        _, r0 = _magnitude(row, W.y, n)
        if i == 0:
            W.turned[0] = r0 > 0.0 >= r1  # the first joint's ratio passed a peak
        if r0 > 0.0 and r1 < 0.0:
            if not dense_ready:
                calls += dense_prepare(
                    mc, t_old, h, W.y, W.y_new, W.K, W.F, W.tmp, n, W.sys_A, W.sys_c, W.sys_e, gr
                )
                dense_ready = True
            v1 = max(v1, _peak_in(row, t_old, t_new, mc, t_old, h, W.y, W.F, W.yq, n))
        if i < n:
            max_ratio[i] = max(max_ratio[i], v1)
        else:
            top[0] = max(top[0], v1)
    # the angle each joint's lean turned, where it leans by WOBBLE_LEVEL of its collapse
    # limit or more at both ends of the step (a wobble)
    for i in range(n):
        row = W.families[n + i]
        ax_, ay_, bx_, by_ = 0.0, 0.0, 0.0, 0.0
        for j in range(n):
            ax_ += row[j] * W.y[j]
            ay_ += row[j] * W.y[n + j]
            bx_ += row[j] * W.y_new[j]
            by_ += row[j] * W.y_new[n + j]
        if (ax_ * ax_ + ay_ * ay_ >= WOBBLE_LEVEL * WOBBLE_LEVEL
                and bx_ * bx_ + by_ * by_ >= WOBBLE_LEVEL * WOBBLE_LEVEL):  # fmt: skip
            cr, dt_ = ax_ * by_ - ay_ * bx_, ax_ * bx_ + ay_ * by_
            swept[i] += abs(math.atan2(cr, dt_))
    # silent closures (e = 1, elastic joints): counted at the step's end
    if W.e_rest == 1.0:
        for i in range(n):
            if W.phase[i] == APPROACH and not W.rigid[i]:
                px, py, _, _ = _phi(i, W.y_new, n, W.argmap)
                if px * W.c[i, 0] + py * W.c[i, 1] <= 0.0:
                    impacts += 1
                    W.pending[i], W.phase[i] = False, FREE
    # the step's end is the next step's start
    copy_into(W.d_old, W.d_new)
    copy_into(W.r_old, W.r_new)
    return calls, n_out, next_out, impacts


@jit
def may_stop(W, can_stop, sure_stop):
    """Free motion past a peak below the collapse barrier, in the motion's plane: every
    figure final (the planar column's stop, its energy of the state in the plane)."""
    n = W.k.size
    return (can_stop and W.turned[0] and in_plane(W.y, n)
            and below_barrier(W.y[:n], W.y[2 * n : 3 * n], W.mass, W.argmap, W.gravity,
                              W.edges, W.nedges, W.intercepts, W.slopes,
                              W.barrier))  # fmt: skip


@jit
def at_event(W, row, t, gr, account):
    """The state change at the watched event row at (t, W.y): a collapse, else event3d.
    Returns (GOING or COLLAPSED, uplifts, impacts, at rest, the collapsed joint from 0 (-1
    going on), the azimuth of its lean [rad])."""
    n = W.k.size
    kind, i = W.kinds[row], W.joints[row]
    if kind == COLLAPSE:
        W.max_ratio[i] = max(W.max_ratio[i], W.c_ratio)
        return COLLAPSED, 0, 0, False, i, lean_azimuth(i, W.y, n, W)
    up, imp, at_rest = event3d(kind, i, t, W.y, n, W, gr, (W.k, W.pending, W.phase, W.rising,
                               W.c), account, W.ledger)  # fmt: skip
    return GOING, up, imp, at_rest, -1, np.nan


#: The column in two directions' run loop (numerics.loop.run_motion with the functions above).
run_3d = loop_for("column3d", globals())
