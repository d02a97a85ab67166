"""The inputs of the compiled kernel, as four typed records (named tuples).

numba reads the fields of a tuple of arrays and scalars at no cost, so the stepper
(step.stepper.run_kernel) takes four records instead of some 45 positional arguments
(passed as plain tuples in the order of their fields, named again inside the kernel:
a named tuple costs more to pass, see run_kernel):

- rbm_cli.structures.arrays.ColumnArrays: everything the kernel needs of a model, made once
  per model by :func:`prepare_kernel` (a sweep prepares a column once, runs it many times);
- :class:`Excitation`: the ground motion of one run;
- :class:`SolverSettings`: method, tolerances, budgets and wall-clock deadline;
- :class:`RunTask`: initial state, early stop and the recording of samples.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from rbm_cli.base.jit import jit
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.inputs.ground import as_samples
from rbm_cli.models.methods import step_method
from rbm_cli.numerics.rk import METHOD_CODES
from rbm_cli.structures.arrays import ColumnArrays, column_arrays
from rbm_cli.structures.equations import Model

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


class Excitation(NamedTuple):
    """The ground motion of one run (rbm_cli.inputs.excitation.GroundMotion; its form's
    numbers as rbm_cli.inputs.ground and inputs.ground read them)."""

    kind: int  #: KIND_CODES
    amplitude: float  #: peak |a_g| [m/s^2]
    omega: float  #: circular frequency [rad/s]
    phase: float  #: [rad]
    pulse_end: float  #: end of a pulse or record [s]
    t_end: float  #: end of the run [s]
    form: int  #: inputs.ground: SINE, RICKER, MP or SAMPLED
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


#: What a structure's functions read of the motion, as a run's record declares it
#: (rbm_cli.numerics.records; motion_into sets them): the record's knots, samples and
#: vertical samples, the peak, the ends of the pulse and of the run, whether steps end at
#: knots.
MOTION_FIELDS = [("knots", "float64[::1]"), ("values", "float64[::1]"),
                 ("vertical", "float64[::1]"), ("amplitude", "float64"), ("pulse_end", "float64"),
                 ("t_end", "float64"), ("clipped", "bool")]  # fmt: skip


@jit
def motion_into(W, motion):
    """Set the fields of a run's record W that MOTION_FIELDS names, from an Excitation."""
    W.knots = motion.knots
    W.values = motion.values
    W.vertical = motion.vertical
    W.amplitude = motion.amplitude
    W.pulse_end = motion.pulse_end
    W.t_end = motion.t_end
    W.clipped = motion.clipped


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
    early_stop: int  #: when the run may stop early (models.status.stop_level)
    record: bool  #: write samples
    output_dt: float  #: sampling interval [s]
    samples: np.ndarray  #: output rows (t, theta, rate) (n_max, 1 + 2n), written in place
    friction_limit: float  #: a friction coefficient [-]: where |T / N| first exceeds it (inf: none)
    held: np.ndarray  #: the held friction demand's state (pieces.held_array), in place


@dataclass(frozen=True)
class PreparedModel:
    """What :func:`prepare_kernel` makes of a model: its kernel arrays (named, and as the
    plain tuple run_kernel takes) and the scale of atol (theta_u for rotations, 10 theta_u
    for rates) [rad, rad/s]."""

    arrays: ColumnArrays
    packed: tuple
    atol_scale: np.ndarray


def prepare_kernel(model: Model) -> PreparedModel:
    """Everything of a model the kernel needs, made once per model.

    Parameters
    ----------
    model : Model  The column's equations (rbm_cli.structures.equations).

    Returns
    -------
    PreparedModel  Its kernel arrays and the scale of atol; pass it to
        integrate(..., prepared=) for every run of this model.
    """
    n = model.n
    tu = float(model.column.rotation_capacity.min())
    atol_scale = np.concatenate([np.full(n, tu), np.full(n, 10.0 * tu)])
    arrays = column_arrays(model)
    return PreparedModel(arrays=arrays, packed=tuple(arrays), atol_scale=atol_scale)


def excitation(motion: GroundMotion) -> tuple:
    """The kernel's Excitation of a ground motion, as the plain tuple run_kernel takes."""
    segments = motion.segments()
    bounds = as_samples([0.0] + [end for _, end in segments])
    forced = np.array([motion.forced(start) for start, _ in segments], dtype=np.bool_)
    return (KIND_CODES[motion.kind], float(motion.amplitude), float(motion.omega),
            float(motion.phase), float(motion.pulse_end), float(motion.t_end),
            int(motion.form), float(motion.shape_gain), float(motion.center),
            float(motion.gamma), as_samples(motion.knots), as_samples(motion.values),
            as_samples(motion.vertical), bool(motion.clipped), bounds, forced,
            bool(motion.is_pulse))  # fmt: skip


def solver_settings(solver, atol_scale: np.ndarray, deadline: float) -> tuple:
    """The kernel's SolverSettings of a SolverConfig (atol scaled by atol_scale; deadline
    [s]), as the plain tuple run_kernel takes."""
    return (METHOD_CODES[step_method(solver)], float(solver.rtol), solver.atol * atol_scale,
            int(solver.max_steps), int(solver.max_events), deadline)  # fmt: skip


__all__ = [
    "KIND_CODES",
    "MOTION_FIELDS",
    "Excitation",
    "PreparedModel",
    "RunTask",
    "SolverSettings",
    "excitation",
    "motion_into",
    "prepare_kernel",
    "solver_settings",
]
