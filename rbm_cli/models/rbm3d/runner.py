"""`rbm-3d`: the Rigid Beam Model of a column of circular drums in two horizontal directions
(rbm_cli.structures.column3d), integrated by the planar step kernel's Runge-Kutta pairs (DOP853,
RK45, RK23) in a compiled run of its own (kernel.py; its source uncompiled with
`solver.implementation: python`), the events located on each step's dense output:

- **a kink** where a joint's |phi_i| reaches an edge of its law's piece (the edges move
  with a vertical record as in the plane): the piece changes. Leaving the elastic branch
  is an **uplift** (the joint opens);
- **an impact** where an open joint closes. A joint that comes back onto its elastic
  branch after an excursion has its direction c pinned there (phi_i / |phi_i|); the
  impact is where phi_i crosses the line across c (phi_i . c = 0: phi_i = 0 in a plane).
  For a rigid law (no elastic branch: a rigid monolith) the joint is pinned within
  solver.atol theta_u of closure (the integrator's absolute tolerance of the rotation:
  a joint that passes closure that near cannot be told from one through it, and its
  direction there is not what the steps control; as `housner-3d` pins its contact), and
  closes there (crossing the line, or turning away); after the impact it rocks on toward
  where it moves, pinned until |phi| is LEAVE_FACTOR times that distance (its phi is
  round-off there). A monolith lifting from rest (phi = 0 exactly, growing from it) is
  pinned at phi = 0 alone, and follows its own direction from there: pinned while it
  leans slowly off the vertical, as the motion turns, its peak moved by about the square
  root of that distance (1e-3 at atol 1e-12 just above the uplift level). A joint that
  passes farther from closure rolls round it (a wobble), and a passage within that
  distance is found wherever it falls in a step (the square of |phi| is watched, smooth
  through closure). 100 times smaller tolerances take that distance 100 times nearer
  closure, so the robustness rule's solver check sees a cell that turns on it.
  The rule: an impulsive moment along c acts at the joint, so that the component of its
  relative rate along c becomes e times itself (momentum-consistent, as in the plane:
  Model.impact_rates; `absolute` scales that rate alone) and the rolling component across
  c is kept. In a plane c is the plane's direction and this is the planar impact. With
  e = 1 and an elastic joint the impact changes nothing: it is counted, not stopped at;
- **collapse** where a joint's collapse quantity (the magnitude of the pair of its
  directions) reaches collapse.ratio times its limit (Outcome.azimuth: the direction of
  that pair);
- **rest** (a rigid monolith) after an impact below REST_RATE p theta_u, and an uplift
  away from the ground's acceleration when it exceeds the uplift level.

An **uplift** is a closed joint opening (leaving its elastic branch; a rigid monolith
lifting from rest); a joint back on its elastic branch that opens again before it closed
goes on with its excursion, as in the plane (rbm_cli.models.rbm.pieces.cross).

The motion is run in its own frame (rbm_cli.models.plan): along x, a pair's second
component along y; what is reported in plan (the top's path, the collapse azimuth) is
turned back to the ground's axes. A motion of one component then stays in its vertical
plane to the bit, and a sweep's run (solver.stop) of a monolith stops where the planar
kernel's does: at a peak of free motion after a pulse or a record, below the collapse
barrier, while the state lies in that plane (a state that left it may wobble, its later
peaks higher: it runs to rest or to the end).

Peaks (max_ratio per joint, the top's displacement in plan) are taken at step ends and
where their rates turn inside a step (Brent on the dense output); the friction demand
|T_i| / N_i at step ends in motion and, at rest, exactly over the rest (a pair: its
resultant), as the planar kernel's. Outcome.turns: the largest angle the direction of a
joint's lean (its collapse quantity in plan) swept while that lean was WOBBLE_LEVEL of its
collapse limit or more at both ends of a step (a wobble), in turns. A recorded run keeps
the energy account of the planar kernel (Outcome.energy, without a vertical record). A
history's rotations are seen in the motion's vertical plane (its frame's x); the top's
path in plan is kept beside them.
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np

from rbm_cli.base.compile_cache import cache_empty
from rbm_cli.base.guard import arm, disarm
from rbm_cli.base.jit import plain
from rbm_cli.config.types import ColumnConfig, InterfaceConfig, SolverConfig
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.inputs.ground import as_samples
from rbm_cli.models.outcome import EnergyAccount, Outcome
from rbm_cli.models.plan import as_line, from_ground, to_ground, turned_start, wrapped
from rbm_cli.models.rbm.pieces import FRICTION_DURATION, held_array, held_result
from rbm_cli.models.rbm.runner import RbmRunner
from rbm_cli.models.rbm.step.inputs import excitation, prepare_kernel, solver_settings
from rbm_cli.models.rbm3d.kernel import AT_REST, run3d
from rbm_cli.models.status import (
    COLLAPSED,
    FAILED_NONFINITE,
    FAILED_STEP,
    STOPPED_EARLY,
    end_by_budget,
    stop_level,
)
from rbm_cli.structures.column import build_column
from rbm_cli.structures.equations import build_model


def integrate3d(
    model,
    motion: GroundMotion,
    theta0: np.ndarray,
    rate0: np.ndarray,
    solver: SolverConfig,
    *,
    record: bool = False,
    output_dt: float = 0.002,
    early_stop: bool = True,
    friction_limit: float = math.inf,
    friction_duration: float = FRICTION_DURATION,
    prepared=None,
    state: np.ndarray | None = None,
    end: list | None = None,
    across: tuple[np.ndarray, np.ndarray] | None = None,
) -> Outcome:
    """One run of a column's RBM in two directions (the module's rules).

    Parameters
    ----------
    model : Model  The column's planar equations (rbm_cli.structures.equations)
    motion : GroundMotion  The ground motion, in any direction, one or two components
    theta0, rate0 : (n,)  Initial drum rotations [rad] and rates [rad/s] in the motion's
        vertical plane
    across : ((n,), (n,)) or None  Those in the vertical plane across it (the motion's
        direction turned by +90 degrees in plan); None: 0
    solver : SolverConfig  Runge-Kutta pair, rtol, atol (scaled by theta_u and 10 theta_u
        per second, as the planar step kernel), budgets, implementation
    record, output_dt : as the planar integrators
    early_stop : bool  A sweep's run: a monolith may stop at a peak of free motion in the
        motion's plane below its collapse barrier (solver.stop; the module's notes); a
        run also stops at rest after the motion (a rigid monolith)
    friction_limit : float  Outcome.slip where |T_i| / N_i first exceeds it (inf: none)
    friction_duration : float  The duration the friction demand is held for [s]
        (Outcome.friction; its peak: Outcome.friction_peak); 0: the peak
    prepared : PreparedModel, optional  prepare_kernel(model), made once by a caller
    state : (4n,) array, optional  A whole initial state (theta_x, theta_y, their rates, in
        the ground's axes) in place of theta0, rate0
    end : list, optional  If a list, the state where the run ended is appended to it (in
        the ground's axes)
    """
    prepared = prepare_kernel(model) if prepared is None else prepared
    n = model.n
    motion, beta = as_line(motion)  # a pair in phase: one component turned by beta
    angle = wrapped(motion.angle)  # the motion's frame (rbm_cli.models.plan)
    own = motion if motion.angle == 0.0 else dataclasses.replace(motion, angle=0.0)
    if state is None:
        theta0, rate0 = np.asarray(theta0, float), np.asarray(rate0, float)
        tc, rc = np.zeros(n), np.zeros(n)
        if across is not None:  # across the motion's plane: along y in the motion's frame
            tc, rc = np.asarray(across[0], float), np.asarray(across[1], float)
        # given in the first component's plane; in the line's (as_line)
        theta0, tc = turned_start(theta0, tc, beta)
        rate0, rc = turned_start(rate0, rc, beta)
        y0 = np.concatenate([theta0, tc, rate0, rc])
    else:
        y0 = np.array(state, dtype=float)
        for part in (0, 2 * n):
            pairs = from_ground(np.stack([y0[part : part + n], y0[part + n : part + 2 * n]], 1),
                                angle)  # fmt: skip
            y0[part : part + n], y0[part + n : part + 2 * n] = pairs[:, 0], pairs[:, 1]
    scale = np.concatenate([prepared.atol_scale[:n], prepared.atol_scale[:n],
                            prepared.atol_scale[n:], prepared.atol_scale[n:]])  # fmt: skip
    solver = solver.for_run(motion.t_end, n)
    deadline = time.monotonic() + float(solver.max_wall_time)
    rows = int(math.floor(motion.t_end / output_dt + 1e-9)) + 2 if record else 0
    samples = np.zeros((rows, 3 + 3 * n))
    held = held_array(n, float(friction_duration), float(friction_limit))
    task = (y0, bool(record), float(output_dt), samples, float(friction_limit),
            stop_level(early_stop, solver), float(solver.atol), held)  # fmt: skip
    pair = (1.0, 0.0, as_samples(own.values_y), own.ground_y, own.knots_y)
    armed = arm()
    try:
        kernel = run3d if solver.implementation == "compiled" else plain(run3d)
        res = kernel(prepared.packed, excitation(own), solver_settings(solver, scale, deadline),
                     task, pair)  # fmt: skip
    finally:
        disarm(armed)
    code, t_end, n_out = res.code, res.t_end, res.n_samples
    if end is not None:
        y_end = task[0].copy()
        for part in (0, 2 * n):
            pairs = to_ground(np.stack([y_end[part : part + n], y_end[part + n : part + 2 * n]],
                                       1), angle)  # fmt: skip
            y_end[part : part + n], y_end[part + n : part + 2 * n] = pairs[:, 0], pairs[:, 1]
        end.append(y_end)
    demand, first = held_result(held, res.friction, res.slip)
    out = Outcome(
        t_end=float(t_end), max_ratio=res.max_ratio, max_top=float(res.max_top),
        friction=demand, friction_peak=res.friction, n_uplifts=int(res.n_uplifts),
        n_impacts=int(res.n_impacts), n_steps=int(res.n_steps), n_rhs=int(res.n_rhs),
        n_events=int(res.n_events), slip=first, azimuth=float(res.azimuth) + angle,
        turns=float(res.swept.max()) / (2.0 * math.pi),
    )  # fmt: skip
    if record:
        rows = samples[:n_out]
        out.samples = [(float(r[0]), r[1 : 1 + n].copy(), r[1 + n : 1 + 2 * n].copy())
                       for r in rows]  # fmt: skip
        out.top_plan = to_ground(rows[:, 1 + 2 * n : 3 + 2 * n].copy(), angle)
        out.across = rows[:, 3 + 2 * n :].copy()
        if motion.vertical is None:
            out.energy = EnergyAccount(*(float(v) for v in res.ledger))
    if code == COLLAPSED:
        out.collapse(float(res.t_collapse), int(res.collapsed) + 1)
    elif code == AT_REST:
        out.message = "at rest in free motion: stopped"
    elif code == STOPPED_EARLY:
        out.stopped_early()
    elif code == FAILED_STEP:
        out.stop("failed", "integrator: Required step size is less than spacing between "
                 "numbers.", t_end)  # fmt: skip
    elif code == FAILED_NONFINITE:
        out.stop("failed", "the state became NaN or infinite (non-finite arithmetic)", t_end)
    else:
        end_by_budget(out, code, solver)
    return out


def needs_compile() -> bool | None:
    """Whether the run in two directions has no usable on-disk cache (its first use then
    compiles it; base.compile_cache.cache_empty)."""
    return cache_empty(run3d)


def warm_up() -> None:
    """Compile (or load from the cache) the run in two directions once."""
    geometry = ColumnConfig(height=2.0, base_width=0.5, top_width=0.5, drum_heights=(2.0,),
                            section="circular")  # fmt: skip
    model = build_model(build_column(geometry, InterfaceConfig()))
    motion = GroundMotion("harmonic", 5.0, 6.0, 0.0, 0.1, 0.1)
    integrate3d(model, motion, np.zeros(1), np.zeros(1), SolverConfig())


class Rbm3dRunner(RbmRunner):
    """`rbm-3d` (rbm_cli.models.contract.Runner): the config's column of circular drums in
    the Rigid Beam Model, in two horizontal directions."""

    def integrator_of(self, method):
        """The integrator of every method that runs `rbm-3d` (a step pair): this module's,
        from the config's initial state in the motion's plane and across it."""
        prepared = prepare_kernel(self.model)
        init, n = self.config.excitation.initial, self.model.n
        across = None
        if init.rotations_across or init.velocities_across:
            across = tuple(np.asarray(v, float) if v else np.zeros(n)
                           for v in (init.rotations_across, init.velocities_across))  # fmt: skip

        def run(model, motion, theta0, rate0, solver, **options):
            return integrate3d(model, motion, theta0, rate0, solver, prepared=prepared,
                               across=across, **options)  # fmt: skip

        return run

    def run(self, motion: GroundMotion, solver: SolverConfig, **options) -> Outcome:
        """One run (rbm_cli.models.contract.Runner.run); a recorded history carries the
        top's path in plan."""
        return super().run(motion, solver, **options).carry_plan()


__all__ = ["Rbm3dRunner", "integrate3d", "needs_compile", "run3d", "warm_up"]
