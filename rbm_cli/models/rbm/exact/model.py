"""The model as the exact integrator reads it: its arrays (made once per column), the
empty cache of modes, and what the run loop computes from them (numba): the friction
demand and the energy of a monolith."""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from rbm_cli.base.jit import jit
from rbm_cli.models.events import REST_RATE
from rbm_cli.physics.equations import Model

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
    me = max(len(law.edges) for law in model.laws)
    edges = np.full((n, max(me, 1)), np.inf)
    intercepts = np.zeros((n, me + 1))
    slopes = np.zeros((n, me + 1))
    for i, law in enumerate(model.laws):
        edges[i, : len(law.edges)] = law.edges
        intercepts[i, : len(law.intercepts)] = law.intercepts
        slopes[i, : len(law.slopes)] = law.slopes
    chol = np.linalg.cholesky(model.mass)
    cmap = model.collapse_map / model.collapse_limit[:, None]
    gf = np.vstack([model.arg_map / tu[:, None], cmap, col.heights[None, :]])
    directions, w = model.impulse_directions
    barrier = math.nan
    if n == 1:
        barrier = float(model.energy(np.array([model.collapse_ratio * tu[0]]), np.zeros(1))[0])
    level = model.uplift_level
    return ExactModel(
        n, model.mass.copy(), chol, np.linalg.inv(chol), model.ground_load.copy(),
        np.ascontiguousarray(model.diff.T), model.arg_map.copy(), model.gravity.copy(), gf,
        edges, np.array([len(law.edges) for law in model.laws], dtype=np.int64), intercepts,
        slopes, np.array([law.rigid for law in model.laws]), model.silent_impacts.copy(),
        tu.copy(), float(model.collapse_ratio), model.arg_inverse.copy(), directions.copy(),
        np.asarray(w, dtype=float), float(model.restitution), level is not None,
        math.nan if level is None else float(level),
        REST_RATE * model.rocking_p * float(tu.min()), barrier, model.centre_map.copy(),
        col.masses.copy(), col.normal_forces.copy(),
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
def friction(mdl, acc, ag, out):
    """Raise out (n) to the friction demand |T_i / N_i| for drum accelerations acc
    [rad/s^2] and ground acceleration ag [m/s^2] (the shear ratios of physics/equations)."""
    n = acc.size
    shear = 0.0
    for i in range(n - 1, -1, -1):
        a = ag
        for j in range(n):
            a += mdl.centre[i, j] * acc[j]
        shear += a * mdl.masses[i]
        out[i] = max(out[i], abs(shear) / mdl.normal_forces[i])


@jit
def _potential(mdl, i, x):
    """Law potential F_i(x) [J] (Law.potential)."""
    ax = abs(x)
    cum, start = 0.0, 0.0
    k = 0
    while k < mdl.nedges[i] and mdl.edges[i, k] <= ax:
        end = mdl.edges[i, k]
        a, b = mdl.intercepts[i, k], mdl.slopes[i, k]
        cum += a * (end - start) + 0.5 * b * (end * end - start * start)
        start = end
        k += 1
    a, b = mdl.intercepts[i, k], mdl.slopes[i, k]
    return cum + a * (ax - start) + 0.5 * b * (ax * ax - start * start)


@jit
def energy1(mdl, theta, rate):
    """Energy [J] of a monolith (the energy of physics/equations, n = 1)."""
    x = mdl.argmap[0, 0] * theta
    return (0.5 * mdl.mass[0, 0] * rate * rate + _potential(mdl, 0, x)
            - 0.5 * mdl.gravity[0, 0] * theta * theta)  # fmt: skip
