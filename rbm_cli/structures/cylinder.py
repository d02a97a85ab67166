"""The rigid cylinder that rocks and rolls on the rim of its base in three dimensions (for
`housner-3d`): its geometry, its equations of motion under a ground acceleration in any
horizontal direction, and its energy.

A monolithic column of circular section (a tapered cylinder: a frustum) stands on a rigid
ground. Once it lifts it touches the ground at one point P of its base's rim and rolls on
that rim without sliding (no twist about the vertical at P either is imposed: the spin
about its own axis is free). Its state is

- q = (n_x, n_y): the horizontal part of its axis n (a unit vector, n_z = sqrt(1 - |q|^2)
  > 0): q points where the column leans, |q| = sin(theta) with theta its tilt from the
  vertical; q stays exact near the vertical, where n_z does not;
- w = (w_x, w_y, w_z): its angular velocity [rad/s], in the ground's axes;
- g = (x_G, y_G): where its centre of mass is in plan [m], from where it stood.

With c = q / |q| the direction it leans (the contact direction), the base-plane unit
vector from the base's centre to P is u = (n_z c, -|q|), and r = h n - R u runs from P to
the centre of mass (R the base's radius, h the centre's height above the base along the
axis). Rolling without sliding makes P's material point still, so the centre moves at
v_G = w x r. The moment of the contact force about the centre, with
m a_G = F + m g_e (g_e = (-a_x, -a_y, -(g + a_v)) the weight and the ground's inertia
force per unit mass in the ground's axes), gives

    J_P w' = -w x (I_G w) - m r x (w x r') + m r x g_e,
    J_P = I_G + m (|r|^2 1 - r r^T),   I_G = I_t (1 - n n^T) + I_a n n^T,

with r' = h n' - R u' and n' = w x n (Srinivasan and Ruina 2008 write the same rolling
equations for any body of revolution). In a vertical plane (q and w_y only, w_x = w_z = 0)
this is Housner's equation of the block whose corner is the rim's point in that plane:
theta'' = -p^2 [sin(alpha - theta) + (a / g) cos(alpha - theta)], p^2 = m g |r| / I_O,
I_O = I_t + m |r|^2 (the rotary inertia about the tangent to the rim at P).

At q = 0 the contact direction is not defined by q, and a lean that passes the vertical
at a distance delta turns the contact point round the rim at a rate |q'| / delta
(Srinivasan and Ruina 2008): as delta goes to 0, without bound. Within a *pinned lean* of
the vertical the column's contact direction is therefore held at a given c0 (the side it
lifts to or rocks onto, or the direction it leaned as it came within that lean): the base
strikes or leaves the ground as a whole there. That lean is a numerical one, not a
flatness of the stone: rbm_cli.models.housner3d ties it to the integrator's absolute
tolerance of the lean (solver.atol alpha; housner3d.runner.pinned_lean), so that the
answer is the rigid cylinder's, converged as the tolerances shrink.

References
----------
.. [1] M. Srinivasan and A. Ruina (2008). Rocking and rolling: a can that appears to rock
   might actually roll. Physical Review E 78, 066609.
.. [2] G. W. Housner (1963). The behavior of inverted pendulum structures during
   earthquakes. Bulletin of the Seismological Society of America 53(2), 403-417.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import Polynomial

from rbm_cli.config.types import ColumnConfig, G
from rbm_cli.structures.block import BlockGeometry, block_geometry

#: Number of state components: q (2), w (3), the centre in plan (2).
STATE_SIZE = 7


@dataclass(frozen=True)
class CylinderGeometry:
    """The rigid cylinder (frustum) of a monolithic circular column.

    block : BlockGeometry  The same solid as Housner's planar block (alpha, p, m, ...)
    radius : float  R, the base's radius [m]
    centre_height : float  h, the centre of mass above the base's centre [m]
    height : float  H [m]
    mass : float  m [kg]
    transverse : float  I_t, rotary inertia about a horizontal axis through the centre of
        mass when upright [kg m^2]
    axial : float  I_a, rotary inertia about the column's own axis [kg m^2]
    """

    block: BlockGeometry
    radius: float
    centre_height: float
    height: float
    mass: float
    transverse: float
    axial: float

    @property
    def slenderness(self) -> float:
        """alpha = atan(R / h) [rad]."""
        return self.block.slenderness


def cylinder_geometry(column: ColumnConfig) -> CylinderGeometry:
    """The rigid cylinder of a monolithic column of circular section (ValueError for any
    other section: a rectangular block's capacity is not the same in every direction).

    Notes
    -----
    With w(z) the diameter at height z and rho the density, exactly (polynomial
    integrals): I_a = rho int pi w^4 / 32 dz, and I_t = I_O - m |r|^2 from the planar
    block's rotary inertia I_O about the rim's tangent (rbm_cli.structures.block).
    """
    if column.section != "circular":
        raise ValueError("cylinder_geometry: a circular section only")
    blk = block_geometry(column)
    H, b1, bt = column.height, column.base_width, column.top_width
    w = Polynomial([b1, (bt - b1) / H])
    axial = column.density * float((math.pi / 32.0 * w**4).integ()(H))
    lever2 = blk.half_base**2 + blk.centre_height**2
    return CylinderGeometry(
        block=blk,
        radius=blk.half_base,
        centre_height=blk.centre_height,
        height=H,
        mass=blk.mass,
        transverse=blk.corner_inertia - blk.mass * lever2,
        axial=axial,
    )


def axis(q: np.ndarray) -> np.ndarray:
    """The unit axis n = (q_x, q_y, sqrt(1 - |q|^2)) of a lean q."""
    s2 = q[0] * q[0] + q[1] * q[1]
    return np.array([q[0], q[1], math.sqrt(max(0.0, 1.0 - s2))])


def tilt(q: np.ndarray) -> float:
    """theta = atan2(|q|, n_z) [rad], the tilt from the vertical."""
    s = math.hypot(q[0], q[1])
    return math.atan2(s, math.sqrt(max(0.0, 1.0 - s * s)))


def lean_direction(q: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    """c = q / |q|, the horizontal unit vector the column leans to (the fallback at q = 0)."""
    s = math.hypot(q[0], q[1])
    if s == 0.0:
        return fallback
    return np.array([q[0] / s, q[1] / s])


def _contact_arm(geo: CylinderGeometry, n: np.ndarray, c: np.ndarray, s: float) -> np.ndarray:
    """r = h n - R u, from the contact point P to the centre of mass [m]."""
    u = np.array([n[2] * c[0], n[2] * c[1], -s])
    return geo.centre_height * n - geo.radius * u


def _inertia(geo: CylinderGeometry, n: np.ndarray) -> np.ndarray:
    """I_G = I_t (1 - n n^T) + I_a n n^T [kg m^2] in the ground's axes."""
    nn = np.outer(n, n)
    return geo.transverse * (np.eye(3) - nn) + geo.axial * nn


def _cross(a0, a1, a2, b0, b1, b2):
    """a x b of two vectors given by their components."""
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


def rolling_rates(
    geo: CylinderGeometry, y: np.ndarray, c0: np.ndarray, ge: np.ndarray, pinned: bool = False
) -> np.ndarray:
    """The state's rate y' = (q', w', v_G in plan) (module docstring), in scalars (a
    3 x 3 system solved by its adjugate: a numpy call per vector product cost 35 us).

    Parameters
    ----------
    geo : CylinderGeometry
    y : (7,) State (q [-], w [rad/s], centre in plan [m])
    c0 : (2,) The contact direction where q = 0, and wherever pinned
    ge : (3,) g_e = (-a_x, -a_y, -(g + a_v)) [m/s^2]
    pinned : bool  The contact direction is c0 (a column within the pinned lean of the
        vertical, module docstring), not q's own
    """
    qx, qy = float(y[0]), float(y[1])
    w0, w1, w2 = float(y[2]), float(y[3]), float(y[4])
    s = math.hypot(qx, qy)
    nz = math.sqrt(max(0.0, 1.0 - s * s))
    fixed = pinned or s == 0.0
    cx, cy = (float(c0[0]), float(c0[1])) if fixed else (qx / s, qy / s)
    h, rad, m = geo.centre_height, geo.radius, geo.mass
    # r = h n - R u, u = (n_z c, -s): from the contact point to the centre of mass
    r0, r1, r2 = h * qx - rad * nz * cx, h * qy - rad * nz * cy, h * nz + rad * s
    dn0, dn1, dn2 = _cross(w0, w1, w2, qx, qy, nz)
    # the contact direction turns as the lean's component across it: c' = (q' - c s') / s
    ds = cx * dn0 + cy * dn1
    dcx, dcy = (0.0, 0.0) if fixed else ((dn0 - cx * ds) / s, (dn1 - cy * ds) / s)
    du0, du1, du2 = dn2 * cx + nz * dcx, dn2 * cy + nz * dcy, -ds
    dr0, dr1, dr2 = h * dn0 - rad * du0, h * dn1 - rad * du1, h * dn2 - rad * du2
    # I_G = I_t 1 + (I_a - I_t) n n^T; J_P = I_G + m (|r|^2 1 - r r^T)
    it, d_ia = geo.transverse, geo.axial - geo.transverse
    wn = w0 * qx + w1 * qy + w2 * nz
    iw0, iw1, iw2 = it * w0 + d_ia * wn * qx, it * w1 + d_ia * wn * qy, it * w2 + d_ia * wn * nz
    a0, a1, a2 = _cross(w0, w1, w2, iw0, iw1, iw2)
    v0, v1, v2 = _cross(w0, w1, w2, dr0, dr1, dr2)
    b0, b1, b2 = _cross(r0, r1, r2, v0, v1, v2)
    g0, g1, g2 = _cross(r0, r1, r2, float(ge[0]), float(ge[1]), float(ge[2]))
    f0, f1, f2 = -a0 - m * b0 + m * g0, -a1 - m * b1 + m * g1, -a2 - m * b2 + m * g2
    rr = r0 * r0 + r1 * r1 + r2 * r2
    j00 = it + d_ia * qx * qx + m * (rr - r0 * r0)
    j11 = it + d_ia * qy * qy + m * (rr - r1 * r1)
    j22 = it + d_ia * nz * nz + m * (rr - r2 * r2)
    j01 = d_ia * qx * qy - m * r0 * r1
    j02 = d_ia * qx * nz - m * r0 * r2
    j12 = d_ia * qy * nz - m * r1 * r2
    # J_P w' = f by the adjugate of the symmetric J_P
    k00, k11, k22 = j11 * j22 - j12 * j12, j00 * j22 - j02 * j02, j00 * j11 - j01 * j01
    k01, k02, k12 = j02 * j12 - j01 * j22, j01 * j12 - j02 * j11, j01 * j02 - j00 * j12
    det = j00 * k00 + j01 * k01 + j02 * k02
    out = np.empty(STATE_SIZE)
    out[0], out[1] = dn0, dn1
    out[2] = (k00 * f0 + k01 * f1 + k02 * f2) / det
    out[3] = (k01 * f0 + k11 * f1 + k12 * f2) / det
    out[4] = (k02 * f0 + k12 * f1 + k22 * f2) / det
    vg0, vg1, _ = _cross(w0, w1, w2, r0, r1, r2)
    out[5], out[6] = vg0, vg1
    return out


def cylinder_energy(
    geo: CylinderGeometry, y: np.ndarray, c0: np.ndarray, pinned: bool = False
) -> float:
    """Kinetic plus potential energy above rest [J] in the ground's axes (conserved in
    free motion): w^T I_G w / 2 + m |v_G|^2 / 2 + m g (z_G - h), z_G = h n_z + R |q|."""
    q, w = y[0:2], y[2:5]
    n = axis(q)
    s = math.hypot(q[0], q[1])
    r = _contact_arm(geo, n, c0 if pinned else lean_direction(q, c0), s)
    v_g = np.cross(w, r)
    m = geo.mass
    kinetic = 0.5 * float(w @ _inertia(geo, n) @ w) + 0.5 * m * float(v_g @ v_g)
    return kinetic + m * G * (float(r[2]) - geo.centre_height)


def lean_rates(y: np.ndarray) -> np.ndarray:
    """q' = (w x n) in plan [1/s], the lean's rate, of states y (7,) or (7, m)."""
    q, w = y[0:2], y[2:5]
    s2 = q[0] * q[0] + q[1] * q[1]
    nz = np.sqrt(np.maximum(0.0, 1.0 - s2))
    return np.array([w[1] * nz - w[2] * q[1], w[2] * q[0] - w[0] * nz])


def tilt_in_plane(y: np.ndarray, d: np.ndarray) -> tuple[float, float]:
    """The tilt seen in the vertical plane of the unit vector d in plan, atan2(q . d, n_z)
    [rad], and its rate [rad/s]: Housner's theta and theta' for a motion in that plane."""
    q = y[0:2]
    along = float(q[0] * d[0] + q[1] * d[1])
    nz = float(axis(q)[2])
    dq = lean_rates(y)
    d_along = float(dq[0] * d[0] + dq[1] * d[1])
    d_nz = -float(q[0] * dq[0] + q[1] * dq[1]) / nz if nz > 0.0 else 0.0
    den = along * along + nz * nz
    return math.atan2(along, nz), (nz * d_along - along * d_nz) / den if den > 0.0 else 0.0


def top_in_plan(geo: CylinderGeometry, y: np.ndarray) -> np.ndarray:
    """The top's centre in plan [m], from where it stood: x_G + (H - h) q."""
    return y[5:7] + (geo.height - geo.centre_height) * y[0:2]


def uplift_level(geo: CylinderGeometry) -> float:
    """The horizontal ground acceleration that lifts the upright cylinder [m/s^2]:
    g tan(alpha) = g R / h (per g of g + a_v)."""
    return G * geo.radius / geo.centre_height


__all__ = [
    "STATE_SIZE",
    "CylinderGeometry",
    "axis",
    "cylinder_energy",
    "cylinder_geometry",
    "lean_direction",
    "lean_rates",
    "rolling_rates",
    "tilt",
    "tilt_in_plane",
    "top_in_plan",
    "uplift_level",
]
