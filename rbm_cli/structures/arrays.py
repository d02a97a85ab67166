"""A column's equations as the compiled integrators read them: one record of arrays and
numbers (:class:`ColumnArrays`), assembled once per column by :func:`column_arrays` and taken
by the step integrator (rbm_cli.models.rbm.step) and the exact one (rbm_cli.models.rbm.exact)
alike: the matrices, the laws' pieces (structures.law.law_arrays), the rows of the quantities a
run watches (structures.equations.event_families) and the levels of the early stop and of a
rigid block's rest (:func:`rest_levels`).

numba reads the fields of a named tuple of arrays and scalars at no cost; n interfaces, SI
units, angles in rad.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from rbm_cli.base.copies import copy_into
from rbm_cli.base.detmath import matmul, matvec
from rbm_cli.base.events import EVENT_EPS
from rbm_cli.base.jit import jit
from rbm_cli.structures.equations import Model, body_masses, event_families
from rbm_cli.structures.law import law_arrays

#: A rigid block whose post-impact rate is below REST_RATE * p * theta_u is
#: put to rest [assumption]: its next excursion would stay below
#: (REST_RATE^2 / 2) theta_u = 100 EVENT_EPS theta_u, a hundred times the offset of the
#: event surfaces (the smallest rotation the event location tells from zero), 1e-10
#: theta_u. This ends Zeno impact sequences (e < 1) and micro-chatter (e = 1, demand
#: just above uplift) in finite work, once the hops are about to sink below what the
#: integrators resolve. (At 1e-3, 5e-7 theta_u, a block under a record was put to rest
#: that the ground would have rocked on: docs/stability.md, "Numerical constants".)
REST_RATE = math.sqrt(200.0 * EVENT_EPS)


class ColumnArrays(NamedTuple):
    """A column as the compiled integrators read it (n interfaces; units SI, angles [rad])."""

    mass: np.ndarray  #: mass matrix M (n, n)
    chol: np.ndarray  #: its Cholesky factor L, M = L L^T (n, n)
    linv: np.ndarray  #: the factor's inverse (n, n)
    argmap: np.ndarray  #: drum rotations -> interface arguments (n, n)
    arg_inv: np.ndarray  #: its inverse (n, n)
    gravity: np.ndarray  #: gravity load (n, n)
    ground_load: np.ndarray  #: ground load vector r (n,)
    diff_t: np.ndarray  #: the difference matrix's transpose D^T (n, n)
    edges: np.ndarray  #: kinks of each law [rad], padded with inf (n, max edges)
    nedges: np.ndarray  #: number of kinks of each law (n,) int
    intercepts: np.ndarray  #: the laws' pieces: intercepts, padded (n, max edges + 1)
    slopes: np.ndarray  #: the laws' pieces: slopes, padded (n, max edges + 1)
    rigid: np.ndarray  #: rigid interfaces (n,) bool
    silent: np.ndarray  #: silent impacts (Model.silent_impacts) (n,) bool
    tu: np.ndarray  #: rotation capacity theta_u of each interface [rad] (n,)
    c_ratio: float  #: collapse ratio [-]
    e_rest: float  #: coefficient of restitution [-]
    literal_impact: bool  #: formulation "absolute"
    impulse_dir: np.ndarray  #: impact impulse directions (n, n)
    impulse_w: np.ndarray  #: their weights (n,)
    centre_map: np.ndarray  #: state -> drum centre accelerations (n, n)
    masses: np.ndarray  #: drum masses [kg] (n,)
    #: normal force at rest of each joint whose friction demand is reported [N]
    #: (Model.friction_normals: the joints', and a monolithic frame's beam joint's)
    normal_forces: np.ndarray
    rigid_mono: bool  #: a rigid monolith (it rests until the ground lifts it)
    uplift_level: float  #: ground acceleration that uplifts a rigid monolith [m/s^2] (-1: none)
    rest_rate: float  #: rate below which a rigid monolith comes to rest after an impact [rad/s]
    barrier: float  #: energy barrier of the early stop [J] (NaN unless n = 1)
    survival: float  #: energy below which free motion cannot collapse [J] (NaN: no such bound)
    families: np.ndarray  #: watched rows: arguments / theta_u, collapse ratios, top (2n + 1, n)
    gx: np.ndarray  #: the joints' law arguments over theta_u, argmap / tu (n, n)
    gc: np.ndarray  #: the collapse ratios, cmap (n, n); the step kernel's event rows are
    #: [gx; -gx; -gc; gc] (step.events._event_rows)
    same: bool  #: gx equals gc (the same rows serve both)
    md: np.ndarray  #: minv @ diff.T, minv the inverse mass matrix (n, n)
    mg: np.ndarray  #: minv @ gravity (n, n)
    track: np.ndarray  #: tracked ratios: the n collapse rows, then the top (n + 1, n)
    es: np.ndarray  #: -minv @ ground_load (n,)
    slope_parts: np.ndarray  #: weight and elastic parts of the slopes (2, n, max edges + 1)
    edge_w: np.ndarray  #: weight share of each kink, 1: fixed (n, max edges), padded with 1
    damp: np.ndarray  #: viscous coefficient of each joint's elastic branch [N m s/rad] (n,)
    damped: bool  #: any joint damped


#: The types of a ColumnArrays' fields as a run's record declares them (numbers as numba
#: spells them; rbm_cli.numerics.records): a run's record holds the column's fields.
COLUMN_TYPES = {
    "mass": "float64[:, ::1]", "chol": "float64[:, ::1]", "linv": "float64[:, ::1]",
    "argmap": "float64[:, ::1]", "arg_inv": "float64[:, ::1]", "gravity": "float64[:, ::1]",
    "ground_load": "float64[::1]", "diff_t": "float64[:, ::1]", "edges": "float64[:, ::1]",
    "nedges": "int64[::1]", "intercepts": "float64[:, ::1]", "slopes": "float64[:, ::1]",
    "rigid": "bool[::1]", "silent": "bool[::1]", "tu": "float64[::1]", "c_ratio": "float64",
    "e_rest": "float64", "literal_impact": "bool", "impulse_dir": "float64[:, ::1]",
    "impulse_w": "float64[::1]", "centre_map": "float64[:, ::1]", "masses": "float64[::1]",
    "normal_forces": "float64[::1]", "rigid_mono": "bool", "uplift_level": "float64",
    "rest_rate": "float64", "barrier": "float64", "survival": "float64",
    "families": "float64[:, ::1]", "gx": "float64[:, ::1]", "gc": "float64[:, ::1]",
    "same": "bool", "md": "float64[:, ::1]", "mg": "float64[:, ::1]",
    "track": "float64[:, ::1]", "es": "float64[::1]", "slope_parts": "float64[:, :, ::1]",
    "edge_w": "float64[:, ::1]", "damp": "float64[::1]", "damped": "bool",
}  # fmt: skip
#: ColumnArrays' fields with their types, in order (a field without a type fails here).
COLUMN_FIELDS = [(name, COLUMN_TYPES[name]) for name in ColumnArrays._fields]


@jit
def column_into(W, col):
    """Set the fields of a run's record W (numerics.records) that a ColumnArrays col has."""
    W.mass = col.mass
    W.chol = col.chol
    W.linv = col.linv
    W.argmap = col.argmap
    W.arg_inv = col.arg_inv
    W.gravity = col.gravity
    W.ground_load = col.ground_load
    W.diff_t = col.diff_t
    W.edges = col.edges
    W.nedges = col.nedges
    W.intercepts = col.intercepts
    W.slopes = col.slopes
    W.rigid = col.rigid
    W.silent = col.silent
    W.tu = col.tu
    W.c_ratio = col.c_ratio
    W.e_rest = col.e_rest
    W.literal_impact = col.literal_impact
    W.impulse_dir = col.impulse_dir
    W.impulse_w = col.impulse_w
    W.centre_map = col.centre_map
    W.masses = col.masses
    W.normal_forces = col.normal_forces
    W.rigid_mono = col.rigid_mono
    W.uplift_level = col.uplift_level
    W.rest_rate = col.rest_rate
    W.barrier = col.barrier
    W.survival = col.survival
    W.families = col.families
    W.gx = col.gx
    W.gc = col.gc
    W.same = col.same
    W.md = col.md
    W.mg = col.mg
    W.track = col.track
    W.es = col.es
    W.slope_parts = col.slope_parts
    W.edge_w = col.edge_w
    W.damp = col.damp
    W.damped = col.damped


def rest_levels(model: Model) -> tuple[float | None, float, float]:
    """The levels a run compares with, made once per model.

    Returns
    -------
    uplift : float or None  Ground acceleration [m/s^2] that uplifts a rigid monolith at rest
        (Model.uplift_level; None: no rigid monolith).
    rest_rate : float  Rate [rad/s] below which a rigid monolith comes to rest after an
        impact: REST_RATE p theta_u (p the rocking frequency [rad/s], theta_u the smallest
        rotation capacity [rad]).
    barrier : float  Energy [J] of a monolith at its collapse ratio at rest (the early stop
        of free motion compares with it); NaN unless n = 1.
    """
    tu = model.column.rotation_capacity
    barrier = math.nan
    if model.n == 1:
        barrier = float(model.energy(model.collapse_ratio * tu, np.zeros(1))[0])
    return model.uplift_level, REST_RATE * model.rocking_p * float(tu.min()), barrier


def survival_barrier(model: Model) -> float:
    """Energy [J] below which a column in free motion cannot collapse; NaN where the model
    gives no such bound.

    For the `relative` formulation the energy is the kinetic energy plus the laws'
    potentials F_j(x_j) = integral_0^x_j f_j, each a function of its own joint's argument.
    A joint collapses where |x_i| reaches c L_i (c <= 1, L_i its collapse limit: theta_u,i
    for a column's joint; for a frame's, past theta_u,i, where the law plus the beam
    joint's cap vanish). Each law's moment is >= 0 up to theta_u and < 0 beyond, so F_j
    grows with |x_j| up to theta_u and falls after: before any joint collapses, F_j(x_j) is
    at least min(0, F_j(c L_j)), and a joint that never collapses (a frame's beam joint,
    its cap without a descending branch) has F_j >= 0 wherever it is. Reaching the collapse
    of joint i therefore takes an energy of at least F_i(c L_i) plus the other joints'
    min(0, F_j(c L_j)). If every F_j(c L_j) is positive the least of these is
    min_i F_i(c L_i), the barrier; if one is not (a frame's heavy beam can take a joint's
    below 0), the least is not positive and there is no barrier (NaN), nor is there one if
    a joint that never collapses has a law that turns negative. Free motion (no forcing,
    impacts with e <= 1, joint damping >= 0) never gains energy, so a column below the
    barrier survives whatever follows. Other formulations: NaN (`geometric` adds gravity's
    potential, negative and coupling the joints; `absolute` is not energy-conserving)."""
    if model.formulation != "relative":
        return math.nan
    watched = np.any(model.collapse_map != 0.0, axis=1)
    limit = model.collapse_ratio * np.asarray(model.collapse_limit, dtype=float)
    barrier = math.inf
    for law, x, w in zip(model.laws, limit, watched, strict=True):
        if w:
            barrier = min(barrier, float(min(law.potential(x), law.potential(-x))))
        elif law.slopes[-1] < 0.0 or law.intercepts[-1] < 0.0:  # never collapses: F >= 0?
            return math.nan
    return barrier if 0.0 < barrier < math.inf else math.nan


@jit
def _derived(args, cmap, top, minv, diff, gravity, ground_load):
    """The step integrator's products of the model's arrays: (same, md, mg, track, es),
    from the event families args, cmap, top."""
    m, n = args.shape  # the joints and the drums
    same = True
    for i in range(m):
        for j in range(n):
            same = same and args[i, j] == cmap[i, j]
    md = matmul(minv, diff.T.copy())
    mg = matmul(minv, gravity)
    track = np.empty((m + 1, n))
    for i in range(m):
        copy_into(track[i], cmap[i])
    copy_into(track[m], top)
    es = -matvec(minv, ground_load, np.empty(n))
    return same, md, mg, track, es


def column_arrays(model: Model) -> ColumnArrays:
    """The model's arrays as the compiled integrators read them (assembled once per
    column)."""
    col = model.column
    impulse_dir, impulse_w = model.impulse_directions
    edges, nedges, inter, slopes, rigid = law_arrays(model.laws)
    args, cmap, top = event_families(model)
    same, md, mg, track, es = _derived(args, cmap, top, model.mass_inv,
                                       model.diff.astype(float), model.gravity,
                                       model.ground_load)  # fmt: skip
    uplift, rest_rate, barrier = rest_levels(model)
    chol = np.linalg.cholesky(model.mass)
    return ColumnArrays(
        mass=model.mass.copy(), chol=chol, linv=np.linalg.inv(chol),
        argmap=model.arg_map.astype(float), arg_inv=model.arg_inverse.copy(),
        gravity=model.gravity.copy(), ground_load=model.ground_load.copy(),
        diff_t=np.ascontiguousarray(model.diff.T), edges=edges, nedges=nedges,
        intercepts=inter, slopes=slopes, rigid=rigid, silent=model.silent_impacts.copy(),
        tu=model.argument_scale.astype(float), c_ratio=float(model.collapse_ratio),
        e_rest=float(model.restitution), literal_impact=model.formulation == "absolute",
        impulse_dir=impulse_dir.copy(), impulse_w=np.asarray(impulse_w, dtype=float),
        centre_map=model.centre_map.copy(), masses=body_masses(col).astype(float),
        normal_forces=model.friction_normals.astype(float), rigid_mono=uplift is not None,
        uplift_level=-1.0 if uplift is None else float(uplift), rest_rate=float(rest_rate),
        barrier=float(barrier), survival=survival_barrier(model),
        families=np.vstack([args, cmap, top[None, :]]),
        gx=np.ascontiguousarray(args, dtype=float), gc=np.ascontiguousarray(cmap, dtype=float),
        same=bool(same),
        md=md, mg=mg, track=track, es=es, slope_parts=np.stack(model.slope_parts),
        edge_w=model.edge_weight_shares, damp=model.joint_damping.copy(),
        damped=bool(model.joint_damping.any()),
    )  # fmt: skip


__all__ = [
    "COLUMN_FIELDS",
    "COLUMN_TYPES",
    "REST_RATE",
    "ColumnArrays",
    "column_arrays",
    "column_into",
    "rest_levels",
    "survival_barrier",
]
