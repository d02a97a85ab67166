"""The step kernel: event-driven integration of the Rigid Beam Model.

Inside one set of active law pieces the equations are smooth (linear), so the kernel runs
an explicit Runge-Kutta pair (scipy's DOP853, RK45 or RK23 tableaux, initial step, error
norm and step-size control, transcribed) and stops exactly at every event, found by
Brent's method on the step's dense output:

- a law argument reaching the end of its current piece (a kink of the law): the pieces
  change and the integration restarts there, with the step size proposed before the event;
- a zero crossing of a law argument after an excursion beyond its elastic branch (every
  crossing for a rigid law): an impact, the argument's rate is multiplied by the
  restitution e and the integration restarts. With e = 1 and a law linear through zero
  (an elastic first piece) the crossing changes nothing: it is no event, only counted at
  the step's end (events.Pieces.silent);
- a collapse quantity reaching c times its limit: the run stops.

The normalised distances to these surfaces are evaluated once per step; a step that comes
within reach of a surface is checked on its dense output in sub-intervals, and the
earliest crossing of any surface is the event. A rigid monolithic column stays at rest,
with no integration, until the ground demand exceeds the uplift level (found exactly from
the excitation); a rigid block that loses its velocity at an impact returns to rest. Free
motion stops early once its outcome cannot change (energy below every barrier).

The whole run is one call of ``run_kernel`` (step.stepper), written once in the subset of
Python that numba compiles: compiled by default, run by Python as written with
``solver.implementation: python`` (rbm_cli.base.jit.plain; the same bits, 30-100x
slower). The modules: step.inputs (the kernel's four typed input records and
prepare_kernel), step.stepper (the stepper), step.rk (Runge-Kutta), step.events (event
location), step.state (the state change at an event), inputs.ground (the excitation),
step.vertical (moving kinks under a vertical record), models.rbm.pieces (the law pieces, as
the exact integrator keeps them too), models.guard (wall-clock budget and Ctrl-C); this one
runs a model from Python.
"""

from __future__ import annotations

import math
import time
from functools import partial

import numpy as np

from rbm_cli.base.compile_cache import cache_empty
from rbm_cli.base.guard import arm, disarm, poll
from rbm_cli.base.jit import plain
from rbm_cli.config.types import ColumnConfig, InterfaceConfig, SolverConfig
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.models.outcome import EnergyAccount, Outcome, sample_buffer, sample_rows
from rbm_cli.models.rbm.pieces import FRICTION_DURATION, held_array, held_result
from rbm_cli.models.rbm.step.inputs import (
    PreparedModel,
    excitation,
    prepare_kernel,
    solver_settings,
)
from rbm_cli.models.rbm.step.stepper import run_kernel
from rbm_cli.models.status import (
    COLLAPSED,
    FAILED_NONFINITE,
    FAILED_STEP,
    STOPPED_EARLY,
    end_by_budget,
    stop_level,
)
from rbm_cli.numerics.loop import RunEnd
from rbm_cli.structures.column import build_column
from rbm_cli.structures.equations import Model, build_model


def integrate(
    model: Model,
    motion: GroundMotion,
    theta0: np.ndarray,
    rate0: np.ndarray,
    solver,
    record: bool = False,
    output_dt: float = 0.002,
    early_stop: bool = True,
    prepared: PreparedModel | None = None,
    friction_limit: float = math.inf,
    friction_duration: float = FRICTION_DURATION,
) -> Outcome:
    """Integrate one motion of a model from the initial state (theta0 [rad], rate0
    [rad/s]) with the step kernel: compiled, or its uncompiled version (the same source,
    rbm_cli.base.jit.plain) with ``solver.implementation: python``.

    Parameters
    ----------
    model : Model  The column's equations (rbm_cli.structures.equations)
    motion : GroundMotion  The ground motion
    theta0, rate0 : array (n,)  Initial drum rotations [rad] and rates [rad/s]
    solver : SolverConfig  Method (a Runge-Kutta pair), tolerances, budgets, implementation
    record : bool  Keep samples every output_dt [s] (Outcome.samples)
    early_stop : bool  Stop free motion once its outcome cannot change
    prepared : PreparedModel, optional  prepare_kernel(model), made once by a caller
        that runs one model many times (a sweep); made here when None.
    friction_limit : float  A friction coefficient [-]: the outcome says where |T / N|
        first exceeded it (Outcome.slip); inf: none.
    friction_duration : float  The duration the friction demand is held for [s]
        (Outcome.friction; its instantaneous peak: Outcome.friction_peak); 0: the peak.
    """
    if prepared is None:
        prepared = prepare_kernel(model)
    n = model.n
    solver = solver.for_run(motion.t_end, model.joints)
    samples = sample_buffer(motion.t_end, output_dt, record, n)
    deadline = time.monotonic() + float(solver.max_wall_time)
    settings = solver_settings(solver, prepared.atol_scale, deadline)
    held = held_array(model.friction_joints, float(friction_duration), float(friction_limit))
    # a RunTask, as a plain tuple (step.inputs)
    task = (np.asarray(theta0, dtype=float), np.asarray(rate0, dtype=float),
            stop_level(early_stop, solver),
            bool(record), float(output_dt), samples, float(friction_limit), held)  # fmt: skip
    armed = arm()  # Ctrl-C reaches the kernel through poll (rbm_cli.base.guard)
    try:
        kernel = run_kernel if solver.implementation == "compiled" else plain(run_kernel)
        res = kernel(prepared.packed, excitation(motion), settings, task)
    finally:
        disarm(armed)
    return _outcome(res, samples, n, record, solver, account=motion.vertical is None,
                    held=held)  # fmt: skip


def prepare(model: Model):
    """The step integrator of one column (rbm_cli.models.methods.Integrator): its kernel
    inputs prepared once, for every run of the column."""
    return partial(integrate, prepared=prepare_kernel(model))


def _outcome(
    res: RunEnd,
    samples: np.ndarray,
    n: int,
    record: bool,
    solver,
    account: bool,
    held: np.ndarray,
) -> Outcome:
    """The Outcome of what run_kernel returned (a numerics.loop.RunEnd; samples: its output
    rows; account: its energy account is kept, a recorded run without a vertical record;
    held: the held friction demand it took, pieces.held_array)."""
    code, t_end = res.code, res.t_end
    demand, first = held_result(held, res.friction, res.slip)
    out = Outcome(
        t_end=float(t_end), max_ratio=res.max_ratio, max_top=float(res.max_top),
        friction=demand, friction_peak=res.friction, n_uplifts=int(res.n_uplifts),
        n_impacts=int(res.n_impacts), n_steps=int(res.n_steps), n_rhs=int(res.n_rhs),
        n_events=int(res.n_events), slip=first,
    )  # fmt: skip
    if record:
        out.samples = sample_rows(samples, res.n_samples, n)
        if account:
            out.energy = EnergyAccount(*(float(v) for v in res.ledger))
    if code == COLLAPSED:
        out.collapse(float(res.t_collapse), int(res.collapsed))
    elif code == STOPPED_EARLY:
        out.stopped_early(solver.stop == "outcome")
    elif code == FAILED_STEP:
        out.stop("failed", "integrator: Required step size is less than spacing between "
                 "numbers.", t_end)  # fmt: skip
    elif code == FAILED_NONFINITE:
        out.stop("failed", "the state became NaN or infinite (non-finite arithmetic)", t_end)
    else:
        end_by_budget(out, code, solver)
    return out


def needs_compile() -> bool | None:
    """Whether the kernel has no usable on-disk cache: its first use then compiles it
    (about 45 s on two shared cores, once per installation). See base.compile_cache.cache_empty."""
    return cache_empty(run_kernel)


def warm_up() -> None:
    """Compile (or load from the cache) the kernel once, e.g. in a worker."""
    geometry = ColumnConfig(height=2.0, base_width=0.5, top_width=0.5, drum_heights=(2.0,))
    col = build_column(geometry, InterfaceConfig())
    model = build_model(col)
    motion = GroundMotion("harmonic", 5.0, 6.0, 0.0, 0.1, 0.1)
    integrate(model, motion, np.zeros(1), np.zeros(1), SolverConfig())
    poll(math.inf)  # its object-mode block loads on first use (~30 ms): not in a timed run


__all__ = [
    "PreparedModel",
    "integrate",
    "needs_compile",
    "prepare_kernel",
    "warm_up",
]
