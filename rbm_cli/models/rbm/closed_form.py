"""The rigid block in closed form, compiled: `solver.method: closed-form` of the RBM on a
rigid monolithic column (what `auto`, the default, resolves to there) and the compiled
implementation of `housner-linear`. Nothing is integrated: each piece of motion between
two events is the exact solution of theta'' = p^2 (theta - s alpha) + e a_g(t)
(closed_form_jit), the events are roots of it, bracketed so that none is missed.

The rigid RBM monolith (one drum, a rigid joint, xi = 1: one law piece a side) is that
equation with the coefficients of its own linear system (Model.linear_system): alpha =
theta_u = B_1 / H and p^2 = m g (H/2) / I_0 (physics.closed_forms.linear_rocking_parameters)
and e = -m (H/2) / I_0; its uplift level, rest rate, collapse limit, early-stop barrier and
friction demand are the model's (as the step kernel reads them). `housner-linear` is the
same equation with e = -p^2 / g for the true block (Spanos and Koh 1984).

Nothing here compiles until a run calls it (numba compiles on first call, then loads from
its cache; base/compile_cache keys that cache on these modules' sources).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from rbm_cli.base.compile_cache import cache_empty
from rbm_cli.base.errors import RbmError
from rbm_cli.config.types import CLOSED_FORM_KINDS, G
from rbm_cli.models.events import EVENT_EPS, REST_RATE
from rbm_cli.models.outcome import Outcome, sample_buffer, sample_rows
from rbm_cli.models.rbm import run_codes as cr
from rbm_cli.models.rbm.closed_form_jit_run import run_block
from rbm_cli.models.rbm.exact.modal import FORCING_SIZE, HARMONIC
from rbm_cli.models.rbm.forcing_arrays import record_arrays, run_settings
from rbm_cli.models.rbm.kernel_guard import arm, disarm
from rbm_cli.physics.equations import Model
from rbm_cli.physics.excitation import GroundMotion


class Block(NamedTuple):
    """A block's constants for the compiled run (closed_form_jit's block array) and how
    its outcome is reported."""

    params: np.ndarray  # closed_form_jit.BLOCK_SIZE floats
    ratio_scale: float  # peak ratio = |theta| / ratio_scale [rad]
    height: float  # top displacement = height |theta| [m]
    rbm: bool  # the RBM's outcome messages (else housner-linear's)


def _params(p, alpha, e, limit, restitution, rest_rate, uplift, barrier, eps, fa, fb, at_zero):
    return np.array([p, alpha, e, limit, restitution, rest_rate, uplift, barrier, eps, fa,
                     fb, at_zero], dtype=float)  # fmt: skip


def why_not(model: Model) -> str | None:
    """Why the closed form does not take this RBM model, or None if it does."""
    if model.n != 1 or not model.laws[0].rigid:
        return "it takes a rigid monolithic column only (one drum, interface.stiffness rigid)"
    if len(model.laws[0].edges) != 0:
        return "it takes one law piece a side only (interface.xi 1)"
    if model.formulation == "absolute":
        return "it takes interface.formulation relative or geometric"
    return None


def rbm_block(model: Model) -> Block:
    """The Block of a rigid RBM monolith (RbmError in one line if it is not one)."""
    reason = why_not(model)
    if reason is not None:
        raise RbmError(f"solver.method closed-form: {reason}; use DOP853 (or auto)")
    law, col = model.laws[0], model.column
    a, c, e = model.linear_system(np.array([law.intercepts[0]]), np.array([law.slopes[0]]))
    p2, e = float(a[0, 0]), float(e[0])
    if not p2 > 0.0:
        raise RbmError("solver.method closed-form: the block's law piece is not descending")
    alpha = -float(c[0]) / p2
    scale = float(model.collapse_limit[0]) / abs(float(model.collapse_map[0, 0]))
    tu = float(col.rotation_capacity[0])
    c_ratio = float(model.collapse_ratio)
    barrier = float(model.energy(np.array([c_ratio * tu]), np.zeros(1))[0]) / model.mass[0, 0]
    centre, mass = float(model.centre_map[0, 0]), float(col.masses[0])
    ratio = mass / float(col.normal_forces[0])
    params = _params(
        math.sqrt(p2), alpha, e, c_ratio * scale, model.restitution,
        REST_RATE * model.rocking_p * tu, float(model.uplift_level), barrier,
        EVENT_EPS * tu, ratio * (1.0 + centre * e), ratio * centre * p2, 0.0,
    )  # fmt: skip
    return Block(params, scale, float(col.heights[0]), True)


def linear_block(alpha, p, restitution=1.0, collapse_ratio=1.0, height=None) -> Block:
    """The Block of Spanos and Koh's linear block (housner_linear.housner_linear_run's
    arguments: alpha [rad], p [rad/s], e [-], c [-], H [m] or None)."""
    limit = collapse_ratio * alpha
    lim_e = min(limit, alpha)
    barrier = p * p * (alpha * lim_e - 0.5 * lim_e * lim_e)
    params = _params(p, alpha, -p * p / G, limit, restitution, REST_RATE * p * alpha,
                     G * alpha, barrier, EVENT_EPS * alpha, math.nan, math.nan, 1.0)  # fmt: skip
    return Block(params, alpha, float(height) if height else 0.0, False)


def block_segments(motion: GroundMotion) -> tuple[np.ndarray, np.ndarray]:
    """(seg_t, seg_fc) of a motion (forcing_arrays; a sine's segments as
    exact_motion.forcing_segments makes them, without its objects); RbmError in one line
    for a motion without a closed form here (a Ricker or Mavroeidis-Papageorgiou pulse, a
    vertical record)."""
    if motion.kind not in CLOSED_FORM_KINDS:
        raise RbmError(f"solver.method closed-form does not take excitation.type {motion.kind}"
                       " (no closed form): use DOP853 (or auto)")  # fmt: skip
    if motion.has_vertical:
        raise RbmError("solver.method closed-form does not take excitation.vertical: use"
                       " DOP853 (or auto)")  # fmt: skip
    if motion.kind == "record":
        return record_arrays(motion)
    segments = motion.segments()
    seg_t = np.array(segments, dtype=float).reshape(-1, 2)
    seg_fc = np.zeros((len(segments), FORCING_SIZE))
    for i, (start, _) in enumerate(segments):
        if motion.forced(start):
            seg_fc[i, :4] = HARMONIC, motion.amplitude, motion.omega, motion.phase
    return seg_t, seg_fc


def _messages(block: Block, code: int, out: Outcome, solver) -> None:
    """Status and message of the outcome from the run's code (the runner's wording)."""
    t = out.t_end
    if code == cr.COLLAPSED:
        out.collapse(out.t_collapse, 1)
        if not block.rbm:
            out.message = "the block reached its collapse limit"
    elif code == cr.STOPPED_EARLY:
        out.stopped_early()
    elif code == cr.AT_REST_END and not block.rbm:
        out.message = "at rest in free motion: stopped"
    else:
        cr.end_by_budget(out, code, solver)
    if out.status != "failed" and not math.isfinite(out.max_top):
        out.stop("failed", "numerical failure: non-finite state", t)


def run_closed_form(
    block: Block,
    motion: GroundMotion,
    theta0: float,
    rate0: float,
    solver,
    record: bool = False,
    output_dt: float = 0.002,
    early_stop: bool = True,
    seg: tuple | None = None,
) -> Outcome:
    """One run of a block (Block) from (theta0 [rad], rate0 [rad/s]).

    seg : (seg_t, seg_fc), optional  The motion's forcing segments
        (forcing_arrays.motion_arrays); made here from the motion when None.
    solver : SolverConfig  Its budgets (max_steps counts pieces, max_events events,
        max_wall_time [s]); its tolerances do not apply.
    Returns the Outcome: n_steps counts pieces, n_rhs closed-form evaluations; samples
    (t, [theta], [rate]) every output_dt [s] when record.
    """
    seg_t, seg_fc = seg if seg is not None else block_segments(motion)
    mo, se = run_settings(motion, solver, early_stop, record, output_dt)
    samples = sample_buffer(motion.t_end, output_dt, record, 1)
    armed = arm()  # Ctrl-C reaches the run through poll (kernel_guard)
    try:
        code, st, cnt = run_block(block.params, seg_t, seg_fc, mo, se, float(theta0),
                                  float(rate0), samples)  # fmt: skip
    finally:
        disarm(armed)
    out = Outcome(t_end=float(st[0]), t_collapse=float(st[9]), max_top=block.height * st[5])
    out.max_ratio = np.array([st[5] / block.ratio_scale])
    out.friction = np.array([st[6] if block.rbm else math.nan])
    out.n_uplifts, out.n_impacts, out.n_steps, out.n_rhs = (int(x) for x in cnt[:4])
    out.n_events = int(cnt[4]) if block.rbm else out.n_uplifts + out.n_impacts
    _messages(block, code, out, solver)
    if record:
        out.samples = sample_rows(samples, int(st[8]), 1)
    return out


def integrate_closed_form(
    model: Model,
    motion: GroundMotion,
    theta0: np.ndarray,
    rate0: np.ndarray,
    solver,
    record: bool = False,
    output_dt: float = 0.002,
    early_stop: bool = True,
    block: Block | None = None,
) -> Outcome:
    """The RBM integrators' signature (rbm.python.integrate) for a rigid monolith:
    block is rbm_block(model), made once by a caller that runs one model many times."""
    block = rbm_block(model) if block is None else block
    return run_closed_form(block, motion, float(theta0[0]), float(rate0[0]), solver,
                           record=record, output_dt=output_dt, early_stop=early_stop)  # fmt: skip


def needs_compile() -> bool | None:
    """Whether the closed form has no usable on-disk cache (compile_cache.cache_empty): its
    first use then compiles it (6-10 s)."""
    return cache_empty(run_block)


def warm_up() -> None:
    """Compile (or load from the cache) the closed form once, e.g. in a worker: a run
    under a harmonic and one under a record (their forcings take other branches)."""
    from rbm_cli.config.types import SolverConfig

    block = linear_block(0.25, 2.0)
    knots = np.array([0.0, 0.05, 0.1])
    record = GroundMotion("record", 5.0, 0.0, 0.0, 0.1, 0.2, gain=1.0, knots=knots,
                          values=np.array([0.0, 5.0, -5.0]))  # fmt: skip
    for motion in (GroundMotion("harmonic", 5.0, 6.0, 0.0, 0.1, 0.1), record):
        run_closed_form(block, motion, 0.0, 0.0, SolverConfig(), record=True)
