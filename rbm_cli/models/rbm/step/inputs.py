"""The inputs of the compiled kernel, as four typed records (named tuples).

numba reads the fields of a tuple of arrays and scalars at no cost, so the stepper
(step.stepper.run_kernel) takes four records instead of some 45 positional arguments
(passed as plain tuples in the order of their fields, named again inside the kernel:
a named tuple costs more to pass, see run_kernel):

- :class:`ModelArrays`: everything the kernel needs of a model, made once per
  model by :func:`prepare_kernel` (a sweep prepares a column once, runs it many times);
- :class:`Excitation`: the ground motion of one run;
- :class:`SolverSettings`: method, tolerances, budgets and wall-clock deadline;
- :class:`RunTask`: initial state, early stop and the recording of samples.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from rbm_cli.base.detmath import matmul, matvec
from rbm_cli.base.jit import jit
from rbm_cli.models.methods import step_method
from rbm_cli.models.rbm.pieces import rest_levels
from rbm_cli.models.rbm.step.rk import METHOD_CODES
from rbm_cli.physics.equations import Model, event_families
from rbm_cli.physics.excitation import GroundMotion
from rbm_cli.physics.law import law_arrays

#: excitation kind -> code in the kernel
KIND_CODES = {
    "harmonic": 0,
    "half-sine": 1,
    "free": 2,
    "one-sine": 3,
    "cycloidal": 4,
    "ricker": 5,
    "mavroeidis-papageorgiou": 6,
    "record": 7,
}


class ModelArrays(NamedTuple):
    """A model as the kernel reads it (n interfaces; units SI, angles [rad])."""

    mass: np.ndarray  #: mass matrix (n, n)
    argmap: np.ndarray  #: drum rotations -> interface arguments (n, n)
    arg_inv: np.ndarray  #: its inverse (n, n)
    gravity: np.ndarray  #: gravity load (n, n)
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
    normal_forces: np.ndarray  #: normal force at each interface [N] (n,)
    uplift_level: float  #: ground acceleration that uplifts a rigid monolith [m/s^2] (-1: none)
    rest_rate: float  #: rate below which a rigid monolith comes to rest after an impact [rad/s]
    barrier: float  #: energy barrier of the early stop [J] (NaN unless n = 1)
    event_rows: np.ndarray  #: event rows: argmap / tu, -argmap / tu, -cmap, cmap (4n, n)
    gx: np.ndarray  #: event_rows[:n]
    gc: np.ndarray  #: event_rows[3n:]
    same: bool  #: gx equals gc (the same rows serve both)
    md: np.ndarray  #: minv @ diff.T, minv the inverse mass matrix (n, n)
    mg: np.ndarray  #: minv @ gravity (n, n)
    track: np.ndarray  #: tracked ratios: the n collapse rows, then the top (n + 1, n)
    es: np.ndarray  #: -minv @ ground_load (n,)
    slope_parts: np.ndarray  #: weight and elastic parts of the slopes (2, n, max edges + 1)
    edge_w: np.ndarray  #: weight share of each kink, 1: fixed (n, max edges), padded with 1


class Excitation(NamedTuple):
    """The ground motion of one run (rbm_cli.physics.excitation.GroundMotion; its form's
    numbers as rbm_cli.physics.ground_forms and models.ground read them)."""

    kind: int  #: KIND_CODES
    amplitude: float  #: peak |a_g| [m/s^2]
    omega: float  #: circular frequency [rad/s]
    phase: float  #: [rad]
    pulse_end: float  #: end of a pulse or record [s]
    t_end: float  #: end of the run [s]
    form: int  #: ground_forms: SINE, RICKER, MP or SAMPLED
    gain: float  #: multiplier of the form [m/s^2]
    center: float  #: centre of a Ricker or MP pulse [s]
    gamma: float  #: MP's gamma [-]
    knots: np.ndarray  #: times a_g is monotone between [s] (a record's samples)
    values: np.ndarray  #: a record's a_g at its samples [m/s^2] (gain 1)
    vertical: np.ndarray  #: its upward a_v at the samples [m/s^2] (empty: none)
    clipped: bool  #: steps end at every knot (a record)
    bounds: np.ndarray  #: segment boundaries, from 0 to t_end [s]
    forced: np.ndarray  #: whether a_g acts on each segment (bool)
    pulse: bool  #: free motion after a pulse or record (may stop early)


class SolverSettings(NamedTuple):
    """Method, tolerances and budgets of one run."""

    mc: int  #: METHOD_CODES
    rtol: float  #: relative tolerance [-]
    atol: np.ndarray  #: absolute tolerance of each state component (2n,)
    max_steps: int  #: step budget
    max_events: int  #: event budget
    deadline: float  #: wall-clock deadline, time.monotonic() [s]


class RunTask(NamedTuple):
    """Where a run starts and what it records."""

    theta0: np.ndarray  #: initial drum rotations [rad] (n,)
    rate0: np.ndarray  #: initial rates [rad/s] (n,)
    early_stop: bool  #: stop free motion below the collapse barrier
    record: bool  #: write samples
    output_dt: float  #: sampling interval [s]
    samples: np.ndarray  #: output rows (t, theta, rate) (n_max, 1 + 2n), written in place


@dataclass(frozen=True)
class PreparedModel:
    """What :func:`prepare_kernel` makes of a model: its kernel arrays (named, and as the
    plain tuple run_kernel takes) and the scale of atol (theta_u for rotations, 10 theta_u
    for rates) [rad, rad/s]."""

    arrays: ModelArrays
    packed: tuple
    atol_scale: np.ndarray


# ---------------------------------------------------------------- preparation
@jit
def _derived(args, cmap, top, minv, diff, gravity, ground_load):
    """The kernel's products of the model's arrays: (event_rows, same, md, mg, track, es),
    from the event families args, cmap, top that physics.equations makes once."""
    n = args.shape[0]
    event_rows = np.empty((4 * n, n))
    for i in range(n):
        for j in range(n):
            event_rows[i, j] = args[i, j]
            event_rows[n + i, j] = -args[i, j]
            event_rows[2 * n + i, j] = -cmap[i, j]
            event_rows[3 * n + i, j] = cmap[i, j]
    gx, gc = event_rows[:n], event_rows[3 * n :]
    same = True
    for i in range(n):
        for j in range(n):
            same = same and gx[i, j] == gc[i, j]
    md = matmul(minv, diff.T.copy())
    mg = matmul(minv, gravity)
    track = np.empty((n + 1, n))
    track[:n, :] = cmap
    track[n, :] = top
    es = -matvec(minv, ground_load, np.empty(n))
    return event_rows, same, md, mg, track, es


def model_arrays(model: Model) -> ModelArrays:
    """The model's arrays as the kernel reads them (assembled once per column)."""
    col = model.column
    tu = col.rotation_capacity.astype(float)
    argmap = model.arg_map.astype(float)
    impulse_dir, impulse_w = model.impulse_directions
    edges, nedges, inter, slopes, rigid = law_arrays(model.laws)
    args, cmap, top = event_families(model)
    event_rows, same, md, mg, track, es = _derived(args, cmap, top, model.mass_inv,
                                          model.diff.astype(float), model.gravity,
                                          model.ground_load)  # fmt: skip
    n = model.n
    uplift, rest_rate, barrier = rest_levels(model)
    uplift = -1.0 if uplift is None else uplift
    return ModelArrays(
        mass=model.mass, argmap=argmap, arg_inv=model.arg_inverse,
        gravity=model.gravity, edges=edges, nedges=nedges, intercepts=inter, slopes=slopes,
        rigid=rigid, silent=model.silent_impacts, tu=tu,
        c_ratio=float(model.collapse_ratio), e_rest=float(model.restitution),
        literal_impact=model.formulation == "absolute", impulse_dir=impulse_dir,
        impulse_w=impulse_w, centre_map=model.centre_map, masses=col.masses.astype(float),
        normal_forces=col.normal_forces.astype(float), uplift_level=float(uplift),
        rest_rate=float(rest_rate), barrier=float(barrier), event_rows=event_rows,
        gx=event_rows[:n], gc=event_rows[3 * n :],
        same=bool(same), md=md, mg=mg, track=track, es=es,
        slope_parts=np.stack(model.slope_parts), edge_w=model.edge_weight_shares,
    )  # fmt: skip


def prepare_kernel(model: Model) -> PreparedModel:
    """Everything of a model the kernel needs, made once per model.

    Parameters
    ----------
    model : Model  The column's equations (rbm_cli.physics.equations).

    Returns
    -------
    PreparedModel  Its kernel arrays and the scale of atol; pass it to
        integrate(..., prepared=) for every run of this model.
    """
    n = model.n
    tu = float(model.column.rotation_capacity.min())
    atol_scale = np.concatenate([np.full(n, tu), np.full(n, 10.0 * tu)])
    arrays = model_arrays(model)
    return PreparedModel(arrays=arrays, packed=tuple(arrays), atol_scale=atol_scale)


def _array(x) -> np.ndarray:
    """A writable float64 copy (numba types read-only arrays apart: one more compile)."""
    return np.array(() if x is None else x, dtype=np.float64)


def excitation(motion: GroundMotion) -> tuple:
    """The kernel's Excitation of a ground motion, as the plain tuple run_kernel takes."""
    segments = motion.segments()
    bounds = _array([0.0] + [end for _, end in segments])
    forced = np.array([motion.forced(start) for start, _ in segments], dtype=np.bool_)
    return (KIND_CODES[motion.kind], float(motion.amplitude), float(motion.omega),
            float(motion.phase), float(motion.pulse_end), float(motion.t_end),
            int(motion.form), float(motion.shape_gain), float(motion.center),
            float(motion.gamma), _array(motion.knots), _array(motion.values),
            _array(motion.vertical), bool(motion.clipped), bounds, forced,
            bool(motion.is_pulse))  # fmt: skip


def solver_settings(solver, atol_scale: np.ndarray, deadline: float) -> tuple:
    """The kernel's SolverSettings of a SolverConfig (atol scaled by atol_scale; deadline
    [s]), as the plain tuple run_kernel takes."""
    return (METHOD_CODES[step_method(solver)], float(solver.rtol), solver.atol * atol_scale,
            int(solver.max_steps), int(solver.max_events), deadline)  # fmt: skip


__all__ = [
    "KIND_CODES",
    "Excitation",
    "ModelArrays",
    "PreparedModel",
    "RunTask",
    "SolverSettings",
    "excitation",
    "model_arrays",
    "prepare_kernel",
    "solver_settings",
]
