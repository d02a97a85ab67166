"""The exact integrator (`solver.method: exact`, rbm_cli.models.rbm.exact) against closed
forms, against its own bounds sampled densely, and against the step kernel.

- the modal closed forms against the semigroup property, scipy's solve_ivp on the modal
  equation, and the resonant t cos term;
- the bounds that make sampling certain (exact.bounds, exact.search) hold on densely
  sampled random pieces of an 8-drum column: no crossing can hide in a certified interval;
- a rigid monolith: the exact linear half-sine threshold, the free rocking period, and
  housner-linear (the same equation in closed form: alpha = B/H, p from the true inertia);
- an elastic monolith forced at its natural frequency: the undamped resonance
  theta = C (sin wt - wt cos wt), and an 8-drum column at its first mode against the
  step kernel at rtol 1e-12;
- compiled and uncompiled (`solver.implementation: python`, the same source) give the same
  bits: every figure of the outcome and every history sample;
- whole domains (tests/test_exact_domains.py): no robust cell differs, and on cells
  where the step kernel has converged, the same events and peaks within 1e-8.
"""

from __future__ import annotations

import dataclasses
import math
import os
import signal
import threading
import time

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rbm_cli.base.errors import RbmError
from rbm_cli.base.events import EVENT_EPS
from rbm_cli.config.load import load_config
from rbm_cli.inputs.excitation import GroundMotion, make_ground_motion
from rbm_cli.models.block.closed_form import linear_run
from rbm_cli.models.rbm.exact.bounds import FULL, THIRD, empty_bounds, row_lower, track_upper
from rbm_cli.models.rbm.exact.integrate import integrate_exact
from rbm_cli.models.rbm.exact.modal import advance
from rbm_cli.models.rbm.exact.piece import eval_point, make_piece, new_cache, point_size, set_point
from rbm_cli.models.rbm.exact.search import bounds_of
from rbm_cli.models.rbm.step import integrate
from rbm_cli.models.registry import make_runner
from rbm_cli.structures.arrays import column_arrays
from rbm_cli.structures.closed_forms import (
    free_rocking_period,
    linear_halfsine_threshold,
    linear_rocking_parameters,
)
from rbm_cli.study.simulate import model_from_config, simulate

from .exact_forcing import Forcing, forcing_array
from .paths import CONFIGS


def exact_config(name: str, **solver):
    cfg = load_config(CONFIGS / f"{name}.yaml")
    return dataclasses.replace(
        cfg, solver=dataclasses.replace(cfg.solver, method="exact", **solver)
    )


# ------------------------------------------------------------------ modal closed forms
LAMS = np.array([1e6, 9.0, 9.0 * (1 + 1e-9), 9.0 * (1 + 1e-4), 2.0, 30.0, -4.0, 0.0, 1e-9, -1e-9])
FORCINGS = [
    Forcing("harmonic", 2.0, 3.0, 0.4),
    Forcing("linear", t0=0.5, a0=1.0, a1=-3.0),
    Forcing("zero"),
]


def _advance(lam, q, v, f, g, forcing, t, tau):
    """(q, v) at t + tau [s] from the compiled closed form (exact.modal.advance)."""
    qn, vn = np.empty(lam.size), np.empty(lam.size)
    advance(lam, q, v, f, g, forcing_array(forcing), t, tau, qn, vn)
    return qn, vn


def _accel(forcing, t):
    """a_g(t) [m/s^2] of a forcing, written from its definition (exact.motion.Forcing)."""
    if forcing.kind == "harmonic":
        return forcing.amplitude * math.sin(forcing.omega * t + forcing.phase)
    return forcing.a0 + forcing.a1 * (t - forcing.t0) if forcing.kind == "linear" else 0.0


@pytest.mark.parametrize("forcing", FORCINGS, ids=["harmonic", "linear", "zero"])
def test_one_long_advance_equals_many_short_ones(forcing):
    """The closed form is exact from any point: one step of 1.3 s and 1000 steps agree
    (modes of both signs, zero, near zero, and at and near resonance with omega = 3)."""
    f, g = np.full(LAMS.size, 0.3), np.full(LAMS.size, 1.7)
    q0, v0 = np.linspace(-1.0, 1.0, LAMS.size), np.linspace(2.0, -1.0, LAMS.size)
    q1, v1 = _advance(LAMS, q0, v0, f, g, forcing, 0.7, 1.3)
    q, v, t = q0, v0, 0.7
    for _ in range(1000):
        q, v = _advance(LAMS, q, v, f, g, forcing, t, 1.3e-3)
        t += 1.3e-3
    assert np.abs(q1 - q).max() < 1e-12
    assert np.abs(v1 - v).max() < 1e-12 * max(1.0, np.abs(v1).max())


@pytest.mark.parametrize("forcing", FORCINGS, ids=["harmonic", "linear", "zero"])
def test_advance_solves_the_modal_equation(forcing):
    """q'' + lam q = f + g a_g(t) integrated by scipy (DOP853 at rtol 1e-13) from t = 0.7 s
    over 1.3 s agrees with the closed form to 1e-9 of the state's size, for modes of both
    signs, zero, near zero and at and near resonance with omega = 3."""
    lams = LAMS[1:]  # 1e6 [1/s^2]: 200 periods, left to the semigroup test
    f, g = np.full(lams.size, 0.3), np.full(lams.size, 1.7)
    q0, v0 = np.linspace(-1.0, 1.0, lams.size), np.linspace(2.0, -1.0, lams.size)
    q1, v1 = _advance(lams, q0, v0, f, g, forcing, 0.7, 1.3)

    def rhs(t, y):
        q, v = y[: lams.size], y[lams.size :]
        return np.concatenate([v, -lams * q + f + g * _accel(forcing, t)])

    sol = solve_ivp(rhs, (0.7, 2.0), np.concatenate([q0, v0]), method="DOP853", rtol=1e-13,
                    atol=1e-14)  # fmt: skip
    ref = sol.y[:, -1]
    scale = max(1.0, np.abs(ref).max())
    assert np.abs(q1 - ref[: lams.size]).max() < 1e-9 * scale
    assert np.abs(v1 - ref[lams.size :]).max() < 1e-9 * scale


@pytest.mark.parametrize("omega", [3.0, 50.0])
def test_resonance_is_the_t_cos_term(omega):
    """q'' + w^2 q = sin(w t) from rest: q = (sin wt - wt cos wt) / (2 w^2) exactly."""
    one = np.ones(1)
    for t in (0.1, 2.0, 7.3):
        q, v = _advance(np.array([omega**2]), 0 * one, 0 * one, 0 * one, one,
                        Forcing("harmonic", 1.0, omega, 0.0), 0.0, t)  # fmt: skip
        wt = omega * t
        assert q[0] == pytest.approx((math.sin(wt) - wt * math.cos(wt)) / (2 * omega**2), abs=1e-15)
        assert v[0] == pytest.approx(t * math.sin(wt) / 2, abs=1e-14)


# ------------------------------------------------------------------ bounds, densely sampled
def _random_piece(model, mdl, cache, rng):
    """A random linear piece of the model (law pieces, forcing) and a random start."""
    n = model.n
    side = rng.choice([-1, 1], size=n).astype(np.int64)
    k = np.array([rng.integers(0, len(law.edges) + 1) for law in model.laws], dtype=np.int64)
    pending, awaiting = k > 0, np.zeros(n, dtype=np.bool_)
    kind = rng.choice(["harmonic", "zero", "linear"])
    forcing = {
        "harmonic": Forcing("harmonic", rng.uniform(0.5, 15.0), rng.uniform(1.0, 60.0),
                            rng.uniform(0.0, 6.0)),
        "zero": Forcing("zero"),
        "linear": Forcing("linear", t0=0.0, a0=rng.uniform(-5, 5), a1=rng.uniform(-50, 50)),
    }[kind]  # fmt: skip
    pc = make_piece(mdl, cache, side, k, pending, awaiting, forcing_array(forcing))
    scale = model.column.rotation_capacity.min() * 10.0 ** rng.uniform(-6, -1)
    theta = rng.normal(size=n) * scale
    rate = rng.normal(size=n) * scale * 10.0 ** rng.uniform(0, 3)
    return pc, forcing, rng.uniform(0.0, 5.0), theta, rate


def test_bounds_hold_on_dense_samples():
    """On random pieces, states, forcings and intervals (8 drums): every mode's |q''| and
    |q'''| (from the modal equation at the sampled state) stay below their bounds, every
    event row stays above its certified lower bound and every tracked quantity below its
    upper bound, at 400 points per interval."""
    cfg = load_config(CONFIGS / "harmonic_multidrum.yaml")
    model = model_from_config(cfg)
    mdl, cache = column_arrays(model), new_cache(model.n)
    rng = np.random.default_rng(7)
    n = model.n
    nf, of = 2 * n + 1, 1 + 2 * n
    pts = np.zeros((3, point_size(n)))
    mb, fb = empty_bounds(n, nf)
    tracked = np.arange(n, 2 * n + 1)  # collapse ratios and top displacement
    for _ in range(150):
        pc, forcing, t0, theta, rate = _random_piece(model, mdl, cache, rng)
        set_point(pc, pts, 0, t0, pc.tom @ theta, pc.tom @ rate)
        h = 10.0 ** rng.uniform(-5, 0)
        eval_point(pc, pts, 0, h, 1)
        fast = bounds_of(pc, pts, 0, 1, mb, fb)
        a, b = pts[0, of:], pts[1, of:]  # F, F', F'' at both ends
        lower = np.array([
            row_lower(pc.sgn[r], pc.off[r], pc.fam[r], a[pc.fam[r]], b[pc.fam[r]],
                      a[nf + pc.fam[r]], b[nf + pc.fam[r]], fb, fast, h)
            for r in range(pc.sgn.size)
        ])  # fmt: skip
        upper = np.array([
            track_upper(j, a[j], b[j], a[nf + j], b[nf + j], fb, fast, h) for j in tracked
        ])  # fmt: skip
        for s in np.linspace(0.0, h, 401):
            eval_point(pc, pts, 0, s, 2)
            t, q, v = pts[2, 0], pts[2, 1 : 1 + n], pts[2, 1 + n : 1 + 2 * n]
            q2 = -pc.lam * q + pc.f + pc.g * _accel(forcing, t)
            q3 = -pc.lam * v + pc.g * _ground_rate(forcing, t)
            assert np.all(np.abs(q2) <= mb[FULL] * (1 + 1e-9))
            assert np.all(np.abs(q3) <= mb[THIRD] * (1 + 1e-9))
            family = pts[2, of : of + nf]  # F = Gf q at the sample
            assert np.all(~(lower > pc.sgn * family[pc.fam] + pc.off))
            assert np.all(~(upper < np.abs(family[tracked])))


def _ground_rate(forcing, t):
    """a_g'(t) [m/s^3]."""
    if forcing.kind == "harmonic":
        return forcing.amplitude * forcing.omega * math.cos(forcing.omega * t + forcing.phase)
    return forcing.a1 if forcing.kind == "linear" else 0.0


# ------------------------------------------------------------------ rigid monolith
@pytest.mark.parametrize("ratio", [0.3, 1.0, 2.0, 4.0])
def test_rigid_halfsine_threshold(ratio):
    """A rigid monolith (housner_halfsine) overturns just above the exact linear half-sine
    threshold and survives just below it (1e-6 apart), at omega / p = ratio."""
    cfg = exact_config("housner_halfsine")
    runner = make_runner(cfg)
    alpha, p = linear_rocking_parameters(runner.model.column)
    f = ratio * p / (2 * math.pi)
    a = float(linear_halfsine_threshold(ratio)) * alpha
    assert simulate(cfg, a * (1 + 1e-6), f, runner=runner).status == "collapsed"
    assert simulate(cfg, a * (1 - 1e-6), f, runner=runner).status == "survived"


def test_free_rocking_period():
    """Free rocking from theta0 = alpha / 2 (e = 1): the m-th impact comes at
    T/4 + (m - 1) T/2, T = (4/p) arccosh(1 / (1 - theta0/alpha)); a run that ends 1e-9 T
    before the 10th has 9 impacts, one that ends 1e-9 T after it has 10; the amplitude
    stays alpha / 2."""
    cfg = load_config(CONFIGS / "spanos_koh_slender.yaml")
    alpha, p = linear_rocking_parameters(model_from_config(cfg).column)
    period = float(free_rocking_period(p, 0.5))
    t10 = period / 4 + 9 * period / 2
    for end, impacts in ((t10 - 1e-9 * period, 9), (t10 + 1e-9 * period, 10)):
        initial = dataclasses.replace(cfg.excitation.initial, rotations=(0.5 * alpha,))
        exc = dataclasses.replace(cfg.excitation, type="free", duration=end, initial=initial)
        solver = dataclasses.replace(cfg.solver, method="exact")
        c = dataclasses.replace(cfg, excitation=exc, solver=solver)
        out = simulate(c, 0.0, 0.0)
        assert out.status == "survived"
        assert out.n_impacts == impacts
        # peak alpha / 2 = theta_u / 2, up to the event convention shared with the step
        # kernel: an impact is located EVENT_EPS theta_u past zero and projected back, which
        # adds M_u EVENT_EPS theta_u of energy, i.e. 2 EVENT_EPS theta_u of amplitude at
        # theta_u / 2 (dE / d amplitude = M_u / 2 there)
        assert abs(out.max_rotation_ratio - 0.5) <= 4 * EVENT_EPS * impacts


def test_rigid_monolith_equals_housner_linear():
    """The rigid RBM with n = 1 is housner-linear (alpha = B/H, p from the true inertia):
    on sub-grids of spanos_koh_slender and housner_halfsine the exact method and the
    closed form give the same outcome and event counts, and peaks and collapse times within
    1e-8 where the closed form is well-conditioned (a 1e-10 change of the amplitude moves
    its peak by less than 1e-9). The two locate an impact differently (the closed form at
    theta = 0, the RBM EVENT_EPS theta_u past it, then projected back), a 1e-12 difference
    per impact that the motion may amplify; hence 1e-8, not rounding."""
    compared = 0
    for study, stride in (("spanos_koh_slender", 3), ("housner_halfsine", 6)):
        cfg = exact_config(study)
        runner = make_runner(cfg)
        alpha, p = linear_rocking_parameters(runner.model.column)
        tu = runner.model.column.rotation_capacity[0]
        for f in cfg.grid.frequencies_hz[::stride]:
            for a in cfg.grid.amplitudes_g[::stride]:
                ref = linear_run(alpha, p, make_ground_motion(cfg.excitation, a, f), 1.0)
                nudged = linear_run(
                    alpha, p, make_ground_motion(cfg.excitation, a * (1 + 1e-10), f), 1.0
                )
                out = simulate(cfg, a, f, runner=runner)
                assert out.status == ref.status, (a, f)
                assert (out.n_uplifts, out.n_impacts) == (ref.n_uplifts, ref.n_impacts), (a, f)
                peak = float(ref.max_ratio[0]) * alpha / tu
                if abs(float(nudged.max_ratio[0]) * alpha / tu - peak) > 1e-9 * peak:
                    continue
                if ref.status == "survived":
                    assert out.max_rotation_ratio == pytest.approx(peak, rel=1e-8), (a, f)
                else:
                    assert out.t_collapse_s == pytest.approx(ref.t_collapse, rel=1e-8), (a, f)
                compared += 1
    assert compared > 40


# ------------------------------------------------------------------ resonance
def test_elastic_monolith_at_resonance_is_the_t_cos_term():
    """An elastic monolith (harmonic_monolithic) forced at its natural frequency w, small
    enough to stay on its elastic branch for 2 s: theta = -(r A / M) (sin wt - wt cos wt)
    / (2 w^2), whose peak over [0, 2 s] is at the last t = k pi / w."""
    cfg = exact_config("harmonic_monolithic")
    cfg = dataclasses.replace(cfg, excitation=dataclasses.replace(cfg.excitation, duration=2.0))
    model = model_from_config(cfg)
    f = model.elastic_frequencies_hz()[0]
    w = 2 * math.pi * f
    amp_g = 1e-3
    c = abs(model.ground_load[0]) / model.mass[0, 0] * amp_g * 9.81 / (2 * w * w)
    k = math.floor(w * 2.0 / math.pi)
    peak = max(c * k * math.pi, c * abs(math.sin(2 * w) - 2 * w * math.cos(2 * w)))
    out = simulate(cfg, amp_g, f)
    assert out.n_uplifts == 0
    assert out.max_rotation_ratio == pytest.approx(
        peak / model.column.rotation_capacity[0], rel=1e-10
    )


def test_multidrum_at_its_first_mode_matches_the_step_kernel():
    """An 8-drum column forced at its first elastic frequency (resonance, no damping) for
    3 s, small enough to stay elastic: the peak agrees with the step kernel at rtol 1e-12
    to 1e-8."""
    cfg = load_config(CONFIGS / "harmonic_multidrum.yaml")
    cfg = dataclasses.replace(cfg, excitation=dataclasses.replace(cfg.excitation, duration=3.0))
    model = model_from_config(cfg)
    f = model.elastic_frequencies_hz()[0]
    motion = make_ground_motion(cfg.excitation, 2e-4, f)
    zeros = np.zeros(model.n)
    tight = dataclasses.replace(cfg.solver, rtol=1e-12, atol=1e-16)
    ref = integrate(model, motion, zeros, zeros, tight)
    out = integrate_exact(model, motion, zeros, zeros, cfg.solver)
    assert ref.n_uplifts == out.n_uplifts == 0
    assert np.max(out.max_ratio) == pytest.approx(np.max(ref.max_ratio), rel=1e-8)
    assert out.max_top == pytest.approx(ref.max_top, rel=1e-8)


# ------------------------------------------------------------------ compiled and uncompiled
def _same_bits(a, b):
    """Every figure of two Outcomes, and every history sample, bit for bit."""
    fields = vars(a)
    assert fields.keys() == vars(b).keys()
    for name, value in fields.items():
        other = vars(b)[name]
        if name == "samples":
            assert len(value) == len(other), name
            for x, y in zip(value, other, strict=True):
                assert float(x[0]) == float(y[0])
                for u, w in zip(x[1:], y[1:], strict=True):
                    np.testing.assert_array_equal(u, w, strict=True)
        elif isinstance(value, np.ndarray):
            np.testing.assert_array_equal(value, other, strict=True)
        elif isinstance(value, float) and math.isnan(value):
            assert isinstance(other, float) and math.isnan(other), name
        else:
            assert value == other, name


@pytest.mark.parametrize(
    ("study", "amplitude", "frequency", "duration"),
    [("spanos_koh_slender", 0.5, 2.0, 4.0), ("spanos_koh_slender", 1.5, 1.0, 4.0),
     ("housner_halfsine", 0.5, 2.0, None), ("harmonic_monolithic", 0.5, 2.0, 2.0),
     ("harmonic_multidrum", 0.15, 2.0, 0.4), ("harmonic_multidrum", 0.3, 2.0, 0.6)],
)  # fmt: skip
def test_compiled_equals_plain(study, amplitude, frequency, duration):
    """`solver.implementation: python` runs the compiled source uncompiled
    (rbm_cli.base.jit.plain): a rigid block rocking and collapsing, a half-sine pulse, an
    elastic monolith, and 8 drums elastic and rocking (178 uplifts in 0.6 s) give the
    same bits, every figure of the outcome and every history sample."""
    cfg = load_config(CONFIGS / f"{study}.yaml")
    if duration is not None:
        excitation = dataclasses.replace(cfg.excitation, duration=duration)
        cfg = dataclasses.replace(cfg, excitation=excitation)
    model = model_from_config(cfg)
    motion = make_ground_motion(cfg.excitation, amplitude, frequency)
    zeros = np.zeros(model.n)
    runs = [
        integrate_exact(model, motion, zeros, zeros,
                        dataclasses.replace(cfg.solver, method="exact", implementation=impl),
                        record=True, output_dt=0.01)
        for impl in ("compiled", "python")
    ]  # fmt: skip
    assert runs[0].samples and runs[0].n_steps > 0
    _same_bits(*runs)


def test_history_is_sampled_from_the_closed_form():
    """rbm run's history with the exact method: a sample every output_dt on the closed
    form, up to the end of the run."""
    cfg = exact_config("harmonic_multidrum")
    model = model_from_config(cfg)
    motion = make_ground_motion(cfg.excitation, 0.15, 2.0)
    zeros = np.zeros(model.n)
    out = integrate_exact(model, motion, zeros, zeros, cfg.solver, record=True, output_dt=0.01)
    assert len(out.samples) == 1001
    t = np.array([s[0] for s in out.samples])
    assert np.allclose(t, 0.01 * np.arange(1001), atol=1e-12, rtol=0)
    theta = np.array([s[1] for s in out.samples])
    assert np.all(np.isfinite(theta)) and np.abs(theta).max() > 0.0


# ------------------------------------------------------------------ refusals
def test_absolute_formulation_is_refused_in_one_line():
    cfg = exact_config("harmonic_multidrum")
    cfg = dataclasses.replace(
        cfg, interface=dataclasses.replace(cfg.interface, formulation="absolute")
    )
    with pytest.raises(RbmError) as err:
        make_runner(cfg)
    assert "\n" not in str(err.value) and "absolute" in str(err.value)


def test_housner_model_refuses_exact_in_one_line():
    """Housner's large-rotation block is not piecewise linear: its runner says so."""
    cfg = exact_config("spanos_koh_slender_housner")
    with pytest.raises(RbmError) as err:
        make_runner(cfg)
    assert "\n" not in str(err.value) and "housner" in str(err.value)


@pytest.mark.parametrize("implementation", ["python", "compiled"])
def test_piecewise_linear_forcing_is_exact(implementation):
    """A record (piecewise linear, one linear forcing a sample interval) through the run
    loop: an elastic monolith from rest under a_g = s t up to t1, then held at
    s t1. theta'' + w^2 theta = -(r / M) a_g gives theta = -(r s / M) [R(t) - R(t - t1)] / w^2
    with R(u) = u - sin(w u) / w for u > 0: the recorded history equals it to 1e-11 of its
    peak, compiled and uncompiled."""
    cfg = load_config(CONFIGS / "harmonic_monolithic.yaml")
    model = model_from_config(cfg)
    w = 2 * math.pi * model.elastic_frequencies_hz()[0]
    t1, t_end, hold = 0.37, 1.5, 2e-3 * 9.81
    times = np.array([0.0, t1, t_end])
    motion = GroundMotion("record", hold, 0.0, 0.0, t_end, t_end, gain=1.0, knots=times,
                          values=np.array([0.0, hold, hold]))  # fmt: skip
    zeros = np.zeros(1)
    solver = dataclasses.replace(cfg.solver, implementation=implementation)
    out = integrate_exact(model, motion, zeros, zeros, solver, record=True, output_dt=1e-3,
                          early_stop=False)  # fmt: skip
    t = np.array([s[0] for s in out.samples])
    theta = np.array([s[1][0] for s in out.samples])

    def ramp(u):
        u = np.maximum(u, 0.0)
        return u - np.sin(w * u) / w

    c = model.ground_load[0] / model.mass[0, 0] * hold / t1
    expected = -c * (ramp(t) - ramp(t - t1)) / w**2
    assert out.n_uplifts == 0 and len(t) == 1501
    assert np.abs(theta - expected).max() < 1e-11 * np.abs(expected).max()
    fine = np.linspace(0.0, t_end, 1_500_001)
    tu = model.column.rotation_capacity[0]
    peak = np.abs(c * (ramp(fine) - ramp(fine - t1)) / w**2).max() / tu
    assert peak <= out.max_ratio[0] <= peak * (1 + 1e-9)


# ------------------------------------------------------------------ guards of a compiled run
def _long_exact_run(**solver):
    """An 8-drum column shaken elastically for 1e4 s (minutes of work): a run only a guard
    ends."""
    cfg = load_config(CONFIGS / "harmonic_multidrum.yaml")
    cfg = dataclasses.replace(cfg, excitation=dataclasses.replace(cfg.excitation, duration=1e4))
    model = model_from_config(cfg)
    motion = make_ground_motion(cfg.excitation, 0.05, 2.0)  # [g, Hz]: stays elastic
    zeros = np.zeros(model.n)
    settings = dataclasses.replace(cfg.solver, method="exact", max_steps=10**9,
                                   max_events=10**9, **solver)  # fmt: skip
    start = time.monotonic()
    out = integrate_exact(model, motion, zeros, zeros, settings)
    return out, time.monotonic() - start


def test_the_wall_clock_budget_ends_a_compiled_exact_run():
    out, took = _long_exact_run(max_wall_time=0.5)
    assert out.status == "failed"
    assert "wall-clock budget exceeded (0.5 s, solver.max_wall_time)" in out.message
    assert took < 10.0


def test_ctrl_c_stops_a_compiled_exact_run():
    """Ctrl-C (SIGINT) reaches the compiled exact loop through guard.poll and
    raises KeyboardInterrupt once the call has returned. Python's own SIGINT handler
    is installed for the test: a test runner started as a background job ignores SIGINT,
    and the test once skipped there."""
    _long_exact_run(max_wall_time=0.1)  # compiled (or loaded) before the clock starts
    timer = threading.Timer(1.0, os.kill, (os.getpid(), signal.SIGINT))
    start = time.monotonic()
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            _long_exact_run(max_wall_time=120.0)
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    assert time.monotonic() - start < 10.0
