"""The exact integrator from Python: the model's arrays and cache of modes (prepare_exact),
one run (integrate_exact: the compiled run loop, rbm_cli.models.rbm.exact.run, or its
uncompiled version with ``solver.implementation: python``), and its first compile.

The modes of every set of law pieces met are cached across the runs of one column
(PreparedExact.cache).
"""

from __future__ import annotations

import math
from functools import partial
from typing import NamedTuple

import numpy as np

from rbm_cli.base.compile_cache import cache_empty
from rbm_cli.base.guard import arm, disarm
from rbm_cli.base.jit import plain
from rbm_cli.config.types import ColumnConfig, InterfaceConfig, SolverConfig, StiffnessConfig
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.models.outcome import Outcome, sample_buffer, sample_rows
from rbm_cli.models.rbm.exact.motion import check_exact
from rbm_cli.models.rbm.exact.piece import new_cache
from rbm_cli.models.rbm.exact.run import run_exact
from rbm_cli.models.rbm.forcing_arrays import motion_arrays, run_settings
from rbm_cli.models.rbm.pieces import FRICTION_DURATION, held_array, held_result
from rbm_cli.models.status import (
    AT_REST_END,
    COLLAPSED,
    OPENED,
    STOPPED_EARLY,
    end_by_budget,
)
from rbm_cli.structures.arrays import ColumnArrays, column_arrays
from rbm_cli.structures.column import build_column
from rbm_cli.structures.equations import Model, build_model

#: Points of the pool (3 for the run loop, the rest for the refinement of peaks) and
#: entries of the refinement's stack.
POOL, STACK = 256, 128


class PreparedExact(NamedTuple):
    """A model's arrays and its cache of modes, made once per column."""

    arrays: ColumnArrays
    cache: tuple


def prepare_exact(model: Model) -> PreparedExact:
    """The arrays and an empty cache of modes of a model the exact method takes
    (RbmError in one line otherwise)."""
    check_exact(model, "free")
    arrays = column_arrays(model)
    bodies = arrays.centre_map.shape[0]
    return PreparedExact(arrays, new_cache(model.n, model.joints, bodies))


def _outcome(code, st, cnt, maxima, fric, solver, m: int, held: np.ndarray) -> Outcome:
    """The Outcome of what run_exact returned (m joints: maxima holds their collapse ratios,
    then the top's displacement)."""
    out = Outcome()
    out.t_end = float(st[0])
    out.max_ratio = maxima[:m].copy()
    out.max_top = float(maxima[m])
    out.friction_peak = fric.copy()
    out.friction, out.slip = held_result(held, fric, st[6:8])  # run.T_SLIP, run.SLIP_IF
    out.n_uplifts, out.n_impacts, out.n_steps, out.n_rhs, out.n_events = (int(x) for x in cnt[:5])
    t = out.t_end
    if code == COLLAPSED:
        out.collapse(float(st[3]), int(cnt[5]))
    elif code == STOPPED_EARLY:
        out.stopped_early(solver.stop == "outcome")
    elif end_by_budget(out, code, solver):
        pass
    elif code != AT_REST_END and not math.isfinite(out.max_top):
        out.stop("failed", "numerical failure: non-finite state", t)
    return out


def integrate_exact(
    model: Model,
    motion: GroundMotion,
    theta0: np.ndarray,
    rate0: np.ndarray,
    solver,
    record: bool = False,
    output_dt: float = 0.002,
    early_stop: bool = True,
    prepared: PreparedExact | None = None,
    friction_limit: float = math.inf,
    until_open: bool = False,
    friction_duration: float = FRICTION_DURATION,
) -> Outcome | None:
    """Integrate one motion of a model from the initial state (theta0 [rad], rate0
    [rad/s]) exactly, piece by piece (rbm_cli.models.rbm.exact): compiled, or its
    uncompiled version (the same source, rbm_cli.base.jit.plain) with
    ``solver.implementation: python``.

    Parameters
    ----------
    model : Model  The column's equations (rbm_cli.structures.equations)
    motion : GroundMotion  The ground motion (its kind, end and pulse end with segments)
    theta0, rate0 : array (n,)  Initial drum rotations [rad] and rates [rad/s]
    solver : SolverConfig  Budgets (max_steps: certified intervals, max_events,
        max_wall_time) and implementation
    record : bool  Keep samples every output_dt [s] (Outcome.samples)
    early_stop : bool  Stop free motion once its outcome cannot change
    prepared : PreparedExact, optional  prepare_exact(model), made once by a caller that
        runs one model many times (a sweep); made here when None.
    friction_limit : float  A friction coefficient [-]: the outcome says where |T / N|
        first exceeded it (Outcome.slip); inf: none.
    friction_duration : float  The duration the friction demand is held for [s]
        (Outcome.friction; its peak: Outcome.friction_peak); 0: the peak.
    until_open : bool  Stop at the first event of a joint (its law argument reaching the
        end of its piece: an uplift from the elastic branch) and return None; the outcome
        otherwise (the run never met one).
    """
    seg_t, seg_fc = motion_arrays(model, motion)
    if prepared is None:
        prepared = prepare_exact(model)
    n, m = model.n, model.joints
    solver = solver.for_run(motion.t_end, m)
    mo, se = run_settings(motion, solver, early_stop, record, output_dt, friction_limit, until_open)
    samples = sample_buffer(motion.t_end, output_dt, record, n)
    held = held_array(model.friction_joints, float(friction_duration), float(friction_limit))
    armed = arm()  # Ctrl-C reaches the run through poll (rbm_cli.base.guard)
    try:
        run = run_exact if solver.implementation == "compiled" else plain(run_exact)
        code, st, cnt, maxima, fric = run(
            prepared.arrays, prepared.cache, seg_t, seg_fc, mo, se,
            np.asarray(theta0, dtype=float), np.asarray(rate0, dtype=float), samples, POOL, STACK,
            held,
        )  # fmt: skip
    finally:
        disarm(armed)
    if code == OPENED:
        return None
    out = _outcome(code, st, cnt, maxima, fric, solver, m, held)
    if record:
        out.samples = sample_rows(samples, int(st[5]), n)
    return out


def prepare(model: Model):
    """The exact integrator of one column (rbm_cli.models.methods.Integrator): its modal
    arrays prepared once, for every run of the column."""
    return partial(integrate_exact, prepared=prepare_exact(model))


def needs_compile() -> bool | None:
    """Whether the exact integrator has no usable on-disk cache (compile_cache.cache_empty):
    its first use then compiles it."""
    return cache_empty(run_exact)


def warm_up() -> None:
    """Compile (or load from the cache) the exact integrator once, e.g. in a worker: a
    rigid monolith and an elastic 2-drum column (their model arrays type differently),
    under a harmonic and a record (a harmonic and a linear forcing)."""
    knots = np.array([0.0, 0.05, 0.1])
    record = GroundMotion("record", 5.0, 0.0, 0.0, 0.1, 0.1, gain=1.0, knots=knots,
                          values=np.array([0.0, 5.0, -5.0]))  # fmt: skip
    elastic = InterfaceConfig(stiffness=StiffnessConfig("normal", (5e9,)))
    for drums, interface in (((2.0,), InterfaceConfig()), ((1.0, 1.0), elastic)):
        geometry = ColumnConfig(height=2.0, base_width=0.5, top_width=0.5, drum_heights=drums)
        model = build_model(build_column(geometry, interface))
        zeros = np.zeros(model.n)
        for motion in (GroundMotion("harmonic", 5.0, 6.0, 0.0, 0.1, 0.1), record):
            integrate_exact(model, motion, zeros, zeros, SolverConfig())
