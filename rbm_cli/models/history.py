"""A run's sampled time history (History), as a runner makes it from its samples."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class History:
    """Sampled time history of a run (SI units).

    t : (k,) Time [s]
    ground_acceleration : (k,) a_g(t) [m/s^2]
    ground_displacement : (k,) u_g(t) [m] (harmonic: the steady form -a_g/omega^2;
        half-sine: integrated from rest)
    node_displacements : (k, n+1) Horizontal displacement of nodes 1..n+1
        relative to the ground [m] (node 1 is the base: always 0)
    rotations : (k, n) Absolute drum rotations theta_i [rad]
    rates : (k, n) Their rates theta_i' [rad/s]
    top_plan : (k, 2) or None  A model in three dimensions: the top centre's place in plan
        [m] (x, y) from where it stood
    ground_acceleration_y : (k,) or None  A pair of records: the second component a_y(t)
        [m/s^2] (ground_acceleration is then the first's)
    rotations_across : (k, n) or None  A model in three dimensions: the drums' rotations
        seen in the vertical plane across the motion's (its direction turned by +90
        degrees) [rad]; ``rotations`` are those seen in the motion's plane
    """

    t: np.ndarray
    ground_acceleration: np.ndarray
    ground_displacement: np.ndarray
    node_displacements: np.ndarray
    rotations: np.ndarray
    rates: np.ndarray | None = None
    top_plan: np.ndarray | None = None
    ground_acceleration_y: np.ndarray | None = None
    rotations_across: np.ndarray | None = None


def history_from_samples(node_map: np.ndarray, motion, samples) -> History:
    """The History of a run from its samples [(t, theta, rate), ...], the map of
    rotations to node displacements (n+1, n) and its ground motion."""
    n = node_map.shape[1]
    if samples:
        t = np.array([s[0] for s in samples])
        theta = np.array([s[1] for s in samples])
        rates = np.array([s[2] for s in samples])
    else:
        t, theta, rates = np.zeros(0), np.zeros((0, n)), np.zeros((0, n))
    return History(
        t=t,
        ground_acceleration=np.asarray(motion.accel(t), dtype=float),
        ground_displacement=motion.displacement(t),
        node_displacements=theta @ node_map.T,
        rotations=theta,
        rates=rates,
        ground_acceleration_y=motion.accel_y(t),
    )
