"""Housner's coefficient of restitution, the one rule for `interface.restitution: housner`.

Conservation of angular momentum about the new corner at an impact gives the
angular-velocity ratio

.. math:: e = 1 - 2 m (R \\sin\\alpha)^2 / I_O

with m the mass, R sin(alpha) the horizontal lever from the corner to the centre of mass
(half the base width) and I_O the inertia about the corner. The RBM and the true block
differ only in where they put the centre and what inertia they give the column, so each
model resolves the setting here with its own geometry (Housner 1963).
"""

from __future__ import annotations

import math
from collections.abc import Callable

from rbm_cli.structures.block import BlockGeometry
from rbm_cli.structures.column import Column


def housner_coefficient(mass: float, lever: float, corner_inertia: float) -> float:
    """e = 1 - 2 m lever^2 / I_O [-] (angular-velocity ratio).

    Parameters
    ----------
    mass : float  m [kg]
    lever : float  Horizontal distance from the rocking corner to the centre of mass [m]
    corner_inertia : float  I_O, rotary inertia about the corner [kg m^2]
    """
    return 1.0 - 2.0 * mass * lever**2 / corner_inertia


def block_restitution(geometry: BlockGeometry) -> float:
    """Housner's e of the true block (uniform rectangle: 1 - 1.5 sin^2 alpha) [-]."""
    g = geometry
    return housner_coefficient(g.mass, g.half_diagonal * math.sin(g.slenderness), g.corner_inertia)


def column_restitution(column: Column) -> float:
    """Housner's e of a monolithic RBM column, with the RBM's centre (mid-height, or the
    centre c with a top mass) and inertia: I_O = I_G + m (c^2 + B^2 / 4), lever B / 2 [-].

    For a rectangle of uniform width this is Housner's 1 - 1.5 sin^2(alpha).
    """
    m = column.total_mass
    half_b = column.widths[0] / 2.0
    half_h = float(column.centres[0]) if column.n == 1 else column.height / 2.0
    i_o = float(column.inertias[0]) + m * (half_h**2 + half_b**2)
    return housner_coefficient(m, half_b, i_o)


def resolve(setting: float | str, housner: Callable[[], float]) -> float:
    """The restitution e [-] of a config's `interface.restitution`: the number itself, or
    for 'housner' Housner's coefficient of the model's own geometry (`housner()`, e.g.
    ``lambda: column_restitution(column)``)."""
    return float(housner()) if setting == "housner" else float(setting)
