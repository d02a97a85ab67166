"""A ground motion's forcing segments as the arrays the compiled closed forms read: the
exact integrator (rbm_cli.models.rbm.exact) and the rigid block's closed form (closed_form).

seg_t (segments, 2): start and end [s] of each smooth segment; seg_fc (segments,
FORCING_SIZE): its forcing (exact.modal: zero, harmonic or linear).
"""

from __future__ import annotations

import math
import time

import numpy as np

from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.models.rbm.exact.modal import FORCING_SIZE, HARMONIC, LINEAR, ZERO
from rbm_cli.models.rbm.exact.motion import check_exact
from rbm_cli.models.status import stop_level
from rbm_cli.structures.equations import Model


def record_arrays(motion: GroundMotion) -> tuple[np.ndarray, np.ndarray]:
    """The segments of a record motion as (seg_t, seg_fc) arrays: rest up to its first
    sample, one linear forcing per sample interval of positive length (a time written twice
    is a jump), then free motion, split at pulse_end [s] (the free motion after the record
    starts there). Vectorised: no Python object per sample (3,000 samples: 0.3 ms a run)."""
    knots = np.asarray(motion.knots, dtype=float)
    values = np.asarray(motion.values, dtype=float)
    t_end = float(motion.t_end)
    k = np.nonzero((np.diff(knots) > 0.0) & (knots[:-1] < t_end))[0]
    lin_t = np.stack([knots[k], np.minimum(knots[k + 1], t_end)], axis=1)
    lin_fc = np.zeros((k.size, FORCING_SIZE))
    lin_fc[:, 0] = LINEAR
    lin_fc[:, 4] = knots[k]
    lin_fc[:, 5] = values[k]
    lin_fc[:, 6] = (values[k + 1] - values[k]) / (knots[k + 1] - knots[k])
    cuts = sorted({0.0, float(knots[0]), float(knots[-1]), float(motion.pulse_end), t_end})
    before, after = [], []
    for a, b in zip(cuts[:-1], cuts[1:], strict=False):
        if b > a and a < t_end and (b <= knots[0] or a >= knots[-1]):
            (before if b <= knots[0] else after).append((a, min(b, t_end)))
    zero = np.zeros(FORCING_SIZE)
    zero[0] = ZERO
    seg_t = np.concatenate([np.array(before).reshape(-1, 2), lin_t, np.array(after).reshape(-1, 2)])
    seg_fc = np.concatenate([np.tile(zero, (len(before), 1)), lin_fc,
                             np.tile(zero, (len(after), 1))])  # fmt: skip
    return seg_t, seg_fc


def sine_arrays(motion: GroundMotion) -> tuple[np.ndarray, np.ndarray]:
    """The segments of a sine motion (a harmonic, or a sine pulse then free motion) as
    (seg_t, seg_fc) arrays: the harmonic forcing on the forced segments, zero on the
    others."""
    segments = motion.segments()
    seg_t = np.array(segments, dtype=float).reshape(-1, 2)
    seg_fc = np.zeros((len(segments), FORCING_SIZE))
    for i, (start, _) in enumerate(segments):
        if motion.forced(start):
            seg_fc[i, :4] = HARMONIC, motion.amplitude, motion.omega, motion.phase
    return seg_t, seg_fc


def motion_arrays(model: Model, motion: GroundMotion) -> tuple[np.ndarray, np.ndarray]:
    """(seg_t, seg_fc) of a run of the exact integrator: a record's or a sine's segments
    (exact.motion.check_exact refuses what has no closed form, in one line)."""
    check_exact(model, motion.kind, motion.has_vertical)
    return record_arrays(motion) if motion.kind == "record" else sine_arrays(motion)


def run_settings(
    motion: GroundMotion,
    solver,
    early_stop: bool,
    record: bool,
    output_dt: float,
    friction_limit: float = math.inf,
    until_open: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """(mo, se) of one run of a compiled closed-form loop: the motion
    mo = [pulse or record (0/1), amplitude, omega, phase, pulse_end, t_end] and the settings
    se = [max_steps, max_events, deadline (monotonic clock, from solver.max_wall_time),
    stop level (models.status.stop_level), record, output_dt, friction limit [-] (inf:
    none), until_open (the exact
    integrator: stop at the first event of a joint, rbm_cli.models.status.OPENED)]."""
    mo = np.array([1.0 if motion.is_pulse else 0.0, motion.amplitude, motion.omega,
                   motion.phase, motion.pulse_end, motion.t_end])  # fmt: skip
    deadline = time.monotonic() + float(solver.max_wall_time)
    se = np.array([solver.max_steps, solver.max_events, deadline,
                   float(stop_level(early_stop, solver)),
                   float(record), output_dt, friction_limit, float(until_open)],
                  dtype=float)  # fmt: skip
    return mo, se
