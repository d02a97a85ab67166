"""The model as the exact integrator reads it: its arrays (made once per column), the
empty cache of modes, and the energy of a monolith (numba)."""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from rbm_cli.base.jit import jit
from rbm_cli.models.rbm.pieces import law_potential, rest_levels
from rbm_cli.physics.equations import Model, event_families
from rbm_cli.physics.law import law_arrays

ExactModel = namedtuple(
    "ExactModel",
    "n mass chol linv ground diff_t argmap gravity gf_theta edges nedges intercepts slopes "
    "rigid silent tu c_ratio arg_inv imp_dir imp_w restitution rigid_mono uplift_level "
    "rest_rate barrier centre masses normal_forces",
)


def exact_model(model: Model) -> ExactModel:
    """The arrays of a model the compiled exact integrator reads (made once per column)."""
    n = model.n
    col = model.column
    tu = col.rotation_capacity
    edges, nedges, intercepts, slopes, rigid = law_arrays(model.laws)
    chol = np.linalg.cholesky(model.mass)
    args, cmap, top = event_families(model)
    gf = np.vstack([args, cmap, top[None, :]])
    directions, w = model.impulse_directions
    level, rest_rate, barrier = rest_levels(model)
    return ExactModel(
        n, model.mass.copy(), chol, np.linalg.inv(chol), model.ground_load.copy(),
        np.ascontiguousarray(model.diff.T), model.arg_map.copy(), model.gravity.copy(), gf,
        edges, nedges, intercepts, slopes, rigid, model.silent_impacts.copy(), tu.copy(),
        float(model.collapse_ratio), model.arg_inverse.copy(), directions.copy(),
        np.asarray(w, dtype=float), float(model.restitution), level is not None,
        math.nan if level is None else float(level), rest_rate, barrier,
        model.centre_map.copy(), col.masses.copy(), col.normal_forces.copy(),
    )  # fmt: skip


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
