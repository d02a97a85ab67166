"""The planar column's run record (numerics.records): its kind, declared apart from the
compiled functions that use it (numba reads a structure type back from its cache only so)."""

from __future__ import annotations

from rbm_cli.models.rbm.step.inputs import MOTION_FIELDS
from rbm_cli.numerics.loop import LOOP_FIELDS
from rbm_cli.numerics.records import record_kind
from rbm_cli.structures.arrays import COLUMN_FIELDS

#: The planar column's work in a run (step.stepper.run_kernel): its pieces (each joint's side
#: and piece, an excursion pending its impact, a silent impact awaited: Model.silent_impacts),
#: the watched rows' bounds and offsets and their moving parts under a vertical record
#: (step.vertical); the step's figures over the n + 1 tracked rows (their peaks, a
#: polynomial's coefficients, zero offsets and none, the rows and their rates at the step's
#: two ends and before it); the event location's (step.events: the rows' distances and their
#: first and second rates at a step's two ends, the rows near a crossing, each row's nonzero
#: columns, first_crossing's own); the friction demand's (theta'' at a step's end, at its
#: start and at a sample of the held demand, the shear ratios there and their peak between
#: step ends) and the ground at the step's end (ends: gravity's factor and the horizontal
#: acceleration); and the run's task (its samples and held demand, in place; whether it
#: records, the sampling interval [s], the friction limit [-]) and kind (a vertical record,
#: silent impacts).
PLANE_WORK_FIELDS = [
    ("side", "int64[::1]"), ("k", "int64[::1]"), ("pending", "bool[::1]"),
    ("awaiting", "bool[::1]"), ("lo", "float64[::1]"), ("hi", "float64[::1]"),
    ("h0", "float64[::1]"), ("mv_e", "float64[::1]"), ("mv_w", "float64[::1]"),
    ("peaks", "float64[::1]"), ("coef", "float64[::1]"), ("zero_t", "float64[::1]"),
    ("no_offset", "float64[::1]"), ("z_old", "float64[::1]"), ("z_new", "float64[::1]"),
    ("z_prev", "float64[::1]"), ("dz_old", "float64[::1]"), ("dz_new", "float64[::1]"),
    ("dz_prev", "float64[::1]"), ("d_old", "float64[::1]"), ("d_new", "float64[::1]"),
    ("dd_old", "float64[::1]"), ("dd_new", "float64[::1]"), ("d2_old", "float64[::1]"),
    ("d2_new", "float64[::1]"), ("near", "bool[::1]"), ("spans", "int64[:, ::1]"),
    ("Dq", "float64[:, ::1]"), ("Rq", "float64[:, ::1]"), ("dc0", "float64[::1]"),
    ("dc1", "float64[::1]"),
    ("rc0", "float64[::1]"), ("rc1", "float64[::1]"), ("CP", "float64[:, ::1]"),
    ("BP", "float64[::1]"), ("CR", "float64[:, ::1]"), ("BR", "float64[::1]"),
    ("acc", "float64[::1]"), ("acc_old", "float64[::1]"), ("acc_k", "float64[::1]"),
    ("rx", "float64[::1]"), ("ry", "float64[::1]"), ("between", "float64[::1]"),
    ("ends", "float64[::1]"), ("samples", "float64[:, ::1]"), ("held", "float64[:, ::1]"),
    ("record", "bool"), ("output_dt", "float64"), ("mu", "float64"), ("vert", "bool"),
    ("any_silent", "bool"),
]  # fmt: skip

#: The planar column's run record: the column (structures.arrays.ColumnArrays), what its
#: functions read of the motion, the loop's arrays and the run's figures, and its work.
PLANE = record_kind(COLUMN_FIELDS + MOTION_FIELDS + LOOP_FIELDS + PLANE_WORK_FIELDS)
