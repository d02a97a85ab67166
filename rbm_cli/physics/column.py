"""Column properties from geometry: masses, inertias, interface widths and strengths.

All quantities SI. Drum i (0-based here, 1-based in the docs) spans
z_i <= z <= z_i + h_i; interface i is the bottom face of drum i.
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
    widths : (n+1,) Column width at the interfaces and at the top [m]
    depths : (n+1,) Out-of-plane depth (rectangular) or diameter (circular) there [m]
    masses : (n,) Drum masses m_i [kg]
    inertias : (n,) Centroidal rotary inertias I_Gi [kg m^2]
    weights : (n,) P_i = m_i g [N]
    normal_forces : (n,) N_i = sum_{j>=i} P_j [N], compression positive
    lever_arms : (n,) zbar_i, height of the resultant weight above interface i [m]
    moment_capacity : (n,) M_u,i = (B_i / 2) N_i [N m]  (paper eq. 6)
    rotation_capacity : (n,) theta_u,i = (B_i / 2) / zbar_i [rad]
    stiffness : (n,) K_M,i [N m/rad]; inf for a rigid law
    section : str  'rectangular' or 'circular'
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

    @property
    def n(self) -> int:
        return len(self.heights)

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
        min_i M_u,i / (N_i zbar_i) = min_i theta_u,i."""
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
        k_m = np.full(n, vals[0]) if len(vals) == 1 else vals.copy()
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
    Width tapers linearly, w(z) = B_1 + (B_top - B_1) z / H. Drum volume is the
    exact volume of the tapered drum; the RBM puts each drum's weight at its
    mid-height (lever arms h_i / 2), and so do zbar_i and the inertias:
    rectangle I_G = m (h^2 + w^2) / 12, cylinder I_G = m (h^2 / 12 + d^2 / 16),
    w or d the drum's mean width [assumption: the paper is silent].

    M_u,i = (B_i / 2) N_i (paper eq. 6); theta_u,i = (B_i / 2) / zbar_i with
    zbar_i = sum_{j>=i} P_j (z_j + h_j / 2 - z_i) / N_i [assumption: Housner's
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
    weights = masses * G
    normal = np.cumsum(weights[::-1])[::-1]
    z_b = z[:-1]
    mid = z_b + h / 2.0
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
    )
