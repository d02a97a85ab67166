"""The readings of `model: bullet` in three dimensions: each joint's lean, overturning
ratio, contact point and twist, and its friction demand, for circular drums moving freely.

The planar readings (:func:`rbm_cli.models.bullet.scene.joint_state`,
:func:`rbm_cli.models.bullet.scene.joint_friction`) take the stack in its plane; these take
it anywhere, and in a plane they are the planar ones (tested). Arrays over the joints,
index 0 the base on the ground; every reading in the support's frame (the drum below, or
the ground), turned to the ground's axes where said. SI units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rbm_cli.config.types import G
from rbm_cli.models.bullet.scene import Frame, StackGeometry

#: Directions in plan over which a drum's projected bottom face is searched for the side
#: its centre of mass is nearest (then refined: :func:`face_distance`).
SEARCH_DIRECTIONS = 64

_ANGLES = np.arange(SEARCH_DIRECTIONS) * (2.0 * math.pi / SEARCH_DIRECTIONS)


@dataclass(frozen=True)
class Joints3d:
    """The stack's contacts at one instant, in three dimensions (index 0: base on ground).

    relative : (n,) angle between drum i's axis and its support's [rad] (>= 0)
    pivots : (n, 3) where drum i touches its support (ground axes) [m]: the point of its
        bottom rim it leans on, or its bottom face's centre where it does not lean
    lean : (n, 2) unit direction in plan (ground axes) drum i leans to on its support
        (where it does not lean, the last direction seen is kept by the watch)
    ratio : (n,) overturning measure over its limit (1: over the edge)
    twist : (n,) turn of drum i about its axis relative to its support [rad]
    azimuth : (n,) direction in plan (ground axes) of the lean of the drums above joint i:
        from the centre of drum i's bottom face to their centre of mass [rad]
    bottoms : (n, 3) centres of the drums' bottom faces (ground axes) [m]
    top : (3,) centre of the top face of the top drum (ground axes) [m]
    slip : (n, 2) sliding of drum i on its support, in plan (ground axes) [m]: the offset
        of its bottom face's centre from its support's top face's centre, less the offset
        b_i (1 - cos relative) along its lean that rocking on its rim gives without sliding
        (the planar joint_state's slip in any direction)
    """

    relative: np.ndarray
    pivots: np.ndarray
    lean: np.ndarray
    ratio: np.ndarray
    twist: np.ndarray
    azimuth: np.ndarray
    bottoms: np.ndarray
    top: np.ndarray
    slip: np.ndarray


def _supports(rot: np.ndarray) -> np.ndarray:
    """(n, 3, 3) the support's rotation of every joint: the ground's, then drum i - 1's."""
    return np.concatenate([np.eye(3)[None], rot[:-1]])


def _in(rot_s: np.ndarray, v: np.ndarray) -> np.ndarray:
    """rot_s^T v per joint: vectors (n, 3) in the ground's axes seen in the supports'."""
    return np.einsum("nji,nj->ni", rot_s, v)


def _shadow_gap(w: np.ndarray, normal: np.ndarray, radius: np.ndarray, angles) -> np.ndarray:
    """h(u) - c.u at the directions u of `angles` (n, m) [rad] (:func:`face_distance`)."""
    ux, uy = np.cos(angles), np.sin(angles)
    nu = normal[:, :1] * ux + normal[:, 1:2] * uy
    return (
        w[:, :1] * ux + w[:, 1:2] * uy + radius[:, None] * np.sqrt(np.maximum(0.0, 1.0 - nu * nu))
    )


def face_distance(w: np.ndarray, normal: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Signed distance in plan from a point to the edge of a tilted circle's shadow [m]
    (positive inside), per joint.

    w : (n, 2) the circle's centre less the point, in plan [m]
    normal : (n, 3) the circle's unit normal
    radius : (n,) its radius [m]

    The shadow of a circle of centre b and unit normal n on the plane has the support
    function h(u) = b.u + r sqrt(1 - (n.u)^2) for a unit u in plan, so the distance of a
    point c inside it to its edge is min over u of h(u) - c.u: taken over
    SEARCH_DIRECTIONS directions, then twice at the vertex of the parabola through the
    least value and its two neighbours, the second time on a stencil a sixteenth as
    wide. In a vertical plane through the normal it is the planar reading (b_x + r
    cos(phi) - c_x on the side the point leans to).
    """
    rows = np.arange(w.shape[0])
    values = _shadow_gap(w, normal, radius, _ANGLES[None, :])
    k = np.argmin(values, axis=1)
    centre = _ANGLES[k]
    step = _ANGLES[1]
    v0 = best = values[rows, k]
    for _ in range(2):
        vm, vp = _shadow_gap(w, normal, radius, centre[:, None] + np.array([-step, step]))[
            :, [0, 1]
        ].T
        curve = vp - 2.0 * v0 + vm
        with np.errstate(divide="ignore", invalid="ignore"):
            shift = np.where(curve > 0.0, 0.5 * (vm - vp) / curve, 0.0)
        centre = centre + np.clip(shift, -1.0, 1.0) * step
        v0 = _shadow_gap(w, normal, radius, centre[:, None])[:, 0]
        best = np.minimum(best, v0)
        step = step / 16.0
    return best


def joint_state_3d(frame: Frame, stack: StackGeometry, alpha: np.ndarray) -> Joints3d:
    """Leans, overturning ratios, contact points and twists of every joint, in three dimensions.

    Notes
    -----
    In the support's frame: the drums above joint i have their centre of mass at c; drum
    i's bottom face is a circle of radius b_i centred at b with normal n_i, the support's
    top face a circle of radius s_i about the origin (the ground: unbounded). The contact
    lies in the shadow of the one on the other, and the drums above fall over its edge
    when c passes it: with d the signed distance in plan from c to the edge of that
    shadow's intersection with the support's face (the smaller of the two distances,
    :func:`face_distance` and s_i - |c_h|), psi = atan2(d, c_z) and ratio = 1 - psi /
    alpha_i, as in the plane (where d is the distance to the nearer end of the contact
    segment). relative: the angle between n_i and the support's axis; lean: n_i's
    direction in plan; pivots: the rim point it leans on. Twist: the turn about the axis left
    when the drum's frame is tilted back onto its support's.
    """
    rot, centres = frame.rotations, frame.centres
    axis_z = rot[:, :, 2]
    bottoms = centres - stack.centres[:, None] * axis_z
    tops = centres + (stack.heights - stack.centres)[:, None] * axis_z
    rot_s = _supports(rot)
    origin = np.concatenate([np.zeros((1, 3)), tops[:-1]])
    b = _in(rot_s, bottoms - origin)
    normal = _in(rot_s, axis_z)
    moment = np.cumsum((stack.masses[:, None] * centres)[::-1], axis=0)[::-1]
    c = _in(rot_s, moment / stack.mass_above[:, None] - origin)
    sine = np.hypot(normal[:, 0], normal[:, 1])
    relative = np.arctan2(sine, normal[:, 2])
    with np.errstate(divide="ignore", invalid="ignore"):
        lean_s = np.where(sine[:, None] > 0.0, normal[:, :2] / sine[:, None], 0.0)
    d_face = face_distance(b[:, :2] - c[:, :2], normal, stack.half_bottom)
    d_support = stack.support_half - np.hypot(c[:, 0], c[:, 1])
    psi = np.arctan2(np.minimum(d_face, d_support), c[:, 2])
    ratio = 1.0 - psi / alpha
    rel = np.einsum("nji,njk->nik", rot_s, rot)  # drum i's frame in its support's
    twist = np.arctan2(rel[:, 1, 0] - rel[:, 0, 1], rel[:, 0, 0] + rel[:, 1, 1])
    lean = _plan(rot_s, lean_s)
    size = np.hypot(lean[:, 0], lean[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        lean = np.where(size[:, None] > 0.0, lean / size[:, None], 0.0)
    azimuth_v = _plan(rot_s, c[:, :2] - b[:, :2])
    # the rim point leant on: the lean's direction in the drum's bottom plane
    down = np.concatenate([lean_s, np.zeros((len(lean_s), 1))], axis=1)
    down -= np.sum(down * normal, axis=1)[:, None] * normal
    size = np.linalg.norm(down, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        reach = np.where(size[:, None] > 0.0, down / size[:, None], 0.0)
    pivot_s = b + stack.half_bottom[:, None] * reach
    pivots = origin + np.einsum("nij,nj->ni", rot_s, pivot_s)
    rocked = (stack.half_bottom * (1.0 - np.cos(relative)))[:, None] * lean_s
    return Joints3d(
        relative=relative,
        pivots=pivots,
        lean=lean,
        ratio=ratio,
        twist=twist,
        azimuth=np.arctan2(azimuth_v[:, 1], azimuth_v[:, 0]),
        bottoms=bottoms,
        top=tops[-1],
        slip=_plan(rot_s, b[:, :2] - rocked),
    )


def _plan(rot_s: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(n, 2) vectors in plan of the supports' frames, turned to the ground's axes (the
    support's tilt left out: its x-y plane's directions as seen from above)."""
    full = np.einsum("nij,nj->ni", rot_s[:, :, :2], v)
    return full[:, :2]


def contact_speeds(frame: Frame, pivots: np.ndarray) -> np.ndarray:
    """Speed at which every drum slides on its support at its contact [m/s]: the relative
    velocity of the two bodies' material points at the pivot, less its part along the
    support's normal (rolling on the rim: 0)."""
    v = frame.velocities + np.cross(frame.angular, pivots - frame.centres)
    below = np.concatenate([np.zeros((1, 3)), frame.velocities[:-1]])
    spin = np.concatenate([np.zeros((1, 3)), frame.angular[:-1]])
    centres = np.concatenate([np.zeros((1, 3)), frame.centres[:-1]])
    rel = v - (below + np.cross(spin, pivots - centres))
    up = normals(frame)[0]
    rel -= np.sum(rel * up, axis=1)[:, None] * up
    return np.linalg.norm(rel, axis=1)


def normals(frame: Frame) -> tuple[np.ndarray, np.ndarray]:
    """The unit normals a contact of every joint may have (ground axes): its support's
    top face's (the ground's, or drum i - 1's axis) and drum i's bottom face's (its axis).
    At the ground the only normal is the plane's (a rim on a plane), as in the plane."""
    axis_z = frame.rotations[:, :, 2]
    up = np.array([[0.0, 0.0, 1.0]])
    return np.concatenate([up, axis_z[:-1]]), np.concatenate([up, axis_z[1:]])


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle between vectors a and b, rowwise [rad] (atan2 of cross and dot: accurate
    near 0)."""
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1))


def arc_distance(f: np.ndarray, p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Angle from the direction of f to the shorter great-circle arc between the unit
    vectors p and q, rowwise [rad] (p = q: the angle to p)."""
    ends = np.minimum(_angle(f, p), _angle(f, q))
    m = np.cross(p, q)
    size = np.linalg.norm(m, axis=-1)
    out = ends.copy()
    arc = size > 1e-15
    if np.any(arc):
        m = m[arc] / size[arc, None]
        fa = f[arc]
        proj = fa - np.sum(fa * m, axis=-1)[:, None] * m  # f in the arc's plane
        # between p and q: the projection is on the arc's side of both ends
        pa, qa = p[arc], q[arc]
        inside = (
            (np.sum(np.cross(pa, proj) * m, axis=-1) >= 0.0)
            & (np.sum(np.cross(proj, qa) * m, axis=-1) >= 0.0)
            & (np.sum(proj * (pa + qa), axis=-1) > 0.0)
        )
        to_plane = np.arcsin(np.minimum(1.0, np.abs(np.sum(fa * m, axis=-1)) /
                                        np.linalg.norm(fa, axis=-1)))  # fmt: skip
        out[arc] = np.where(inside, to_plane, ends[arc])
    return out


def joint_friction_3d(
    before: Frame,
    after: Frame,
    stack: StackGeometry,
    duration: float,
    mean_accel: tuple[float, float],
    faces: list[tuple[np.ndarray, np.ndarray]],
    mean_up: float = 0.0,
) -> np.ndarray:
    """Mobilised friction of every joint over an interval, in three dimensions: the least
    |T| / N of the joint's mean force over the contact normals its faces admit [-] (nan:
    not loaded).

    Parameters
    ----------
    before, after : Frame  The stack at the start and end of the interval
    duration : float  Its length [s]
    mean_accel : (a_x, a_y)  Mean horizontal ground acceleration over it, as the engine
        applied it [m/s^2]
    faces : list of (support normals, drum normals)  The faces' normals at every frame
        read over the interval (:func:`normals`)
    mean_up : float  Mean upward ground acceleration a_v over it [m/s^2]

    Notes
    -----
    The joint's mean force is F_i = Delta P_i / Delta t + M_i (a_x, a_y, g + a_v), exactly
    (as in the plane, :func:`rbm_cli.models.bullet.scene.joint_friction`). At an open
    joint any normal between its two faces' is admissible: the reading is tan of the
    least angle from F_i to the arc between the two normals over the frames read. In a
    plane it is the planar reading.
    """
    momentum = stack.masses[:, None] * (after.velocities - before.velocities)
    above = np.cumsum(momentum[::-1], axis=0)[::-1]
    inertial = np.array([mean_accel[0], mean_accel[1], G + mean_up])
    force = above / duration + stack.mass_above[:, None] * inertial
    gap = np.min([arc_distance(force, p, q) for p, q in faces], axis=0)
    normal = np.linalg.norm(force, axis=1) * np.cos(gap)
    out = np.full(len(stack.masses), np.nan)
    loaded = (gap < 0.5 * math.pi) & (normal > 1e-6 * G * stack.mass_above)
    out[loaded] = np.tan(gap[loaded])
    return out
