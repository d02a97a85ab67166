"""A ground motion's azimuth in plan, for the models in three dimensions.

A motion of one component (or a pair: the first along its azimuth, the second across it)
is the same motion turned: `housner-3d` and `rbm-3d` run it in its own frame, along x, and
turn what they report in plan (the top's path, the collapse azimuth) back to the ground's
axes. Every azimuth then gives the run of azimuth 0 to the bit, and a motion along x
stays in its vertical plane to the bit (nothing across it): the planar model's run.
An azimuth is taken modulo a whole turn, so 360 degrees is 0 to the bit.
"""

from __future__ import annotations

import math

import numpy as np


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


__all__ = ["from_ground", "to_ground", "wrapped"]
