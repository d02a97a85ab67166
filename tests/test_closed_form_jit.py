"""The rigid block's closed form (rbm_cli.models.block): the RBM's `solver.method:
closed-form` on a rigid monolith (what `auto`, the default, runs there) and
`housner-linear`, compiled and uncompiled.

Expected values from other sources:

- the step kernel (DOP853 at rtol 1e-11 and 1e-12) on sub-grids of the shipped rigid
  studies (harmonic, half-sine) and under a record: on the cells where its two tolerances
  agree (same outcome and events, peaks and collapse times within 1e-9), the same outcome
  and events, peaks and collapse times within 1e-8 of rtol 1e-12 (the two locate an impact
  differently: the kernel EVENT_EPS theta_u past zero, then projected back);
- the RBM's mapping (structures.closed_forms.linear_rocking_parameters): the rigid monolith's
  block (closed_form.rbm_block, from the model's linear system) runs as Spanos and Koh's
  block of those (alpha, p) (closed_form.linear_block);
- the same source run uncompiled (rbm_cli.base.jit.plain): the same bits, on a rigid RBM,
  a housner-linear block and a vertical record;
- free rocking: the energy theta'^2/2 + p^2 (alpha |theta| - theta^2/2) is conserved
  between impacts, and the impacts come at the period of
  structures.closed_forms.free_rocking_period;
- a dense sampling of random pieces: the first event the scan finds is the first crossing
  of 200,001 samples (none missed, none invented).
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

from rbm_cli.base.errors import RbmError
from rbm_cli.config.load import load_config, parse_config
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.models.block.closed_form import linear_run
from rbm_cli.models.registry import make_runner
from rbm_cli.structures.closed_forms import free_rocking_period, linear_rocking_parameters
from rbm_cli.study.simulate import simulate

from .converged import assert_agrees, close, converged
from .paths import CONFIGS

RECORD = CONFIGS / "records" / "synthetic" / "rdk_01.AT2"
COLUMN = {"height": 5.0, "base_width": 0.96, "top_width": 0.66, "drums": 1}


def _with(cfg, **solver):
    return dataclasses.replace(cfg, solver=dataclasses.replace(cfg.solver, **solver))


def _against_kernel(cfg, cells) -> int:
    """Closed form (the default) against the step kernel on the converged cells; returns
    how many were compared."""
    runs = {}
    for label, solver in (("cf", {}), ("k11", {"method": "DOP853", "rtol": 1e-11}),
                          ("k12", {"method": "DOP853", "rtol": 1e-12})):  # fmt: skip
        c = _with(cfg, **solver)
        runner = make_runner(c)
        runs[label] = [simulate(c, a, f, runner=runner) for a, f in cells]
    assert {r.method for r in runs["cf"]} == {"closed-form"}
    assert {r.method for r in runs["k12"]} == {"DOP853"}
    count = 0
    for cell, cf, k11, k12 in zip(cells, runs["cf"], runs["k11"], runs["k12"], strict=True):
        if not converged(k11, k12):
            continue
        assert_agrees(k12, cf, cell)
        # the closed form's peak friction demand is the maximum over time; the kernel reads
        # it at its step ends and samples only, so it can only be lower
        assert cf.max_friction_demand_peak >= k12.max_friction_demand_peak * (1 - 1e-9), cell
        count += 1
    return count


@pytest.mark.parametrize("study, stride", [("spanos_koh_slender", 4), ("housner_halfsine", 4)])
def test_the_step_kernel_agrees_on_a_grid(study, stride):
    cfg = load_config(CONFIGS / f"{study}.yaml")
    cells = [(a, f) for f in cfg.grid.frequencies_hz[::stride]
             for a in cfg.grid.amplitudes_g[::stride]]  # fmt: skip
    assert _against_kernel(cfg, cells) >= 0.8 * len(cells)


def test_the_step_kernel_agrees_under_a_record_and_pulses():
    """A synthetic record (0.01 s samples) at three PGAs, a one-sine and a cycloidal pulse."""
    count = 0
    for excitation, cells in (
        ({"type": "record", "file": str(RECORD), "units": "g", "free_time": 2.0},
         [(0.2, None), (0.5, None), (0.9, None)]),
        ({"type": "one-sine", "duration": 4.0}, [(0.25, 1.0), (0.5, 2.0), (1.2, 3.0)]),
        ({"type": "cycloidal", "duration": 4.0}, [(0.3, 1.0), (0.5, 2.0), (1.2, 3.0)]),
    ):  # fmt: skip
        cfg = parse_config({"name": "x", "column": COLUMN, "excitation": excitation})
        count += _against_kernel(cfg, cells)
    assert count >= 6


def _facts(run):
    """(status, uplifts, impacts, peak ratio, collapse time [s]) of a RunResult or an
    Outcome."""
    if hasattr(run, "max_rotation_ratio"):
        return (run.status, run.n_uplifts, run.n_impacts, run.max_rotation_ratio,
                run.t_collapse_s)  # fmt: skip
    return run.status, run.n_uplifts, run.n_impacts, float(run.max_ratio[0]), run.t_collapse


def test_the_rbm_block_is_the_linear_block_of_its_mapping():
    """The RBM's closed form against Spanos and Koh's block of its mapping (alpha,
    p), and housner-linear compiled against python (its source uncompiled): same outcome
    and events, peaks and collapse times within 1e-9 where a 1e-10 change of the amplitude
    moves the peak by < 1e-9 (the RBM places an impact EVENT_EPS theta_u past zero,
    housner-linear at zero); compiled and python give the same figures."""
    cfg = load_config(CONFIGS / "spanos_koh_slender.yaml")
    runner = make_runner(cfg)
    alpha, p = linear_rocking_parameters(runner.model.column)
    lin = load_config(CONFIGS / "spanos_koh_slender_linear.yaml")
    lin_py = _with(lin, implementation="python")
    lin_c, lin_p = make_runner(lin), make_runner(lin_py)
    compared = 0
    for f in cfg.grid.frequencies_hz[::5]:
        for a in cfg.grid.amplitudes_g[::5]:
            motion = make_ground_motion(cfg.excitation, a, f)
            ref = linear_run(alpha, p, motion)
            nudged = linear_run(alpha, p, make_ground_motion(cfg.excitation, a * (1 + 1e-10), f))
            steady = abs(nudged.max_ratio[0] - ref.max_ratio[0]) <= 1e-9 * ref.max_ratio[0]
            compiled = simulate(lin, a, f, runner=lin_c)
            python = simulate(lin_py, a, f, runner=lin_p)
            assert compiled.method == python.method == "closed-form"
            assert repr(_facts(compiled)) == repr(_facts(python)), (a, f)  # NaN as NaN
            for out, want in ((simulate(cfg, a, f, runner=runner), ref), (compiled, python)):
                got, expected = _facts(out), _facts(want)
                assert got[:3] == expected[:3], (a, f)
                if steady:
                    assert close(got[3], expected[3], 1e-9), (a, f)
                    assert close(got[4], expected[4], 1e-9), (a, f)
                    compared += 1
    assert compared >= 40


def test_free_rocking_conserves_energy_at_the_closed_form_period():
    """Free rocking from theta0 = 0.1 rad, e = 1: the energy theta'^2/2 + p^2 (alpha |theta|
    - theta^2/2) at every sample equals its initial value to round-off for housner-linear's
    impacts (at theta = 0); the RBM's (where s theta = -eps, then projected onto 0) each
    add p^2 alpha eps, no more; the impacts come at T/4, 3T/4, ... of free_rocking_period."""
    from rbm_cli.base.events import EVENT_EPS
    from rbm_cli.models.block.closed_form import linear_block, rbm_block, run_closed_form

    cfg = parse_config({"name": "free", "column": COLUMN, "interface": {"restitution": 1.0},
                        "excitation": {"type": "free", "duration": 8.0,
                                       "initial": {"rotations": [0.1]}}})  # fmt: skip
    model = make_runner(cfg).model
    alpha, p = linear_rocking_parameters(model.column)
    motion = make_ground_motion(cfg.excitation, 0.0, 0.0)
    e0 = p * p * (alpha * 0.1 - 0.5 * 0.1**2)
    period = free_rocking_period(p, 0.1 / alpha)
    for block, per_impact in ((linear_block(alpha, p), 0.0),
                              (rbm_block(model), p * p * alpha * EVENT_EPS * alpha)):  # fmt: skip
        out = run_closed_form(block, motion, 0.1, 0.0, cfg.solver, record=True, output_dt=1e-3)
        theta = np.array([s[1][0] for s in out.samples])
        rate = np.array([s[2][0] for s in out.samples])
        energy = 0.5 * rate**2 + p * p * (alpha * np.abs(theta) - 0.5 * theta**2)
        assert out.n_impacts == math.floor((8.0 / period - 0.25) / 0.5) + 1
        assert np.abs(energy - e0).max() <= 1e-14 * e0 + 1.01 * out.n_impacts * per_impact
        assert out.status == "survived"
        # the RBM's impact adds p^2 alpha eps of energy: 2 eps of amplitude at alpha / 2
        grown = 4 * EVENT_EPS * out.n_impacts if per_impact else 0.0
        assert abs(out.max_ratio[0] - 0.1 / alpha) <= 1e-13 + grown


def _dense(pc, ts):
    """s theta at t0 + ts, written out from the piece's coefficients (numpy)."""
    from rbm_cli.models.block import piece as cj

    theta = (pc[cj.SIDE] * pc[cj.ALPHA] + pc[cj.AMP] * np.sin(pc[cj.OM] * ts + pc[cj.PHI])
             + pc[cj.Q0] + pc[cj.Q1] * ts + pc[cj.C1] * np.exp(pc[cj.P] * ts)
             + pc[cj.C2] * np.exp(-pc[cj.P] * ts))  # fmt: skip
    return pc[cj.SIDE] * theta


def _random_piece(rng, pc):
    from rbm_cli.models.block.closed_form import linear_block
    from rbm_cli.models.block.piece import start_piece

    alpha, p = rng.uniform(0.05, 0.3), rng.uniform(0.5, 5.0)
    blk = linear_block(alpha, p).params
    fc = np.zeros(7)
    kind = rng.integers(0, 3)
    if kind == 1:
        fc[:4] = 1, rng.uniform(0.2, 3.0) * 9.81 * alpha, rng.uniform(0.5, 40.0), rng.uniform(0, 6)
    elif kind == 2:
        fc[0], fc[5], fc[6] = 2, rng.uniform(-2, 2) * 9.81 * alpha, rng.uniform(-50, 50)
    side = rng.choice([-1.0, 1.0])
    theta, rate = side * alpha * rng.uniform(0.0, 0.99), side * alpha * p * rng.uniform(-0.5, 0.5)
    start_piece(blk, rng.uniform(0.0, 3.0), theta, rate, side, fc, 1.0, pc)
    return blk


def test_the_scan_misses_no_crossing_of_random_pieces():
    """Random pieces (harmonic, linear, free) against 100,001 samples: the scan's first
    event (impact where s theta + eps <= 0, collapse where s theta >= limit) is the first
    sample crossing, to the sample spacing; the peak before it is not below the samples'."""
    from rbm_cli.models.block.piece import (
        B_EPS,
        B_LIMIT,
        COLLAPSE,
        IMPACT,
        NONE,
        PIECE_SIZE,
        scan_piece,
    )  # fmt: skip

    rng = np.random.default_rng(11)
    checked = {NONE: 0, IMPACT: 0, COLLAPSE: 0}
    pc = np.zeros(PIECE_SIZE)
    for _ in range(400):
        blk = _random_piece(rng, pc)
        tau_max = 10.0 ** rng.uniform(-1.5, 0.6)
        acc = np.zeros(4)
        got, tau = scan_piece(pc, blk, tau_max, acc)
        ts = np.linspace(0.0, tau_max, 100_001)
        f = _dense(pc, ts)
        hit = np.nonzero((f + blk[B_EPS] <= 0.0) | (f >= blk[B_LIMIT]))[0]
        k = hit[0] if hit.size else ts.size
        if hit.size == 0:
            assert got == NONE and tau == tau_max
        else:
            want = COLLAPSE if f[k] >= blk[B_LIMIT] else IMPACT
            assert got == want and ts[k - 1] - 1e-9 <= tau <= ts[k] + 1e-9
        if got != COLLAPSE:  # the peak before the event (a collapse's is the limit)
            assert acc[0] >= f[:k].max() - 1e-14
        checked[got] += 1
    assert min(checked.values()) >= 40


@pytest.mark.parametrize("delta", [1e-4, 1e-7, -1e-9])
def test_a_grazing_peak_is_seen(delta):
    """Free motion from theta = 0 at the rate that peaks at alpha (1 - delta): delta > 0
    turns back (impact), delta < 0 collapses; one interval of the scan spans the peak."""
    from rbm_cli.models.block.closed_form import linear_block
    from rbm_cli.models.block.piece import (
        COLLAPSE,
        IMPACT,
        PIECE_SIZE,
        scan_piece,
        start_piece,
    )  # fmt: skip

    alpha, p = 0.2, 2.0
    blk = linear_block(alpha, p).params
    pc, acc = np.zeros(PIECE_SIZE), np.zeros(4)
    peak = alpha * (1.0 - delta)
    rate = math.sqrt(2.0 * p * p * (alpha * peak - 0.5 * peak * peak))  # energy at the peak
    start_piece(blk, 0.0, 0.0, rate, 1.0, np.zeros(7), 1.0, pc)
    got, tau = scan_piece(pc, blk, 20.0, acc)
    assert got == (IMPACT if delta > 0 else COLLAPSE)
    if delta > 0:
        assert acc[0] == pytest.approx(peak, rel=1e-11 / delta)  # dpeak/dE ~ 1 / delta


def test_auto_resolves_and_an_explicit_method_is_kept():
    """auto: the closed form on a rigid monolith, DOP853 on an elastic column, a Ricker
    pulse, a vertical record (tests/test_vertical.py's kind) or the Python implementation;
    explicit DOP853 runs the step kernel; closed-form where it does not apply: one line."""
    from rbm_cli.models.methods import resolve_method
    from rbm_cli.study.sweep import config_hash

    cfg = load_config(CONFIGS / "spanos_koh_slender.yaml")
    assert cfg.solver.method == "auto" and resolve_method(cfg) == "closed-form"
    step = _with(cfg, method="DOP853")
    out, kernel = simulate(cfg, 0.5, 1.0), simulate(step, 0.5, 1.0)
    assert (out.method, kernel.method) == ("closed-form", "DOP853")
    assert kernel.n_steps > 10 * out.n_steps  # steps of the kernel, pieces of the closed form
    # the hash holds the method that runs: auto's closed form, not the step kernel
    assert config_hash(cfg) == config_hash(_with(cfg, method="closed-form"))
    assert config_hash(cfg) != config_hash(step)
    assert resolve_method(_with(cfg, implementation="python")) == "DOP853"
    for other in ("harmonic_monolithic", "harmonic_multidrum"):  # elastic joints
        assert resolve_method(load_config(CONFIGS / f"{other}.yaml")) == "DOP853"
    ricker = parse_config({"name": "r", "column": COLUMN, "excitation": {"type": "ricker"}})
    assert simulate(ricker, 0.5, 2.0).method == "DOP853"
    with pytest.raises(RbmError, match="closed-form") as err:
        make_runner(_with(load_config(CONFIGS / "harmonic_monolithic.yaml"),
                          method="closed-form"))  # fmt: skip
    assert "\n" not in str(err.value)
    with pytest.raises(RbmError, match="ricker"):
        make_runner(_with(ricker, method="closed-form"))


def test_a_vertical_record_falls_back_to_the_integrator(tmp_path):
    from rbm_cli.config.types import G
    from rbm_cli.inputs.records import write_csv

    t = np.linspace(0.0, 1.0, 101)
    h = write_csv(tmp_path / "h.csv", (t, 0.5 * G * np.sin(2 * np.pi * t)), units="g")
    v = write_csv(tmp_path / "v.csv", (t, 0.2 * G * np.ones_like(t)), units="g")
    exc = {"type": "record", "file": str(h), "vertical": str(v), "scale": "factor"}
    cfg = parse_config({"name": "v", "column": COLUMN, "excitation": exc})
    from rbm_cli.models.methods import resolve_method

    assert resolve_method(cfg) == "DOP853"
    assert simulate(cfg, 1.0, None).method == "DOP853"
    with pytest.raises(RbmError, match="vertical"):
        make_runner(_with(cfg, method="closed-form"))
    lin = dataclasses.replace(cfg, model="housner-linear")
    assert simulate(lin, 1.0, None).status in ("survived", "collapsed")  # its closed form


def test_a_history_is_recorded():
    """`rbm run`'s history: samples every output_dt, the closed form's (the step kernel's
    to 1e-8 of alpha)."""
    cfg = load_config(CONFIGS / "spanos_koh_slender.yaml")
    out = simulate(cfg, 0.6, 1.5, record=True, output_dt=0.01)
    ref = simulate(_with(cfg, method="DOP853", rtol=1e-12), 0.6, 1.5, record=True, output_dt=0.01)
    assert out.history.t.size == ref.history.t.size > 100
    assert np.abs(out.history.rotations - ref.history.rotations).max() < 1e-8 * 0.25


def _figures(out):
    """Every figure of an Outcome, samples included, as text (repr: a float's shortest exact
    digits; NaN equals NaN)."""
    samples = [(t, float(th[0]), float(r[0])) for t, th, r in out.samples]
    return repr((out.status, out.message, out.t_end, out.t_collapse, out.max_top,
                 out.max_ratio.tolist(), out.friction.tolist(), out.n_uplifts, out.n_impacts,
                 out.n_events, out.n_steps, out.n_rhs, samples))  # fmt: skip


def test_compiled_and_uncompiled_give_the_same_bits(tmp_path):
    """The closed form compiled and its source run uncompiled (implementation python,
    rbm_cli.base.jit.plain): the same figures, every history sample included, for a rigid
    RBM monolith (explicit closed-form, harmonic and record), a housner-linear block and a
    housner-linear block under a vertical record (gam per piece); the event log too."""
    from rbm_cli.config.types import G
    from rbm_cli.inputs.records import write_csv
    from rbm_cli.models.block.closed_form import linear_run

    t = np.linspace(0.0, 4.0, 401)  # a_g = A g sin(2 pi t), a_v = 0.4 A g sin(6 pi t + 0.3)
    h = write_csv(tmp_path / "h.csv", (t, G * np.sin(2 * np.pi * t)), units="g")
    v = write_csv(tmp_path / "v.csv", (t, 0.4 * G * np.sin(6 * np.pi * t + 0.3)), units="g")
    vertical = {"type": "record", "file": str(h), "vertical": str(v), "scale": "factor",
                "free_time": 2.0}  # fmt: skip
    rigid = load_config(CONFIGS / "spanos_koh_slender.yaml")
    record = parse_config({"name": "r", "column": COLUMN, "excitation": {
        "type": "record", "file": str(RECORD), "units": "g", "free_time": 2.0}})  # fmt: skip
    cases = [
        (_with(rigid, method="closed-form"), [(0.3, 3.0), (0.6, 1.5), (1.2, 1.0)]),
        (_with(record, method="closed-form"), [(0.5, None), (0.9, None)]),
        (dataclasses.replace(rigid, model="housner-linear"), [(0.3, 3.0), (0.6, 1.5)]),
        (parse_config({"name": "v", "model": "housner-linear", "column": COLUMN,
                       "excitation": vertical}), [(0.2, None), (0.25, None), (0.4, None)]),
    ]  # fmt: skip
    statuses = set()
    for cfg, cells in cases:
        python_cfg = _with(cfg, implementation="python")
        compiled, python = make_runner(cfg), make_runner(python_cfg)
        for a, f in cells:
            motion = make_ground_motion(cfg.excitation, a, f)
            got = compiled.run(motion, cfg.solver, record=True, output_dt=0.01)
            want = python.run(motion, python_cfg.solver, record=True, output_dt=0.01)
            assert got.method == want.method == "closed-form"
            assert _figures(got) == _figures(want), (cfg.name, a, f)
            statuses.add((cfg.name, got.status))
    assert {status for name, status in statuses if name == "v"} == {"survived", "collapsed"}
    assert {status for _, status in statuses} == {"survived", "collapsed"}
    motion = make_ground_motion(cfg.excitation, 0.25, None)
    logs = []
    for implementation in ("compiled", "python"):
        events: list = []
        solver = dataclasses.replace(cfg.solver, implementation=implementation)
        linear_run(0.19, 1.5, motion, 0.9, solver=solver, events=events)
        logs.append(events)
    assert logs[0] == logs[1] and {k for _, k in logs[0]} >= {"uplift", "impact"}


# ------------------------------------------------------------------ guards of a compiled run
def _long_rocking(max_wall_time):
    """The slender block rocking without loss (e = 1) under a harmonic for 1e7 s: millions
    of pieces, a run only a guard ends. Returns the Outcome and the time it took [s]."""
    cfg = load_config(CONFIGS / "spanos_koh_slender.yaml")
    cfg = dataclasses.replace(cfg, excitation=dataclasses.replace(cfg.excitation, duration=1e7))
    cfg = _with(cfg, method="closed-form", max_steps=10**12, max_events=10**12,
                max_wall_time=max_wall_time)  # fmt: skip
    runner = make_runner(cfg)
    motion = make_ground_motion(cfg.excitation, 0.3, 3.0)  # [g, Hz]: rocks (916 impacts in 200 s)
    start = time.monotonic()
    out = runner.run(motion, cfg.solver)
    return out, time.monotonic() - start


def test_the_wall_clock_budget_ends_a_compiled_closed_form_run():
    out, took = _long_rocking(0.5)
    assert out.status == "failed", out.message
    assert "wall-clock budget exceeded (0.5 s, solver.max_wall_time)" in out.message
    assert took < 10.0


def test_ctrl_c_stops_a_compiled_closed_form_run():
    """Ctrl-C (SIGINT) reaches the compiled closed form through guard.poll and raises
    KeyboardInterrupt once the call has returned. Python's own SIGINT handler
    is installed for the test: a test runner started as a background job ignores SIGINT,
    and the test once skipped there."""
    _long_rocking(0.1)  # compiled (or loaded) before the clock starts
    timer = threading.Timer(1.0, os.kill, (os.getpid(), signal.SIGINT))
    start = time.monotonic()
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            _long_rocking(120.0)
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    assert time.monotonic() - start < 10.0
