"""A ground motion's azimuth in plan, for the models in three dimensions.

A motion of one component (or a pair: the first along its azimuth, the second across it)
is the same motion turned: `housner-3d` and `rbm-3d` run it in its own frame, along x, and
turn what they report in plan (the top's path, the collapse azimuth) back to the ground's
axes. Every azimuth then gives the run of azimuth 0 to the bit, and a motion along x
stays in its vertical plane to the bit (nothing across it): the planar model's run.
An azimuth is taken modulo a whole turn, so 360 degrees is 0 to the bit. A formula's
second component in phase or in antiphase with the first (excitation.y with phase_deg a
multiple of 180) makes a line: the motion of one component turned (:func:`as_line`), run
in its plane as any other.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from rbm_cli.inputs.motion import GroundMotion

#: Multiples of 180 degrees a second component's phase may lead by (excitation.y).
_HALF_TURNS = (-2, -1, 0, 1, 2)


def as_line(motion: GroundMotion) -> tuple[GroundMotion, float]:
    """The motion and 0.0, or, where its second component is its first times a constant
    (an analytic second component of the same form led by a multiple of 180 degrees:
    a_y = s r a_x, s = +-1), the motion of one component A sqrt(1 + r^2) along its
    azimuth turned by beta = atan2(s r, 1), and beta [rad]. Computed in the ground's axes,
    such a pair leaves its plane by round-off, and the planar rocking of a cylinder is
    unstable across its plane; in its own frame it is the planar run, to the bit. A start
    given in the first component's plane and across it is then turned by -beta
    (:func:`turned_start`)."""
    y = motion.second
    if y is None or (y.kind, y.omega, y.center, y.gamma) != (
        motion.kind, motion.omega, motion.center, motion.gamma):  # fmt: skip
        return motion, 0.0
    turns = [k for k in _HALF_TURNS if y.phase == motion.phase + math.radians(180.0 * k)]
    if not turns or motion.shape_gain == 0.0:
        return motion, 0.0
    ratio = (1.0 if turns[0] % 2 == 0 else -1.0) * y.shape_gain / motion.shape_gain
    size, beta = math.hypot(1.0, ratio), math.atan2(ratio, 1.0)
    line = dataclasses.replace(
        motion,
        amplitude=motion.amplitude * size,
        gain=None if motion.gain is None else motion.gain * size,
        angle=motion.angle + beta,
        second=None,
    )
    return line, beta


def turned_start(along, across, beta: float):
    """Rotations (or rates) given in a motion's vertical plane (along) and across it (the
    plane of its direction turned by +90 degrees), seen in the frame of that direction
    turned by beta [rad] (:func:`as_line`): (along', across'), arrays or floats."""
    if beta == 0.0:
        return along, across
    c, s = math.cos(beta), math.sin(beta)
    return c * along + s * across, c * across - s * along


def wrapped(angle: float) -> float:
    """angle [rad] taken modulo a whole turn, in [-pi, pi] (IEEE remainder: exact, and a
    whole turn is 0.0)."""
    return math.remainder(angle, 2.0 * math.pi)


def to_ground(vectors: np.ndarray, angle: float) -> np.ndarray:
    """Vectors in plan (k, 2) of a motion's frame turned to the ground's axes by angle
    [rad] (wrapped); at a wrapped angle of 0 the same array."""
    angle = wrapped(angle)
    if angle == 0.0:
        return vectors
    c, s = math.cos(angle), math.sin(angle)
    x, y = vectors[:, 0], vectors[:, 1]
    return np.stack([c * x - s * y, s * x + c * y], axis=1)


def from_ground(vectors: np.ndarray, angle: float) -> np.ndarray:
    """Vectors in plan (k, 2) in the ground's axes seen in a motion's frame of azimuth
    angle [rad] (the inverse of :func:`to_ground`)."""
    return to_ground(vectors, -angle)


__all__ = ["as_line", "from_ground", "to_ground", "turned_start", "wrapped"]
