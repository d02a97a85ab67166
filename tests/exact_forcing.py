"""Forcings written as objects, for the tests of the exact integrator's closed forms: a
segment's ground acceleration (Forcing), its array as the compiled code reads it
(forcing_array, the layout of rbm_cli.models.rbm.exact.modal), a sampled record's segments
one by one (sampled_segments) and their arrays (segment_arrays): an independent, per-object
construction of what rbm_cli.models.rbm.forcing_arrays builds vectorised."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rbm_cli.models.rbm.exact.modal import FORCING_SIZE, HARMONIC, LINEAR, ZERO


@dataclass(frozen=True)
class Forcing:
    """The ground acceleration on a segment of the motion, from absolute time t [s]
    (forcing_array makes its array).

    kind : str  'harmonic' (a_g = amplitude sin(omega t + phase)), 'linear'
        (a_g = a0 + a1 (t - t0), t0 the segment's start) or 'zero'
    amplitude [m/s^2], omega [rad/s], phase [rad]: the harmonic's
    t0 [s], a0 [m/s^2], a1 [m/s^3]: the linear piece's
    """

    kind: str
    amplitude: float = 0.0
    omega: float = 0.0
    phase: float = 0.0
    t0: float = 0.0
    a0: float = 0.0
    a1: float = 0.0


def forcing_array(forcing) -> np.ndarray:
    """The fc array of a Forcing."""
    kind = {"zero": ZERO, "harmonic": HARMONIC, "linear": LINEAR}[forcing.kind]
    return np.array(
        [kind, forcing.amplitude, forcing.omega, forcing.phase, forcing.t0, forcing.a0,
         forcing.a1], dtype=np.float64,
    )  # fmt: skip


def sampled_segments(
    times: np.ndarray, accel: np.ndarray, t_end: float
) -> list[tuple[float, float, Forcing]]:
    """Segments of a sampled record: a_g linear between samples (times [s], non-decreasing,
    a time written twice where a_g jumps; accel [m/s^2]), zero after the last sample up
    to t_end [s]."""
    times, accel = np.asarray(times, dtype=float), np.asarray(accel, dtype=float)
    out = []
    for k in range(times.size - 1):
        t0, t1 = float(times[k]), float(times[k + 1])
        if t0 >= t_end:
            break
        if t1 <= t0:  # a time written twice: a jump, from the value before to the one after
            continue
        slope = (accel[k + 1] - accel[k]) / (t1 - t0)
        out.append((t0, min(t1, t_end), Forcing("linear", t0=t0, a0=float(accel[k]), a1=slope)))
    if times.size and times[-1] < t_end:
        out.append((float(times[-1]), t_end, Forcing("zero")))
    return out


def segment_arrays(segs: list) -> tuple[np.ndarray, np.ndarray]:
    """(seg_t, seg_fc) of a list of (start [s], end [s], Forcing)."""
    seg_t = np.array([[s, e] for s, e, _ in segs], dtype=float).reshape(-1, 2)
    seg_fc = np.array([forcing_array(f) for _, _, f in segs]).reshape(-1, FORCING_SIZE)
    return seg_t, seg_fc
