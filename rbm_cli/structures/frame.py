"""A frame: N identical columns standing in a row in the plane of the motion under one rigid
beam (an architrave) that rests freely on their tops, a colonnade's bay (`frame` in a
config).

Rigid monolithic columns of a symmetric (prismatic) shape rock in unison about their base
corners and the opposite corners of their tops; the beam translates without rotating, by
the column's diagonal 2R turned through theta, so it rises as the columns rock. With m a
column's mass, R its semi-diagonal, alpha its slenderness, I_O its inertia about a base
corner and m_b the beam's mass, Lagrange's equation of the frame is (Makris and Vassiliou
2013)

    (N I_O + 4 m_b R^2) theta'' = -(N m + 2 m_b) R [ g sin(alpha sgn(theta) - theta)
                                   + a_g cos(alpha sgn(theta) - theta) ]

which is Housner's equation of one column with

    p_hat^2 = p^2 (1 + 2 gamma) / (1 + 4 gamma m R^2 / I_O),   gamma = m_b / (N m)

(for rectangular columns m R^2 / I_O = 3/4: the frame rocks as one block of the columns'
slenderness and semi-diagonal R (1 + 3 gamma) / (1 + 2 gamma)). The columns lift at
tan(alpha) g whatever gamma; a heavier beam lowers p_hat, so the frame is more stable than
its columns alone. Angular momentum about the new pivots, kept through an impact, gives the
frame's coefficient of restitution

    eta = [N (I_O - 2 m R^2 sin^2 alpha) + 4 m_b R^2 cos 2 alpha] / (N I_O + 4 m_b R^2)

(rectangles: (1 - 1.5 sin^2 alpha + 3 gamma cos 2 alpha) / (1 + 3 gamma)), which is
Housner's coefficient of one column when m_b = 0. Each figure is written here as the
column's times a factor of gamma that is exactly 1 at gamma = 0, so a frame with a beam of
no mass is its column to the bit.

References
----------
.. [1] N. Makris and M. F. Vassiliou (2013). Planar rocking response and stability
   analysis of an array of free-standing columns capped with a freely supported rigid
   beam. Earthquake Engineering and Structural Dynamics 42(3), 431-449.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from rbm_cli.config.types import FrameConfig, G, InterfaceConfig
from rbm_cli.structures.block import BlockGeometry
from rbm_cli.structures.column import Column
from rbm_cli.structures.restitution import block_restitution, column_restitution


@dataclasses.dataclass(frozen=True)
class FrameFigures:
    """What a frame of rigid columns is, as one equivalent block.

    ratio : float  gamma = m_b / (N m) [-]
    frequency_parameter : float  p_hat [rad/s]
    half_diagonal : float  R_hat [m], the semi-diagonal of a block of the column's shape
        rocking with p_hat (R p^2 / p_hat^2)
    restitution : float  eta, Housner's coefficient of the frame [-]
    static_multiplier : float  The ground acceleration that lifts the frame [g], tan(alpha)
    """

    ratio: float
    frequency_parameter: float
    half_diagonal: float
    restitution: float
    static_multiplier: float


def _factors(column: BlockGeometry, frame: FrameConfig) -> tuple[float, float, float]:
    """(gamma, 1 + 2 gamma, 1 + 4 gamma m R^2 / I_O): the frame's weight and inertia over
    the columns' (each exactly 1 at gamma = 0)."""
    gamma = frame.ratio(column.mass)
    share = column.mass * column.half_diagonal**2 / column.corner_inertia
    return gamma, 1.0 + 2.0 * gamma, 1.0 + 4.0 * gamma * share


def frame_block(column: BlockGeometry, frame: FrameConfig) -> BlockGeometry:
    """The block the frame rocks as: the column's geometry with a column's share of the
    frame's weight, m (1 + 2 gamma), and of its inertia about the pivots,
    I_O (1 + 4 gamma m R^2 / I_O), so its p is p_hat (the module's docstring)."""
    _, weight, inertia = _factors(column, frame)
    return dataclasses.replace(
        column,
        mass=column.mass * weight,
        corner_inertia=column.corner_inertia * inertia,
        frequency_parameter=column.frequency_parameter * math.sqrt(weight / inertia),
    )


def frame_restitution(column: BlockGeometry, frame: FrameConfig) -> float:
    """eta, Housner's coefficient of restitution of the frame [-] (the module's docstring,
    :func:`eta`) with e the column's own."""
    share = column.mass * column.half_diagonal**2 / column.corner_inertia
    cos2a = math.cos(2.0 * column.slenderness)
    return eta(block_restitution(column), frame.ratio(column.mass), share, cos2a)


def eta(e: float, gamma: float, share: float, cos2a: float) -> float:
    """(e + 4 gamma share cos 2 alpha) / (1 + 4 gamma share): the frame's restitution [-]
    from its column's e, the beam's ratio gamma, share = m R^2 / I_O and cos 2 alpha;
    exactly e at gamma = 0."""
    return (e + 4.0 * gamma * share * cos2a) / (1.0 + 4.0 * gamma * share)


def frame_figures(column: BlockGeometry, frame: FrameConfig) -> FrameFigures:
    """gamma, p_hat, R_hat, eta and the lifting acceleration of a frame of these columns."""
    gamma, weight, inertia = _factors(column, frame)
    return FrameFigures(
        ratio=gamma,
        frequency_parameter=frame_block(column, frame).frequency_parameter,
        half_diagonal=column.half_diagonal * inertia / weight,
        restitution=frame_restitution(column, frame),
        static_multiplier=math.tan(column.slenderness),
    )


# ---- the Rigid Beam Model's frame


def beam_stiffness(interface: InterfaceConfig, column: Column) -> float:
    """K_M of the beam's joint [N m/rad]: rigid, the last value given (one for every joint,
    or the beam's after the drums'), or k_n over the column's top section."""
    stiff = interface.stiffness
    if stiff.kind == "rigid":
        return math.inf
    if stiff.kind == "moment":
        return float(stiff.values[-1])
    k_n, width, depth = float(stiff.values[0]), float(column.widths[-1]), float(column.depths[-1])
    if column.section == "circular":
        return k_n * math.pi * width**4 / 64.0
    return k_n * depth * width**3 / 12.0


def frame_column(column: Column, frame: FrameConfig, interface: InterfaceConfig) -> Column:
    """A column of the RBM's frame: the drums of ``column`` under a share m_b / N of the
    beam, a point body on the top node (the RBM's small rotations move it horizontally with
    the top; it does not rotate). Every joint below carries its weight W_b / N at the top's
    height (normal forces, lever arms, M_u and theta_u of the drums' joints), and the beam
    rests on the top on a joint of its own: width the top's, M_u = (B_top / 2) W_b / N, no
    descending branch (the beam's weight acts at the joint: theta_u infinite), its argument
    -theta_n (the beam does not rotate). A monolith's beam joint reads minus the base's
    argument, so its law joins the base's (Column.beam_law; one joint: M_u, K_M the sums,
    theta_u the rigid frame's, (M_u,1 + M_u,b) / (N_1 zbar_1)); beam_mass 0 is the column
    itself."""
    share = frame.beam_mass / frame.columns
    if share == 0.0:
        return column
    n, w = column.n, share * G
    normal = column.normal_forces + w
    lever = (
        column.normal_forces * column.lever_arms + w * (column.height - column.bottoms)
    ) / normal
    half = column.widths[:n] / 2.0
    beam = (float(column.widths[-1]) / 2.0 * w, beam_stiffness(interface, column))
    if n == 1:
        mu = half * normal + beam[0]
        return dataclasses.replace(column, beam_mass=share, lever_arms=lever,
                                   normal_forces=normal, beam_law=beam, moment_capacity=mu,
                                   rotation_capacity=mu / (normal * lever),
                                   stiffness=column.stiffness + beam[1])  # fmt: skip
    return dataclasses.replace(
        column,
        beam_mass=share,
        normal_forces=np.append(normal, w),
        lever_arms=np.append(lever, 0.0),
        moment_capacity=np.append(half * normal, beam[0]),
        rotation_capacity=np.append(half / lever, math.inf),
        stiffness=np.append(column.stiffness, beam[1]),
    )


def rbm_frame_restitution(column: Column, frame: FrameConfig) -> float:
    """eta of a monolithic RBM column under a frame's beam (``restitution: housner``):
    the module's eta with the RBM's column (its centre at mid-height, I_O = I_G +
    m (h^2 + b^2), h = H / 2, b = B_1 / 2, R^2 = h^2 + b^2), as
    (e + 4 gamma (m R^2 / I_O) cos 2 alpha) / (1 + 4 gamma m R^2 / I_O), e the column's
    own (rbm_cli.structures.restitution.column_restitution)."""
    m = column.total_mass
    half_b, half_h = float(column.widths[0]) / 2.0, float(column.centres[0])
    r2 = half_h**2 + half_b**2
    share = m * r2 / (float(column.inertias[0]) + m * r2)
    return eta(column_restitution(column), frame.ratio(m), share, (half_h**2 - half_b**2) / r2)


# ---- the frame as drawn (and as the contact engine builds it)

#: The columns' axes stand this many base widths apart [assumption: an intercolumniation
#: of 1.5 base widths between the shafts, the Greek and Roman orders' range being about
#: 1.5 to 3]; the planar frame's equations do not depend on it.
AXIS_SPACING = 2.5


def beam_box(column: dict, frame: dict) -> tuple[float, float, float, float]:
    """(spacing of the axes, beam length, beam height, beam depth) [m] of a frame: the
    columns' axes AXIS_SPACING base widths apart; the beam spans the row from the first
    column's outer top edge to the last one's, as deep as the top (or the capital), of
    the columns' density, as high as its mass then makes it. ``column`` and ``frame``:
    the config's sections as plain data (Config.resolved()'s)."""
    capital = column.get("capital")
    if capital:
        top, depth = float(capital["width"]), capital.get("depth")
    else:
        top, depth = float(column["top_width"]), column.get("depth")
    depth = top if depth is None or column.get("section") == "circular" else float(depth)
    spacing = AXIS_SPACING * float(column["base_width"])
    length = (int(frame["columns"]) - 1) * spacing + top
    height = float(frame["beam_mass"]) / (float(column["density"]) * length * depth)
    return spacing, length, height, depth
