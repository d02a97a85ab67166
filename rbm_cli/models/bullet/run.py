"""`model: bullet`: the column as stacked rigid drums in Bullet's contact dynamics.

The drums are rigid solids of their true shape (:mod:`rbm_cli.models.bullet.geometry`)
stacked on a rigid ground plane, in contact with dry Coulomb friction
(``interface.friction``), so they may rock, slide, bounce and fall with large
displacements: an open stand-in for the paper's discrete element model (UDEC).
The engine is PyBullet (Bullet Physics), driven without a GUI.

The scene is the ground's own frame. The ground motion enters exactly as the
inertial force it produces there: the gravity vector is set to
(-a_g(t), 0, -g) at every step, so there is no drift of the ground.

Engine settings (fixed, see :class:`EngineSettings`): time step 1e-4 s (the
config's ``solver.time_step``), 100 solver iterations, restitution 0 with a
restitution velocity threshold of 0 (impacts are perfectly plastic at the
contact points; the loss of angular velocity at an impact comes out of the
contact dynamics, measured by :func:`measure_restitution`), no linear or
angular damping (PyBullet's defaults are not 0), collision margin 0, split
impulse on, erp 0.2.

Collapse: the run stops when, at a joint (or the base), the centre of mass of
the drums above it passes over the pivot edge of the contact, i.e. when the
line from the pivot to that centre of mass turns by ``collapse.ratio`` times
its rest angle alpha_i (the stack's overturning angle). For one drum rocking
on a corner this is Housner's |theta| = alpha, the rule of `housner`. It also
stops when a drum's centre of mass drops by half the drum's height (a drum
slid off its support).

References
----------
.. [1] E. Coumans and Y. Bai (2016-2021). PyBullet, a Python module for physics
   simulation for games, robotics and machine learning. http://pybullet.org
"""

from __future__ import annotations

import dataclasses

import numpy as np

from rbm_cli.base.errors import RbmError
from rbm_cli.config.types import Config, G, SolverConfig
from rbm_cli.models.bullet.geometry import drum_solids, stack_slenderness
from rbm_cli.models.bullet.impact import impact_rate_ratios, measure_restitution
from rbm_cli.models.bullet.scene import (
    EngineSettings,
    Frame,
    Joints,
    StackGeometry,
    build_scene,
    joint_friction,
    joint_state,
    keep_in_plane,
    read_frame,
)
from rbm_cli.models.contract import DEFAULT_OUTPUT_DT
from rbm_cli.models.outcome import Outcome
from rbm_cli.models.result import History
from rbm_cli.physics.excitation import GroundMotion

__all__ = [
    "EngineSettings",
    "bullet_run",
    "engine_uplift_g",
    "impact_rate_ratios",
    "measure_restitution",
    "settings_from_config",
    "uplift_level",
]

#: Interval of the collapse, sliding and contact checks [s].
CHECK_DT = 1e-3
#: Interval over which a joint's mean force gives its friction demand [s]: long
#: enough to average out the contact's step-to-step chatter (measured: +-10 % of
#: a_g / g on a block at rest over 1 ms, docs/engine.md), short against rocking.
FRICTION_DT = 1e-2
#: A joint is open when its relative rotation exceeds this fraction of alpha_i.
OPEN_FRACTION = 1e-3
#: Drop of a drum's centre of mass, as a fraction of its height, that is collapse.
DROP_FRACTION = 0.5
#: Half-sine/free early stop: every rate below this [rad/s] and every joint
#: closed for REST_TIME [s] after the pulse.
REST_ANGULAR_RATE = 1e-4
REST_TIME = 0.2
#: A drum faster than this [m/s or rad/s] means the engine blew up.
BLOWUP = 1e3


#: Bullet caps a contact's friction coefficient at this (btManifoldResult's MAX_FRICTION).
MAX_FRICTION = 10.0


def settings_from_config(config: Config) -> EngineSettings:
    friction = config.interface.friction
    if friction > MAX_FRICTION:
        raise RbmError(
            f"interface.friction must be <= {MAX_FRICTION:g} for model bullet (the engine caps"
            f" a contact's friction there), got {friction:g}"
        )
    return EngineSettings(time_step=config.solver.time_step, friction=friction)


# ------------------------------------------------------------------------- run


def uplift_level(solids, friction: float) -> float:
    """Horizontal ground acceleration [m/s^2] below which the rigid stack cannot
    move: min(tan alpha_i, friction) g (statics of the stacks above each joint)."""
    return G * min(float(np.min(np.tan(stack_slenderness(solids)))), friction)


def engine_uplift_g(config: Config) -> float:
    """The engine's uplift level of a configured column [g] (uplift_level of its true solids)."""
    return uplift_level(drum_solids(config.column), config.interface.friction) / G


def bullet_run(
    config: Config,
    motion: GroundMotion,
    *,
    record: bool = False,
    output_dt: float = 0.002,
    early_stop: bool = True,
    settings: EngineSettings | None = None,
) -> tuple[Outcome, History | None]:
    """One run of the drum stack in the contact engine.

    Parameters
    ----------
    config : Config  Column geometry, interface.friction, collapse.ratio,
        solver.time_step, excitation.initial (a rigid stack only: one rotation
        [rad] and rate [rad/s] shared by every drum)
    motion : GroundMotion  a_g(t) [m/s^2], simulated time [s]
    record : bool  Keep a history sampled every output_dt [s]
    early_stop : bool  After a half-sine pulse (or in free motion), stop once
        the stack has been at rest for REST_TIME
    settings : EngineSettings  Override the config's engine settings (tests)

    Returns
    -------
    (Outcome, History or None)  Outcome as the RBM integrator fills it: status,
        t_collapse, collapse_interface (1-based joint, 1 = base on ground),
        max_ratio (per joint), max_top (top relative to the base [m]),
        n_uplifts / n_impacts (joint openings / closures seen at the 1 ms
        checks), n_steps = n_rhs = engine steps; friction (per joint) the
        largest mobilised friction |T| / N of the joint's mean force over each
        FRICTION_DT interval (:func:`rbm_cli.models.bullet.scene.joint_friction`; nan
        if never loaded);
        the message gives the largest slips.
    """
    solids = drum_solids(config.column)
    n = len(solids)
    settings = settings or settings_from_config(config)
    tilt, rate = _initial(config)
    alpha = stack_slenderness(solids)
    out = Outcome()
    out.max_ratio = np.zeros(n)
    limit = config.collapse.ratio
    level = uplift_level(solids, settings.friction)
    if not record and tilt == 0.0 and rate == 0.0 and motion.amplitude < level * (1 - 1e-9):
        # the stack moves with the ground: every joint carries m_above a_g on m_above g
        out.friction = np.full(n, motion.amplitude / G)
        out.message = "at rest: ground acceleration below the uplift and sliding levels"
        return out.stop("survived", out.message, motion.t_end), None

    p, cid, bodies = build_scene(solids, settings, tilt, rate)
    stack = StackGeometry.of(solids)
    dt = settings.time_step
    n_steps = int(round(motion.t_end / dt))
    check = max(1, int(round(CHECK_DT / dt)))
    sample = max(1, int(round(output_dt / dt))) if record else 0
    rest_z = np.array([d.bottom + d.centre for d in solids])
    drop = np.array([DROP_FRACTION * d.height for d in solids])
    open_tol = OPEN_FRACTION * alpha
    max_slip = np.zeros(n)
    out.friction = np.full(n, np.nan)
    was_open = np.zeros(n, bool)
    last_sign = np.zeros(n)
    prev_ratio, prev_t, quiet_since = 0.0, 0.0, None
    samples: list = []
    set_gravity, step = p.setGravity, p.stepSimulation
    # a_g at every mid-step, at once (the same numbers as one call per step)
    accel_array = np.asarray(motion.accel((np.arange(n_steps) + 0.5) * dt), dtype=float)
    accel = accel_array.tolist()
    accel_sum = np.concatenate([[0.0], np.cumsum(accel_array)])  # for the mean over a check

    frame = read_frame(p, cid, bodies)
    joints = joint_state(frame, stack, alpha)
    if record:
        samples.append(_sample(0.0, frame, joints))
    k = k_prev = 0
    frame_prev = frame
    tilt_lo = tilt_hi = frame.tilts
    friction_steps = max(1, int(round(FRICTION_DT / dt)))
    while k < n_steps:
        set_gravity(-accel[k], 0.0, -G, physicsClientId=cid)
        step(physicsClientId=cid)
        k += 1
        checked = keep_in_plane(p, cid, bodies, pose=k % check == 0)
        if checked is None and not (sample and k % sample == 0) and k != n_steps:
            continue
        t = k * dt
        frame = checked if checked is not None else read_frame(p, cid, bodies)
        joints = joint_state(frame, stack, alpha)
        tilts = frame.tilts
        tilt_lo, tilt_hi = np.minimum(tilt_lo, tilts), np.maximum(tilt_hi, tilts)
        if sample and k % sample == 0:
            samples.append(_sample(t, frame, joints))
        if not (np.all(np.isfinite(frame.centres)) and np.max(frame.speeds) < BLOWUP):
            out.n_steps = out.n_rhs = k
            out.stop("failed", "the engine diverged (non-finite or runaway drum)", t)
            break
        if k - k_prev >= friction_steps:
            mean_accel = (accel_sum[k] - accel_sum[k_prev]) / (k - k_prev)
            demand = joint_friction(
                frame_prev, frame, stack, (k - k_prev) * dt, mean_accel, (tilt_lo, tilt_hi)
            )
            out.friction = np.fmax(out.friction, demand)
            frame_prev, k_prev = frame, k
            tilt_lo = tilt_hi = tilts
        out.max_ratio = np.maximum(out.max_ratio, joints.ratio)
        out.max_top = max(out.max_top, abs(joints.top[0] - joints.bottoms[0, 0]))
        max_slip = np.maximum(max_slip, np.abs(joints.slip))
        is_open = np.abs(joints.relative) > open_tol
        sign = np.sign(joints.relative) * is_open
        out.n_uplifts += int(np.sum(is_open & ~was_open))
        out.n_impacts += int(np.sum(was_open & (~is_open | (sign * last_sign < 0))))
        was_open, last_sign = is_open, np.where(is_open, sign, last_sign)
        worst = int(np.argmax(joints.ratio))
        dropped = np.nonzero(rest_z - frame.centres[:, 2] > drop)[0]
        if joints.ratio[worst] >= limit or dropped.size:
            out.n_steps = out.n_rhs = k
            if joints.ratio[worst] >= limit:
                frac = (limit - prev_ratio) / max(joints.ratio[worst] - prev_ratio, 1e-300)
                out.t_collapse = prev_t + min(max(frac, 0.0), 1.0) * (t - prev_t)
                out.collapse_interface = worst + 1
                why = f"the drums above joint {worst + 1} passed over its edge"
            else:
                out.t_collapse = t
                out.collapse_interface = int(dropped[0]) + 1
                why = f"drum {dropped[0] + 1} dropped by half its height"
            out.stop("collapsed", why, out.t_collapse)
            break
        prev_ratio, prev_t = float(joints.ratio[worst]), t
        if early_stop and motion.kind != "harmonic" and t >= motion.pulse_end:
            still = np.max(np.abs(frame.rates)) < REST_ANGULAR_RATE and not np.any(is_open)
            quiet_since = (quiet_since if quiet_since is not None else t) if still else None
            if quiet_since is not None and t - quiet_since >= REST_TIME:
                out.n_steps = out.n_rhs = k
                out.stop("survived", "at rest after the pulse", t)
                break
    else:
        out.n_steps = out.n_rhs = k
        out.stop("survived", "no joint passed over its edge", motion.t_end)
    out.message += "; " + _slip_text(max_slip)
    history = _history(samples, motion) if record else None
    return out, history


def _initial(config: Config) -> tuple[float, float]:
    init = config.excitation.initial
    rot = set(init.rotations) or {0.0}
    vel = set(init.velocities) or {0.0}
    if len(rot) > 1 or len(vel) > 1:
        raise RbmError(
            "excitation.initial: model bullet needs the same rotation and velocity for every"
            " drum (a rigid stack turning on the base corner)"
        )
    return float(rot.pop()), float(vel.pop())


def _slip_text(max_slip: np.ndarray) -> str:
    text = f"max slip: base {1e3 * max_slip[0]:.3g} mm"
    if max_slip.size > 1:
        j = int(np.argmax(max_slip[1:])) + 1
        text += f", joints {1e3 * max_slip[j]:.3g} mm (joint {j + 1})"
    return text


def _sample(t: float, frame: Frame, joints: Joints):
    nodes = np.concatenate([joints.bottoms[:, 0], [joints.top[0]]])
    return t, frame.tilts, frame.rates, nodes


def _history(samples, motion: GroundMotion) -> History:
    t = np.array([s[0] for s in samples])
    return History(
        t=t,
        ground_acceleration=np.asarray(motion.accel(t), dtype=float),
        ground_displacement=motion.displacement(t),
        node_displacements=np.array([s[3] for s in samples]),
        rotations=np.array([s[1] for s in samples]),
        rates=np.array([s[2] for s in samples]),
    )


class BulletRunner:
    """`bullet` (rbm_cli.models.contract.Runner): the config's drums in Bullet's contact
    dynamics; the engine's own history (from the drums' poses) when recording."""

    def __init__(self, config: Config) -> None:
        self.config = config
        self.n_interfaces = config.column.n_drums

    def run(
        self,
        motion: GroundMotion,
        solver: SolverConfig,
        *,
        record: bool = False,
        output_dt: float = DEFAULT_OUTPUT_DT,
        early_stop: bool = True,
    ) -> Outcome:
        """One run (rbm_cli.models.contract.Runner.run): the engine steps at solver.time_step."""
        config = self.config
        if solver != config.solver:
            config = dataclasses.replace(config, solver=solver)
        out, history = bullet_run(
            config, motion, record=record, output_dt=output_dt, early_stop=early_stop
        )
        out.history = history
        return out
