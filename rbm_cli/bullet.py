"""`model: bullet`: the column as stacked rigid drums in Bullet's contact dynamics.

The drums are rigid solids of their true shape (:mod:`rbm_cli.bullet_geometry`)
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

import math
from dataclasses import dataclass

import numpy as np

from .bullet_engine import engine
from .bullet_geometry import drum_solids, stack_slenderness
from .config_types import Config, G
from .errors import RbmError
from .excitation import GroundMotion
from .integrate import Outcome
from .result import History

#: Interval of the collapse, sliding and contact checks [s].
CHECK_DT = 1e-3
#: A joint is open when its relative rotation exceeds this fraction of alpha_i.
OPEN_FRACTION = 1e-3
#: Drop of a drum's centre of mass, as a fraction of its height, that is collapse.
DROP_FRACTION = 0.5
#: Half-sine/free early stop: every rate below this [rad/s] and every joint
#: closed for REST_TIME [s] after the pulse.
REST_RATE = 1e-4
REST_TIME = 0.2
#: A drum faster than this [m/s or rad/s] means the engine blew up.
BLOWUP = 1e3


@dataclass(frozen=True)
class EngineSettings:
    """Bullet settings of a run (SPEC: the issue's scoping values).

    time_step : float  Fixed engine step [s]
    solver_iterations : int  Sequential-impulse iterations per step
    erp : float  Error reduction parameter of contacts and friction [-]
    friction : float  Coulomb friction coefficient, drum-drum and drum-ground [-]
    """

    time_step: float = 1e-4
    solver_iterations: int = 100
    erp: float = 0.2
    friction: float = 1.0


def settings_from_config(config: Config) -> EngineSettings:
    return EngineSettings(time_step=config.solver.time_step, friction=config.interface.friction)


# ----------------------------------------------------------------------- scene


def build_scene(solids, settings: EngineSettings, tilt: float = 0.0, rate: float = 0.0):
    """Reset the engine and build ground and drums; returns (pybullet, client, bodies).

    tilt [rad], rate [rad/s]: the whole stack turned rigidly about the bottom
    corner of the base on the side of the tilt (positive: towards +x).
    """
    p, cid = engine()
    p.resetSimulation(physicsClientId=cid)
    p.setPhysicsEngineParameter(
        fixedTimeStep=settings.time_step,
        numSubSteps=0,
        numSolverIterations=settings.solver_iterations,
        restitutionVelocityThreshold=0.0,
        useSplitImpulse=1,
        erp=settings.erp,
        contactERP=settings.erp,
        frictionERP=settings.erp,
        deterministicOverlappingPairs=1,
        physicsClientId=cid,
    )
    plane = p.createCollisionShape(p.GEOM_PLANE, physicsClientId=cid)
    ground = p.createMultiBody(0.0, plane, physicsClientId=cid)
    _contact_dynamics(p, cid, ground, settings)
    pivot = np.array([math.copysign(solids[0].half_bottom, tilt or 1.0), 0.0, 0.0])
    c, s = math.cos(tilt), math.sin(tilt)
    rot = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    quat = p.getQuaternionFromEuler([0.0, tilt, 0.0])
    bodies = []
    for d in solids:
        if d.box:
            shape = p.createCollisionShape(
                p.GEOM_BOX, halfExtents=[float(v) for v in d.half_extents], physicsClientId=cid
            )
        else:  # a convex hull; SAT features give full contact manifolds between faces
            shape = p.createCollisionShape(
                p.GEOM_MESH,
                vertices=d.vertices.tolist(),
                flags=p.URDF_INITIALIZE_SAT_FEATURES,
                physicsClientId=cid,
            )
        centre = pivot + rot @ (np.array([0.0, 0.0, d.bottom + d.centre]) - pivot)
        body = p.createMultiBody(  # the body frame is the centre of mass (box: its centre)
            float(d.mass),
            shape,
            basePosition=centre.tolist(),
            baseOrientation=quat,
            physicsClientId=cid,
        )
        # (a multibody: PyBullet zeroes the mass of a maximal-coordinates rigid
        # body given localInertiaDiagonal; Bullet's own inertia of a hull is its box's)
        p.changeDynamics(
            body, -1, localInertiaDiagonal=[float(v) for v in d.inertia], physicsClientId=cid
        )
        _contact_dynamics(p, cid, body, settings)
        if rate:
            arm = centre - pivot
            p.resetBaseVelocity(
                body,
                linearVelocity=np.cross([0.0, rate, 0.0], arm).tolist(),
                angularVelocity=[0.0, rate, 0.0],
                physicsClientId=cid,
            )
        bodies.append(body)
    return p, cid, bodies


def _contact_dynamics(p, cid, body, settings: EngineSettings) -> None:
    p.changeDynamics(
        body,
        -1,
        lateralFriction=settings.friction,
        rollingFriction=0.0,
        spinningFriction=0.0,
        restitution=0.0,
        linearDamping=0.0,
        angularDamping=0.0,
        collisionMargin=0.0,
        physicsClientId=cid,
    )


# ----------------------------------------------------------------------- state


@dataclass(frozen=True)
class Frame:
    """Kinematics of the stack at one instant (arrays bottom first; x, y, z)."""

    centres: np.ndarray  # (n, 3) centres of mass [m]
    rotations: np.ndarray  # (n, 3, 3) body-to-world rotation matrices
    rates: np.ndarray  # (n,) in-plane angular velocities (about y) [rad/s]
    speeds: np.ndarray  # (n,) |linear velocity| [m/s]

    @property
    def tilts(self) -> np.ndarray:
        """In-plane absolute rotations of the drums [rad] (positive: top towards +x)."""
        return np.arctan2(self.rotations[:, 0, 2], self.rotations[:, 2, 2])


def read_frame(p, cid, bodies) -> Frame:
    n = len(bodies)
    centres, rots = np.empty((n, 3)), np.empty((n, 3, 3))
    rates, speeds = np.empty(n), np.empty(n)
    for i, b in enumerate(bodies):
        pos, quat = p.getBasePositionAndOrientation(b, physicsClientId=cid)
        lin, ang = p.getBaseVelocity(b, physicsClientId=cid)
        centres[i] = pos
        rots[i] = np.reshape(p.getMatrixFromQuaternion(quat), (3, 3))
        rates[i] = ang[1]
        speeds[i] = max(math.sqrt(sum(v * v for v in lin)), abs(ang[0]), abs(ang[2]))
    return Frame(centres, rots, rates, speeds)


@dataclass(frozen=True)
class Joints:
    """Geometry of the stack's contacts at one instant (index 0: base on ground)."""

    relative: np.ndarray  # (n,) in-plane rotation of drum i relative to its support [rad]
    ratio: np.ndarray  # (n,) overturning measure over its limit (1: over the edge)
    slip: np.ndarray  # (n,) sliding of drum i on its support [m]
    bottoms: np.ndarray  # (n, 3) centres of the drums' bottom faces (world) [m]
    top: np.ndarray  # (3,) centre of the top face of the top drum (world) [m]


def joint_state(frame: Frame, solids, alpha: np.ndarray) -> Joints:
    """Relative rotations, overturning ratios and slips of every joint.

    Notes
    -----
    Everything is measured in the support's frame (the drum below, or the
    ground). Ratio: with the pivot at the edge of the contact (the inner one of
    the drum's bottom corner and the support's top corner, on either side), psi
    is the angle between the support's normal and the line from the pivot to
    the centre of mass of the drums above; ratio = 1 - psi / alpha_i, alpha_i
    its rest value (for a block on a corner, theta / alpha). Slip: the offset
    of the bottom-face centre from the support's top-face centre, less the
    offset b (1 - cos phi) that rocking on a corner gives without sliding.
    """
    n = len(solids)
    masses = np.array([d.mass for d in solids])
    local_bottom = np.array([[0.0, 0.0, -d.centre] for d in solids])
    local_top = np.array([[0.0, 0.0, d.height - d.centre] for d in solids])
    bottoms = frame.centres + np.einsum("nij,nj->ni", frame.rotations, local_bottom)
    tops = frame.centres + np.einsum("nij,nj->ni", frame.rotations, local_top)
    tilts = frame.tilts
    relative, ratio, slip = np.empty(n), np.empty(n), np.empty(n)
    for i, d in enumerate(solids):
        if i == 0:
            rot_s, origin, half_s, tilt_s = np.eye(3), np.zeros(3), math.inf, 0.0
        else:
            rot_s, origin = frame.rotations[i - 1], tops[i - 1]
            half_s, tilt_s = solids[i - 1].half_top, tilts[i - 1]
        phi = tilts[i] - tilt_s
        relative[i] = phi
        to_support = rot_s.T
        b = to_support @ (bottoms[i] - origin)
        axis_x = to_support @ frame.rotations[i][:, 0]
        corner_r = b + d.half_bottom * axis_x
        corner_l = b - d.half_bottom * axis_x
        right = min(max(corner_r[0], corner_l[0]), half_s)
        left = max(min(corner_r[0], corner_l[0]), -half_s)
        m = masses[i:]
        com = (m[:, None] * frame.centres[i:]).sum(axis=0) / m.sum()
        c = to_support @ (com - origin)
        psi_r = math.atan2(right - c[0], c[2])
        psi_l = math.atan2(c[0] - left, c[2])
        ratio[i] = 1.0 - min(psi_r, psi_l) / alpha[i]
        slip[i] = b[0] - math.copysign(d.half_bottom * (1.0 - math.cos(phi)), phi)
    return Joints(relative, ratio, slip, bottoms, tops[-1])


# ------------------------------------------------------------------------- run


def uplift_level(solids, friction: float) -> float:
    """Horizontal ground acceleration [m/s^2] below which the rigid stack cannot
    move: min(tan alpha_i, friction) g (statics of the stacks above each joint)."""
    return G * min(float(np.min(np.tan(stack_slenderness(solids)))), friction)


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
        checks), n_steps = n_rhs = engine steps; the message gives the largest
        slips. Friction demand is not computed (nan).
    """
    solids = drum_solids(config.column)
    n = len(solids)
    settings = settings or settings_from_config(config)
    tilt, rate = _initial(config)
    alpha = stack_slenderness(solids)
    out = Outcome()
    out.max_ratio = np.zeros(n)
    out.friction = np.full(n, np.nan)
    limit = config.collapse.ratio
    level = uplift_level(solids, settings.friction)
    if not record and tilt == 0.0 and rate == 0.0 and motion.amplitude < level * (1 - 1e-9):
        out.message = "at rest: ground acceleration below the uplift and sliding levels"
        return out.stop("survived", out.message, motion.t_end), None

    p, cid, bodies = build_scene(solids, settings, tilt, rate)
    dt = settings.time_step
    n_steps = int(round(motion.t_end / dt))
    check = max(1, int(round(CHECK_DT / dt)))
    sample = max(1, int(round(output_dt / dt))) if record else 0
    rest_z = np.array([d.bottom + d.centre for d in solids])
    drop = np.array([DROP_FRACTION * d.height for d in solids])
    open_tol = OPEN_FRACTION * alpha
    max_slip = np.zeros(n)
    was_open = np.zeros(n, bool)
    last_sign = np.zeros(n)
    prev_ratio, prev_t, quiet_since = 0.0, 0.0, None
    samples: list = []
    set_gravity, step = p.setGravity, p.stepSimulation

    def observe(k: int):
        frame = read_frame(p, cid, bodies)
        return frame, joint_state(frame, solids, alpha)

    frame, joints = observe(0)
    if record:
        samples.append(_sample(0.0, frame, joints))
    k = 0
    while k < n_steps:
        t_mid = (k + 0.5) * dt
        set_gravity(-motion.accel(t_mid), 0.0, -G, physicsClientId=cid)
        step(physicsClientId=cid)
        k += 1
        if k % check and not (sample and k % sample == 0) and k != n_steps:
            continue
        t = k * dt
        frame, joints = observe(k)
        if sample and k % sample == 0:
            samples.append(_sample(t, frame, joints))
        if not (np.all(np.isfinite(frame.centres)) and np.max(frame.speeds) < BLOWUP):
            out.n_steps = out.n_rhs = k
            out.stop("failed", "the engine diverged (non-finite or runaway drum)", t)
            break
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
            still = np.max(np.abs(frame.rates)) < REST_RATE and not np.any(is_open)
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


def measure_restitution(
    config: Config,
    tilt_fraction: float = 0.5,
    impacts: int = 4,
    settings: EngineSettings | None = None,
) -> np.ndarray:
    """The engine's own impact loss: angular-velocity ratios of free rocking [-].

    The stack (rigid, turned by tilt_fraction * alpha_1 on its base corner) is
    released from rest with no ground motion; at each of the first `impacts`
    impacts (sign changes of the base drum's tilt) the in-plane angular velocity
    just before and just after is extrapolated to the crossing from straight
    lines fitted over 2 ms on either side (leaving out 0.5 ms around it, where
    the contact switches corners), and their ratio returned.
    """
    solids = drum_solids(config.column)
    settings = settings or settings_from_config(config)
    alpha = stack_slenderness(solids)
    p, cid, bodies = build_scene(solids, settings, tilt_fraction * alpha[0], 0.0)
    p.setGravity(0.0, 0.0, -G, physicsClientId=cid)
    dt = settings.time_step
    base = bodies[0]
    t_max = 20.0 * (impacts + 1)  # s, far beyond `impacts` half-cycles of any column
    tilt, rate = [], []
    found, k = 0, 0
    fit, gap = max(3, int(round(2e-3 / dt))), max(1, int(round(5e-4 / dt)))
    while found < impacts and k * dt < t_max:
        p.stepSimulation(physicsClientId=cid)
        k += 1
        _, quat = p.getBasePositionAndOrientation(base, physicsClientId=cid)
        _, ang = p.getBaseVelocity(base, physicsClientId=cid)
        m = p.getMatrixFromQuaternion(quat)
        tilt.append(math.atan2(m[2], m[8]))
        rate.append(ang[1])
        if len(tilt) > 1 and tilt[-1] * tilt[-2] < 0.0:
            found += 1
    tilt_a, rate_a = np.array(tilt), np.array(rate)
    crossings = np.nonzero(tilt_a[1:] * tilt_a[:-1] < 0.0)[0]
    ratios = []
    for c in crossings:
        lo, hi = c - gap - fit, c + 1 + gap + fit
        if lo < 0:
            continue
        while hi > len(rate_a) and k * dt < t_max:  # run on to fill the fitting window
            p.stepSimulation(physicsClientId=cid)
            _, ang = p.getBaseVelocity(base, physicsClientId=cid)
            rate_a = np.append(rate_a, ang[1])
            k += 1
        t_c = (c + tilt_a[c] / (tilt_a[c] - tilt_a[c + 1])) * dt
        before = np.arange(c - gap - fit, c - gap)
        after = np.arange(c + 1 + gap, c + 1 + gap + fit)
        w_b = np.polyval(np.polyfit(before * dt, rate_a[before], 1), t_c)
        w_a = np.polyval(np.polyfit(after * dt, rate_a[after], 1), t_c)
        ratios.append(w_a / w_b)
    return np.array(ratios)


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
