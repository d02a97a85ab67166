"""True rigid-body geometry of the drums for the contact engine (`model: bullet`).

Pure functions, no engine: each drum is a solid of its true shape (a tapered
rectangular or circular frustum), with its exact mass, centre of mass and
principal rotary inertias, and the vertices of the convex hull Bullet collides
(vertices relative to the drum's centre of mass). Axes: x in the plane of
motion, y out of plane, z up. SI units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import Polynomial

from rbm_cli.config.types import ColumnConfig

#: Sides of the polygon that stands in for a circular section. An edge (not a
#: vertex) faces +x and -x, with its apothem equal to the true radius, so the
#: rocking corners sit at the true half-width.
CIRCLE_SIDES = 32


@dataclass(frozen=True)
class DrumSolid:
    """One drum as a rigid solid.

    bottom : float  Elevation of its bottom face at rest [m]
    height : float  h [m]
    half_bottom, half_top : float  Half-widths of its bottom and top faces in x [m]
    mass : float  [kg]
    centre : float  Height of the centre of mass above the bottom face [m]
    inertia : (3,) Principal rotary inertias about the centre of mass,
        (I_xx, I_yy, I_zz) [kg m^2]; I_yy is the one of in-plane rocking
    vertices : (k, 3) Convex hull, relative to the centre of mass [m]
    box : bool  A prism of constant rectangular section (collided as a box)
    half_extents : (3,) Half-sizes of that box [m] (zeros otherwise)
    """

    bottom: float
    height: float
    half_bottom: float
    half_top: float
    mass: float
    centre: float
    inertia: tuple[float, float, float]
    vertices: np.ndarray
    box: bool
    half_extents: tuple[float, float, float]


def drum_solids(column: ColumnConfig, sides: int = CIRCLE_SIDES) -> tuple[DrumSolid, ...]:
    """The drums of a column as true solids, bottom first.

    Parameters
    ----------
    column : ColumnConfig  height, base_width, top_width [m], section, depth [m]
        (None: square drums), density [kg/m^3], drum_heights [m]
    sides : int  Polygon sides standing in for a circular section (collision only)

    Notes
    -----
    The width tapers linearly over the whole column. Over one drum (local z from
    0 to h) the width w(z) is linear; the area a(z) is d w (fixed depth d), w^2
    (square) or pi w^2 / 4 (circle). Exactly (polynomial integrals):

    .. math:: m = \\rho \\int a\\,dz, \\quad z_c = \\frac{\\rho}{m} \\int a z\\,dz,
    .. math:: I_{yy} = \\rho \\int [j_y + a (z - z_c)^2] dz

    with j_y = d w^3 / 12 (rectangle) or pi w^4 / 64 (circle), and alike for
    I_xx (j_x = w d^3 / 12); I_zz = rho int j_z dz with j_z = w d (w^2 + d^2) / 12
    (or pi w^4 / 32).
    The hull (``vertices``) of a circular drum is a regular polygonal frustum whose
    apothem is the true radius; its mass and inertia are the circle's. A run collides
    circular drums as the engine's cylinders (rbm_cli.models.bullet.scene.cylinder_shape),
    not as this hull.
    """
    z0 = np.concatenate([[0.0], np.cumsum(column.drum_heights)])
    return tuple(_drum(column, z0, i, h, sides) for i, h in enumerate(column.drum_heights))


def _drum(column: ColumnConfig, z0: np.ndarray, i: int, h: float, sides: int) -> DrumSolid:
    """Drum i, of height h [m] from z0[i] to z0[i + 1] [m], as a true solid (notes of
    :func:`drum_solids`)."""
    H = column.height
    rho = column.density
    wa = column.base_width + (column.top_width - column.base_width) * z0[i] / H
    wb = column.base_width + (column.top_width - column.base_width) * z0[i + 1] / H
    w = Polynomial([wa, (wb - wa) / h])
    z = Polynomial([0.0, 1.0])
    d, area, j_x, j_y, j_z = _section(column, w)

    def integral(poly, h=h):
        return float(poly.integ()(h))

    mass = rho * integral(area)
    zc = rho * integral(area * z) / mass
    arm = area * (z - zc) ** 2
    inertia = (rho * integral(j_x + arm), rho * integral(j_y + arm), rho * integral(j_z))
    box = column.section == "rectangular" and wa == wb
    half = (wa / 2.0, float(d(0.0)) / 2.0, h / 2.0) if box else (0.0, 0.0, 0.0)
    return DrumSolid(
        bottom=float(z0[i]),
        height=float(h),
        half_bottom=wa / 2.0,
        half_top=wb / 2.0,
        mass=mass,
        centre=zc,
        inertia=inertia,
        vertices=_hull(column, wa, wb, d, h, zc, sides),
        box=box,
        half_extents=half,
    )


def _section(column: ColumnConfig, w: Polynomial):
    """Depth d, area a and second moments j_x, j_y, j_z of the section of width w,
    as polynomials in the drum's local z [m, m^2, m^4]."""
    if column.section == "circular":
        d = w
        area = math.pi / 4.0 * w**2
        j_x = j_y = math.pi / 64.0 * w**4
        j_z = math.pi / 32.0 * w**4
    else:
        d = w if column.depth is None else Polynomial([column.depth])
        area = w * d
        j_y = d * w**3 / 12.0
        j_x = w * d**3 / 12.0
        j_z = w * d * (w**2 + d**2) / 12.0
    return d, area, j_x, j_y, j_z


def _hull(column: ColumnConfig, wa, wb, d: Polynomial, h, zc, sides: int) -> np.ndarray:
    """Vertices of the drum's collision hull relative to its centre of mass [m]:
    widths wa (bottom), wb (top), depth d(z), height h, centre of mass at zc."""
    if column.section == "circular":
        return _polygon_frustum(wa / 2.0, wb / 2.0, h, zc, sides)
    da, db = float(d(0.0)), float(d(h))
    return np.array(
        [
            (sx * ww / 2.0, sy * dd / 2.0, zz - zc)
            for ww, dd, zz in ((wa, da, 0.0), (wb, db, h))
            for sx in (-1.0, 1.0)
            for sy in (-1.0, 1.0)
        ]
    )


def _polygon_frustum(ra: float, rb: float, h: float, zc: float, sides: int) -> np.ndarray:
    """Vertices of a regular polygonal frustum with apothems ra (bottom), rb (top),
    an edge facing +x and -x (sides must be even), relative to the centre zc."""
    angles = (np.arange(sides) + 0.5) * 2.0 * math.pi / sides
    scale = 1.0 / math.cos(math.pi / sides)
    rows = []
    for r, zz in ((ra, 0.0), (rb, h)):
        for a in angles:
            rows.append((r * scale * math.cos(a), r * scale * math.sin(a), zz - zc))
    return np.array(rows)


def stack_slenderness(solids: tuple[DrumSolid, ...]) -> np.ndarray:
    """Overturning angle of the stack above each joint, about its bottom corner [rad].

    alpha_i = atan(b_i / zbar_i), b_i the half-width of drum i's bottom face and
    zbar_i the height above that face of the true centre of mass of drums i..n.
    For one drum this is Housner's slenderness alpha of :mod:`rbm_cli.models.housner.runner`;
    tan(alpha_i) g is the horizontal acceleration that uplifts the rigid stack.
    """
    out = []
    for i, s in enumerate(solids):
        above = solids[i:]
        m = sum(d.mass for d in above)
        zbar = sum(d.mass * (d.bottom + d.centre) for d in above) / m - s.bottom
        out.append(math.atan2(s.half_bottom, zbar))
    return np.array(out)
