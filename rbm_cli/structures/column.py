"""Column properties from geometry: masses, inertias, interface widths and strengths.

All quantities SI. Drum i (0-based here, 1-based in the docs) spans
z_i <= z <= z_i + h_i; interface i is the bottom face of drum i. A capital
(column.capital) is the last drum, above the shaft; a top mass (column.top_mass) is a
point mass on the axis fixed to the last drum: it is part of that drum's mass, centre
and inertia.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rbm_cli.config.types import ColumnConfig, G, InterfaceConfig


@dataclass(frozen=True)
class Column:
    """Derived properties of a column (arrays indexed bottom first).

    heights : (n,) Drum heights h_i [m]
    bottoms : (n,) Drum bottom elevations z_i [m]
    widths : (n+1,) Column width at the interfaces and at the top [m] (with a capital,
        the last is the capital's own width; its interface's is the shaft's top width)
    depths : (n+1,) Out-of-plane depth (rectangular) or diameter (circular) there [m]
    masses : (n,) Drum masses m_i [kg] (the top drum's with the top mass)
    inertias : (n,) Centroidal rotary inertias I_Gi [kg m^2], about the drum's centre
    centres : (n,) Height of each drum's centre of mass above its bottom face [m]: h_i / 2,
        but the top drum's with a top mass
    weights : (n,) P_i = m_i g [N]
    normal_forces : (n,) N_i = sum_{j>=i} P_j [N], compression positive
    lever_arms : (n,) zbar_i, height of the resultant weight above interface i [m]
    moment_capacity : (n,) M_u,i = (B_i / 2) N_i [N m]  (paper eq. 6)
    rotation_capacity : (n,) theta_u,i = (B_i / 2) / zbar_i [rad]
    stiffness : (n,) K_M,i [N m/rad]; inf for a rigid law
    section : str  'rectangular' or 'circular'
    beam_mass : float  A frame's beam share m_b / N [kg] carried on the top node (a point
        body moving with the top, rbm_cli.structures.frame), 0 for a column standing
        alone; with one, the interface arrays (normal_forces to stiffness) are the joints'
        (:attr:`joints` of them: the drums' and the beam's), the drum arrays the drums'
    beam_law : (float, float) or None  (M_u [N m], K_M [N m/rad]) of a monolithic frame's
        beam joint, whose argument is minus the base's: its law joins the base's
        (rbm_cli.structures.frame.frame_column)
    """

    heights: np.ndarray
    bottoms: np.ndarray
    widths: np.ndarray
    depths: np.ndarray
    masses: np.ndarray
    inertias: np.ndarray
    weights: np.ndarray
    normal_forces: np.ndarray
    lever_arms: np.ndarray
    moment_capacity: np.ndarray
    rotation_capacity: np.ndarray
    stiffness: np.ndarray
    section: str = "rectangular"
    centres: np.ndarray | None = None
    beam_mass: float = 0.0
    beam_law: tuple[float, float] | None = None

    def __post_init__(self):
        if self.centres is None:  # drums of uniform section: the centre at mid-height
            object.__setattr__(self, "centres", self.heights / 2.0)

    @property
    def n(self) -> int:
        return len(self.heights)

    @property
    def joints(self) -> int:
        """Joints with a law: the drums' (n), and a frame's beam joint unless folded into
        the base's (:attr:`beam_law`)."""
        return len(self.normal_forces)

    @property
    def height(self) -> float:
        return float(self.heights.sum())

    @property
    def total_mass(self) -> float:
        return float(self.masses.sum())

    @property
    def rigid(self) -> bool:
        return bool(np.all(np.isinf(self.stiffness)))

    @property
    def static_multiplier(self) -> float:
        """Uniform horizontal acceleration [g] that overturns the weakest rigid stack:
        min_i M_u,i / (N_i zbar_i) = min_i theta_u,i. Under a frame's beam the stack above
        joint i lifts the beam's joint too: min_i (M_u,i + M_u,beam) / (N_i zbar_i)
        (rbm_cli.structures.frame.frame_limits)."""
        if self.joints > self.n:
            mu, beam = self.moment_capacity[: self.n], self.moment_capacity[self.n]
            return float(np.min(self.rotation_capacity[: self.n] * (1.0 + beam / mu)))
        return float(np.min(self.rotation_capacity))


def _frustum_area_integral(w_a: float, w_b: float, h: float) -> float:
    """Integral of w(z)^2 over a drum whose width varies linearly from w_a to w_b [m^3]."""
    return h * (w_a * w_a + w_a * w_b + w_b * w_b) / 3.0


def _volumes_and_depths(
    column: ColumnConfig, widths: np.ndarray, h: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Drum volumes [m^3] (exact for the tapered drum) and the depth or diameter at the
    interfaces and the top [m] (square drums: the width; circular: the diameter)."""
    w_a, w_b = widths[:-1], widths[1:]
    if column.section == "circular":
        volumes = (
            np.pi
            / 4.0
            * np.array(
                [_frustum_area_integral(a, b, hh) for a, b, hh in zip(w_a, w_b, h, strict=True)]
            )
        )
        depths = widths.copy()
    elif column.depth is None:  # square drums
        volumes = np.array(
            [_frustum_area_integral(a, b, hh) for a, b, hh in zip(w_a, w_b, h, strict=True)]
        )
        depths = widths.copy()
    else:
        mean_w = 0.5 * (w_a + w_b)
        volumes = column.depth * h * mean_w
        depths = np.full(len(h) + 1, float(column.depth))
    return volumes, depths


def _capital_drum(column: ColumnConfig) -> tuple[float, float, float, float]:
    """(mass [kg], centroidal inertia [kg m^2], width [m], depth or diameter [m]) of the
    column's capital: a prism (rectangular: width x depth, depth defaulting to the width)
    or a cylinder (circular: the width is its diameter) of the column's density."""
    cap = column.capital
    h, w = cap.height, cap.width
    if column.section == "circular":
        mass = column.density * np.pi / 4.0 * w * w * h
        return mass, mass * (h * h / 12.0 + w * w / 16.0), w, w
    d = w if cap.depth is None else cap.depth
    mass = column.density * w * d * h
    return mass, mass * (h * h + w * w) / 12.0, w, d


def _with_top_mass(
    column: ColumnConfig, masses: np.ndarray, inertias: np.ndarray, h: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(masses, inertias, centres) with the top mass fixed to the top drum: a point mass M
    on the axis at e above the drum's top face joins the drum (m, I_G at h / 2): mass
    m + M, centre c = (m h / 2 + M (h + e)) / (m + M) above the drum's bottom, inertia
    about c by the parallel axis, I_G + m (c - h / 2)^2 + M (h + e - c)^2."""
    centres = h / 2.0
    if column.top_mass is None:
        return masses, inertias, centres
    big_m, e = column.top_mass.mass, column.top_mass.height_of_centre
    m, ht, i_g = float(masses[-1]), float(h[-1]), float(inertias[-1])
    z_m = ht + e
    total = m + big_m
    c = (m * ht / 2.0 + big_m * z_m) / total
    masses, inertias, centres = masses.copy(), inertias.copy(), centres.copy()
    masses[-1] = total
    inertias[-1] = i_g + m * (c - ht / 2.0) ** 2 + big_m * (z_m - c) ** 2
    centres[-1] = c
    return masses, inertias, centres


def _moment_stiffness(
    interface: InterfaceConfig, section: str, widths: np.ndarray, depths: np.ndarray, n: int
) -> np.ndarray:
    """K_M,i [N m/rad] of the n interfaces: inf (rigid), given, or from the joint normal
    stiffness k_n [Pa/m] over the interface section (k_n I of the contact area)."""
    stiff = interface.stiffness
    if stiff.kind == "rigid":
        k_m = np.full(n, np.inf)
    elif stiff.kind == "moment":
        vals = np.asarray(stiff.values, dtype=float)
        k_m = np.full(n, vals[0]) if len(vals) == 1 else vals[:n].copy()  # a frame's: +1
    else:  # joint normal stiffness k_n [Pa/m]
        k_n = float(stiff.values[0])
        b_i = widths[:-1]
        if section == "circular":
            k_m = k_n * np.pi * b_i**4 / 64.0
        else:
            k_m = k_n * depths[:-1] * b_i**3 / 12.0
    return k_m


def build_column(column: ColumnConfig, interface: InterfaceConfig) -> Column:
    """Derive masses, inertias and interface strengths from the geometry.

    Parameters
    ----------
    column : ColumnConfig  Geometry [m] and density [kg/m^3]
    interface : InterfaceConfig  Stiffness of the moment-rotation law

    Notes
    -----
    Width tapers linearly, w(z) = B_1 + (B_top - B_1) z / H. A capital is one more
    drum above H (a prism or cylinder of its own width); its joint is the shaft's top
    section (width B_top, the shaft's top depth), and ``widths[-1]``, ``depths[-1]`` are
    the capital's own. A top mass joins the top drum (:func:`_with_top_mass`); the
    lever arms and the normal forces of every joint below carry its weight. Drum volume is the
    exact volume of the tapered drum; the RBM puts each drum's weight at its
    mid-height (lever arms h_i / 2), and so do zbar_i and the inertias:
    rectangle I_G = m (h^2 + w^2) / 12, cylinder I_G = m (h^2 / 12 + d^2 / 16),
    w or d the drum's mean width [assumption: the paper is silent].

    M_u,i = (B_i / 2) N_i (paper eq. 6); theta_u,i = (B_i / 2) / zbar_i with
    zbar_i = sum_{j>=i} P_j (z_j + c_j - z_i) / N_i, c_j the drum's centre above its
    bottom (h_j / 2 but for a top mass's drum) [assumption: Housner's
    linearised overturning angle of the stack above interface i].
    """
    h = np.asarray(column.drum_heights, dtype=float)
    n = len(h)
    H = float(h.sum())
    z = np.concatenate([[0.0], np.cumsum(h)])  # interfaces 1..n and the top
    widths = column.base_width + (column.top_width - column.base_width) * z / H
    w_a, w_b = widths[:-1], widths[1:]
    mean_w = 0.5 * (w_a + w_b)

    volumes, depths = _volumes_and_depths(column, widths, h)
    masses = column.density * volumes
    if column.section == "circular":
        inertias = masses * (h**2 / 12.0 + mean_w**2 / 16.0)
    else:
        inertias = masses * (h**2 + mean_w**2) / 12.0
    if column.capital is not None:
        cap_m, cap_i, cap_w, cap_d = _capital_drum(column)
        h = np.append(h, column.capital.height)
        z = np.append(z, z[-1] + column.capital.height)
        widths = np.append(widths, cap_w)
        depths = np.append(depths, cap_d)
        masses = np.append(masses, cap_m)
        inertias = np.append(inertias, cap_i)
        n += 1
    masses, inertias, centres = _with_top_mass(column, masses, inertias, h)
    weights = masses * G
    normal = np.cumsum(weights[::-1])[::-1]
    z_b = z[:-1]
    mid = z_b + centres
    lever = np.array([np.sum(weights[i:] * (mid[i:] - z_b[i])) / normal[i] for i in range(n)])
    mu = widths[:-1] / 2.0 * normal
    theta_u = (widths[:-1] / 2.0) / lever

    k_m = _moment_stiffness(interface, column.section, widths, depths, n)

    return Column(
        heights=h,
        bottoms=z_b,
        widths=widths,
        depths=depths,
        masses=masses,
        inertias=inertias,
        weights=weights,
        normal_forces=normal,
        lever_arms=lever,
        moment_capacity=mu,
        rotation_capacity=theta_u,
        stiffness=k_m,
        section=column.section,
        centres=centres,
    )
