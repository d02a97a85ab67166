"""The column of drums as drawn (shapes.png): rigid drums rocking on their corners, and
the slip of a base that a contact engine reports.

Pure numpy: the report draws what these functions return
(:func:`rbm_cli.report.plots.plot_shapes`).
"""

from __future__ import annotations

import math

import numpy as np


def _rotation(angle: float) -> np.ndarray:
    """Matrix turning a drum by ``angle`` [rad], positive towards +x (clockwise in x-z)."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, s], [-s, c]])


def drum_outlines(
    theta: np.ndarray, widths: np.ndarray, heights: np.ndarray, base_shift: float = 0.0
) -> list[np.ndarray]:
    """Corners of rigid drums stacked on the corners they rock on.

    Parameters
    ----------
    theta : (n,) Absolute drum rotations theta_i [rad], positive when the top moves to +x
    widths : (n+1,) Widths at the interfaces and the top [m] (drum i: widths[i] below,
        widths[i+1] above)
    heights : (n,) Drum heights h_i [m]
    base_shift : float  Horizontal displacement of the base on the ground (slip) [m]

    Returns
    -------
    list of (4, 2) arrays, bottom drum first: corners (x, z) [m] bottom-left,
    bottom-right, top-right, top-left.

    Notes
    -----
    Drum i is the rigid trapezoid of its end widths, turned by theta_i about
    the corner it rocks on: the corner on the side of its relative rotation
    phi_i = theta_i - theta_{i-1} (theta_0 = 0: drum 1 on the ground), which
    sits on the same corner of the drum below (on the ground for drum 1). The
    joint opens as a wedge of angle |phi_i| on the other side. This is the exact
    kinematics of drums rocking without sliding; the node displacements it gives,
    sum_{j<i} h_j sin(theta_j) + O(B theta^2), agree with the RBM's
    sum_{j<i} h_j theta_j to first order in the rotations.
    """
    theta = np.asarray(theta, dtype=float)
    widths = np.asarray(widths, dtype=float)
    heights = np.asarray(heights, dtype=float)
    previous = 0.0
    # the pivot of drum 1: a ground point under its bottom corner on the side it tilts to
    pivot = None
    outlines = []
    for i, (angle, h) in enumerate(zip(theta, heights, strict=True)):
        side = 1.0 if angle - previous >= 0.0 else -1.0
        if pivot is None:
            pivot = np.array([base_shift + side * widths[0] / 2.0, 0.0])
        else:  # the top corner of the drum below on that side
            pivot = outlines[-1][2] if side > 0 else outlines[-1][3]
        bottom, top = widths[i] / 2.0, widths[i + 1] / 2.0
        local = np.array([[-bottom, 0.0], [bottom, 0.0], [top, h], [-top, h]])
        corner = np.array([side * bottom, 0.0])
        outlines.append(pivot + (local - corner) @ _rotation(float(angle)).T)
        previous = float(angle)
    return outlines


def base_slip(node_displacements: np.ndarray, theta_1: np.ndarray, width: float) -> np.ndarray:
    """Slip of the base on the ground [m] per sample; zeros if the base node never moves.

    Parameters
    ----------
    node_displacements : (k, n+1) Node displacements relative to the ground [m]
    theta_1 : (k,) Rotation of the bottom drum [rad]
    width : float  Width of the base B_1 [m]

    Notes
    -----
    The RBM's base node is fixed (its column 0 is zero). A contact engine
    reports where the centre of the base's bottom face is; rocking on a corner
    alone moves it by (B_1 / 2)(1 - cos theta_1) towards the pivot, and the
    rest is slip.
    """
    u1 = np.asarray(node_displacements, dtype=float)[:, 0]
    if not np.any(u1):
        return np.zeros_like(u1)
    theta_1 = np.asarray(theta_1, dtype=float)
    side = np.where(theta_1 >= 0.0, 1.0, -1.0)
    return u1 - side * (width / 2.0) * (1.0 - np.cos(theta_1))
