"""Vertical shaking of columns with elastic joints (``excitation.vertical`` with a finite
``interface.stiffness``): the weight part of every law scales with gam = (g + a_v) / g, the
joint stiffness does not, and the kinks between the two move with gam(t).

Expected values from reasons independent of the code:

- similarity: with a constant a_v = c g, theta'' = M^-1 [gam (W theta + c_w) + K_el theta]
  + e a_g; with tau = t sqrt(gam) it is the problem without a vertical record whose joint
  stiffness is K / (1 + c), under the same record divided by (1 + c) and stretched in time
  by sqrt(1 + c) (a sampled record stays exactly similar: its knots scale with it);
- the stiff limit: joints of a very large k_n act as rigid ones;
- a closed form: a monolith on its elastic branch (relative formulation) vibrates as
  x0 cos(omega t) with omega^2 = K_M / M whatever gam is; its elastic branch ends at
  gam(t) xi M_u / K_M, which a falling gam(t) brings below the vibration's amplitude: the
  block must then leave the elastic branch (an uplift), which a kink fixed at its gam = 1
  place never lets happen.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from rbm_cli.config.load import parse_config
from rbm_cli.config.types import G
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.inputs.records import write_csv
from rbm_cli.models.rbm.step import integrate
from rbm_cli.models.registry import make_runner
from rbm_cli.structures.assembly import SHAPE_CHANGE, model_from_config

#: (drums, xi, k_n [Pa/m], formulation): a tri-linear law (the elastic end moves as gam:
#: w = 0), a bilinear one (elastic against the descending branch: 0 < w < 1)
COLUMNS = {
    "two-drum-trilinear": (2, 0.7, 5e8, "relative"),
    "monolith-bilinear": (1, 1.0, 5e8, "relative"),
    "four-drum-geometric": (4, 0.8, 1e9, "geometric"),
}
SPAN = 2.5  # s: the run (pulse then free motion), short enough not to be chaotic


def _column(drums):
    return {"height": 5.0, "base_width": 0.96, "top_width": 0.66, "drums": drums}


def _interface(xi, k_n, formulation):
    return {"stiffness": {"normal": k_n}, "xi": xi, "formulation": formulation}


def _half_sine(f, stretch=1.0):
    """A 1 g half-sine of frequency f [Hz], 2000 samples, times x stretch: (t [s], a [m/s^2])."""
    end = 0.5 / f
    t = np.linspace(0.0, end, 2001)
    a = G * np.sin(np.pi * t / end)
    a[0] = a[-1] = 0.0
    return t * stretch, a


def _config(tmp_path, name, column, interface, impl, h, v=None, free_time=0.0):
    exc = {"type": "record", "file": str(write_csv(tmp_path / f"{name}.csv", h, units="g")),
           "scale": "factor", "free_time": free_time}  # fmt: skip
    if v is not None:
        exc["vertical"] = str(write_csv(tmp_path / f"{name}_v.csv", v, units="g"))
    data = {"name": name, "model": "rbm", "column": column, "interface": interface,
            "excitation": exc, "solver": {"implementation": impl}}  # fmt: skip
    return parse_config(data)


def _run(cfg, amplitude, **kw):
    return make_runner(cfg).run(make_ground_motion(cfg.excitation, amplitude), cfg.solver, **kw)


CASES = [(name, "compiled") for name in COLUMNS] + [
    pytest.param("two-drum-trilinear", "python", marks=pytest.mark.slow),
    pytest.param("monolith-bilinear", "python", marks=pytest.mark.slow),
]


@pytest.mark.parametrize("name, impl", CASES)
@pytest.mark.parametrize("c", [0.3, -0.3])
def test_constant_vertical_is_a_softer_joint_in_slower_time(tmp_path, name, impl, c):
    """A half-sine record under a_v = c g is the record / (1 + c), stretched sqrt(1 + c) in
    time, on joints of stiffness k_n / (1 + c), without a vertical record: the same outcome,
    collapse time x sqrt(1 + c) within 1e-3 s, the same peak ratios within the integrators'
    accuracy (kernel: 5 x the reference's own global error, measured as its change when
    rtol is divided by 100, + 100 rtol; Python: its Hermite peaks, 1e-4 as in test_kernel).
    The four-drum column chatters (some 500 events in 2.5 s at 0.2 g): its peaks differ by
    up to 1e-3 between two step sequences, so it is held to outcomes and collapse times."""
    drums, xi, k_n, formulation = COLUMNS[name]
    s = math.sqrt(1.0 + c)
    column = _column(drums)
    tol = 1e-4  # Python's Hermite peaks
    frequencies = (1.0, 2.0) if impl == "compiled" else (2.0,)
    amplitudes = (0.2, 0.4, 0.6, 0.9) if impl == "compiled" else (0.3, 0.9, 1.6)
    outcomes = set()
    for f in frequencies:
        t, a = _half_sine(f)
        free = SPAN - t[-1]  # of the reference: the vertical record lasts the whole run
        v = (np.array([0.0, SPAN]), np.full(2, c * G))
        for amp in amplitudes:
            # the vertical file holds c g / amp: scaled by amp with the horizontal record
            v_amp = (v[0], v[1] / amp)
            cfg = _config(tmp_path, "v", column, _interface(xi, k_n, formulation), impl,
                          (t, a), v_amp, 0.0)  # fmt: skip
            ref_cfg = _config(tmp_path, "r", column, _interface(xi, k_n / (1 + c), formulation),
                              impl, (t * s, a), None, free * s)  # fmt: skip
            got, ref = _run(cfg, amp), _run(ref_cfg, amp / (1.0 + c))
            where = (name, impl, c, f, amp)
            assert got.status == ref.status, where
            outcomes.add(ref.status)
            if ref.status == "collapsed":
                assert got.collapse_interface == ref.collapse_interface, where
                assert abs(got.t_collapse * s - ref.t_collapse) < 1e-3, where
            if name == "four-drum-geometric":
                continue  # chattering (500 events in 2.5 s): peaks sensitive to every step
            if impl == "compiled":  # the reference's own error: its change at rtol / 100
                fine = dataclasses.replace(ref_cfg.solver, rtol=ref_cfg.solver.rtol / 100.0)
                ref_fine = make_runner(ref_cfg).run(
                    make_ground_motion(ref_cfg.excitation, amp / (1.0 + c)), fine
                )
                err = np.abs(ref_fine.max_ratio - ref.max_ratio)
                bound = 5.0 * err + 1e-8 * np.abs(ref.max_ratio)
                assert np.all(np.abs(got.max_ratio - ref.max_ratio) <= bound), (where, err)
            else:
                np.testing.assert_allclose(
                    got.max_ratio, ref.max_ratio, rtol=tol, err_msg=str(where)
                )
    assert outcomes == {"survived", "collapsed"}


def _sine_vertical(amp_g, f, span, n=4001):
    t = np.linspace(0.0, span, n)
    return t, amp_g * G * np.sin(2.0 * np.pi * f * t)


@pytest.mark.parametrize("name", ["two-drum-trilinear", "monolith-bilinear"])
def test_time_varying_vertical_compiled_equals_python(tmp_path, name):
    """A sine vertical record (0.4 g at 3 Hz, the kinks moving all the time) under a
    half-sine: the kernel compiled and uncompiled (its own source run by Python) give the
    same figures, bit for bit."""
    drums, xi, k_n, formulation = COLUMNS[name]
    t, a = _half_sine(1.5)
    v = _sine_vertical(0.4, 3.0, SPAN)
    for amp in (0.3, 0.6):
        cfgs = [_config(tmp_path, impl, _column(drums), _interface(xi, k_n, formulation), impl,
                        (t, a), (v[0], v[1] / amp), SPAN - t[-1])
                for impl in ("compiled", "python")]  # fmt: skip
        got, ref = (_run(cfg, amp) for cfg in cfgs)
        assert got.status == ref.status
        assert (got.n_uplifts, got.n_impacts, got.n_steps) == (
            ref.n_uplifts, ref.n_impacts, ref.n_steps)  # fmt: skip
        assert got.t_collapse == ref.t_collapse or (
            got.t_collapse != got.t_collapse and ref.t_collapse != ref.t_collapse
        )
        np.testing.assert_array_equal(got.max_ratio, ref.max_ratio)


@pytest.mark.parametrize("impl", ["compiled", "python"])
def test_a_falling_gravity_pulls_the_elastic_end_below_a_vibrating_joint(tmp_path, impl):
    """A monolith (xi 0.7, relative) released at x0 = 0.6 E (E = xi M_u / K_M, the elastic
    end at gam = 1) with no horizontal motion vibrates as x0 cos(omega t), omega^2 = K_M / M,
    whatever gam is. a_v falls linearly from 0 to -0.8 g over 1 s, so the elastic end
    gam(t) E passes below x0 at gam = 0.6 (t = 0.5 s): the block must leave its elastic
    branch at the first t where |x0 cos(omega t)| = gam(t) E (found here by bisection on
    these closed forms). Up to it the history is the cosine; an uplift follows and the
    rotation then exceeds x0. A kink kept where it is at gam = 1 would never be met."""
    # a_g of 1e-10 g: a motion with no horizontal record is not forced (GroundMotion.forced)
    cfg = _config(tmp_path, "h", _column(1), _interface(0.7, 5e7, "relative"), impl,
                  (np.array([0.0, 1.0]), np.full(2, 1e-10 * G)),
                  (np.array([0.0, 1.0]), np.array([0.0, -0.8 * G])), 0.0)  # fmt: skip
    model = model_from_config(cfg)
    law = model.laws[0]
    edge, tu = float(law.edges[0]), float(model.column.rotation_capacity[0])
    x0 = 0.6 * edge
    omega = math.sqrt(float(model.column.stiffness[0]) / float(model.mass[0, 0]))

    def gap(tt):  # > 0 while the joint stays on its elastic branch
        return (1.0 - 0.8 * tt) * edge - abs(x0 * math.cos(omega * tt))

    grid = np.linspace(0.0, 1.0, 200001)
    k = int(np.argmax([gap(tt) < 0.0 for tt in grid]))
    lo_t, hi_t = grid[k - 1], grid[k]
    for _ in range(60):
        mid = 0.5 * (lo_t + hi_t)
        lo_t, hi_t = (mid, hi_t) if gap(mid) > 0.0 else (lo_t, mid)
    t_u = hi_t
    assert 0.5 < t_u < 0.95  # after gam = 0.6, before the record ends
    motion = make_ground_motion(cfg.excitation, 1.0)
    out = integrate(model, motion, np.array([x0]), np.zeros(1), cfg.solver, record=True,
                    output_dt=1e-3)  # fmt: skip
    assert out.n_uplifts >= 1
    times = np.array([s[0] for s in out.samples])
    theta = np.array([s[1][0] for s in out.samples])
    before = times < t_u - 1e-3
    np.testing.assert_allclose(theta[before], x0 * np.cos(omega * times[before]), rtol=0,
                               atol=1e-6 * x0)  # fmt: skip
    assert np.abs(theta[times > t_u]).max() > 1.05 * x0
    assert out.max_ratio[0] > 1.05 * x0 / tu


def test_stiff_joints_act_as_rigid_ones_under_vertical_shaking(tmp_path):
    """A monolith with k_n = 5e12 Pa/m (the elastic end some 1e-5 of theta_u) under a
    half-sine and a sine vertical record (0.3 g at 4 Hz): the rigid block's outcome at
    every amplitude, and its collapse time within 1e-2 s."""
    t, a = _half_sine(1.0)
    v = _sine_vertical(0.3, 4.0, SPAN)
    column = _column(1)
    outcomes = set()
    for amp in (0.2, 0.3, 0.45, 0.7, 1.0):
        vv = (v[0], v[1] / amp)
        stiff = _config(tmp_path, "s", column, _interface(0.9, 5e12, "relative"), "compiled",
                        (t, a), vv, SPAN - t[-1])  # fmt: skip
        rigid_if = {"stiffness": "rigid", "xi": 0.9}
        rigid = _config(tmp_path, "r", column, rigid_if, "compiled", (t, a), vv, SPAN - t[-1])
        got, ref = _run(stiff, amp), _run(rigid, amp)
        assert got.status == ref.status, amp
        outcomes.add(ref.status)
        if ref.status == "collapsed":
            assert abs(got.t_collapse - ref.t_collapse) < 1e-2, amp
    assert outcomes == {"survived", "collapsed"}


@pytest.mark.parametrize("impl", ["compiled", "python"])
def test_a_vertical_that_reorders_the_law_fails_the_run(tmp_path, impl):
    """The cap xi gam M_u is on the tri-linear envelope while the elastic end xi gam M_u /
    K_M is below the cap's end theta_u (1 - xi): for gam < gam_c = K_M theta_u (1 - xi) /
    (xi M_u). a_v rising linearly to 2 (gam_c - 1) g over 2 s crosses gam_c at t = 1 s:
    the run ends 'failed' there with that reason (one line)."""
    column = _column(1)
    interface = _interface(0.7, 1.2e7, "relative")
    h = (np.array([0.0, 2.0]), np.zeros(2))
    probe = _config(tmp_path, "p", column, interface, impl, h, None, 0.0)
    model = model_from_config(probe)
    col = model.column
    gam_c = float(
        col.stiffness[0] * col.rotation_capacity[0] * 0.3 / (0.7 * col.moment_capacity[0])
    )
    assert 1.0 < gam_c < 3.0
    rise = (np.array([0.0, 2.0]), np.array([0.0, 2.0 * (gam_c - 1.0) * G]))
    cfg = _config(tmp_path, "v", column, interface, impl, h, rise, 0.0)
    out = _run(cfg, 1.0)
    assert out.status == "failed"
    assert out.t_end == pytest.approx(1.0, abs=1e-9)
    assert SHAPE_CHANGE in out.message and "\n" not in out.message
