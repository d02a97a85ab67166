"""The discrete state of the compiled kernel at an event (numba).

At an event of interface i (a kink of its law reached, going up or down), the
state moves exactly onto the kink and the interface's piece changes: an uplift
from closure, one piece out or in, or an impact (closure crossed, restitution
applied, and a rigid monolith slow enough comes to rest).

Both functions are inlined into the stepper (inline="always"): a call would pass the
model record by value, some 30 arrays, at every event (+5 % on the slender block's
runs, measured).
"""

from __future__ import annotations

from rbm_cli.base.jit import jit

#: What an event was (switch returns it).
PIECE, UPLIFT, IMPACT, REST = 0, 1, 2, 3


@jit(inline=True)
def _restitution(model, i, y, n):
    """The impact's loss of rate at interface i (e < 1), on y's rates in place."""
    argmap, arg_inv, e_rest = model.argmap, model.arg_inv, model.e_rest
    xdot = 0.0
    for j in range(n):
        xdot += argmap[i, j] * y[n + j]
    if model.literal_impact:
        for j in range(n):
            y[n + j] += arg_inv[j, i] * (e_rest - 1.0) * xdot
    else:
        lam = (e_rest - 1.0) * xdot / model.impulse_w[i]
        for j in range(n):
            y[n + j] += model.impulse_dir[j, i] * lam


@jit(inline=True)
def switch(model, i, going_up, bound, y, side, k, pending, awaiting, rigid_mono):
    """Interface i's event at argument bound [rad]: y (state), side, k (piece),
    pending and awaiting (silent impacts) updated in place.

    Returns
    -------
    int  PIECE, UPLIFT, IMPACT or REST (an impact after which the monolith rests).
    """
    n = side.size
    argmap, arg_inv = model.argmap, model.arg_inv
    x_i = 0.0
    for j in range(n):
        x_i += argmap[i, j] * y[j]
    for j in range(n):
        y[j] += arg_inv[j, i] * (bound - x_i)
    s, ki = side[i], k[i]
    outward = going_up == (s > 0)
    if ki == 0 and not (model.rigid[i] or pending[i]):
        side[i] = 1 if going_up else -1
        k[i] = 1
        pending[i] = True
        awaiting[i] = False
        return UPLIFT
    if outward:
        k[i] = ki + 1
        return PIECE
    if ki > 0:
        k[i] = ki - 1
        if ki == 1 and model.silent[i]:
            pending[i] = False
            awaiting[i] = True
        return PIECE
    side[i] = -s
    pending[i] = False
    if model.e_rest < 1.0:
        _restitution(model, i, y, n)
    if rigid_mono and abs(y[n]) < model.rest_rate:
        for j in range(2 * n):
            y[j] = 0.0
        return REST
    return IMPACT


@jit(inline=True)
def settle(awaiting, argmap, y, side):
    """events.Pieces.settle in the kernel: the silent impacts (interfaces back on their
    first piece whose argument changed sign) counted and their sides flipped; returns how
    many."""
    n = side.size
    hits = 0
    for i in range(n):
        if awaiting[i]:
            x_i = 0.0
            for j in range(n):
                x_i += argmap[i, j] * y[j]
            if side[i] * x_i < 0.0:
                side[i] = -side[i]
                awaiting[i] = False
                hits += 1
    return hits
