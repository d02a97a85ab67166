"""`model: bullet`: the column as stacked rigid drums in Bullet's contact dynamics.

The drums are rigid solids of their true shape (:mod:`rbm_cli.models.bullet.geometry`)
stacked on a rigid ground plane, in contact with dry Coulomb friction
(``interface.friction``), so they may rock, slide, bounce and fall with large
displacements: an open stand-in for the paper's discrete element model (UDEC).
The engine is PyBullet (Bullet Physics), driven without a GUI.

The scene is the ground's own frame. The ground motion enters exactly as the
inertial force it produces there: the gravity vector is set to
(-a_g(t), 0, -(g + a_v(t))) at every step (a_v the upward ground acceleration of
``excitation.vertical``, else 0), so there is no drift of the ground, horizontal
or vertical. When g + a_v(t) reaches 0 the stack would leave the ground: the run
ends there `failed` (GroundMotion.lift_off), as in the other models.

Engine settings (fixed, see :class:`EngineSettings`): time step 1e-4 s (the
config's ``solver.time_step``), 100 solver iterations, restitution 0 with a
restitution velocity threshold of 0 (impacts are perfectly plastic at the
contact points; the loss of angular velocity at an impact comes out of the
contact dynamics, measured by :func:`measure_restitution`), no linear or
angular damping (PyBullet's defaults are not 0), collision margin 0, split
impulse on, erp 0.2.

In three dimensions (Config.three_d: the motion given a direction, ``excitation.angle``,
or a second horizontal component, ``excitation.file_y`` or ``excitation.y``; circular
drums), the drums are
the engine's cylinders (:func:`rbm_cli.models.bullet.scene.cylinder_shape`) and nothing
holds them in a plane: they rock, roll on their rims, slide and twist as the contacts
let them, the gravity vector (-a_x(t), -a_y(t), -(g + a_v(t))); the joints are read by
:mod:`rbm_cli.models.bullet.space` (the same rules in any direction). An azimuth is taken
modulo a whole turn (rbm_cli.models.plan.wrapped): 360 degrees is 0 to the bit. Circular
drums are the engine's cylinders in the plane too, held in it: along x the run in the
plane is then the run free in three dimensions (to 1e-10 of the peak: a pair whose second
record is zeros, or an angle of 0, gives the run of the motion in the plane).

Collapse: the run stops when, at a joint (or the base), the centre of mass of
the drums above it passes over the pivot edge of the contact, i.e. when the
line from the pivot to that centre of mass turns by ``collapse.ratio`` times
its rest angle alpha_i (the stack's overturning angle). For one drum rocking
on a corner this is Housner's |theta| = alpha, the rule of `housner`. It also
stops when a drum's centre of mass drops by half the drum's height (a drum
slid off its support).

A frame (Config.frame: N columns under one beam) is N stacks of the drums in a row along x
under a free rigid box resting on their tops (:mod:`rbm_cli.models.bullet.colonnade`: its
layout, its readings and its collapse, a column's or the beam's fall from the tops, joint
n + 1); a beam of no mass is the free column, whose run this is to the bit.

References
----------
.. [1] E. Coumans and Y. Bai (2016-2021). PyBullet, a Python module for physics
   simulation for games, robotics and machine learning. http://pybullet.org
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from rbm_cli.base.errors import RbmError
from rbm_cli.config.types import Config, G, SolverConfig
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.models.bullet.colonnade import FrameWatch, frame_layout, seat_contact
from rbm_cli.models.bullet.engine import PhysicsClient
from rbm_cli.models.bullet.geometry import drum_solids, stack_slenderness
from rbm_cli.models.bullet.impact import impact_rate_ratios, measure_restitution
from rbm_cli.models.bullet.scene import (
    Frame,
    build_frame,
    build_scene,
    keep_in_plane,
    read_frame,
)
from rbm_cli.models.bullet.settings import MAX_FRICTION, EngineSettings, settings_from_config
from rbm_cli.models.bullet.watch import (
    BLOWUP,
    CHECK_DT,
    DROP_FRACTION,
    FRICTION_DT,
    OPEN_FRACTION,
    REST_ANGULAR_RATE,
    REST_SPEED,
    REST_TIME,
    RunWatch,
)
from rbm_cli.models.contract import DEFAULT_OUTPUT_DT
from rbm_cli.models.history import History
from rbm_cli.models.outcome import Outcome
from rbm_cli.models.plan import wrapped

__all__ = [
    "BLOWUP",
    "CHECK_DT",
    "DROP_FRACTION",
    "FRICTION_DT",
    "MAX_FRICTION",
    "OPEN_FRACTION",
    "REST_ANGULAR_RATE",
    "REST_SPEED",
    "REST_TIME",
    "EngineSettings",
    "PhysicsClient",
    "bullet_run",
    "has_beam",
    "engine_uplift_g",
    "ground_friction_demand",
    "impact_rate_ratios",
    "measure_restitution",
    "settings_from_config",
    "uplift_level",
    "upward_accel",
]


# ------------------------------------------------------------------------- run


def uplift_level(solids, friction: float) -> float:
    """Horizontal ground acceleration [m/s^2] below which the rigid stack cannot
    move: min(tan alpha_i, friction) g (statics of the stacks above each joint)."""
    return G * min(float(np.min(np.tan(stack_slenderness(solids)))), friction)


def engine_uplift_g(config: Config) -> float:
    """The engine's uplift level of a configured column [g] (uplift_level of its true solids)."""
    return uplift_level(drum_solids(config.column), config.interface.friction) / G


def upward_accel(motion: GroundMotion, t: np.ndarray) -> np.ndarray | None:
    """The upward ground acceleration a_v(t) [m/s^2] at times t [s] (linear between the
    knots, 0 outside them: GroundMotion.gravity's values times g, less g), or None
    without excitation.vertical."""
    if not motion.has_vertical:
        return None
    return np.interp(t, motion.knots, motion.vertical, left=0.0, right=0.0)


def ground_friction_demand(motion: GroundMotion) -> float:
    """max over t of |a_h(t)| / (g + a_v(t)) [-]: the friction a stack moving with the
    ground needs (inf where g + a_v reaches 0), a_h the horizontal acceleration (a pair's
    resultant). With a vertical record both are linear between the same knots (a pair's
    resultant convex), so the ratio is at most its value at an end of each interval and
    its maximum is at a knot."""
    if motion.second is not None:  # an analytic second component (no vertical record)
        return motion.horizontal_peak / G
    horizontal = None
    if motion.values_y is not None:  # a pair: the resultant, convex on each interval
        horizontal = np.hypot(motion.values, motion.values_y)
    if not motion.has_vertical:
        return motion.amplitude / G if horizontal is None else float(np.max(horizontal)) / G
    weight = G + np.asarray(motion.vertical)
    if np.any(weight <= 0.0):
        return math.inf
    horizontal = np.abs(motion.values) if horizontal is None else horizontal
    return float(np.max(horizontal / weight))


def _drive(client, bodies, dt, motion, out, sample, early_stop, observe, space, watch_of,
           survived="no joint passed over its edge"):  # fmt: skip
    """Step the engine from t = 0 to the motion's end or a stop, checking the bodies
    every CHECK_DT (and at every sample); fills `out`. ``watch_of(accel, frame, upward)``
    makes the run's watch (RunWatch or the frame's) from a_g (and a_v) at every mid-step
    and the bodies at t = 0; ``survived`` is the message of a run that went to its end.
    Returns (samples, watch)."""
    p, cid = client.module, client.id
    n_steps = int(round(motion.t_end / dt))
    check = max(1, int(round(CHECK_DT / dt)))
    set_gravity, step = p.setGravity, p.stepSimulation
    # a_g and a_v at every mid-step, at once (the same numbers as one call per step)
    mid = (np.arange(n_steps) + 0.5) * dt
    if space:
        ax, ay = motion.accel_plan(mid)
        accel_array = np.stack([ax, ay], axis=1)
        accel, side = ax.tolist(), (-ay).tolist()
    else:
        accel_array = np.asarray(motion.accel(mid), dtype=float)
        accel, side = accel_array.tolist(), [0.0] * n_steps
    upward = upward_accel(motion, mid)
    down = (-(G + upward)).tolist() if upward is not None else [-G] * n_steps
    frame = read_frame(p, cid, bodies)
    watch = watch_of(accel_array, frame, upward)
    look = motion.direction if space else None
    samples = [_sample(0.0, *watch.seen(frame, watch.joints(frame)), look)] if sample else []
    k = 0
    while k < n_steps:
        set_gravity(-accel[k], side[k], down[k], physicsClientId=cid)
        step(physicsClientId=cid)
        k += 1
        if observe is not None:
            observe(p, cid, bodies)
        if space:
            checked = read_frame(p, cid, bodies) if k % check == 0 else None
        else:
            checked = keep_in_plane(p, cid, bodies, pose=k % check == 0)
        if checked is None and not (sample and k % sample == 0) and k != n_steps:
            continue
        frame = checked if checked is not None else read_frame(p, cid, bodies)
        joints = watch.see(frame)
        if sample and k % sample == 0:
            samples.append(_sample(k * dt, *watch.seen(frame, joints), look))
        if watch.check(out, k, frame, joints, motion, early_stop):
            break
    else:
        out.n_steps = out.n_rhs = k
        out.stop("survived", survived, motion.t_end)
    return samples, watch


def bullet_run(
    config: Config,
    motion: GroundMotion,
    *,
    record: bool = False,
    output_dt: float = 0.002,
    early_stop: bool = True,
    settings: EngineSettings | None = None,
    client: PhysicsClient | None = None,
    observe=None,
) -> tuple[Outcome, History | None]:
    """One run of the drum stack in the contact engine.

    Parameters
    ----------
    config : Config  Column geometry, interface.friction, collapse.ratio,
        solver.time_step, excitation.initial (a rigid stack only: one rotation
        [rad] and rate [rad/s] shared by every drum)
    motion : GroundMotion  a_g(t) [m/s^2], a_v(t) [m/s^2] if any, simulated time [s]
    record : bool  Keep a history sampled every output_dt [s]
    early_stop : bool  After a half-sine pulse (or in free motion), stop once
        the stack has been at rest for REST_TIME
    settings : EngineSettings  Override the config's engine settings (tests)
    client : PhysicsClient  The engine client to build the scene in (its world is
        reset; the caller keeps and closes it). Default: the process's own
        (:meth:`PhysicsClient.for_process`).
    observe : callable(pybullet, client id, body ids), optional  Called after
        every engine step, before the drums are held in the plane (a probe of the
        engine's own state, e.g. :class:`rbm_cli.models.bullet.normals.NormalCensus`);
        it must not change the scene.

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
        the message gives the largest slips; residual_slip [m], residual_top [m] and
        residual_tilt [-] the state where the run ended (RunWatch.residual; nan unless
        it survived; 0 where the ground's acceleration stays below the uplift and
        sliding levels, the stack moving with it). A vertical record reaching -g ends
        the run there, 'failed' (unless it collapsed before).
        A frame whose beam has mass (Config.frame, :func:`has_beam`): its columns and beam
        (:mod:`rbm_cli.models.bullet.colonnade`), the per-joint arrays n + 1 long (the
        beam's joint last, collapse_interface n + 1 where the beam fell; its history the
        first column's); a frame whose beam has no mass is its free column, whose run this
        is to the bit.
    """
    if has_beam(config):
        return _frame_run(config, motion, record, output_dt, early_stop, settings, client,
                          observe)  # fmt: skip
    solids = drum_solids(config.column)
    n = len(solids)
    settings = settings or settings_from_config(config)
    tilt, rate = _initial(config)
    if motion.angle != 0.0:  # a whole turn is none
        motion = dataclasses.replace(motion, angle=wrapped(motion.angle))
    t_lift = motion.lift_off  # a vertical record dropping faster than gravity
    if t_lift is not None:
        motion = motion.until(t_lift)
    out = Outcome()
    out.max_ratio = np.zeros(n)
    demand = ground_friction_demand(motion)
    level = uplift_level(solids, settings.friction) / G
    if not record and tilt == 0.0 and rate == 0.0 and demand < level * (1 - 1e-9):
        # the stack moves with the ground: every joint carries m_above a_g on m_above (g + a_v)
        out.friction = np.full(n, demand)
        out.message = "at rest: ground acceleration below the uplift and sliding levels"
        if config.three_d:
            out.turns = 0.0
        out.stop("survived", out.message, motion.t_end).lifted_off(t_lift)
        if out.status == "survived":  # nothing moved on the ground
            out.residual_slip = out.residual_top = out.residual_tilt = 0.0
        return out, None

    dt = settings.time_step
    sample = max(1, int(round(output_dt / dt))) if record else 0
    out.friction = np.full(n, np.nan)
    if client is None:
        client = PhysicsClient.for_process()
    space = config.three_d
    # circular drums as the engine's cylinders, in three dimensions and held in the plane
    cylinders = space or config.column.section == "circular"
    bodies = build_scene(client, solids, settings, tilt, rate, cylinders=cylinders)
    alpha, limit = stack_slenderness(solids), config.collapse.ratio

    def watch_of(accel, frame, upward):
        return RunWatch(solids, alpha, limit, dt, accel, frame, upward, space)

    samples, watch = _drive(client, bodies, dt, motion, out, sample, early_stop, observe, space,
                            watch_of)  # fmt: skip
    out.lifted_off(t_lift)
    watch.residual(out)
    if space:
        out.turns = float(np.max(watch.swept)) / (2.0 * math.pi)
        out.message += "; " + _slip_text(watch.slid, "slid") + "; " + _twist_text(watch.max_twist)
    else:
        out.message += "; " + _slip_text(watch.max_slip)
    history = _history(samples, motion, space) if record else None
    return out, history


def has_beam(config: Config) -> bool:
    """The config is a frame whose beam has mass (a frame with a beam of no mass is its
    free column: its run is the column's, to the bit)."""
    return config.frame is not None and config.frame.beam_mass > 0.0


def _frame_run(config, motion, record, output_dt, early_stop, settings, client, observe):
    """bullet_run of a frame of columns under a beam of mass (its parameters): every run
    in the engine (a frame's ground motion below its columns' uplift and sliding levels is
    not skipped: how the columns share the beam's load, so their friction demand and the
    level that uplifts the beam, are the engine's to find)."""
    solids = drum_solids(config.column)
    n = len(solids)
    layout = frame_layout(config.column, config.frame, solids)
    settings = settings or settings_from_config(config)
    tilt, rate = _initial(config)
    t_lift = motion.lift_off  # a vertical record dropping faster than gravity
    if t_lift is not None:
        motion = motion.until(t_lift)
    out = Outcome()
    out.max_ratio = np.zeros(n + 1)
    out.friction = np.full(n + 1, np.nan)
    dt = settings.time_step
    sample = max(1, int(round(output_dt / dt))) if record else 0
    if client is None:
        client = PhysicsClient.for_process()
    cylinders = config.column.section == "circular"
    seat = seat_contact(config.column, config.frame, config.interface, solids)
    bodies = build_frame(client, solids, layout.axes, layout.beam, settings, tilt, rate,
                         cylinders=cylinders, seat=seat)  # fmt: skip
    alpha, limit = stack_slenderness(solids), config.collapse.ratio

    def watch_of(accel, frame, upward):
        return FrameWatch(solids, layout, alpha, limit, dt, accel, frame, upward)

    went = "no joint passed over its edge, the beam on every top"
    samples, watch = _drive(client, bodies, dt, motion, out, sample, early_stop, observe, False,
                            watch_of, went)  # fmt: skip
    out.lifted_off(t_lift)
    watch.residual(out)
    out.message += "; " + _slip_text(watch.max_slip) + f", beam {1e3 * watch.max_beam_slip:.3g} mm"
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


def _slip_text(max_slip: np.ndarray, what: str = "max slip") -> str:
    text = f"{what}: base {1e3 * max_slip[0]:.3g} mm"
    if max_slip.size > 1:
        j = int(np.argmax(max_slip[1:])) + 1
        text += f", joints {1e3 * max_slip[j]:.3g} mm (joint {j + 1})"
    return text


def _twist_text(max_twist: np.ndarray) -> str:
    j = int(np.argmax(max_twist))
    return f"max twist {np.degrees(max_twist[j]):.3g} deg (joint {j + 1})"


def _seen_in(d: np.ndarray, frame: Frame) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The drums' rotations seen in the vertical plane of the motion's direction d (unit,
    in plan) and across it (d turned by +90 degrees), and the rate in that plane, as the
    models in three dimensions give them [rad, rad, rad/s]: the drum's axis leaning to +x
    by atan2(z_x, z_z), to +y by atan2(z_y, z_z); its lean towards +x turns at omega_y,
    towards +y at -omega_x."""
    axis = frame.rotations[:, :, 2]
    tx = np.arctan2(axis[:, 0], axis[:, 2])
    ty = np.arctan2(axis[:, 1], axis[:, 2])
    (c, s), w = d, frame.angular
    return tx * c + ty * s, -tx * s + ty * c, w[:, 1] * c - w[:, 0] * s


def _sample(t: float, frame: Frame, joints, d: np.ndarray | None = None):
    """A history sample; d: the motion's direction in plan for a run in three dimensions
    (None: in the plane)."""
    if d is None:
        nodes = np.concatenate([joints.bottoms[:, 0], [joints.top[0]]])
        return t, frame.tilts, frame.rates, nodes, None, None
    along, across, rates = _seen_in(d, frame)
    points = np.concatenate([joints.bottoms[:, :2], joints.top[None, :2]])
    return t, along, rates, points @ d, across, joints.top[:2].copy()


def _history(samples, motion: GroundMotion, space: bool = False) -> History:
    t = np.array([s[0] for s in samples])
    extra = {}
    if space:
        extra = {
            "rotations_across": np.array([s[4] for s in samples]),
            "top_plan": np.array([s[5] for s in samples]),
        }
        extra["ground_acceleration_y"] = motion.accel_y(t)  # None: one component
    return History(
        t=t,
        ground_acceleration=np.asarray(motion.accel(t), dtype=float),
        ground_displacement=motion.displacement(t),
        node_displacements=np.array([s[3] for s in samples]),
        rotations=np.array([s[1] for s in samples]),
        rates=np.array([s[2] for s in samples]),
        **extra,
    )


class BulletRunner:
    """`bullet` (rbm_cli.models.contract.Runner): the config's drums in Bullet's contact
    dynamics; the engine's own history (from the drums' poses) when recording."""

    def __init__(self, config: Config) -> None:
        self.config = config
        # a frame's beam joint after the columns' (bullet_run)
        self.n_interfaces = config.column.n_drums + int(has_beam(config))
        self._client: PhysicsClient | None = None  # the runner's own, opened on first run

    def close(self) -> None:
        """Disconnect the runner's engine client (a later run opens a new one)."""
        if self._client is not None:
            self._client.close()
            self._client = None

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:  # at interpreter exit pybullet may be gone already
            pass

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
        if self._client is None or self._client.id is None:
            self._client = PhysicsClient()
        out, history = bullet_run(
            config,
            motion,
            record=record,
            output_dt=output_dt,
            early_stop=early_stop,
            client=self._client,
        )
        out.history = history
        return out
