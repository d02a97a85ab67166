"""The discrete state of the compiled kernel at an event (numba).

At an event of interface i (a kink of its law reached, going up or down), the
state moves exactly onto the kink and the interface's piece changes (pieces.cross): an
uplift from closure, one piece out or in, or an impact (closure crossed, restitution
applied, and a rigid monolith slow enough comes to rest).

Both functions are inlined into the stepper (inline="always"): a call would pass the
model record by value, some 30 arrays, at every event (+5 % on the slender block's
runs, measured).
"""

from __future__ import annotations

from rbm_cli.base.jit import jit
from rbm_cli.models.rbm.pieces import IMPACT, cross, restitute

#: An impact after which a rigid monolith rests (switch returns it, or what pieces.cross
#: returns: UPLIFT, KINK, IMPACT).
REST = 3


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
        restitute(i, xdot, e_rest, model.impulse_dir, model.impulse_w, y[n:])


@jit(inline=True)
def switch(model, i, going_up, bound, y, side, k, pending, awaiting, rigid_mono):
    """Interface i's event at argument bound [rad]: y (state) moved onto the bound, the
    pieces (side, k, pending, awaiting) crossed (pieces.cross), an impact's restitution
    applied to y, all in place.

    Returns
    -------
    int  UPLIFT, KINK, IMPACT (rbm_cli.models.rbm.pieces) or REST (an impact after which the
        monolith rests).
    """
    n = y.size // 2
    argmap, arg_inv = model.argmap, model.arg_inv
    x_i = 0.0
    for j in range(n):
        x_i += argmap[i, j] * y[j]
    for j in range(n):
        y[j] += arg_inv[j, i] * (bound - x_i)
    what = cross(i, going_up, side, k, pending, awaiting, model.rigid, model.silent)
    if what != IMPACT:
        return what
    if model.e_rest < 1.0:
        _restitution(model, i, y, n)
    if rigid_mono and abs(y[n]) < model.rest_rate:
        for j in range(2 * n):
            y[j] = 0.0
        return REST
    return IMPACT


__all__ = ["REST", "switch"]
