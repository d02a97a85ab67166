"""The column in two directions' run record (numerics.records): its kind, declared apart from
the compiled functions that use it (numba reads a structure type back from its cache only
so)."""

from __future__ import annotations

from rbm_cli.models.rbm.step.inputs import MOTION_FIELDS
from rbm_cli.numerics.loop import LOOP_FIELDS
from rbm_cli.numerics.records import record_kind
from rbm_cli.structures.arrays import COLUMN_FIELDS

#: The column's work in a run in two directions (kernel.run3d): its pieces (each joint's
#: piece, an excursion pending its impact, its phase, leaving closure, the pinned direction
#: and distance c (n, 3)); the watched rows (their kinds and joints, how many: count) and
#: their distances and rates at a step's two ends; the rows near a crossing and their values
#: at the step's check points; the friction demand's (the shear ratios, theta'' at a sample of
#: the held demand, their peak between step ends); whether the first joint's ratio passed a
#: peak in the last step (turned); the run's task (its samples and held demand, in place;
#: whether it records, the sampling interval [s], the friction limit [-]) and its pair (the
#: motion's direction (d0, d1), a second record's samples or a formula's ground tuple gy,
#: its knots; whether there is a second component, and whether it is a formula).
COLUMN3D_WORK_FIELDS = [
    ("k", "int64[::1]"), ("pending", "bool[::1]"), ("phase", "int64[::1]"),
    ("rising", "bool[::1]"), ("c", "float64[:, ::1]"), ("kinds", "int64[::1]"),
    ("joints", "int64[::1]"), ("count", "int64[::1]"), ("d_old", "float64[::1]"),
    ("r_old", "float64[::1]"), ("d_new", "float64[::1]"), ("r_new", "float64[::1]"),
    ("near", "bool[::1]"), ("D", "float64[:, ::1]"), ("R", "float64[:, ::1]"),
    ("rx", "float64[::1]"), ("ry", "float64[::1]"), ("acc_k", "float64[::1]"),
    ("between", "float64[::1]"), ("turned", "bool[::1]"), ("samples", "float64[:, ::1]"),
    ("held", "float64[:, ::1]"), ("record", "bool"), ("output_dt", "float64"), ("mu", "float64"),
    ("d0", "float64"), ("d1", "float64"), ("values_y", "float64[::1]"),
    ("gy", "Tuple((int64, float64, float64, float64, float64, float64, float64, float64, "
           "float64))"),
    ("knots_y", "float64[::1]"), ("pair_on", "bool"), ("formula_y", "bool"),
]  # fmt: skip

#: The column in two directions' run record: the column (structures.arrays.ColumnArrays), what
#: its functions read of the motion, the loop's arrays and the run's figures, and its work.
COLUMN3D = record_kind(COLUMN_FIELDS + MOTION_FIELDS + LOOP_FIELDS + COLUMN3D_WORK_FIELDS)
