"""The true rigid-body geometry of a monolithic column (for `housner`): mass, true centre of
mass, corner inertia, slenderness alpha and frequency parameter p of the block that the
reference models `housner` and `housner-linear` rock; its top displacement and energy."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import Polynomial

from rbm_cli.config.types import ColumnConfig, Config, G


@dataclass(frozen=True)
class BlockGeometry:
    """True rigid-body geometry of a monolithic column (Housner's block).

    height : float  H [m]
    half_base : float  b = B_1 / 2 [m]
    mass : float  m [kg]
    centre_height : float  z_c, height of the true centre of mass [m]
    half_diagonal : float  R = sqrt(b^2 + z_c^2), base corner to centre of mass [m]
    slenderness : float  alpha = atan(b / z_c) [rad]
    corner_inertia : float  I_O, rotary inertia about a base corner [kg m^2]
    frequency_parameter : float  p = sqrt(m g R / I_O) [rad/s]
    """

    height: float
    half_base: float
    mass: float
    centre_height: float
    half_diagonal: float
    slenderness: float
    corner_inertia: float
    frequency_parameter: float


def block_geometry(column: ColumnConfig) -> BlockGeometry:
    """Mass, true centre of mass and corner inertia of a monolithic (tapered) column.

    Parameters
    ----------
    column : ColumnConfig  height [m], base_width and top_width [m], section
        ('rectangular' with depth [m] or None for a square section, or
        'circular' with diameter = width), density [kg/m^3]

    Returns
    -------
    BlockGeometry

    Notes
    -----
    The width is w(z) = B_1 + (B_top - B_1) z / H. A slice at height z has area
    a(z) (d w, w^2 or pi w^2 / 4) and second moment j(z) about its centroidal
    axis normal to the plane of motion (d w^3 / 12, w^4 / 12, pi w^4 / 64).
    With rho the density, exactly (polynomial integrals):

    .. math:: m = \\rho \\int_0^H a\\,dz, \\quad z_c = \\frac{\\rho}{m} \\int_0^H a z\\,dz,
    .. math:: I_O = \\rho \\int_0^H [\\, j + a (b^2 + z^2) \\,] dz

    (each slice's own inertia plus the parallel-axis term to the corner at
    horizontal distance b). For a uniform rectangle I_O = 4 m R^2 / 3 and
    p = sqrt(3 g / (4 R)).
    """
    if column.n_drums > 1:
        raise ValueError("block_geometry: a monolithic column only (one drum)")
    H, b1, bt = column.height, column.base_width, column.top_width
    if not (H > 0.0 and b1 > 0.0 and bt >= 0.0 and column.density > 0.0):
        raise ValueError("height, base_width, density must be > 0 and top_width >= 0")
    w = Polynomial([b1, (bt - b1) / H])
    z = Polynomial([0.0, 1.0])
    if column.section == "circular":
        area, second = math.pi / 4.0 * w**2, math.pi / 64.0 * w**4
    elif column.depth is None:
        area, second = w**2, w**4 / 12.0
    else:
        area, second = column.depth * w, column.depth * w**3 / 12.0
    rho, b = column.density, 0.5 * b1

    def integral(poly):
        return float(poly.integ()(H))

    mass = rho * integral(area)
    z_c = rho * integral(area * z) / mass
    i_o = rho * integral(second + area * (b * b + z * z))
    r = math.hypot(b, z_c)
    return BlockGeometry(
        height=H,
        half_base=b,
        mass=mass,
        centre_height=z_c,
        half_diagonal=r,
        slenderness=math.atan2(b, z_c),
        corner_inertia=i_o,
        frequency_parameter=math.sqrt(mass * G * r / i_o),
    )


def top_displacement(geometry: BlockGeometry, theta) -> np.ndarray | float:
    """Horizontal displacement of the top centre relative to the ground [m].

    Notes
    -----
    Rotation |theta| about the base corner at horizontal distance b from the
    axis: u = H sin|theta| + b (1 - cos theta), exact for large rotations.
    """
    a = np.abs(theta)
    return geometry.height * np.sin(a) + geometry.half_base * (1.0 - np.cos(a))


def housner_energy(theta, rate, alpha: float, p: float):
    """Energy per unit corner inertia [rad^2/s^2].

    E = theta'^2 / 2 + p^2 (cos(alpha - |theta|) - cos(alpha)), zero at rest.
    """
    return 0.5 * rate * rate + p * p * (np.cos(alpha - np.abs(theta)) - math.cos(alpha))


def block_initial(config: Config) -> tuple[float, float]:
    """(theta0 [rad], rate0 [rad/s]) of a block from the config's initial state."""
    init = config.excitation.initial
    return (
        float(init.rotations[0]) if init.rotations else 0.0,
        float(init.velocities[0]) if init.velocities else 0.0,
    )
