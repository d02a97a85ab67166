"""The scene of `model: bullet`: ground and drums in the engine, and their kinematics.

Builds the drums (:mod:`rbm_cli.bullet_geometry`) in the process's PyBullet
client (:mod:`rbm_cli.bullet_engine`) with the engine settings of a run, and
reads back the stack's state: drum positions and tilts, and per joint the
relative rotation, the overturning ratio and the slip. Axes: x in the plane of
motion, y out of plane, z up. SI units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .bullet_engine import engine


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


def keep_in_plane(p, cid, bodies, pose: bool = False) -> None:
    """Hold the drums in the plane of motion (x, z), as UDEC's 2D model and the RBM are.

    Zeroes every drum's out-of-plane velocities (v_y, omega_x, omega_z); with
    `pose`, also puts its centre back on y = 0 and keeps only its in-plane tilt.
    Without this a 3D stack under in-plane shaking picks up out-of-plane rocking
    from the contact solver's round-off (one corner of an edge loaded before
    the other) and 'walks': measured, a 4 x 1 m block at 1.1 g, 1.5 Hz with
    friction 2 slid 0.38 m standing on one corner.
    """
    for b in bodies:
        lin, ang = p.getBaseVelocity(b, physicsClientId=cid)
        if pose:  # (this zeroes a multibody's velocities: they are set again below)
            pos, quat = p.getBasePositionAndOrientation(b, physicsClientId=cid)
            m = p.getMatrixFromQuaternion(quat)
            half = 0.5 * math.atan2(m[2], m[8])
            p.resetBasePositionAndOrientation(
                b,
                (pos[0], 0.0, pos[2]),
                (0.0, math.sin(half), 0.0, math.cos(half)),
                physicsClientId=cid,
            )
        p.resetBaseVelocity(b, (lin[0], 0.0, lin[2]), (0.0, ang[1], 0.0), physicsClientId=cid)


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
