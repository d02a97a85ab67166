"""The contact engine's run of a motion in the plane of x is one run, whichever way the
config says it: no direction, `excitation.angle` 0 or a whole turn, or a second record of
zeros (the engine's cylinders held in the plane, or free in three dimensions).

Independent reasons: a cylinder under a motion along x has nothing that pushes it out of
the plane (along x the engine keeps its contact points in the plane of rocking,
docs/engine.md), so holding it there changes nothing but round-off; and an azimuth is an
angle modulo a whole turn.
"""

from __future__ import annotations

import numpy as np
import pytest

import rbm

from .paths import CONFIGS

#: Contact-engine runs: `pytest -m 'not slow'` leaves this file out.
pytestmark = pytest.mark.slow

COLUMN = {"height": 5.0, "base_width": 0.96, "top_width": 0.66, "section": "circular"}


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    """The first 4 s of a record of the project as x, and a record of zeros as y [g]."""
    folder = tmp_path_factory.mktemp("plane")
    lines = (CONFIGS / "records" / "synthetic" / "rdk_01.AT2").read_text().splitlines()[4:]
    acc = np.array([float(v) for line in lines for v in line.split()])
    t = 0.01 * np.arange(acc.size)
    keep = t <= 4.0
    for name, values in (("x", acc[keep]), ("y", np.zeros(keep.sum()))):
        np.savetxt(folder / f"{name}.csv", np.c_[t[keep], values], delimiter=",",
                   header="time_s,acc_g", comments="")  # fmt: skip
    return folder


def config(folder, **excitation):
    return rbm.load_config({
        "name": "plane", "model": "bullet", "column": {**COLUMN, "drums": 1},
        "interface": {"friction": 1.0},
        "excitation": {"type": "record", "file": str(folder / "x.csv"), "units": "g",
                       "scale": "pga", "free_time": 1.0, **excitation},
    })  # fmt: skip


@pytest.mark.parametrize("amplitude", [0.6, 1.0])
def test_a_zero_second_record_is_the_run_in_the_plane(record, amplitude):
    """A circular monolith rocking under a record: the run in the plane (no direction)
    and the run free in three dimensions with a second record of zeros have the same
    outcome, uplifts and impacts, and peaks within 1e-9 (they differed by 0.6 %: the plane
    held polygonal prisms)."""
    plane = rbm.run(config(record), amplitude, record=False).result
    zero = rbm.run(config(record, file_y=str(record / "y.csv")), amplitude, record=False).result
    assert plane.n_uplifts > 0 and plane.n_impacts > 3
    assert (zero.status, zero.n_uplifts, zero.n_impacts) == (
        plane.status, plane.n_uplifts, plane.n_impacts)  # fmt: skip
    assert zero.max_rotation_ratio == pytest.approx(plane.max_rotation_ratio, rel=1e-9)
    assert zero.wobble_turns == 0.0


def _same(a, b) -> bool:
    """Equal, NaN equal to NaN (a survived run's collapse time and azimuth)."""
    if isinstance(a, float | tuple) and isinstance(b, float | tuple):
        return np.array_equal(np.asarray(a, float), np.asarray(b, float), equal_nan=True)
    return a == b


def test_a_whole_turn_is_no_turn(record):
    """excitation.angle 360 and -360 give the run of angle 0 to the bit: every figure of
    the result (the engine takes the azimuth modulo a whole turn)."""
    runs = [rbm.run(config(record, angle=angle), 1.0, record=False).result
            for angle in (0.0, 360.0, -360.0)]  # fmt: skip
    assert runs[0].n_uplifts > 0
    for run in runs[1:]:
        for k in runs[0]:
            if k != "wall_time_s":
                assert _same(run[k], runs[0][k]), k
