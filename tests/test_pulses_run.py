"""Near-fault pulses as excitation types (one-sine, cycloidal, ricker,
mavroeidis-papageorgiou) through the config and every model.

Expected values are independent of the code under test: below the uplift level a rigid
block does not move; a one-sine pulse is one period of the harmonic; a ground
acceleration of the opposite sign mirrors the rotation; the pulse formulas equal
inputs/pulses.py's; the rigid RBM (the kernel evaluating each formula) equals
housner-linear under the exact mapping (alpha = B/H, true p), which integrates a Ricker or
MP pulse sampled at 2000 points a period, so the sampling error is shown negligible;
uplift times agree with a brute-force scan.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from rbm_cli.base.errors import ConfigError
from rbm_cli.config.load import parse_config
from rbm_cli.config.types import G
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.inputs.ground import next_uplift
from rbm_cli.inputs.pulses import mavroeidis_papageorgiou, ricker_wavelet
from rbm_cli.models.block.closed_form import linear_run
from rbm_cli.models.registry import make_runner
from rbm_cli.structures.assembly import model_from_config

COLUMN = {"height": 5.0, "base_width": 0.96, "top_width": 0.66, "drums": 1}
UPLIFT_G = 0.96 / 5.0  # the rigid RBM's static multiplier B/H (housner's tan(alpha) is more)
PULSES = [
    ("one-sine", {}),
    ("cycloidal", {}),
    ("ricker", {}),
    ("mavroeidis-papageorgiou", {"gamma": 2.0, "nu": 0.5}),
    ("mavroeidis-papageorgiou", {"gamma": 3.0, "nu": -1.2}),
]
MODELS = [("rbm", "compiled"), ("rbm", "python"), ("housner", "compiled"),
          ("housner-linear", "compiled")]  # fmt: skip


def _config(kind, extra, model="rbm", impl="compiled", **excitation):
    return parse_config(
        {
            "name": "pulse",
            "model": model,
            "column": COLUMN,
            "excitation": {"type": kind, **extra, **excitation},
            "solver": {"implementation": impl},
        }
    )


def _mirrored(motion):
    """The motion with its acceleration negated: a sine by half a turn of phase, a
    formula by a negative gain (the peak stays positive)."""
    if motion.form == 0:
        return dataclasses.replace(motion, phase=motion.phase + math.pi)
    return dataclasses.replace(motion, gain=-motion.shape_gain)


@pytest.mark.parametrize("model, impl", MODELS)
@pytest.mark.parametrize("kind, extra", PULSES)
def test_below_uplift_the_block_stays_at_rest(kind, extra, model, impl):
    """0.9 of the static multiplier: survived, no uplift, zero rotation."""
    cfg = _config(kind, extra, model, impl)
    out = make_runner(cfg).run(make_ground_motion(cfg.excitation, 0.9 * UPLIFT_G, 1.3), cfg.solver)
    assert out.status == "survived"
    assert out.n_uplifts == 0 and out.max_ratio[0] == 0.0


@pytest.mark.parametrize("model, impl", MODELS)
@pytest.mark.parametrize("a, f", [(0.3, 0.5), (0.3, 1.0), (0.6, 1.0), (1.2, 2.0), (2.0, 0.7)])
def test_one_sine_is_one_period_of_the_harmonic(model, impl, a, f):
    """A one-sine pulse simulated for its own period is the harmonic of duration 1/f:
    the same outcome, collapse time and peak, to the bit."""
    one = _config("one-sine", {}, model, impl, duration=1.0 / f)
    harm = _config("harmonic", {}, model, impl, duration=1.0 / f)
    got = make_runner(one).run(make_ground_motion(one.excitation, a, f), one.solver)
    ref = make_runner(harm).run(make_ground_motion(harm.excitation, a, f), harm.solver)
    assert got.status == ref.status
    assert got.t_collapse == ref.t_collapse or (
        math.isnan(got.t_collapse) and math.isnan(ref.t_collapse)
    )
    assert got.max_ratio[0] == ref.max_ratio[0]


@pytest.mark.parametrize("model, impl", [("rbm", "compiled"), ("rbm", "python"), ("housner", "")])
@pytest.mark.parametrize("kind, extra", PULSES)
def test_opposite_acceleration_mirrors_the_rotation(kind, extra, model, impl):
    """a_g -> -a_g gives theta -> -theta: the same outcome and peak, the mirrored history."""
    cfg = _config(kind, extra, model, impl or "compiled", duration=6.0)
    runner = make_runner(cfg)
    for a in (0.3, 0.8):
        motion = make_ground_motion(cfg.excitation, a, 1.0)
        one = runner.run(motion, cfg.solver, record=True, output_dt=0.01, early_stop=False)
        two = runner.run(
            _mirrored(motion), cfg.solver, record=True, output_dt=0.01, early_stop=False
        )
        assert one.status == two.status
        assert one.max_ratio[0] == pytest.approx(two.max_ratio[0], abs=1e-7)
        assert one.max_ratio[0] > 0.05  # it rocked
        th1, th2 = one.history.rotations[:, 0], two.history.rotations[:, 0]
        np.testing.assert_allclose(th1, -th2, atol=1e-7 * UPLIFT_G)


def test_pulse_formulas_are_those_of_pulses_py():
    """The integrators' scalar formulas (inputs.ground) equal inputs/pulses.py's."""
    t = np.linspace(-0.1, 3.5, 2001)
    for kind, extra, reference in [
        ("ricker", {}, lambda tt: ricker_wavelet(tt, 0.7 * G, 1.1)),
        ("mavroeidis-papageorgiou", {"gamma": 2.5, "nu": 0.3},
         lambda tt: mavroeidis_papageorgiou(tt, 0.7 * G, 1.1, 2.5, 0.3)),
    ]:  # fmt: skip
        cfg = _config(kind, extra)
        motion = make_ground_motion(cfg.excitation, 0.7, 1.1)
        scalar = motion.scalar(True)
        inside = t[(t >= 0.0) & (t <= motion.pulse_end)]
        got = np.array([scalar(x) for x in inside])
        np.testing.assert_allclose(got, reference(inside), rtol=0, atol=1e-12 * 0.7 * G)
        np.testing.assert_allclose(motion.accel(t), reference(t), rtol=0, atol=1e-12 * G)
        assert np.max(np.abs(motion.accel(np.linspace(0, motion.pulse_end, 20001)))) == (
            pytest.approx(0.7 * G, rel=1e-6)
        )


def test_ground_displacement_of_the_sine_pulses():
    """One-sine: the ground ends displaced by A T / w with no velocity; cycloidal (a
    cosine): back to where it started (Zhang and Makris)."""
    a, f = 0.5, 0.8
    w, period = 2 * math.pi * f, 1 / f
    end = np.array([period, period + 3.0])
    one = make_ground_motion(_config("one-sine", {}).excitation, a, f)
    np.testing.assert_allclose(one.displacement(end), a * G * period / w, rtol=1e-7)
    cyc = make_ground_motion(_config("cycloidal", {}).excitation, a, f)
    np.testing.assert_allclose(cyc.displacement(end), 0.0, atol=1e-9 * a * G / w**2)
    assert cyc.accel(0.0) == pytest.approx(a * G) and cyc.accel(period / 2) == pytest.approx(-a * G)


@pytest.mark.parametrize(
    "kind, extra", [p for p in PULSES if p[0] in ("ricker", "mavroeidis-papageorgiou")]
)
def test_rigid_rbm_equals_housner_linear_under_sampled_pulse(kind, extra):
    """The rigid n = 1 RBM is housner-linear with alpha = B/H and the RBM's p (from
    the true inertia). The kernel evaluates the pulse's formula; housner-linear integrates it
    sampled at 2000 points a period: the same outcomes on a grid, collapse times within
    1e-4 s and peaks within 1e-4 (the sampling error is negligible)."""
    cfg = _config(kind, extra, duration=10.0)
    model = model_from_config(cfg)
    alpha, p = float(model.column.rotation_capacity[0]), model.rocking_p
    runner = make_runner(cfg)
    statuses = set()
    for f in (0.5, 1.0, 2.5):
        for a in (0.25, 0.4, 0.6, 0.9, 1.5, 3.0):
            motion = make_ground_motion(cfg.excitation, a, f)
            rbm = runner.run(motion, cfg.solver)
            lin = linear_run(alpha, p, motion)
            assert rbm.status == lin.status, (a, f)
            statuses.add(rbm.status)
            if rbm.status == "collapsed":
                assert abs(rbm.t_collapse - lin.t_collapse) < 1e-4, (a, f)
            else:
                assert rbm.max_ratio[0] == pytest.approx(lin.max_ratio[0], abs=1e-4), (a, f)
    assert statuses == {"survived", "collapsed"}


@pytest.mark.parametrize("kind, extra", PULSES)
@pytest.mark.parametrize("level_g", [0.15, 0.45, 0.8])
def test_uplift_time_against_a_scan(kind, extra, level_g):
    """The first |a_g| > L: GroundMotion (Python) and the kernel agree to 1e-12 s, and a
    scan on 10^6 points finds it within one point's spacing."""
    cfg = _config(kind, extra)
    motion = make_ground_motion(cfg.excitation, 1.0, 0.8)
    level = level_g * G
    t_py = motion.next_exceedance(0.0, level)
    gr = (motion.form, motion.shape_gain, motion.omega, motion.phase, motion.center,
          motion.gamma, 0.0, 0.0, 0.0)  # fmt: skip
    knots = np.zeros(0) if motion.knots is None else np.array(motion.knots)
    none = np.zeros(0)
    t_k = next_uplift(0.0, level, motion.amplitude, gr, knots, none, none, motion.pulse_end)
    assert t_py is not None and t_k == pytest.approx(t_py, abs=1e-12)
    ts = np.linspace(0.0, motion.pulse_end, 1_000_001)
    first = ts[np.argmax(np.abs(motion.accel(ts)) > level)]
    assert first - ts[1] <= t_py <= first + 1e-12


@pytest.mark.parametrize(
    "excitation, needle",
    [
        ({"type": "mavroeidis-papageorgiou", "nu": 0.0}, "excitation.gamma is required"),
        ({"type": "mavroeidis-papageorgiou", "gamma": 2.0}, "excitation.nu is required"),
        ({"type": "mavroeidis-papageorgiou", "gamma": 1.0, "nu": 0}, "excitation.gamma must"),
        ({"type": "mavroeidis-papageorgiou", "gamma": 2, "nu": 7}, "excitation.nu must"),
        ({"type": "ricker", "gamma": 2.0}, "excitation.gamma applies only"),
        ({"type": "one-sine", "phase": 1.0}, "excitation.phase applies only"),
        ({"type": "cycloidal", "file": "x.AT2"}, "excitation.file applies only"),
    ],
)
def test_pulse_keys_validated(excitation, needle):
    with pytest.raises(ConfigError) as err:
        parse_config({"name": "p", "column": COLUMN, "excitation": excitation}, "c.yaml")
    assert needle in str(err.value) and "\n" not in str(err.value)


def test_pulse_duration_is_the_maximum_simulated_time():
    """Default 20 s; the whole pulse is always simulated (a 0.05 Hz Ricker lasts 60 s)."""
    for kind, extra in PULSES:
        cfg = _config(kind, extra)
        assert cfg.excitation.duration == 20.0
        assert make_ground_motion(cfg.excitation, 0.3, 1.0).t_end == 20.0
    cfg = _config("ricker", {})
    assert make_ground_motion(cfg.excitation, 0.3, 0.05).t_end == pytest.approx(60.0)
