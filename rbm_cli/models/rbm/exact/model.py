"""What the exact integrator keeps besides the column's arrays (rbm_cli.physics.arrays):
the empty cache of modes, and the energy of a monolith (numba)."""

from __future__ import annotations

import numpy as np

from rbm_cli.base.jit import jit
from rbm_cli.models.rbm.pieces import law_potential


def new_cache(n: int) -> tuple:
    """An empty cache of modes for n interfaces (exact.piece.modes): a power-of-two
    table of at most 2^22 / n^2 sets of pieces (64 MB of modes at most)."""
    cap = 64
    while cap * 2 <= min(8192, (1 << 22) // (n * n)):
        cap *= 2
    return (
        np.zeros((cap, n), dtype=np.int64), np.zeros(cap, dtype=np.bool_), np.zeros((cap, n)),
        np.zeros((cap, n, n)), np.zeros((cap, n, n)), np.zeros((cap, n)),
        np.zeros(1, dtype=np.int64),
    )  # fmt: skip


@jit
def energy1(mdl, theta, rate):
    """Energy [J] of a monolith at rotation theta [rad] and rate rate [rad/s] (the energy of
    physics/equations, n = 1)."""
    x = mdl.argmap[0, 0] * theta
    potential = law_potential(0, x, mdl.edges, mdl.nedges, mdl.intercepts, mdl.slopes)
    return (0.5 * mdl.mass[0, 0] * rate * rate + potential
            - 0.5 * mdl.gravity[0, 0] * theta * theta)  # fmt: skip
