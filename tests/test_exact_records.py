"""`solver.method: exact` under every excitation it takes beyond the harmonic: sine pulses
(one-sine, cycloidal) and records (piecewise linear per sample interval), and one-line
refusals of the rest (Ricker, Mavroeidis-Papageorgiou, vertical records).

Expected values from a second path to the same answer:

- the step kernel (DOP853 at rtol 1e-11 and 1e-12, atol 1e-14 and 1e-16 theta_u) on the
  same cells: where the two tolerances agree (tests/test_exact_domains.py's rule: same
  outcome and events, peaks and collapse time within 1e-9; a chaotic 8-drum run under a
  record agrees with no other run), the same outcome and events and peak rotation ratio,
  top displacement and collapse time within 1e-8 of rtol 1e-12, on an elastic 8-drum column
  and a rigid monolith; every test needs some such cells;
- a half-sine written as a record of 4000 samples against the analytic half-sine, both
  exact: the same outcome, peak ratio within the interpolation's error (h^2 max|a''| / 8
  = (pi/4000)^2 / 8 of the peak: 8e-8; asserted at 1e-5 of the peak, the response of a
  rocking block to a forcing error of 8e-8 g being far below it).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from rbm_cli.base.errors import RbmError
from rbm_cli.config.load import parse_config
from rbm_cli.config.types import G
from rbm_cli.inputs.records import Record, write_at2
from rbm_cli.models.registry import make_runner
from rbm_cli.study.simulate import simulate

from .converged import assert_agrees, converged
from .paths import CONFIGS

pytestmark = pytest.mark.timeout(900)

RECORD = CONFIGS / "records" / "synthetic" / "rdk_01.AT2"
#: The paper's tapered column, 8 drums and monolithic (rigid).
COLUMN = {"height": 5.0, "base_width": 0.96, "top_width": 0.66}
ELASTIC = {"stiffness": {"normal": 5e9}, "xi": 1.0, "restitution": 1.0}


def _config(drums, excitation, method, interface=None, rtol=1e-12):
    solver = {"method": method}
    if method == "DOP853":
        solver.update(rtol=rtol, atol=rtol * 1e-4)
    data = {"name": "x", "model": "rbm", "column": {**COLUMN, "drums": drums},
            "excitation": excitation, "solver": solver}  # fmt: skip
    if interface is not None:
        data["interface"] = interface
    return parse_config(data)


def _runs(drums, excitation, cells, interface=None):
    """(step kernel at rtol 1e-11, at 1e-12, exact) results on the cells (amplitude [g],
    frequency [Hz] or None)."""
    out = []
    for method, rtol in (("DOP853", 1e-11), ("DOP853", 1e-12), ("exact", 1e-12)):
        cfg = _config(drums, excitation, method, interface=interface, rtol=rtol)
        runner = make_runner(cfg)
        out.append([simulate(cfg, a, f, runner=runner) for a, f in cells])
    return out


def _check(drums, excitation, cells, interface=None) -> int:
    """Compare exact with the step kernel on the converged cells; returns how many."""
    k11, k12, exact = _runs(drums, excitation, cells, interface)
    count = 0
    for cell, a, b, e in zip(cells, k11, k12, exact, strict=True):
        if converged(a, b):
            assert_agrees(b, e, cell)
            count += 1
    return count


@pytest.mark.parametrize("kind", ["one-sine", "cycloidal"])
@pytest.mark.parametrize("drums", [1, pytest.param(8, marks=pytest.mark.slow)])
def test_sine_pulses_agree_with_the_step_kernel(kind, drums):
    interface = ELASTIC if drums > 1 else None
    excitation = {"type": kind, "duration": 4.0}
    if drums > 1:
        cells = [(0.05, 2.0), (0.1, 1.0), (0.15, 2.0), (0.3, 1.0)]
    else:
        cells = [(0.25, 1.0), (0.3, 1.0), (0.5, 2.0), (1.2, 3.0)]
    assert _check(drums, excitation, cells, interface) >= 2


@pytest.mark.parametrize("drums", [1, pytest.param(8, marks=pytest.mark.slow)])
def test_a_record_agrees_with_the_step_kernel(drums):
    """A synthetic record (rdk_01, 0.01 s samples), scaled to three PGAs."""
    interface = ELASTIC if drums > 1 else None
    excitation = {"type": "record", "file": str(RECORD), "units": "g", "free_time": 2.0}
    amplitudes = (0.03, 0.06, 0.1) if drums > 1 else (0.2, 0.5, 0.9)
    cells = [(a, None) for a in amplitudes]
    assert _check(drums, excitation, cells, interface) >= 2


def test_a_half_sine_record_is_the_half_sine(tmp_path):
    """A rigid monolith: the half-sine as 4000 samples (record) and as its formula."""
    f, samples = 1.0, 4000
    t = np.linspace(0.0, 0.5 / f, samples + 1)
    a = G * np.sin(2 * np.pi * f * t)  # m/s^2 (Record), written in g: a 1 g half-sine
    a[0] = a[-1] = 0.0
    path = write_at2(tmp_path / "hs.AT2", Record(t, a, name="hs"))
    rec = _config(1, {"type": "record", "file": str(path), "units": "g", "scale": "factor",
                      "free_time": 4.0}, "exact")  # fmt: skip
    ana = _config(1, {"type": "half-sine", "duration": 4.0 + 0.5 / f}, "exact")
    for amp in (0.3, 0.6, 1.0):
        x = simulate(rec, amp, None)
        y = simulate(ana, amp, f)
        assert x.status == y.status, amp
        assert abs(x.max_rotation_ratio - y.max_rotation_ratio) <= 1e-5 * y.max_rotation_ratio
    # uncompiled (the same source, implementation python): the same bits under a record
    short = dataclasses.replace(rec, excitation=dataclasses.replace(rec.excitation, free_time=0.3))
    py = dataclasses.replace(short, solver=dataclasses.replace(rec.solver, implementation="python"))
    x, y = simulate(py, 0.6, None), simulate(short, 0.6, None)
    assert (x.status, x.n_uplifts, x.n_impacts) == (y.status, y.n_uplifts, y.n_impacts)
    same = ("n_steps", "n_rhs", "max_rotation_ratio", "max_top_displacement_m")
    assert [getattr(x, k) for k in same] == [getattr(y, k) for k in same]


@pytest.mark.parametrize(
    ("excitation", "word"),
    [({"type": "ricker"}, "ricker"),
     ({"type": "mavroeidis-papageorgiou", "gamma": 2.0, "nu": 0.0}, "mavroeidis-papageorgiou"),
     ({"type": "record", "file": str(RECORD), "vertical": str(RECORD)}, "vertical")],
)  # fmt: skip
def test_what_exact_does_not_take_is_refused_in_one_line(excitation, word):
    cfg = _config(1, excitation, "exact")  # a rigid monolith: it takes a vertical record
    with pytest.raises(RbmError) as err:
        make_runner(cfg)
    assert "\n" not in str(err.value) and word in str(err.value)
    assert "exact" in str(err.value)


def test_the_step_method_still_takes_them():
    cfg = _config(1, {"type": "ricker"}, "DOP853")
    assert simulate(cfg, 0.5, 2.0, runner=make_runner(cfg)).status in ("survived", "collapsed")


def _record_segments(motion):
    """The oracle: a record's segments as Forcing objects, one per sample interval of
    positive length (exact_forcing.sampled_segments), with rest before the first sample and
    free motion after the last, split at pulse_end."""
    from .exact_forcing import Forcing, sampled_segments

    knots, values = motion.knots, motion.values
    inner = [s for s in sampled_segments(knots, values, motion.t_end) if s[2].kind == "linear"]
    cuts = sorted({0.0, float(knots[0]), float(knots[-1]), motion.pulse_end, motion.t_end})
    rest = [(a, min(b, motion.t_end), Forcing("zero"))
            for a, b in zip(cuts[:-1], cuts[1:], strict=False)
            if b > a and (b <= knots[0] or a >= knots[-1]) and a < motion.t_end]  # fmt: skip
    return sorted(rest + inner, key=lambda s: s[0])


def test_the_record_arrays_are_the_record_segments():
    """The arrays of a record (record_arrays, vectorised) and its segments as Forcing
    objects, one per interval, are the same, a jump (a time written twice) and rest before
    the first sample included."""
    from rbm_cli.inputs.motion import GroundMotion
    from rbm_cli.models.rbm.forcing_arrays import record_arrays

    from .exact_forcing import segment_arrays as _segments

    knots = np.array([0.5, 0.6, 0.7, 0.7, 0.8])
    values = np.array([0.3, -0.2, 0.4, -0.5, 0.1])
    motion = GroundMotion("record", 0.5, 0.0, 0.0, 0.8, 1.8, gain=1.0, knots=knots,
                          values=values)  # fmt: skip
    seg_t, seg_fc = record_arrays(motion)
    ref_t, ref_fc = _segments(_record_segments(motion))
    assert np.array_equal(seg_t, ref_t) and np.array_equal(seg_fc, ref_fc)
    assert seg_t.tolist() == [[0.0, 0.5], [0.5, 0.6], [0.6, 0.7], [0.7, 0.8], [0.8, 1.8]]
    # each interval's line through its samples (the jump at 0.7: before, then after)
    expected = [(0.3, -5.0), (-0.2, 6.0), (-0.5, 6.0)]
    for (a0, a1), fc in zip(expected, seg_fc[1:4], strict=True):
        assert fc[0] == 2 and abs(fc[5] - a0) < 1e-15 and abs(fc[6] - a1) < 1e-12
    assert seg_fc[0, 0] == seg_fc[-1, 0] == 0
