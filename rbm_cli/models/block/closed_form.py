"""The rigid block in closed form: `solver.method: closed-form` of the RBM on a rigid
monolithic column (what `auto`, the default, resolves to there) and `housner-linear`.
Nothing is integrated: each piece of motion between two events is the exact solution of
theta'' = p^2 gam (theta - s alpha) + e a_g(t) (block.piece; gam = (g + a_v) / g per
piece under a vertical record, else 1), the events are roots of it, bracketed so that
none is missed. The run loop (block.run) runs compiled, or uncompiled as written
(rbm_cli.base.jit.plain) with `solver.implementation: python`.

The rigid RBM monolith (one drum, a rigid joint, xi = 1: one law piece a side) is that
equation with the coefficients of its own linear system (Model.linear_system): alpha =
theta_u = B_1 / H and p^2 = m g (H/2) / I_0 (structures.closed_forms.linear_rocking_parameters)
and e = -m (H/2) / I_0; its uplift level, rest rate, collapse limit, early-stop barrier and
friction demand are the model's (as the step kernel reads them). `housner-linear` is the
same equation with e = -p^2 / g for the true block (Spanos and Koh 1984), and linear_run
runs it as a function of (alpha, p).

References
----------
.. [1] G. W. Housner (1963). The behavior of inverted pendulum structures
   during earthquakes. Bulletin of the Seismological Society of America
   53(2), 403-417.
.. [2] P. D. Spanos and A.-S. Koh (1984). Rocking of rigid blocks due to
   harmonic shaking. Journal of Engineering Mechanics 110(11), 1627-1642.

Nothing here compiles until a run calls it (numba compiles on first call, then loads from
its cache; base/compile_cache keys that cache on these modules' sources).
"""

from __future__ import annotations

import math
from functools import partial
from typing import NamedTuple

import numpy as np

from rbm_cli.base.compile_cache import cache_empty
from rbm_cli.base.errors import RbmError
from rbm_cli.base.events import EVENT_EPS
from rbm_cli.base.guard import arm, disarm
from rbm_cli.base.jit import plain
from rbm_cli.config.types import CLOSED_FORM_KINDS, G, SolverConfig
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.models import status as cr
from rbm_cli.models.block.piece import B_FA2
from rbm_cli.models.block.run import (
    FRICTION2,
    LOG_COLLAPSE,
    LOG_IMPACT,
    LOG_REST,
    LOG_UPLIFT,
    N_LOG,
    SLIP_IF,
    T_SLIP,
    run_block,
)
from rbm_cli.models.methods import model_why_not
from rbm_cli.models.outcome import Outcome, sample_buffer, sample_rows
from rbm_cli.models.rbm.exact.modal import LINEAR
from rbm_cli.models.rbm.forcing_arrays import record_arrays, run_settings, sine_arrays
from rbm_cli.models.rbm.pieces import FRICTION_DURATION, held_array, held_result
from rbm_cli.structures.arrays import REST_RATE, rest_levels
from rbm_cli.structures.equations import Model, body_masses


class Block(NamedTuple):
    """A block's constants for the run (block.piece's block array) and how its outcome is
    reported."""

    params: np.ndarray  # block.piece.BLOCK_SIZE floats
    ratio_scale: float  # peak ratio = |theta| / ratio_scale [rad]
    height: float  # top displacement = height |theta| [m]
    rbm: bool  # the RBM's outcome messages (else housner-linear's)


def _params(p, alpha, e, limit, restitution, rest_rate, uplift, barrier, eps, fa, fb, at_zero,
            fa2=math.nan, fb2=math.nan):  # fmt: skip
    return np.array([p, alpha, e, limit, restitution, rest_rate, uplift, barrier, eps, fa,
                     fb, at_zero, fa2, fb2], dtype=float)  # fmt: skip


def rbm_block(model: Model) -> Block:
    """The Block of a rigid RBM monolith (RbmError in one line if it is not one).

    Its friction demand T / N [-]: the ground joint carries the shear T = m (a_g + c
    theta'') of the drum's centre, c = centre_map[0, 0] [m] (its horizontal acceleration
    over theta'', H/2 for the RBM's small rotations), against the normal force at rest
    N = m g (normal_forces[0]); under a frame's beam, of the drum and the beam's share
    (m their masses' sum, c their centre: sum m_b c_b / m). On a piece
    theta'' = p^2 (theta - s alpha) + e a_g, so
    T / N = (1 + c e) a_g / g + (c p^2 / g)(theta - s alpha) = fa a_g + fb (theta - s
    alpha) with fa = (m / N)(1 + c e) [s^2/m] and fb = (m / N) c p^2 [1/rad] (block.piece's
    demand, linear in a_g and theta: exact on every piece). At rest theta'' = 0 and
    T / N = a_g / g (block.run._rest_friction), up to the uplift level alpha; at uplift
    theta'' starts from 0 (p^2 s alpha = e a_g there), so the two meet. A monolithic frame's
    beam joint (Model.friction_normals' last) carries the beam share's shear
    T_b = m_b (a_g + c_b theta''), c_b = H its top node's lever, on N_b = m_b g: the same form
    with m_b and c_b, fa2 = (m_b / N_b)(1 + c_b e) and fb2 = (m_b / N_b) c_b p^2.
    """
    reason = model_why_not(model)
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
    uplift, rest_rate, barrier = rest_levels(model)
    centre, mass = float(model.centre_map[0, 0]), float(col.masses[0])
    fa2 = fb2 = math.nan
    if model.centre_map.shape[0] > 1:  # a frame's beam share on the top node too
        bodies = body_masses(col)
        mass = float(bodies.sum())
        centre = float(bodies @ model.centre_map[:, 0]) / mass
        lever, share = float(model.centre_map[-1, 0]), bodies[-1] / model.friction_normals[-1]
        fa2, fb2 = share * (1.0 + lever * e), share * lever * p2
    ratio = mass / float(col.normal_forces[0])
    params = _params(
        math.sqrt(p2), alpha, e, c_ratio * scale, model.restitution,
        rest_rate, float(uplift), barrier / model.mass[0, 0],
        EVENT_EPS * tu, ratio * (1.0 + centre * e), ratio * centre * p2, 0.0, fa2, fb2,
    )  # fmt: skip
    return Block(params, scale, float(col.heights[0]), True)


def linear_block(alpha, p, restitution=1.0, collapse_ratio=1.0, height=None) -> Block:
    """The Block of Spanos and Koh's linear block (linear_run's arguments: alpha [rad],
    p [rad/s], e [-], c [-], H [m] or None)."""
    limit = collapse_ratio * alpha
    lim_e = min(limit, alpha)
    barrier = p * p * (alpha * lim_e - 0.5 * lim_e * lim_e)
    params = _params(p, alpha, -p * p / G, limit, restitution, REST_RATE * p * alpha,
                     G * alpha, barrier, EVENT_EPS * alpha, math.nan, math.nan, 1.0)  # fmt: skip
    return Block(params, alpha, float(height) if height else 0.0, False)


def vertical_lines(motion: GroundMotion, seg_fc: np.ndarray) -> np.ndarray:
    """seg_v of a record's segments (block.run): the upward acceleration a_v at each linear
    forcing's t0 [m/s^2] and its slope to the next sample [m/s^3]; no rows without a
    vertical record."""
    if not motion.has_vertical:
        return np.zeros((0, 2))
    knots, vertical = np.asarray(motion.knots, float), np.asarray(motion.vertical, float)
    seg_v = np.zeros((seg_fc.shape[0], 2))
    rows = np.nonzero(seg_fc[:, 0] == LINEAR)[0]
    k = np.searchsorted(knots, seg_fc[rows, 4], side="right") - 1  # the sample at t0
    seg_v[rows, 0] = vertical[k]
    seg_v[rows, 1] = (vertical[k + 1] - vertical[k]) / (knots[k + 1] - knots[k])
    return seg_v


def block_segments(
    motion: GroundMotion, vertical: bool = False
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(seg_t, seg_fc, seg_v) of a motion (forcing_arrays: record_arrays or sine_arrays;
    seg_v: vertical_lines); RbmError in one line for a motion without a closed form here
    (a Ricker or Mavroeidis-Papageorgiou pulse; a vertical record unless vertical)."""
    if motion.kind not in CLOSED_FORM_KINDS:
        raise RbmError(f"solver.method closed-form does not take excitation.type {motion.kind}"
                       " (no closed form): use DOP853 (or auto)")  # fmt: skip
    if motion.has_vertical and not vertical:
        raise RbmError("solver.method closed-form does not take excitation.vertical: use"
                       " DOP853 (or auto)")  # fmt: skip
    if motion.kind == "record":
        seg_t, seg_fc = record_arrays(motion)
        return seg_t, seg_fc, vertical_lines(motion, seg_fc)
    seg_t, seg_fc = sine_arrays(motion)
    return seg_t, seg_fc, np.zeros((0, 2))


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
    events: list | None = None,
    friction_limit: float = math.inf,
    friction_duration: float = FRICTION_DURATION,
) -> Outcome:
    """One run of a block (Block) from (theta0 [rad], rate0 [rad/s]).

    friction_limit : float  A friction coefficient [-]: the outcome says where the RBM
        block's |T / N| first exceeded it (Outcome.slip; exact for the peak); inf: none.
    friction_duration : float  The duration the RBM block's friction demand is held for
        [s] (Outcome.friction; its peak, exact: Outcome.friction_peak); 0: the peak.

    seg : (seg_t, seg_fc, seg_v), optional  The motion's forcing segments
        (block_segments); made here from the motion when None (a vertical record taken
        for a housner-linear block only).
    solver : SolverConfig  Its budgets (max_steps counts pieces, max_events events,
        max_wall_time [s]) and implementation (`python`: the run loop uncompiled); its
        tolerances do not apply.
    events : list, optional  Gets (t [s], kind) for every 'uplift', 'impact', 'rest' and
        'collapse', in order.
    Returns the Outcome: n_steps counts pieces, n_rhs closed-form evaluations; samples
    (t, [theta], [rate]) every output_dt [s] when record.
    """
    seg_t, seg_fc, seg_v = seg if seg is not None else block_segments(motion, not block.rbm)
    solver = solver.for_run(motion.t_end, 1)
    mo, se = run_settings(motion, solver, early_stop, record, output_dt, friction_limit)
    samples = sample_buffer(motion.t_end, output_dt, record, 1)
    run = run_block if solver.implementation == "compiled" else plain(run_block)
    rows = 0 if events is None else LOG_ROWS
    joints = 1 if math.isnan(block.params[B_FA2]) else 2  # a monolithic frame's beam joint
    while True:
        log = np.zeros((rows, 2))
        held = held_array(joints, float(friction_duration) if block.rbm else 0.0,
                          float(friction_limit))  # fmt: skip
        armed = arm()  # Ctrl-C reaches the run through poll (rbm_cli.base.guard)
        try:
            code, st, cnt = run(block.params, seg_t, seg_fc, seg_v, mo, se, float(theta0),
                                float(rate0), samples, log, held)  # fmt: skip
        finally:
            disarm(armed)
        if int(st[N_LOG]) < rows or events is None:
            break
        rows *= 16  # the log was full: the run again with room for its events
    if events is not None:
        events.extend((float(t), _LOG_KINDS[int(k)]) for t, k in log[: int(st[N_LOG])])
    out = Outcome(t_end=float(st[0]), t_collapse=float(st[9]), max_top=block.height * st[5])
    out.max_ratio = np.array([st[5] / block.ratio_scale])
    out.friction_peak = np.array([st[6] if block.rbm else math.nan, st[FRICTION2]][:joints])
    if block.rbm:
        slip = (st[T_SLIP], 0.0 if math.isnan(st[T_SLIP]) else st[SLIP_IF])
        out.friction, out.slip = held_result(held, out.friction_peak, slip)
    else:
        out.friction = out.friction_peak.copy()
    out.n_uplifts, out.n_impacts, out.n_steps, out.n_rhs = (int(x) for x in cnt[:4])
    out.n_events = int(cnt[4]) if block.rbm else out.n_uplifts + out.n_impacts
    _messages(block, code, out, solver)
    if record:
        out.samples = sample_rows(samples, int(st[8]), 1)
    return out


#: The event log's kinds (block.run.LOG_*) by name.
_LOG_KINDS = {LOG_UPLIFT: "uplift", LOG_IMPACT: "impact", LOG_REST: "rest",
              LOG_COLLAPSE: "collapse"}  # fmt: skip


#: Rows of an event log a run is given first (a run that fills it runs again with more).
LOG_ROWS = 1024


def linear_run(
    alpha: float,
    p: float,
    motion: GroundMotion,
    restitution: float = 1.0,
    collapse_ratio: float = 1.0,
    record: bool = False,
    output_dt: float = 0.002,
    *,
    height: float | None = None,
    initial: tuple[float, float] = (0.0, 0.0),
    early_stop: bool = True,
    solver: SolverConfig | None = None,
    events: list | None = None,
) -> Outcome:
    """One run of Spanos and Koh's piecewise-linear rocking block, in closed form.

    Parameters
    ----------
    alpha : float  Slenderness, also the uplift level in g [rad]
    p : float  Frequency parameter [rad/s]
    motion : GroundMotion  a_g(t) [m/s^2] (a pulse without a closed form is sampled
        first, GroundMotion.sampled), a_v(t) of a vertical record, the simulated time [s]
    restitution : float  Angular-velocity ratio e at impacts, in (0, 1] [-]
    collapse_ratio : float  Collapse at |theta| >= collapse_ratio * alpha [-]
    record : bool  Keep samples (t [s], [theta] [rad], [rate] [rad/s]) every output_dt [s]
    output_dt : float  Sampling interval of the history [s]
    height : float or None  Block height H [m] for the top displacement H |theta| [m];
        None reports 0
    initial : (float, float)  Initial rotation [rad] and rate [rad/s]
    early_stop : bool  After a pulse or a record, stop at rest, or at a peak when the
        energy is below the collapse barrier (no later peak is larger)
    solver : SolverConfig or None  Budgets (max_steps counts pieces) and implementation;
        the defaults when None
    events : list or None  If a list, (t [s], kind) is appended for every 'uplift',
        'impact', 'rest' and 'collapse'

    Returns
    -------
    Outcome  status 'collapsed', 'survived' or 'failed' (a budget); n_steps counts
        closed-form pieces, n_rhs closed-form evaluations.

    Notes
    -----
    On side s = sgn(theta), theta'' = p^2 (theta - s alpha) - p^2 a_g(t) / g, with
    a_g / g = A sin(omega t + phi):

    .. math:: \\theta = s\\alpha + C \\sin(\\omega t + \\phi) + c_1 e^{p\\tau}
              + c_2 e^{-p\\tau}, \\quad C = p^2 A / (p^2 + \\omega^2)

    (C = 0 in free motion; a straight line between two samples of a record). The block
    rests until |a_g| > g alpha and lifts on the side turning away from a_g. At theta = 0
    the rate is multiplied by e; a post-impact rate below REST_RATE p alpha puts the block
    to rest. Energy per unit inertia, E = theta'^2/2 + p^2 (alpha |theta| - theta^2/2),
    is conserved in free motion between impacts; its barrier is E at
    |theta| = min(c, 1) alpha.
    """
    if not (alpha > 0.0 and p > 0.0):
        raise ValueError("alpha [rad] and p [rad/s] must be > 0")
    if not 0.0 < restitution <= 1.0:
        raise ValueError("restitution must be in (0, 1]")
    block = linear_block(alpha, p, restitution, collapse_ratio, height)
    return run_closed_form(block, motion.sampled(), float(initial[0]), float(initial[1]),
                           SolverConfig() if solver is None else solver, record=record,
                           output_dt=output_dt, early_stop=early_stop,
                           events=events)  # fmt: skip


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
    friction_limit: float = math.inf,
    friction_duration: float = FRICTION_DURATION,
) -> Outcome:
    """The RBM integrators' signature (rbm.kernel.integrate) for a rigid monolith:
    block is rbm_block(model), made once by a caller that runs one model many times."""
    block = rbm_block(model) if block is None else block
    return run_closed_form(block, motion, float(theta0[0]), float(rate0[0]), solver,
                           record=record, output_dt=output_dt, early_stop=early_stop,
                           friction_limit=friction_limit,
                           friction_duration=friction_duration)  # fmt: skip


def prepare(model: Model):
    """The closed form of one rigid RBM monolith (rbm_cli.models.methods.Integrator): its
    Block made once, for every run of the column (RbmError in one line if it is not one)."""
    return partial(integrate_closed_form, block=rbm_block(model))


def needs_compile() -> bool | None:
    """Whether the closed form has no usable on-disk cache (compile_cache.cache_empty): its
    first use then compiles it (6-10 s)."""
    return cache_empty(run_block)


def warm_up() -> None:
    """Compile (or load from the cache) the closed form once, e.g. in a worker: a run
    under a harmonic and one under a record (their forcings take other branches)."""
    block = linear_block(0.25, 2.0)
    knots = np.array([0.0, 0.05, 0.1])
    record = GroundMotion("record", 5.0, 0.0, 0.0, 0.1, 0.2, gain=1.0, knots=knots,
                          values=np.array([0.0, 5.0, -5.0]))  # fmt: skip
    for motion in (GroundMotion("harmonic", 5.0, 6.0, 0.0, 0.1, 0.1), record):
        run_closed_form(block, motion, 0.0, 0.0, SolverConfig(), record=True)
