"""One definition of an impact, an uplift and a wobbling turn for every model
(docs/reference/outputs.md), through the public API.

Checked against what does not follow the 3D models' code:

- the planar models themselves: on a motion exactly in the plane of x (angle 0, no
  second component) `housner-3d` gives `housner`'s counts and `rbm-3d` the planar
  `rbm`'s, in a sweep (whose runs stop once no figure can change) as in a recorded run;
- the definition of an excursion: it opens with one uplift and ends with one impact, so
  a column's uplifts exceed its impacts by at most its number of joints (those still
  open at the end), whatever the restitution;
- the definition of a wobble: a lean smaller than WOBBLE_LEVEL of its collapse limit
  turns no wobbling turn, however its direction turns;
- symmetry: a motion turned by a whole turn is the same motion (to the bit), and turned
  by any angle the same run seen turned (to the bit: the models run it in its own frame).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

import rbm
from rbm_cli.models.outcome import WOBBLE_LEVEL

from .paths import CONFIGS

RECORDS = CONFIGS / "records" / "synthetic"
#: A tapered cylinder 4 m tall, 1 m across at the base and 0.8 m at the top.
COLUMN = {"height": 4.0, "base_width": 1.0, "top_width": 0.8, "section": "circular",
          "density": 2700}  # fmt: skip
#: The paper's tapered column in circular drums.
PAPER = {"height": 5.0, "base_width": 0.96, "top_width": 0.66, "section": "circular",
         "density": 2700}  # fmt: skip
ELASTIC = {"normal": 5e9}


def bursts() -> list:
    """Two seconds of a sine at 1, 1.5, 2 and 3 Hz, ended while the column rocks: its
    free motion after them is long, and a sweep's run stops in it."""
    t = np.linspace(0.0, 2.0, 2001)
    return [rbm.motion_from_arrays(t, np.sin(2.0 * math.pi * f * t), name=f"sine-{f:g}hz")
            for f in (1.0, 1.5, 2.0, 3.0)]  # fmt: skip


def config(model: str, column=None, **interface):
    return rbm.load_config({
        "name": "counts", "model": model, "column": dict(column or COLUMN),
        "interface": {"restitution": 0.9, **interface},
        "excitation": {"type": "harmonic"}, "grid": {"amplitudes": [0.3, 0.45]},
    })  # fmt: skip


#: (planar, 3D, interface): the rigid block and cylinder, the rigid RBM monolith (its
#: planar runs in the block's closed form, `auto`) and an elastic RBM monolith.
PAIRS = [
    ("housner", "housner-3d", {}),
    ("rbm", "rbm-3d", {}),
    ("rbm", "rbm-3d", {"stiffness": ELASTIC}),
]


@pytest.mark.parametrize("planar_model, model, interface", PAIRS)
def test_along_x_a_sweep_counts_the_planar_models_impacts_and_uplifts(
    planar_model, model, interface
):
    """A sweep of four sine bursts at two amplitudes: the same outcome, impacts and
    uplifts on every cell, peaks within 1e-8 (the along-x tests' tolerance); the planar
    runs stop early in the free motion on most cells (the case where the counts parted)."""
    motions = bursts()
    planar = rbm.sweep(config(planar_model, **interface), motions=motions)
    three = rbm.sweep(config(model, **interface), motions=motions)
    assert len(planar) == len(three) == 8
    stopped = 0
    for (_, a), (_, b) in zip(planar.iterrows(), three.iterrows(), strict=True):
        cell = (a.record, a.amplitude_g)
        assert (b.status, b.n_impacts, b.n_uplifts) == (a.status, a.n_impacts, a.n_uplifts), cell
        assert b.max_rotation_ratio == pytest.approx(a.max_rotation_ratio, rel=1e-8), cell
        stopped += "stopped early" in a.message and a.n_impacts > 0
    assert stopped >= 4


def test_along_x_a_recorded_run_counts_the_planar_models_impacts_and_uplifts():
    """`rbm run`'s runs (recorded: to the end of the free motion) count alike too."""
    for planar_model, model, interface in PAIRS:
        for motion in bursts()[:2]:
            a = rbm.run(config(planar_model, **interface), 0.3, motion=motion).result
            b = rbm.run(config(model, **interface), 0.3, motion=motion).result
            assert (b.n_impacts, b.n_uplifts) == (a.n_impacts, a.n_uplifts), (model, motion.name)
            assert a.n_impacts > 5


@pytest.mark.parametrize("model", ["rbm", "rbm-3d"])
@pytest.mark.parametrize("interface", [{"restitution": 1.0}, {"restitution": 1.0, "damping": 0.05},
                                       {"restitution": 0.9}])  # fmt: skip
def test_an_excursion_is_one_uplift_and_one_impact(model, interface):
    """Three elastic drums shaken for 10 s: every joint's excursion opens with an uplift
    and closes with an impact, so 0 <= uplifts - impacts <= 3 (the joints open at the
    end). With e = 1 (silent closures) a joint that comes back onto its elastic branch
    and opens again before it closed used to count a second uplift (51 more uplifts than
    impacts with damping)."""
    cfg = rbm.load_config({
        "name": "excursions", "model": model, "column": {**PAPER, "drums": 3},
        "interface": {"stiffness": ELASTIC, **interface},
        "excitation": {"type": "harmonic", "duration": 10.0},
    })  # fmt: skip
    for amplitude, frequency in ((0.3, 2.0), (0.4, 3.0)):
        r = rbm.run(cfg, amplitude, frequency, record=False).result
        assert r.n_impacts > 100, (amplitude, frequency)
        assert 0 <= r.n_uplifts - r.n_impacts <= 3, (amplitude, frequency, r.n_uplifts,
                                                      r.n_impacts)  # fmt: skip


def test_a_lean_below_the_wobble_level_turns_no_wobbling_turn():
    """Three elastic drums under a pair of records at 0.2 g: the joints open and close
    hundreds of times and their small rotations point every way, but none leans by
    WOBBLE_LEVEL of its limit: no wobbling turn (1,247 were counted for six drums, the
    direction of near-zero rotations turning round at every pass). At 0.35 g a joint
    leans farther and the pair turns it."""
    cfg = rbm.load_config({
        "name": "pair", "model": "rbm-3d", "column": {**PAPER, "drums": 3},
        "interface": {"stiffness": ELASTIC, "restitution": 1.0},
        "excitation": {"type": "record", "file": str(RECORDS / "rdk_01.AT2"),
                       "file_y": str(RECORDS / "rdk_02.AT2"), "units": "g", "free_time": 2.0},
    })  # fmt: skip
    low = rbm.run(cfg, 0.2, record=False).result
    assert low.n_impacts > 100 and low.max_rotation_ratio < WOBBLE_LEVEL
    assert low.wobble_turns == 0.0
    high = rbm.run(cfg, 0.35, record=False).result
    assert high.max_rotation_ratio > 2 * WOBBLE_LEVEL and high.wobble_turns > 0.5


def angled(model: str, angle=None, column=None, **interface):
    excitation = {"type": "half-sine", "duration": 3.0}
    if angle is not None:
        excitation["angle"] = angle
    return rbm.load_config({
        "name": "turned", "model": model, "column": dict(column or COLUMN),
        "interface": {"restitution": 0.9, **interface}, "excitation": excitation,
    })  # fmt: skip


#: The 3D models' columns: the rigid cylinder, the RBM's rigid monolith, two elastic drums.
TURNED = [("housner-3d", None, {}), ("rbm-3d", None, {}),
          ("rbm-3d", {**PAPER, "drums": 2}, {"stiffness": ELASTIC})]  # fmt: skip


def _figures(result) -> dict:
    return {k: v for k, v in result.items() if k != "wall_time_s"}


@pytest.mark.parametrize("model, column, interface", TURNED)
def test_a_whole_turn_is_no_turn(model, column, interface):
    """excitation.angle 360 and -360 give the run of 0 to the bit (every figure of the
    result), recorded (its top's path in plan too) and as a sweep's run; on a cell that
    rocks and one that collapses."""
    for (amplitude, frequency), record in itertools.product(((0.35, 1.5), (0.8, 1.0)),
                                                            (True, False)):  # fmt: skip
        runs = [rbm.run(angled(model, angle, column, **interface), amplitude, frequency,
                        record=record) for angle in (0.0, 360.0, -360.0)]  # fmt: skip
        base = _figures(runs[0].result)
        for cell in runs[1:]:
            assert _nan_equal(_figures(cell.result), base), (model, amplitude, record)
            if record:
                plan = cell.result.history.top_plan
                assert np.array_equal(plan, runs[0].result.history.top_plan)
        assert runs[0].result.n_uplifts > 0


def _nan_equal(a: dict, b: dict) -> bool:
    """Equal dicts where NaN equals NaN (a survived run's azimuth and collapse time, a
    model's friction demand it does not compute)."""
    if a.keys() != b.keys():
        return False
    for k in a:
        x, y = a[k], b[k]
        if isinstance(x, float | tuple) and isinstance(y, float | tuple):
            if not np.array_equal(np.asarray(x), np.asarray(y), equal_nan=True):
                return False
        elif x != y:
            return False
    return True


@pytest.mark.parametrize("model, column, interface", TURNED)
def test_a_turned_motion_is_the_run_along_x_seen_turned(model, column, interface):
    """A motion of one component turned to 37 or -123 degrees: the same outcome, counts,
    peaks and collapse time as along x to the bit, the collapse azimuth turned by the
    angle, the top's path in plan turned by it (1e-12 m)."""
    for amplitude, frequency in ((0.35, 1.5), (0.8, 1.0)):
        along = rbm.run(angled(model, None, column, **interface), amplitude, frequency).result
        for angle in (37.0, -123.0):
            turned = rbm.run(angled(model, angle, column, **interface), amplitude,
                             frequency).result  # fmt: skip
            for k in ("status", "n_impacts", "n_uplifts", "max_rotation_ratio", "n_steps",
                      "max_top_displacement_m", "wobble_turns"):  # fmt: skip
                assert turned[k] == along[k], (model, angle, k)
            if along.status == "collapsed":
                assert turned.t_collapse_s == along.t_collapse_s
                shift = math.remainder(turned.collapse_azimuth_deg - along.collapse_azimuth_deg
                                       - angle, 360.0)  # fmt: skip
                assert abs(shift) < 1e-9
            c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
            xy = along.history.top_plan
            expected = np.stack([c * xy[:, 0] - s * xy[:, 1], s * xy[:, 0] + c * xy[:, 1]], 1)
            assert np.max(np.abs(turned.history.top_plan - expected)) < 1e-12
