"""The Rigid Beam Model equations (paper eqs. 1-5), assembled once per column.

Generalised coordinates are the absolute drum rotations theta_i; the nodal
displacements relative to the ground are u_{k+1} = sum_{j<=k} h_j theta_j. In
these coordinates the paper's system (5) reads

    M theta'' = D^T m(x) + K_g theta - r a_g(t)  (- D^T C x' with damping)

with M = L^T diag(m) L + diag(I_G) the (constant, symmetric) mass matrix,
L the map from theta to the drums' centre displacements (weight at the drum's centre,
mid-height but for the drum carrying a top mass: L_ij = h_j for j < i, c_i for j = i),
r = L^T m the ground load vector,
D the difference matrix (D^T M gives M_i - M_{i+1}: interface moments acting
on the drums above and below), m(x) = -f(x) the interface moments, x the
argument the law reads (phi = D theta, or theta for `absolute`), and K_g the
gravity term of the `geometric` formulation. Eliminating the shears T of
eq. (1) gives the same system; for n = 1 it is
(I_G + m h^2 / 4) theta'' = -f(theta) - m (h / 2) a_g.

Inside one set of active law pieces the right-hand side is linear:
theta'' = A theta + c + e a_g(t).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from rbm_cli.base.detmath import inverse, product
from rbm_cli.config.types import G
from rbm_cli.structures.column import Column
from rbm_cli.structures.law import Law, law_sum, make_law

#: Significant digits of the first elastic frequency where it sets the joints' damping. The
#: eigenvalue solver (LAPACK) rounds its last bits as the processor's kernels do, so the
#: frequency can differ by an ulp or two between machines; rounded, it is the same on
#: every machine (but for a frequency within a few ulp of a rounding boundary), and so is
#: every damped run. The damping ratio it sets is exact to 1e-10 relative.
DAMPING_DIGITS = 10


@dataclass(frozen=True)
class Model:
    """Assembled equations of one column (SI units): n drums, m joints with a law (n, or
    n + 1 with a frame's beam joint, rbm_cli.structures.frame), the drums' bodies and a
    frame's beam share (centre_map's last row, on the top node).

    mass : (n, n) Mass matrix M [kg m^2]
    mass_inv : (n, n) M^-1
    ground_load : (n,) r = L^T m [kg m]
    centre_map : (bodies, n) L, theta -> the bodies' centre displacements [m]
    node_map : (n+1, n) theta -> node displacements relative to the ground [m]
    arg_map : (m, n) theta -> law arguments x (D, or I for `absolute`)
    diff : (m, n) D
    gravity : (n, n) K_g [N m/rad] (zero unless `geometric`)
    laws : tuple of Law, one per joint
    collapse_map : (m, n) theta -> collapse quantities (law arguments, or
        overturning moments of the stacks above each joint for `geometric`)
    collapse_limit : (m,) their limits (theta_u [rad] or M_u [N m])
    collapse_ratio : float  c, collapse when |quantity| >= c * limit
    restitution : float  e, angular-velocity ratio at an impact
    formulation : str
    xi : float  Smoothing parameter of the laws [-]
    damping : float  zeta, the ratio of critical damping of the first elastic mode [-]
        (:attr:`joint_damping`)
    """

    column: Column
    mass: np.ndarray
    mass_inv: np.ndarray
    ground_load: np.ndarray
    centre_map: np.ndarray
    node_map: np.ndarray
    arg_map: np.ndarray
    diff: np.ndarray
    gravity: np.ndarray
    laws: tuple[Law, ...]
    collapse_map: np.ndarray
    collapse_limit: np.ndarray
    collapse_ratio: float
    restitution: float
    formulation: str
    xi: float = 1.0
    damping: float = 0.0

    @property
    def n(self) -> int:
        return self.mass.shape[0]

    @property
    def joints(self) -> int:
        """Joints with a law (n, or n + 1 with a frame's beam joint)."""
        return len(self.laws)

    @property
    def rigid(self) -> bool:
        return any(law.rigid for law in self.laws)

    @cached_property
    def friction_normals(self) -> np.ndarray:
        """The normal forces at rest [N] of the joints whose friction demand a run reports
        (|T_i / N_i|): every joint with a law, and a monolithic frame's beam joint, whose law
        is folded into the base's (Column.beam_law) but whose shear, the beam share's
        inertia force, is its own: N = W_b / N (the beam share's weight), last."""
        col = self.column
        if col.beam_law is not None:
            return np.append(col.normal_forces, col.beam_mass * G)
        return col.normal_forces

    @property
    def friction_joints(self) -> int:
        """Joints whose friction demand a run reports (:attr:`friction_normals`): the joints,
        and a monolithic frame's beam joint."""
        return len(self.friction_normals)

    def arguments(self, theta: np.ndarray) -> np.ndarray:
        """Law arguments x (..., n) of rotations theta (..., n) [rad]."""
        return theta @ self.arg_map.T

    def collapse_ratios(self, theta: np.ndarray) -> np.ndarray:
        """|collapse quantity| / limit (..., n); collapse at collapse_ratio."""
        return np.abs(theta @ self.collapse_map.T) / self.collapse_limit

    def energy(self, theta: np.ndarray, rate: np.ndarray) -> np.ndarray:
        """Energy relative to the ground [J]: kinetic + the laws' potential
        (+ gravity's for `geometric`). Conserved in free motion with e = 1
        for `relative` and `geometric`."""
        theta, rate = np.atleast_2d(theta), np.atleast_2d(rate)
        kin = 0.5 * np.einsum("ki,ij,kj->k", rate, self.mass, rate)
        x = self.arguments(theta)
        pot = sum(law.potential(x[:, i]) for i, law in enumerate(self.laws))
        grav = -0.5 * np.einsum("ki,ij,kj->k", theta, self.gravity, theta)
        return kin + pot + grav

    @property
    def rocking_p(self) -> float:
        """p of the column rocking as one rigid stack on its base [rad/s]:
        p^2 = N_1 zbar_1 / (1^T M 1); for n = 1, m g (H/2) / (I_G + m H^2/4)."""
        col = self.column
        ones = np.ones(self.n)
        return math.sqrt(
            col.normal_forces[0] * col.lever_arms[0] / product(ones, product(self.mass, ones))
        )

    @property
    def uplift_level(self) -> float | None:
        """Ground acceleration at which a rigid monolith starts rocking [m/s^2]:
        f(0+) / (m h / 2) = xi M_u / (m h / 2); None unless n = 1 with a rigid law."""
        if self.n != 1 or not self.laws[0].rigid:
            return None
        return float(self.laws[0].intercepts[0] / abs(self.ground_load[0]))

    @cached_property
    def argument_scale(self) -> np.ndarray:
        """(m,) the rotation each joint's argument is watched over [rad]: its theta_u, and
        for a frame's beam joint (theta_u infinite: no descending branch) the top drum's."""
        tu = self.column.rotation_capacity
        if self.joints == self.n:
            return tu
        return np.where(np.isfinite(tu), tu, tu[self.n - 1])

    @cached_property
    def arg_inverse(self) -> np.ndarray:
        """(n, m) the moves of the drum rotations that change one joint's argument by 1: the
        inverse of the argument map for n joints; a frame's beam joint (argument -theta_n)
        moves the top drum alone (and so changes the top drum's joint by -1)."""
        n = self.n
        if self.joints == n:
            return inverse(self.arg_map)
        beam = np.zeros((n, 1))
        beam[n - 1, 0] = -1.0
        return np.hstack([inverse(self.arg_map[:n]), beam])

    @cached_property
    def silent_impacts(self) -> np.ndarray:
        """(n,) bool: interfaces whose impact changes nothing (e = 1 and a law linear
        through zero on its first piece), so a zero crossing after an excursion need
        not stop the integrator (events.Pieces.settle and the kernel count it)."""
        return np.array(
            [
                self.restitution == 1.0 and not law.rigid
                and len(law.edges) > 0 and law.intercepts[0] == 0.0
                for law in self.laws
            ],
            dtype=bool,
        )  # fmt: skip

    def elastic_frequencies_hz(self) -> list[float]:
        """Natural frequencies [Hz] of the column on the elastic branches of its laws,
        ascending (none for a rigid law)."""
        if self.rigid:
            return []
        slopes = np.array([law.slopes[0] for law in self.laws])
        # lazy: scipy.linalg loads only where needed (docs/architecture.md, Start-up)
        from scipy.linalg import eig  # here: no scipy at import (a shorter start-up)

        w2 = np.real(eig(self.stiffness(slopes), self.mass, right=False))
        return sorted(float(math.sqrt(v) / (2 * math.pi)) for v in w2 if v > 0)

    @cached_property
    def joint_damping(self) -> np.ndarray:
        """(n,) viscous coefficients c_i [N m s/rad] of the joints on their elastic branch:
        c_i = beta K_M,i with beta = 2 zeta / omega_1, omega_1 the first elastic circular
        frequency. The damping moment c_i x_i' acts while interface i is on the first piece
        of its law (elastic), not once it has lifted off: stiffness-proportional (Rayleigh
        beta) damping of the elastic column, which gives its first mode the ratio zeta
        exactly (C = beta K for `relative` and `absolute`; for `geometric` K also holds
        gravity's softening, and zeta is then the first mode's ratio to first order) and
        leaves rigid-body rocking undamped (impacts dissipate it, as for an undamped
        column). Zero without damping or for a rigid law. omega_1 is that of the first
        frequency rounded to DAMPING_DIGITS significant digits [Hz]."""
        out = np.zeros(self.joints)
        if self.damping == 0.0 or self.rigid:
            return out
        f_1 = float(f"{self.elastic_frequencies_hz()[0]:.{DAMPING_DIGITS}g}")
        omega_1 = 2.0 * math.pi * f_1
        beta = 2.0 * self.damping / omega_1
        return beta * np.asarray(self.column.stiffness, dtype=float)

    @cached_property
    def impulse_directions(self) -> tuple[np.ndarray, np.ndarray]:
        """(D, w) of an impact at joint i: the impulsive moment acts along P^T e_i, so
        the rates change along column i of D = M^-1 P^T; w_i = e_i^T P M^-1 P^T e_i."""
        directions = product(self.mass_inv, self.arg_map.T)
        w = np.array([product(self.arg_map[i], directions[:, i]) for i in range(self.joints)])
        return directions, w

    def impact_rates(self, rate: np.ndarray, i: int) -> np.ndarray:
        """Drum rates [rad/s] after an impact at joint i (its argument's rate times e).

        Momentum-consistent: an impulsive moment along the joint's direction, so the
        kinetic energy changes by -(1 - e^2) xdot_i^2 / (2 w_i) <= 0 (identical to the
        paper's rule for n = 1). `absolute` keeps the paper's wording: only the
        joint's own rate is scaled, the others unchanged."""
        xdot = float(self.arg_map[i] @ rate)
        if self.formulation == "absolute":
            return rate + self.arg_inverse[:, i] * (self.restitution - 1.0) * xdot
        directions, w = self.impulse_directions
        return rate + directions[:, i] * ((self.restitution - 1.0) * xdot / w[i])

    def stiffness(self, slopes: np.ndarray) -> np.ndarray:
        """Stiffness matrix [N m/rad] of active law pieces of the given slopes,
        gravity of the `geometric` formulation included."""
        return product(self.diff.T, slopes[:, None] * self.arg_map) - self.gravity

    def linear_system(self, intercepts: np.ndarray, slopes: np.ndarray):
        """(A, c, e) of theta'' = A theta + c + e a_g for active pieces
        f_i(x) = intercepts_i + slopes_i x."""
        minv = self.mass_inv
        stiff = self.stiffness(slopes)
        c = product(self.diff.T, intercepts)
        return -product(minv, stiff), -product(minv, c), -product(minv, self.ground_load)

    # ---- vertical shaking: the weight and non-weight parts of the laws
    @cached_property
    def slope_parts(self) -> tuple[np.ndarray, np.ndarray]:
        """(weight, elastic) parts of every piece's slope, (n, max pieces) each, padded with 0
        [N m/rad]: under g + a_v(t) a piece is f = gam (a_k + bs_k x) + be_k x with
        gam = (g + a_v) / g. The weight part is the descending branch's -M_u / theta_u and the
        `geometric` extra slope M_u / theta_u; the elastic part is K_M on the elastic branch
        (piece 0 of a law with a finite stiffness), 0 elsewhere."""
        width = max(len(law.slopes) for law in self.laws)
        weight, elastic = np.zeros((self.joints, width)), np.zeros((self.joints, width))
        for i, law in enumerate(self.laws):
            m = len(law.slopes)
            weight[i, :m] = law.slopes
            if not law.rigid:
                stiff = float(self.column.stiffness[i])
                extra = self._extra_slope(i)
                weight[i, 0], elastic[i, 0] = extra, stiff
        return weight, elastic

    def _extra_slope(self, i: int) -> float:
        """The `geometric` formulation's extra slope M_u / theta_u of law i (0 otherwise)."""
        if self.formulation != "geometric":
            return 0.0
        col = self.column
        return float(col.moment_capacity[i] / col.rotation_capacity[i])

    @cached_property
    def edge_weight_shares(self) -> np.ndarray:
        """(n, max edges) w_q, padded with 1: under gam = (g + a_v) / g the kink q between
        pieces q and q+1 (where their lines cross) moves to x_q(gam) = E_q gam / (1 + w_q (gam
        - 1)), E_q its position at gam = 1 [rad]: w = dbs / (dbs + dbe), the weight share of
        the two lines' slope difference. 1: a kink between two weight lines, fixed (the cap's
        end theta_u (1 - xi)); 0: elastic against the cap, x = gam xi M_u / K_M; between:
        elastic against the descending branch."""
        weight, elastic = self.slope_parts
        width = max(1, max(len(law.edges) for law in self.laws))
        shares = np.ones((self.joints, width))
        for i, law in enumerate(self.laws):
            for q in range(len(law.edges)):
                dbs = weight[i, q + 1] - weight[i, q]
                dbe = elastic[i, q + 1] - elastic[i, q]
                if dbe != 0.0:
                    shares[i, q] = dbs / (dbs + dbe)
        return shares

    def shape_range(self) -> tuple[float, float]:
        """(lowest, highest) gam = (g + a_v) / g [-] over which every law keeps the order of
        its pieces (the lower envelope of K_M x, xi gam M_u, gam M_u (1 - x / theta_u)): with
        xi < 1 and a finite K_M the cap xi gam M_u is on the envelope while the elastic end
        xi gam M_u / K_M is below the cap's end theta_u (1 - xi), i.e. for gam below
        gam_c = K_M theta_u (1 - xi) / (xi M_u). The integrators keep the pieces of gam = 1:
        gam must stay on the same side of every gam_c."""
        lo, hi = 0.0, math.inf
        col = self.column
        for i, law in enumerate(self.laws):
            if law.rigid or self.xi >= 1.0:
                continue
            gam_c = (float(col.stiffness[i]) * float(col.rotation_capacity[i]) * (1.0 - self.xi)
                     / (self.xi * float(col.moment_capacity[i])))  # fmt: skip
            if len(law.edges) >= 2:  # elastic, cap, descending: the cap while gam < gam_c
                hi = min(hi, gam_c)
            else:  # elastic then descending: no cap while gam >= gam_c
                lo = max(lo, gam_c)
        return lo, hi

    def vertical_system(self, intercepts: np.ndarray, weight: np.ndarray, elastic: np.ndarray):
        """(Aw, Ae, c, e) of theta'' = gam (Aw theta + c) + Ae theta + e a_g for active pieces
        f_i = gam (intercepts_i + weight_i x) + elastic_i x (gam = (g + a_v) / g): the weight
        part (gravity of `geometric` included) scales with gam, the joint stiffness does not."""
        minv = self.mass_inv
        aw = -product(minv, product(self.diff.T, weight[:, None] * self.arg_map) - self.gravity)
        ae = -product(minv, product(self.diff.T, elastic[:, None] * self.arg_map))
        c = product(self.diff.T, intercepts)
        return aw, ae, -product(minv, c), -product(minv, self.ground_load)

    def shear_ratios(self, accel: np.ndarray, ground_accel: np.ndarray) -> np.ndarray:
        """|T_i / N_i| (k, friction_joints) from drum angular accelerations (k, n) and a_g
        (k,), N_i the :attr:`friction_normals`.

        T_i = -sum_{j>=i} m_j (absolute horizontal acceleration of body j's centre: the
        drums', then a frame's beam share on the top node).
        """
        abs_acc = accel @ self.centre_map.T + np.asarray(ground_accel)[:, None]
        forces = abs_acc * body_masses(self.column)
        shear = np.cumsum(forces[:, ::-1], axis=1)[:, ::-1][:, : self.friction_joints]
        return np.abs(shear) / self.friction_normals


def build_model(
    column: Column,
    xi: float = 1.0,
    restitution: float = 1.0,
    formulation: str = "relative",
    collapse_ratio: float = 1.0,
    damping: float = 0.0,
) -> Model:
    """Assemble the equations of a column.

    Parameters
    ----------
    column : Column  Derived properties (rbm_cli.structures.column.build_column)
    xi : float  Smoothing parameter of the law, 0 < xi <= 1
    restitution : float  e in (0, 1]
    formulation : str  'relative', 'absolute' or 'geometric' (docs/guide/assumptions.md)
    collapse_ratio : float  c in (0, 1]
    damping : float  zeta in [0, 1): damping of the first elastic mode (Model.joint_damping)
    """
    n, m = column.n, column.joints
    h = column.heights
    lower = np.tril(np.ones((n, n)), -1) * h[None, :]
    centre = lower + np.diag(column.centres)
    node = np.vstack([np.zeros(n), np.tril(np.ones((n, n))) * h[None, :]])
    if column.beam_mass > 0.0:  # a frame's beam share: a body moving with the top node
        centre = np.vstack([centre, node[n]])
    bodies = body_masses(column)
    mass = product(centre.T, bodies[:, None] * centre) + np.diag(column.inertias)
    diff = np.eye(m, n) - np.eye(m, n, k=-1)  # a beam joint's row: -theta_n
    # `absolute`: a drum's joint reads the drum's rotation; a frame's beam joint, between
    # the top drum and the level beam, reads -theta_n in every formulation
    arg_map = np.vstack([np.eye(n), diff[n:]]) if formulation == "absolute" else diff.copy()

    mu, tu = column.moment_capacity, column.rotation_capacity
    if formulation == "geometric":
        # the load on each drum's top: the drums above it and a frame's beam share
        n_above = np.append(column.normal_forces[1:n], column.beam_mass * G)
        normal = column.normal_forces[:n]
        # P_i c_i + N_{i+1} h_i: written as (N_i + N_{i+1}) h_i / 2 + P_i (c_i - h_i / 2),
        # whose last term is 0 for a drum with its centre at mid-height
        gravity = np.diag(
            (normal + n_above) * h / 2.0 + column.weights * (column.centres - h / 2.0)
        )
        extra = mu / tu
        # overturning moment of the drums above joint i about the joint:
        # sum_{j>=i} P_j (x_j - u_i), x_j the centre, u_i the joint's node (and a frame's
        # beam share's weight at the top node; its joint's row 0)
        over = np.zeros((m, n))
        for i in range(n):
            for j in range(i, n):
                over[i] += column.weights[j] * (centre[j] - node[i])
            if column.beam_mass > 0.0:
                over[i] += column.beam_mass * G * (node[n] - node[i])
        collapse_map, collapse_limit = over, mu.copy()
    else:
        gravity = np.zeros((n, n))
        extra = np.zeros(m)
        collapse_map, collapse_limit = arg_map.copy(), tu.copy()

    laws = tuple(
        make_law(mu[i], tu[i], column.stiffness[i], xi, extra_slope=float(extra[i]))
        for i in range(m)
    )
    if column.beam_mass > 0.0:
        laws, collapse_map, collapse_limit = frame_joints(
            column, laws, xi, collapse_map, formulation == "geometric"
        )
    return Model(
        column=column,
        mass=mass,
        mass_inv=inverse(mass),
        ground_load=product(centre.T, bodies),
        centre_map=centre,
        node_map=node,
        arg_map=arg_map,
        diff=diff,
        gravity=gravity,
        laws=laws,
        collapse_map=collapse_map,
        collapse_limit=collapse_limit,
        collapse_ratio=float(collapse_ratio),
        restitution=float(restitution),
        formulation=formulation,
        xi=float(xi),
        damping=float(damping),
    )


def body_masses(column: Column) -> np.ndarray:
    """The masses [kg] of the bodies that move: the drums, then a frame's beam share
    (Column.beam_mass) on the top node."""
    if column.beam_mass > 0.0:
        return np.append(column.masses, column.beam_mass)
    return column.masses


def frame_joints(
    column: Column, laws: tuple, xi: float, collapse_map: np.ndarray, geometric: bool = False
):
    """The laws and the collapse map and limits of a frame's joints (Column.beam_mass > 0).

    The beam joint's law (the cap M_u,b = (B_top / 2) W_b / N, no descending branch)
    resists the stack above every joint i: with the beam held level, joint i opening by x
    turns the drums above it and opens the beam joint too, so the stack above i overturns
    where f_i(x) + xi M_u,b = 0, at x = theta_u,i (1 + xi M_u,b / M_u,i), not at
    theta_u,i (where f_i alone vanishes). That is joint i's collapse limit; the beam joint
    itself never overturns (its row of the collapse map is 0). In the `geometric`
    formulation the collapse quantity is the overturning moment of the stack above i (the
    beam's share included), and its limit M_u,i + xi M_u,b: the same tilt of a rigid stack.
    A monolith's beam joint reads minus the base's argument (Column.beam_law): its law is
    added to the base's, whose limit is then the sum's zero (`geometric`: the sum's
    intercept). For a rigid monolith the frame's base law is (M_u,1 + M_u,b) (1 - |x| /
    limit), limit = (B / 2) / (H / 2) for a prismatic column: the uplift and the collapse
    of the free column, whatever the beam."""
    n = column.n
    if column.beam_law is not None:  # the base's own law and the beam joint's, summed
        mu_b, k_b = column.beam_law
        k_0 = float(column.stiffness[0])
        mu_0 = float(column.moment_capacity[0]) - mu_b
        tu_0 = float(column.widths[0]) / 2.0 / float(column.lever_arms[0])
        base = make_law(mu_0, tu_0, k_0 if math.isinf(k_0) else k_0 - k_b, xi,
                        extra_slope=mu_0 / tu_0 if geometric else 0.0)  # fmt: skip
        law = law_sum(base, make_law(mu_b, math.inf, k_b, xi))
        return (law,), collapse_map, np.array([_collapse_limit(law, 0.0, geometric)])
    cap = float(laws[n].intercepts[-1])
    limits = [_collapse_limit(law, cap, geometric) for law in laws[:n]]
    collapse_map = collapse_map.copy()
    collapse_map[n] = 0.0  # the beam joint: never (its limit, 1, any finite number)
    return laws, collapse_map, np.array(limits + [1.0])


def _collapse_limit(law: Law, cap: float, geometric: bool) -> float:
    """Where the stack on a law's joint overturns with the beam joint's cap beside it: the
    moment capacity, the law's last intercept plus the cap [N m] (`geometric`), or the
    argument at which the law's last piece plus the cap vanishes [rad]."""
    capacity = float(law.intercepts[-1]) + cap
    return capacity if geometric else -capacity / float(law.slopes[-1])


def event_families(model: Model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The quantities linear in theta [rad] that a run watches, one row each: where they
    cross a bound is an event, their peaks are its maxima.

    Returns
    -------
    arguments : (m, n)  Each interface's law argument over its rotation capacity theta_u
        (arg_map / theta_u; Model.argument_scale) [-/rad].
    collapse : (n, n)  Each interface's collapse ratio (collapse_map / collapse_limit),
        collapse at Model.collapse_ratio [-/rad].
    top : (n,)  The top's horizontal displacement (the drums' heights) [m/rad].
    """
    column = model.column
    arguments = model.arg_map / model.argument_scale[:, None]
    collapse = model.collapse_map / model.collapse_limit[:, None]
    return arguments, collapse, column.heights.astype(float)
