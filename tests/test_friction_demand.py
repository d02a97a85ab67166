"""The friction demand of the RBM's joints: the largest |T_i / N_i| held, in one direction,
over 0.03 s (rbm_cli.models.rbm.pieces.FRICTION_DURATION), its instantaneous peak apart.

Independent reasons:

- A rigid block at rest carries T = m a_g on N = m g. Under A sin(omega t) below uplift
  |T / N| = (A / g) |sin(omega t)|: a window of tau held in one direction around a crest
  has its least value at its ends, so the held demand is (A / g) cos(omega tau / 2) for a
  window centred on the crest. The integrators sample the window every tau / 60 from t = 0:
  a window of samples is off the centre by at most tau / 120, so the demand lies in
  [(A / g) cos(omega (tau / 2 + tau / 120)), (A / g) cos(omega tau / 2)] (the upper bound:
  every window's end samples include one at least tau / 2 from the crest). It first holds
  above mu from t* = asin(mu g / A) / omega (the first sample at or after it).
- A rigid block rocking freely (the RBM's small rotations about the joint's centre:
  I theta'' = m g (H / 2) (theta - s alpha), I = m (B^2 / 12 + H^2 / 3), alpha = B / H,
  so theta'' = p^2 (theta - s alpha), p^2 = g (H / 2) / (B^2 / 12 + H^2 / 3)) released from
  rest at theta0 has theta - alpha = (theta0 - alpha) cosh(p t) up to its impact at
  T = acosh(alpha / (alpha - theta0)) / p. Its centre's horizontal acceleration is
  (H / 2) theta'', so |T / N| = (H / 2) p^2 (alpha - theta) / g grows to its peak
  (H / 2) p^2 alpha / g at the impact, where the shear reverses. The held demand is its
  value tau before the impact, within a sample of it, the instantaneous peak the value at
  the impact. With restitution 0.01 the block comes to rest in excursions shorter than tau.
- The elastic multi-drum columns of the sweeps guide: every method and tolerance gives the
  same held demand (within 5 %) although their instantaneous peaks (1.28 and 1.37 at the
  base) hold for a few ms only; on a harmonic grid of the 6-drum column interface.friction
  0.7 marks exactly the cells whose held demand exceeds it, not every cell that rocks.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import rbm
from rbm_cli.config.types import G
from rbm_cli.models.rbm.pieces import FRICTION_DURATION
from rbm_cli.study.simulate import simulate
from rbm_cli.study.sweep import sweep_rows

from .paths import CONFIGS

TAU = FRICTION_DURATION
H, B = 2.0, 0.5  # a rigid monolith: uplift level B / H = 0.25 g
FREQ = 1.3  # Hz
METHODS = ("closed-form", "exact", "DOP853", "RK45", "RK23")
TIGHT = {"solver.method": "DOP853", "solver.rtol": 1e-12, "solver.atol": 1e-14}
#: the methods and tolerances that must agree on the elastic columns
SOLVERS = {
    "DOP853": {"solver.method": "DOP853"},
    "DOP853 tight": TIGHT,
    "RK45": {"solver.method": "RK45"},
    "exact": {"solver.method": "exact"},
}


def test_the_window_is_the_documented_one():
    assert TAU == 0.03


def _block(method, friction=None):
    raw = {
        "name": "held_block",
        "column": {"height": H, "base_width": B},
        "excitation": {"type": "harmonic", "duration": 3.0},
        "solver": {"method": method},
    }
    if friction is not None:
        raw["interface"] = {"friction": friction}
    return rbm.load_config(raw)


@pytest.mark.parametrize("method", METHODS)
def test_a_block_at_rest_holds_its_crest_over_the_window(method):
    mu = 0.12
    om = 2 * math.pi * FREQ
    for a in (0.05, 0.15, 0.24):
        r = simulate(_block(method, mu), a, FREQ)
        assert r.method == method and r.n_uplifts == 0 and r.status == "survived"
        lo, hi = a * math.cos(om * (TAU / 2 + TAU / 120)), a * math.cos(om * TAU / 2)
        assert lo - 1e-12 <= r.friction_demand[0] <= hi + 1e-12, (a, r.friction_demand, lo, hi)
        assert r.friction_demand_peak[0] == pytest.approx(a, abs=1e-6)  # the crest itself
        assert r.friction_duration_s == TAU
        if a > mu:
            t_first = math.asin(mu / a) / om
            t_slip, where = r.slip
            assert where == 1 and t_first - 1e-12 <= t_slip <= t_first + TAU / 60 + 1e-12
            assert r.slides == 1
        else:
            assert r.slip is None and r.slides == 0


def _free_block(method, theta0):
    return rbm.load_config({
        "name": "free_block",
        "column": {"height": H, "base_width": B},
        "interface": {"restitution": 0.01},
        "excitation": {"type": "free", "duration": 3.0, "initial": {"rotations": [theta0]}},
        "solver": {"method": method},
    })  # fmt: skip


@pytest.mark.parametrize("method", METHODS)
def test_a_rocking_block_holds_its_demand_a_window_before_the_impact(method):
    alpha = B / H
    p2 = G * (H / 2) / (B * B / 12 + H * H / 3)
    p = math.sqrt(p2)
    theta0 = 0.6 * alpha
    t_imp = math.acosh(alpha / (alpha - theta0)) / p

    def demand(t):  # |T / N| on the way to the impact
        return (H / 2) * p2 * (alpha - theta0) * math.cosh(p * t) / G

    r = rbm.run(_free_block(method, theta0), record=False).result
    assert r.method == method and r.n_impacts >= 1 and r.status == "survived"
    lo, hi = demand(t_imp - TAU - TAU / 60), demand(t_imp - TAU)
    assert lo - 1e-9 <= r.friction_demand[0] <= hi + 1e-9, (r.friction_demand, lo, hi)
    assert r.friction_demand_peak[0] == pytest.approx((H / 2) * p2 * alpha / G, rel=1e-6)
    assert r.friction_demand[0] < 0.95 * r.friction_demand_peak[0]  # the window matters


def _drums6(**over):
    raw = {
        "name": "six_drums",
        "model": "rbm",
        "column": {"height": 4.5, "base_width": 0.9, "top_width": 0.7, "section": "circular",
                   "density": 2700, "drums": 6},
        "interface": {"stiffness": {"normal": 5e9}, "restitution": 0.9},
        "excitation": {"type": "harmonic", "duration": 10.0},
    }  # fmt: skip
    raw.update(over)
    return rbm.load_config(raw)


def _agree(cfg, amplitude_g, frequency_hz, solvers=SOLVERS):
    runs = {}
    for name, values in solvers.items():
        r = rbm.run(rbm.with_values(cfg, values), amplitude_g=amplitude_g,
                    frequency_hz=frequency_hz, record=False).result  # fmt: skip
        assert r.status != "failed", (name, r.message)
        runs[name] = r
    held = {name: r.max_friction_demand for name, r in runs.items()}
    assert max(held.values()) <= 1.05 * min(held.values()), held
    return held, runs


def test_the_6_drum_column_demand_agrees_between_methods_and_is_not_its_peak():
    held, runs = _agree(_drums6(), 0.2, 2.0)
    assert all(h < 0.7 for h in held.values()), held
    for r in runs.values():  # the base's peak holds for a few ms: not the demand
        assert r.friction_demand_peak[0] > 1.2, r.friction_demand_peak


@pytest.mark.slow
def test_the_8_drum_column_demand_agrees_between_methods_and_is_not_its_peak():
    """At 0.18 g, 2 Hz (its joints barely open) and at 0.25 g, 3.25 Hz (it rocks, its peak
    rotation 0.18-0.34 of the limit by method, and survives) the held demand agrees between
    methods; where it rocks, the base's peak (its impacts) holds for a few ms only, and the
    held demand is about half of it. At 0.2 g, 2 Hz the column rocks or barely moves as
    the amplitude changes by 1e-9: no cell to compare methods on. Where it rocks the
    trajectories are chaotic: at cells beside this one (0.25 g at 2.75 and 3 Hz, 0.28 g at
    3 Hz, 0.3 g at 3.5 Hz) one method's run in four holds 1.13-1.19 for 0.03 s where the
    others hold 0.72-0.75."""
    cfg = rbm.load_config(CONFIGS / "harmonic_multidrum.yaml")
    held, _ = _agree(cfg, 0.18, 2.0)
    assert all(h < 0.7 for h in held.values()), held
    held, runs = _agree(cfg, 0.25, 3.25)
    for name, r in runs.items():
        assert r.friction_demand_peak[0] > 1.3, (name, r.friction_demand_peak)
        assert held[name] < 0.6 * r.friction_demand_peak[0], (name, held)


@pytest.mark.slow
def test_the_damped_6_drum_column_in_3d_agrees_between_tolerances():
    damped = {"stiffness": {"normal": 5e9}, "restitution": 0.9, "damping": 0.05}
    cfg = _drums6(model="rbm-3d", interface=damped)
    solvers = {k: v for k, v in SOLVERS.items() if k != "exact"}
    _, runs = _agree(cfg, 0.2, 2.0, solvers)
    for r in runs.values():
        assert np.all(np.array(r.friction_demand) <= np.array(r.friction_demand_peak) + 1e-12)


def test_slides_at_07_marks_the_cells_whose_held_demand_exceeds_it():
    grid = {"amplitudes": [0.2, 0.4, 0.6], "frequencies": [2.0, 3.0]}
    cfg = _drums6(grid=grid, interface={"stiffness": {"normal": 5e9}, "restitution": 0.9,
                                        "friction": 0.7})  # fmt: skip
    df = sweep_rows(cfg).frame()
    assert len(df) == 6 and (df["status"] != "failed").all()
    np.testing.assert_array_equal(df["slides"], (df["friction_demand"] > 0.7).astype(int))
    rocked = df["max_rotation_ratio"] > 0.01
    assert rocked.sum() >= 4  # the column rocks in these cells ...
    assert df.loc[rocked, "slides"].sum() < rocked.sum()  # ... and not every one slides
