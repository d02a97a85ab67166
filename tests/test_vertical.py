"""Vertical shaking (``excitation.vertical``): the ground's upward acceleration a_v(t) makes
every weight act as if gravity were g + a_v(t).

Expected values from a similarity law, not from the code: for a rigid block, a constant
upward a_v = c g is the problem without it at amplitude A / (1 + c) and frequency
f / sqrt(1 + c), in a time sqrt(1 + c) longer (theta'' = (1 + c) [weight terms] + e a_g,
and tau = t sqrt(1 + c)); uplift times and lift-off times from straight lines.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rbm_cli.base.errors import ConfigError
from rbm_cli.config.load import parse_config
from rbm_cli.config.types import G
from rbm_cli.inputs.excitation import make_ground_motion, merge_records
from rbm_cli.inputs.ground import next_uplift
from rbm_cli.inputs.records import write_csv
from rbm_cli.models.registry import make_runner

from .record_files import half_sine_csv

COLUMN = {"height": 5.0, "base_width": 0.96, "top_width": 0.66, "drums": 1}
MODELS = [("rbm", "compiled"), ("rbm", "python"), ("housner", "compiled"),
          ("housner-linear", "compiled"), ("housner-linear", "python")]  # fmt: skip
SPAN = 12.0  # s: the vertical record lasts the whole run


def _record(model, impl, horizontal, vertical, **extra):
    exc = {"type": "record", "file": str(horizontal), "vertical": str(vertical),
           "scale": "factor", "free_time": 0.0, **extra}  # fmt: skip
    data = {"name": "v", "model": model, "column": COLUMN, "excitation": exc,
            "solver": {"implementation": impl}}  # fmt: skip
    return parse_config(data)


@pytest.mark.parametrize("model, impl", MODELS)
@pytest.mark.parametrize("c", [0.3, -0.3])
def test_constant_vertical_is_a_change_of_gravity(tmp_path, model, impl, c):
    """A half-sine record with a_v = c g over the whole run equals the analytic half-sine
    at A / (1 + c), f / sqrt(1 + c), run sqrt(1 + c) times longer: the same outcome, the
    collapse time times sqrt(1 + c) within 1e-3 s (found: ~1e-6 s), the same peak ratio
    within 1e-4. The vertical record is scaled by the horizontal's factor, so its file
    holds c / A."""
    s = math.sqrt(1.0 + c)
    frequencies = (0.5, 1.0) if impl == "compiled" else (1.0,)
    ref_cfg = parse_config(
        {"name": "h", "model": model, "column": COLUMN, "solver": {"implementation": impl},
         "excitation": {"type": "half-sine", "duration": SPAN * s}}
    )  # fmt: skip
    ref_runner = make_runner(ref_cfg)
    outcomes = set()
    for f in frequencies:
        horizontal = half_sine_csv(tmp_path / f"h{f}.csv", f)
        for a in (0.3, 0.5, 0.8, 1.2):
            vertical = write_csv(
                tmp_path / "v.csv", (np.array([0.0, SPAN]), np.full(2, c * G / a)), units="g"
            )
            cfg = _record(model, impl, horizontal, vertical)
            got = make_runner(cfg).run(make_ground_motion(cfg.excitation, a), cfg.solver)
            ref_motion = make_ground_motion(ref_cfg.excitation, a / (1.0 + c), f / s)
            ref = ref_runner.run(ref_motion, ref_cfg.solver)
            where = (model, impl, c, f, a)
            assert got.status == ref.status, where
            outcomes.add(ref.status)
            if ref.status == "collapsed":
                assert abs(got.t_collapse * s - ref.t_collapse) < 1e-3, where
            assert got.max_ratio[0] == pytest.approx(ref.max_ratio[0], abs=1e-4), where
    if impl == "compiled":
        assert outcomes == {"survived", "collapsed"}


@pytest.mark.parametrize("model, impl", MODELS)
def test_ground_dropping_faster_than_gravity_fails_the_run(tmp_path, model, impl):
    """a_v falls linearly from 0 to -2 g over 2 s: g + a_v reaches 0 at t = 1 s exactly;
    a run still standing then ends 'failed' with that reason; one that collapsed before
    keeps its collapse."""
    horizontal = write_csv(tmp_path / "h.csv", (np.array([0.0, 3.0]), np.zeros(2)), units="g")
    vertical = write_csv(
        tmp_path / "v.csv", (np.array([0.0, 2.0]), np.array([0.0, -2.0 * G])), units="g"
    )
    cfg = _record(model, impl, horizontal, vertical, scale="factor")
    motion = make_ground_motion(cfg.excitation, 1.0)
    assert motion.lift_off == pytest.approx(1.0, abs=1e-12)
    out = make_runner(cfg).run(motion, cfg.solver)
    assert out.status == "failed"
    assert "g + a_v(t) <= 0" in out.message and "at t=1 s" in out.message
    # a strong pulse first: the block collapses before the ground drops away
    strong = half_sine_csv(tmp_path / "s.csv", 2.0)
    cfg = _record(model, impl, strong, vertical, scale="factor")
    out = make_runner(cfg).run(make_ground_motion(cfg.excitation, 3.0), cfg.solver)
    assert out.status == "collapsed" and out.t_collapse < 1.0 / 3.0


def test_uplift_level_follows_the_vertical(tmp_path):
    """Under a_g = 2 g t and a_v = c g, a rigid block lifts when 2 g t = L (1 + c):
    GroundMotion and kernel alike."""
    c = 0.4
    h = write_csv(tmp_path / "h.csv", (np.array([0.0, 1.0, 2.0]), np.array([0.0, 2 * G, 0.0])))
    v = write_csv(tmp_path / "v.csv", (np.array([0.0, 2.0]), np.full(2, c * G)))
    cfg = _record("rbm", "compiled", h, v, scale="factor")
    motion = make_ground_motion(cfg.excitation, 1.0)
    level = 0.5 * G
    expected = 0.5 * (1.0 + c) / 2.0
    assert motion.next_exceedance(0.0, level) == pytest.approx(expected, abs=1e-12)
    gr = (motion.form, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    arrays = (np.array(motion.knots), np.array(motion.values), np.array(motion.vertical))
    t_k = next_uplift(0.0, level, motion.amplitude, gr, *arrays, motion.pulse_end)
    assert t_k == pytest.approx(expected, abs=1e-12)


def test_merge_keeps_the_jumps():
    """Horizontal 1 g on [0, 1] s (a jump to 0 at 1 s), vertical a ramp on [0.5, 2] s from
    0.2 g (a jump at 0.5 s): the union of times, a time written twice where either jumps,
    the values before then after."""
    knots, h, v = merge_records(
        np.array([0.0, 1.0]), np.array([G, G]), np.array([0.5, 2.0]), np.array([0.2 * G, 0.5 * G])
    )
    np.testing.assert_array_equal(knots, [0.0, 0.5, 0.5, 1.0, 1.0, 2.0])
    np.testing.assert_allclose(h / G, [1.0, 1.0, 1.0, 1.0, 0.0, 0.0])
    np.testing.assert_allclose(v / G, [0.0, 0.0, 0.2, 0.3, 0.3, 0.5])


def test_segments_restart_at_the_jumps(tmp_path):
    h = write_csv(tmp_path / "h.csv", (np.array([0.0, 1.0]), np.array([0.1, 0.1]) * G))
    v = write_csv(tmp_path / "v.csv", (np.array([0.5, 2.0]), np.array([0.2, 0.5]) * G))
    cfg = _record("rbm", "compiled", h, v, scale="factor", free_time=1.0)
    motion = make_ground_motion(cfg.excitation, 1.0)
    assert motion.segments() == [(0.0, 0.5), (0.5, 1.0), (1.0, 2.0), (2.0, 3.0)]
    assert motion.gravity()(0.25) == 1.0 and motion.gravity()(1.25) == pytest.approx(
        1.35
    )  # 0.2 + 0.3 * 0.75 / 1.5


@pytest.mark.parametrize(
    "data, needle",
    [
        ({"excitation": {"type": "harmonic", "vertical": "v.csv"}}, "applies only to type record"),
        ({"excitation": {"type": "record", "file": "h.csv", "vertical": "nope.csv"}},
         "excitation.vertical: "),
        ({"excitation": {"type": "record", "file": "h.csv", "vertical": "bad.csv"}},
         "line 3"),
    ],
)  # fmt: skip
def test_vertical_refused(tmp_path, data, needle):
    write_csv(tmp_path / "h.csv", (np.array([0.0, 1.0]), np.array([0.1, 0.1]) * G))
    write_csv(tmp_path / "v.csv", (np.array([0.0, 1.0]), np.array([0.1, 0.1]) * G))
    (tmp_path / "bad.csv").write_text("time_s,a\n0,0.1\n0,0.2\n")
    exc = {"type": "record", "file": "h.csv", "vertical": "v.csv"}
    full = {"name": "v", "column": COLUMN, "excitation": exc, **data}
    with pytest.raises(ConfigError) as err:
        parse_config(full, "c.yaml", tmp_path)
    assert needle in str(err.value) and "\n" not in str(err.value)


def test_vertical_in_the_resolved_config(tmp_path):
    """The vertical file is in the config's hash (as written, with its SHA-256); a
    record without one has no vertical keys."""
    write_csv(tmp_path / "h.csv", (np.array([0.0, 1.0]), np.array([0.1, 0.1]) * G))
    write_csv(tmp_path / "v.csv", (np.array([0.0, 3.0]), np.array([0.1, 0.1]) * G))
    exc = {"type": "record", "file": "h.csv", "vertical": "v.csv"}
    cfg = parse_config({"name": "v", "column": COLUMN, "excitation": exc}, "c", tmp_path)
    resolved = cfg.resolved()["excitation"]
    assert resolved["vertical"] == "v.csv" and len(resolved["vertical_sha256"]) == 64
    assert cfg.excitation.duration == pytest.approx(3.0 + 5.0)  # the longer record + 5 s
    del exc["vertical"]
    cfg = parse_config({"name": "v", "column": COLUMN, "excitation": exc}, "c", tmp_path)
    assert cfg.resolved()["excitation"]["vertical"] is None
