"""The Rigid Beam Model in two horizontal directions (for `rbm-3d`): a column of circular
drums whose nodes move in x and y, each drum's small rotation a vector.

A drum's rotation is the pair (theta_x, theta_y): theta_x the small rotation that moves its
top along +x, theta_y along +y (so a planar run along x has theta_y = 0 and theta_x the
planar theta). The kinematics of the planar model hold in each direction on its own: the
nodes' displacements are node_map @ theta_x and node_map @ theta_y, the drums' centres
centre_map @ theta_x and @ theta_y, and the mass matrix M (a drum of circular section has
the same inertia I_G about every horizontal axis) is the planar one for both. The two
directions meet only in the joints. A circular joint of diameter D carries the same
capacity M_u = (D / 2) N in every direction, so its moment is the planar law f applied to
the magnitude of its relative rotation vector phi_i (the law's argument, D theta or theta
for `absolute`, in each direction), along that vector:

    m_i = -f(|phi_i|) phi_i / |phi_i|        (the moment restoring the joint),

and with it, per direction d = x, y (as the planar equations, rbm_cli.physics.equations),

    M theta_d'' = D^T m_d + gam K_g theta_d - r a_d(t) - D^T (c phi_d')  (elastic joints),

gam = (g + a_v) / g the vertical record's factor on the laws' weight parts and on gravity's
term K_g of `geometric` (the elastic parts K_M do not scale), c the joints' damping on their
elastic branch (Model.joint_damping). On the elastic branch f = K_M |phi| and the moment is
-K_M phi: the column is linear and the two directions do not meet at all.

Near a closed joint of a rigid law (f jumps at 0: a rigid monolith) the direction of phi is
round-off; there the law reads the component x = phi . c of phi along a pinned direction c
(the side the joint rocks onto), as a base flat to that side, and m = -f(x) c
(rbm_cli.models.rbm3d says when).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rbm_cli.physics.equations import Model
from rbm_cli.physics.law import law_arrays


@dataclass(frozen=True)
class Beam3d:
    """The arrays of one column's equations in two directions (SI units), made once by
    :func:`beam3d` from its planar Model.

    model : Model  The planar equations (mass, maps, laws, restitution, damping)
    minv, dt, argmap, gravity, load : the planar M^-1, D^T, the argument map, K_g, r
    edges : (n, m) each law's edges [rad], padded with inf; nedges (n,) their number
    a, bw, be : (n, m + 1) each piece's intercept [N m] and the weight and elastic parts of
        its slope [N m/rad] (Model.slope_parts)
    edge_w : (n, m) the kinks' weight shares (Model.edge_weight_shares)
    rigid : (n,) rigid laws; damp : (n,) the joints' damping on their elastic branch
    collapse : (n, n) theta -> collapse quantity over its limit, per direction
    heights : (n,) theta -> the top's displacement, per direction [m/rad]
    """

    model: Model
    minv: np.ndarray
    dt: np.ndarray
    argmap: np.ndarray
    gravity: np.ndarray
    load: np.ndarray
    edges: np.ndarray
    nedges: np.ndarray
    a: np.ndarray
    bw: np.ndarray
    be: np.ndarray
    edge_w: np.ndarray
    rigid: np.ndarray
    damp: np.ndarray
    collapse: np.ndarray
    heights: np.ndarray

    @property
    def n(self) -> int:
        return self.model.n

    def arguments(self, theta_x: np.ndarray, theta_y: np.ndarray):
        """(phi_x, phi_y): the joints' relative rotation vectors (n, ...) [rad]."""
        return self.argmap @ theta_x, self.argmap @ theta_y

    def edge(self, i: int, q: int, gam: float | np.ndarray = 1.0):
        """Joint i's kink q [rad] under gam = (g + a_v) / g: E gam / (1 + w (gam - 1)) (where
        the pieces' lines cross, Model.edge_weight_shares); inf past the last."""
        if q >= self.nedges[i]:
            return np.inf
        e, w = self.edges[i, q], self.edge_w[i, q]
        return e * gam / (1.0 + w * (gam - 1.0))

    def moments(self, phx, phy, dphx, dphy, k, pinned, c, gam: float = 1.0):
        """The joints' moment vectors (m_x, m_y) (n,) [N m] at arguments phi (n,) and their
        rates [rad/s], each joint on piece k_i of its law (|phi_i| between its edges k_i - 1
        and k_i), read along its pinned direction c_i (n, 2) where pinned_i."""
        rows = np.arange(phx.size)
        a, slope = gam * self.a[rows, k], gam * self.bw[rows, k] + self.be[rows, k]
        r = np.hypot(phx, phy)
        per_r = np.divide(a, r, out=np.zeros_like(r), where=r > 0.0)
        mx, my = -(per_r + slope) * phx, -(per_r + slope) * phy
        if pinned.any():
            along = a + slope * (phx * c[:, 0] + phy * c[:, 1])
            mx = np.where(pinned, -along * c[:, 0], mx)
            my = np.where(pinned, -along * c[:, 1], my)
        if self.model.damping > 0.0:
            elastic = self.damp * ((k == 0) & ~self.rigid)
            mx, my = mx - elastic * dphx, my - elastic * dphy
        return mx, my

    def rates(self, y: np.ndarray, ax: float, ay: float, gam: float, k, pinned, c):
        """y' of the state y = (theta_x, theta_y, theta_x', theta_y') (4n,) under the ground
        acceleration (a_x, a_y) [m/s^2] and gam (:meth:`moments` for k, pinned, c)."""
        n = self.n
        tx, ty, vx, vy = y[:n], y[n : 2 * n], y[2 * n : 3 * n], y[3 * n :]
        phx, phy = self.argmap @ tx, self.argmap @ ty
        mx, my = self.moments(phx, phy, self.argmap @ vx, self.argmap @ vy, k, pinned, c, gam)
        accx = self.minv @ (self.dt @ mx + gam * (self.gravity @ tx) - self.load * ax)
        accy = self.minv @ (self.dt @ my + gam * (self.gravity @ ty) - self.load * ay)
        return np.concatenate([vx, vy, accx, accy])

    def ratios(self, yy: np.ndarray):
        """The collapse quantities over their limits (n, ...) [-] and their rates [-/s] of
        states yy (4n, ...): the magnitude of each joint's pair (collapse @ theta_x,
        collapse @ theta_y)."""
        return _magnitudes(self.collapse, yy, self.n)

    def top(self, yy: np.ndarray):
        """The top's displacement in plan from the column's axis, its magnitude [m] and
        rate [m/s] (...)."""
        v, dv = _magnitudes(self.heights[None, :], yy, self.n)
        return v[0], dv[0]

    def shear_demand(self, acc_x, acc_y, ax: float, ay: float, gam: float) -> np.ndarray:
        """|T_i| / (N_i gam) (n,) [-]: the resultant shear of the drums above each joint over
        its normal force, from the drums' theta'' (n,) per direction [rad/s^2] and the
        ground's acceleration (a_x, a_y) [m/s^2]."""
        col = self.model.column
        cm = self.model.centre_map
        fx = (cm @ acc_x + ax) * col.masses
        fy = (cm @ acc_y + ay) * col.masses
        tx, ty = np.cumsum(fx[::-1])[::-1], np.cumsum(fy[::-1])[::-1]
        return np.hypot(tx, ty) / (col.normal_forces * gam)


def _magnitudes(rows: np.ndarray, yy: np.ndarray, n: int):
    """|(rows @ theta_x, rows @ theta_y)| and its rate, for states yy (4n, ...)."""
    vx, vy = rows @ yy[:n], rows @ yy[n : 2 * n]
    dx, dy = rows @ yy[2 * n : 3 * n], rows @ yy[3 * n :]
    mag = np.hypot(vx, vy)
    safe = np.where(mag > 0.0, mag, 1.0)
    return mag, (vx * dx + vy * dy) / safe


def beam3d(model: Model) -> Beam3d:
    """The equations in two directions of a column's planar Model (circular drums)."""
    edges, nedges, a, _, rigid = law_arrays(model.laws)
    weight, elastic = model.slope_parts
    return Beam3d(
        model=model,
        minv=model.mass_inv,
        dt=model.diff.T.copy(),
        argmap=model.arg_map,
        gravity=model.gravity,
        load=model.ground_load,
        edges=edges,
        nedges=nedges,
        a=a,
        bw=weight,
        be=elastic,
        edge_w=model.edge_weight_shares,
        rigid=rigid,
        damp=model.joint_damping,
        collapse=model.collapse_map / model.collapse_limit[:, None],
        heights=model.column.heights.astype(float),
    )
