"""The scene of `model: bullet`: ground and drums in the engine, and their kinematics.

Builds the drums (:mod:`rbm_cli.models.bullet.geometry`) in a PyBullet client
(:mod:`rbm_cli.models.bullet.engine`) with the engine settings of a run, and
reads back the stack's state: drum positions and tilts, and per joint the
relative rotation, the overturning ratio and the slip in the plane
(:mod:`rbm_cli.models.bullet.space` reads them in three dimensions). Axes: x in the plane
of motion, y out of plane, z up. SI units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from rbm_cli.config.types import G
from rbm_cli.models.bullet.engine import PhysicsClient
from rbm_cli.models.bullet.settings import EngineSettings


def build_scene(
    client: PhysicsClient,
    solids,
    settings: EngineSettings,
    tilt: float = 0.0,
    rate: float = 0.0,
    cylinders: bool = False,
) -> list[int]:
    """Reset the client's world and build ground and drums in it; returns the drums'
    body ids (bottom first).

    tilt [rad], rate [rad/s]: the whole stack turned rigidly about the bottom
    corner of the base on the side of the tilt (positive: towards +x).
    cylinders: circular drums collided as the engine's cylinders (:func:`cylinder_shape`)
    rather than as polygonal prisms (a run's circular drums, in three dimensions or held
    in the plane).
    """
    p, cid = client.module, client.id
    _reset_world(p, cid, settings)
    return _add_columns(p, cid, solids, (0.0,), settings, tilt, rate, cylinders)


def build_frame(
    client: PhysicsClient,
    solids,
    axes: np.ndarray,
    beam,
    settings: EngineSettings,
    tilt: float = 0.0,
    rate: float = 0.0,
    cylinders: bool = False,
    seat: tuple[float, float] | None = None,
) -> list[int]:
    """Reset the client's world and build ground, a frame's columns and its beam
    (:mod:`rbm_cli.models.bullet.colonnade`); returns the body ids: column by column, each
    bottom first, then the beam.

    axes : (N,) x of each column's axis [m]; every column is the stack ``solids``.
    beam : DrumSolid  The beam (a box) resting on the columns' tops, centred on x = 0.
    tilt [rad], rate [rad/s]: every column turned rigidly about its own base corner on the
    side of the tilt, as :func:`build_scene` turns its stack; the beam, resting on the
    tops' corners on the other side, translated with them and moving as they move
    (Makris and Vassiliou's frame rocking in unison).
    cylinders: circular drums collided as the engine's cylinders (the beam is a box).
    seat : (stiffness [N/m], damping [N s/m]) of each of the beam's contact points, or None:
        rigid contacts, as the drums' (rbm_cli.models.bullet.colonnade.seat_contact).
    """
    p, cid = client.module, client.id
    _reset_world(p, cid, settings)
    bodies = _add_columns(p, cid, solids, axes, settings, tilt, rate, cylinders)
    c, s = math.cos(tilt), math.sin(tilt)
    rot = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    side = math.copysign(1.0, tilt or 1.0)
    spin = np.array([0.0, rate, 0.0])
    # the corner the beam rests on moves alike in every column
    pivot = np.array([axes[0] + side * solids[0].half_bottom, 0.0, 0.0])
    corner = np.array([axes[0] - side * solids[-1].half_top, 0.0, beam.bottom])
    arm = rot @ (corner - pivot)
    centre = np.array([0.0, 0.0, beam.bottom + beam.centre]) + (pivot + arm - corner)
    body = _add_drum(p, cid, beam, settings, centre, (0.0, 0.0, 0.0, 1.0))
    if seat is not None:  # the engine's soft contact: an implicit spring and dashpot
        p.changeDynamics(body, -1, contactStiffness=seat[0], contactDamping=seat[1],
                         physicsClientId=cid)  # fmt: skip
    if rate:
        p.resetBaseVelocity(body, linearVelocity=np.cross(spin, arm).tolist(),
                            angularVelocity=[0.0, 0.0, 0.0], physicsClientId=cid)  # fmt: skip
    bodies.append(body)
    return bodies


def _add_columns(p, cid, solids, axes, settings, tilt, rate, cylinders) -> list[int]:
    """The stack ``solids`` standing on each of the axes (x [m]), every stack turned
    rigidly by ``tilt`` [rad] about its own base corner on the side of the tilt and
    turning at ``rate`` [rad/s]; returns the drums' body ids, stack by stack, bottom
    first."""
    c, s = math.cos(tilt), math.sin(tilt)
    rot = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    quat = p.getQuaternionFromEuler([0.0, tilt, 0.0])
    side = math.copysign(1.0, tilt or 1.0)
    spin = np.array([0.0, rate, 0.0])
    bodies = []
    for x in axes:
        pivot = np.array([x + side * solids[0].half_bottom, 0.0, 0.0])
        for d in solids:
            centre = pivot + rot @ (np.array([x, 0.0, d.bottom + d.centre]) - pivot)
            body = _add_drum(p, cid, d, settings, centre, quat, cylinders)
            if rate:
                p.resetBaseVelocity(body, linearVelocity=np.cross(spin, centre - pivot).tolist(),
                                    angularVelocity=spin.tolist(), physicsClientId=cid)  # fmt: skip
            bodies.append(body)
    return bodies


def _reset_world(p, cid, settings: EngineSettings) -> None:
    """Empty the world, set the engine's parameters and lay the ground plane."""
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
        enableConeFriction=1,  # Coulomb's cone (the pyramid lets |T| reach 1.41 mu N)
        physicsClientId=cid,
    )
    plane = p.createCollisionShape(p.GEOM_PLANE, physicsClientId=cid)
    ground = p.createMultiBody(0.0, plane, physicsClientId=cid)
    _contact_dynamics(p, cid, ground, settings)


def _add_drum(
    p, cid, d, settings: EngineSettings, centre: np.ndarray, quat, cylinders: bool = False
) -> int:
    """One drum (a DrumSolid) as a multibody with its centre of mass at `centre` [m]."""
    if cylinders:
        shape = cylinder_shape(p, cid, d)
    elif d.box:
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
    return body


def cylinder_shape(p, cid, d) -> int:
    """A circular drum (a DrumSolid) as two of the engine's cylinders, one on the other,
    each half the drum high: the lower of the drum's bottom radius, the upper of its top
    radius (relative to its centre of mass). Its two faces are the true ones, so every
    joint's contact is the true circle and every pivot on its true rim; the side between
    them is stepped (it touches nothing while the drums stand on one another). The engine
    holds a cylinder's rim on a face better than a polygon's: measured on a straight
    drum rolling round its rim (docs/engine.md)."""
    h, zc = d.height, d.centre
    return p.createCollisionShapeArray(
        [p.GEOM_CYLINDER, p.GEOM_CYLINDER],
        radii=[float(d.half_bottom), float(d.half_top)],
        lengths=[0.5 * h, 0.5 * h],
        collisionFramePositions=[[0.0, 0.0, 0.25 * h - zc], [0.0, 0.0, 0.75 * h - zc]],
        physicsClientId=cid,
    )


def keep_in_plane(p, cid, bodies, pose: bool = False) -> Frame | None:
    """Hold the drums in the plane of motion (x, z), as UDEC's 2D model and the RBM are.

    Zeroes every drum's out-of-plane velocities (v_y, omega_x, omega_z); with
    `pose`, also puts its centre back on y = 0 and keeps only its in-plane tilt,
    and returns the :class:`Frame` it leaves the drums in (the state
    :func:`read_frame` would read back, with only the orientations read again).
    Without this a 3D stack under in-plane shaking picks up out-of-plane rocking
    from the contact solver's round-off (one corner of an edge loaded before
    the other) and 'walks': measured, a 4 x 1 m block at 1.1 g, 1.5 Hz with
    friction 2 slid 0.38 m standing on one corner.
    """
    get_vel, set_vel = p.getBaseVelocity, p.resetBaseVelocity
    if not pose:
        for b in bodies:
            lin, ang = get_vel(b, physicsClientId=cid)
            set_vel(b, (lin[0], 0.0, lin[2]), (0.0, ang[1], 0.0), physicsClientId=cid)
        return None
    n = len(bodies)
    centres, rots, vels = np.empty((n, 3)), [], np.empty((n, 3))
    rates, speeds = np.empty(n), np.empty(n)
    get_pose, set_pose, matrix = (
        p.getBasePositionAndOrientation,
        p.resetBasePositionAndOrientation,
        p.getMatrixFromQuaternion,
    )
    for i, b in enumerate(bodies):
        lin, ang = get_vel(b, physicsClientId=cid)
        pos, quat = get_pose(b, physicsClientId=cid)
        m = matrix(quat)
        half = 0.5 * math.atan2(m[2], m[8])
        centre = (pos[0], 0.0, pos[2])
        quat = (0.0, math.sin(half), 0.0, math.cos(half))
        # (resetting the pose zeroes a multibody's velocities: they are set again below)
        set_pose(b, centre, quat, physicsClientId=cid)
        lin = (lin[0], 0.0, lin[2])
        set_vel(b, lin, (0.0, ang[1], 0.0), physicsClientId=cid)
        centres[i] = centre
        # the orientation as Bullet stored it (it may differ from quat in the last bit)
        rots.append(matrix(get_pose(b, physicsClientId=cid)[1]))
        rates[i] = ang[1]
        speeds[i] = math.sqrt(sum(v * v for v in lin))
        vels[i] = lin
    angular = np.zeros((n, 3))
    angular[:, 1] = rates
    return Frame(centres, np.reshape(rots, (n, 3, 3)), rates, speeds, vels, angular)


def _contact_dynamics(p, cid, body, settings: EngineSettings) -> None:
    # Bullet's coefficient of a contact is the product of the two bodies' (capped
    # at 10): every body gets sqrt(friction), so each contact has `friction`
    p.changeDynamics(
        body,
        -1,
        lateralFriction=math.sqrt(settings.friction),
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
    velocities: np.ndarray  # (n, 3) linear velocities of the centres of mass [m/s]
    angular: np.ndarray  # (n, 3) angular velocities [rad/s]

    @cached_property
    def tilts(self) -> np.ndarray:
        """In-plane absolute rotations of the drums [rad] (positive: top towards +x);
        computed once per frame (joints, friction window and samples all read it)."""
        return np.arctan2(self.rotations[:, 0, 2], self.rotations[:, 2, 2])


def read_frame(p, cid, bodies) -> Frame:
    n = len(bodies)
    centres, rots = np.empty((n, 3)), np.empty((n, 3, 3))
    rates, speeds, vels = np.empty(n), np.empty(n), np.empty((n, 3))
    angular = np.empty((n, 3))
    for i, b in enumerate(bodies):
        pos, quat = p.getBasePositionAndOrientation(b, physicsClientId=cid)
        lin, ang = p.getBaseVelocity(b, physicsClientId=cid)
        centres[i] = pos
        rots[i] = np.reshape(p.getMatrixFromQuaternion(quat), (3, 3))
        rates[i] = ang[1]
        speeds[i] = max(math.sqrt(sum(v * v for v in lin)), abs(ang[0]), abs(ang[2]))
        vels[i] = lin
        angular[i] = ang
    return Frame(centres, rots, rates, speeds, vels, angular)


@dataclass(frozen=True)
class Joints:
    """Geometry of the stack's contacts at one instant (index 0: base on ground)."""

    relative: np.ndarray  # (n,) in-plane rotation of drum i relative to its support [rad]
    ratio: np.ndarray  # (n,) overturning measure over its limit (1: over the edge)
    slip: np.ndarray  # (n,) sliding of drum i on its support [m]
    bottoms: np.ndarray  # (n, 3) centres of the drums' bottom faces (world) [m]
    top: np.ndarray  # (3,) centre of the top face of the top drum (world) [m]


@dataclass(frozen=True)
class StackGeometry:
    """Per-drum constants of the joint readings (bottom first), computed once per run."""

    masses: np.ndarray  # (n,) [kg]
    centres: np.ndarray  # (n,) centre of mass above the drum's bottom face [m]
    heights: np.ndarray  # (n,) [m]
    half_bottom: np.ndarray  # (n,) half-width of the drum's bottom face [m]
    support_half: np.ndarray  # (n,) half-width of the support's top face (inf: ground) [m]
    mass_above: np.ndarray  # (n,) mass of drums i..n [kg]

    @classmethod
    def of(cls, solids) -> StackGeometry:
        masses = np.array([d.mass for d in solids])
        return cls(
            masses=masses,
            centres=np.array([d.centre for d in solids]),
            heights=np.array([d.height for d in solids]),
            half_bottom=np.array([d.half_bottom for d in solids]),
            support_half=np.array([math.inf] + [d.half_top for d in solids[:-1]]),
            mass_above=np.cumsum(masses[::-1])[::-1],
        )


def joint_state(frame: Frame, stack: StackGeometry, alpha: np.ndarray) -> Joints:
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
    All joints at once (arrays over the joints).
    """
    rot, centres = frame.rotations, frame.centres
    axis_z = rot[:, :, 2]
    bottoms = centres - stack.centres[:, None] * axis_z
    tops = centres + (stack.heights - stack.centres)[:, None] * axis_z
    tilts = frame.tilts
    rot_s = np.concatenate([np.eye(3)[None], rot[:-1]])
    origin = np.concatenate([np.zeros((1, 3)), tops[:-1]])
    phi = tilts - np.concatenate([[0.0], tilts[:-1]])

    def in_support(v):  # rot_s^T v, per joint
        return np.einsum("nji,nj->ni", rot_s, v)

    b = in_support(bottoms - origin)
    axis_x = in_support(rot[:, :, 0])
    x_r = b[:, 0] + stack.half_bottom * axis_x[:, 0]
    x_l = b[:, 0] - stack.half_bottom * axis_x[:, 0]
    right = np.minimum(np.maximum(x_r, x_l), stack.support_half)
    left = np.maximum(np.minimum(x_r, x_l), -stack.support_half)
    moment = np.cumsum((stack.masses[:, None] * centres)[::-1], axis=0)[::-1]
    c = in_support(moment / stack.mass_above[:, None] - origin)
    psi = np.minimum(np.arctan2(right - c[:, 0], c[:, 2]), np.arctan2(c[:, 0] - left, c[:, 2]))
    ratio = 1.0 - psi / alpha
    slip = b[:, 0] - np.copysign(stack.half_bottom * (1.0 - np.cos(phi)), phi)
    return Joints(phi, ratio, slip, bottoms, tops[-1])


def joint_normal_range(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Range of the in-plane normal angles of every joint's two faces [rad], from
    the range [lo, hi] of each drum's tilt: the support's (the ground's, 0, or drum
    i - 1's top) and drum i's bottom. At the ground the only normal is the plane's."""
    return (
        np.concatenate([[0.0], np.minimum(lo[:-1], lo[1:])]),
        np.concatenate([[0.0], np.maximum(hi[:-1], hi[1:])]),
    )


def joint_friction(
    before: Frame,
    after: Frame,
    stack: StackGeometry,
    duration: float,
    mean_accel: float,
    tilt_range: tuple[np.ndarray, np.ndarray] | None = None,
    mean_up: float = 0.0,
) -> np.ndarray:
    """Mobilised friction of every joint over an interval: the least |T| / N of the
    joint's mean force, from the momentum balance of the drums above it, over the
    contact normals the joint's faces admit [-] (nan: not loaded).

    Parameters
    ----------
    before, after : Frame  The stack at the start and end of the interval
    duration : float  Its length [s]
    mean_accel : float  Mean ground acceleration a_g over it, as the engine applied it [m/s^2]
    tilt_range : (lo, hi), optional  Range of each drum's tilt over the interval [rad]
        (every frame read); by default that of its two ends.
    mean_up : float  Mean upward ground acceleration a_v over it, as the engine applied
        it [m/s^2] (excitation.vertical; 0 without)

    Notes
    -----
    The drums i..n touch the rest only through joint i, so the joint's mean force
    over the interval is, exactly (Newton, in the ground's frame where gravity is
    (-a_g, 0, -(g + a_v))),

    .. math:: F_i = \\frac{\\Delta P_i}{\\Delta t} + M_i (\\bar a_g, 0, g + \\bar a_v),

    P_i the momentum of drums i..n, M_i their mass. At angle psi in the plane
    and a contact normal at angle phi, T / N = tan(psi - phi). Where an open
    joint pivots on the corner where its two faces meet, the contact normal is
    not defined: any phi between the two faces' normals is admissible (Bullet
    takes one face's), and the faces turn during the interval. So the reading is
    tan of the distance from psi to that range of phi: the least friction
    coefficient for which the mean force lies in a Coulomb cone about an
    admissible normal. It cannot exceed the engine's friction if every contact
    force obeys Coulomb about a normal in the range, since their sum then lies
    in the union of those cones. A seated joint has one normal. (Taking the
    support's normal alone read up to 11.2 with friction 10: at T / N near mu
    the reading moves by (1 + mu^2) per radian of normal.) Out of plane is left
    out: the model is 2D. Read per 10 ms rather than from the contact points of
    one engine step, whose split between points, and so between T and N,
    jitters by 5-10 % of the weight from step to step (docs/engine.md).
    """
    n = len(stack.masses)
    momentum = stack.masses[:, None] * (after.velocities - before.velocities)
    above = np.cumsum(momentum[::-1], axis=0)[::-1]
    inertial = np.array([mean_accel, 0.0, G + mean_up])
    force = above / duration + stack.mass_above[:, None] * inertial
    if tilt_range is None:
        tilt_range = (np.minimum(before.tilts, after.tilts), np.maximum(before.tilts, after.tilts))
    lo, hi = joint_normal_range(*tilt_range)
    psi = np.arctan2(force[:, 0], force[:, 2])
    gap = np.maximum(0.0, np.maximum(lo - psi, psi - hi))
    normal = np.hypot(force[:, 0], force[:, 2]) * np.cos(gap)
    out = np.full(n, np.nan)
    loaded = (gap < 0.5 * math.pi) & (normal > 1e-6 * G * stack.mass_above)
    out[loaded] = np.tan(gap[loaded])
    return out
