"""The contact engine's residual state: the slip, top offset and tilt where a run ended.

Expected values come from outside the engine: the slip of a rigid block that slides
without rocking on a plane under a half-sine pulse with Coulomb friction (written here:
it sticks until a_g = mu g, then slides back relative to the ground, friction mu g
against it, until its relative velocity is 0 again), the history the engine samples, and
statics (a block with friction above its uplift level rocks and does not slide). Runs of
about 0.2-1 s of engine time each.
"""

from __future__ import annotations

import json
import math

import pandas as pd
import pytest
from click.testing import CliRunner
from scipy.integrate import quad
from scipy.optimize import brentq

import rbm
from rbm_cli.cli.main import cli
from rbm_cli.config.types import G
from rbm_cli.study.domain import read_domain

from .paths import RESULTS

#: Slow (contact-engine runs): `pytest -m 'not slow'` leaves this file out.
pytestmark = pytest.mark.slow

RESIDUAL = ("residual_slip_m", "residual_top_offset_m", "residual_tilt_ratio")
#: A cube of 1 m (tan alpha = 1) with friction 0.2 under a 0.6 g half-sine of 2 Hz: the
#: friction caps the base shear at 0.2 m g, whose moment 0.2 m g H/2 cannot lift it (that
#: needs m g B/2): it slides, and does not rock.
AMPLITUDE_G, FREQUENCY_HZ, MU = 0.6, 2.0, 0.2


def sliding_config(section="rectangular", **excitation):
    column = {"height": 1.0, "base_width": 1.0, "section": section}
    if section == "rectangular":
        column["depth"] = 1.0
    return rbm.load_config({
        "name": "slide",
        "model": "bullet",
        "column": column,
        "interface": {"friction": MU},
        "excitation": {"type": "half-sine", "duration": 1.5, **excitation},
    })  # fmt: skip


def coulomb_slip(amplitude_g: float, frequency_hz: float, mu: float) -> float:
    """The slip [m] of a rigid block on a plane under a_g = A sin(w t), 0 <= t <= pi / w,
    with Coulomb friction mu (mu g < A), sliding only: it sticks until A sin(w t1) = mu g,
    then its velocity relative to the ground is v(t) = -(A / w)(cos w t1 - cos w t) +
    mu g (t - t1) during the pulse and v(T) + mu g (t - T) after it, until v = 0 at t2;
    the slip is the integral of |v| from t1 to t2."""
    a, w = amplitude_g * G, 2.0 * math.pi * frequency_hz
    end = math.pi / w
    t1 = math.asin(mu * G / a) / w

    def v(t):
        during = -(a / w) * (math.cos(w * t1) - math.cos(w * min(t, end))) + mu * G * (
            min(t, end) - t1
        )
        return during + mu * G * max(t - end, 0.0)

    t2 = brentq(v, t1 + 1e-9, end + 10.0)
    return -quad(v, t1, t2, points=[end] if t2 > end else None, limit=200)[0]


def test_closed_form_of_the_slip_is_the_rectangle_pulse_s_in_its_limit():
    """The closed form itself: a half-sine of A_max = mu g (1 + eps) barely slides (its
    slip tends to 0), and the slip grows with the amplitude."""
    assert coulomb_slip(0.2 * 1.0001, 2.0, 0.2) < 1e-6
    slips = [coulomb_slip(a, 2.0, 0.2) for a in (0.3, 0.6, 0.9)]
    assert slips[0] < slips[1] < slips[2]


@pytest.mark.parametrize("record", [False, True])
def test_a_sliding_block_s_residual_slip_is_coulomb_s(record):
    """The residual slip of the sliding cube is the closed form's, 119.0 mm, to 0.5 %
    (the engine's fixed step of 1e-4 s and its friction solver), whether the run stops at
    rest after the pulse (record False: it must not stop while the block still slides) or
    runs the whole 1.5 s (record True); the top moved as much, and nothing tilted."""
    cell = rbm.run(sliding_config(), AMPLITUDE_G, FREQUENCY_HZ, record=record)
    r = cell.result
    expected = coulomb_slip(AMPLITUDE_G, FREQUENCY_HZ, MU)
    assert cell.status == "survived" and r.max_rotation_ratio < 1e-3
    assert r["residual_slip_m"] == pytest.approx(expected, rel=5e-3)
    assert r["residual_top_offset_m"] == pytest.approx(r["residual_slip_m"], rel=1e-6)
    assert r["residual_tilt_ratio"] < 1e-6
    if record:  # the engine's own sampled history: the base's last place on the ground
        last = cell.history.iloc[-1]
        assert abs(last["u1_m"]) == pytest.approx(r["residual_slip_m"], rel=1e-6)
        assert last["u1_m"] < 0.0  # it lags the ground, which moved to +x


def test_a_circular_block_free_in_three_dimensions_slides_as_in_the_plane():
    """The same cube as a cylinder of diameter 1 m moving free in three dimensions
    (excitation.angle 0: Config.three_d) reads its slip in plan: the closed form's, to
    0.5 %, as the cylinder held in the plane."""
    plane = rbm.run(sliding_config("circular"), AMPLITUDE_G, FREQUENCY_HZ, record=False)
    free_cfg = sliding_config("circular", angle=0.0)
    assert free_cfg.three_d
    free = rbm.run(free_cfg, AMPLITUDE_G, FREQUENCY_HZ, record=False)
    expected = coulomb_slip(AMPLITUDE_G, FREQUENCY_HZ, MU)
    for r in (plane.result, free.result):
        assert r["residual_slip_m"] == pytest.approx(expected, rel=5e-3)
        assert r["residual_top_offset_m"] == pytest.approx(expected, rel=5e-3)


def test_a_high_friction_block_that_rocked_keeps_no_slip():
    """A slender block (H/B = 4, tan alpha = 0.25) with friction 1.5 under 0.4 g rocks
    (it lifts, its ratio passes 0.02) and comes to rest: its base never slides (friction
    above the uplift level), so its residual slip is below 0.05 mm (measured: 0.006 mm;
    the sliding block's is 119 mm) and it stands upright again."""
    cfg = rbm.load_config({
        "name": "rock",
        "model": "bullet",
        "column": {"height": 2.0, "base_width": 0.5, "depth": 0.5},
        "interface": {"friction": 1.5},
        "excitation": {"type": "half-sine", "duration": 4.0},
    })  # fmt: skip
    r = rbm.run(cfg, 0.4, 2.0, record=False).result
    assert r.status == "survived" and r.n_uplifts > 0 and r.max_rotation_ratio > 0.02
    assert "at rest after the pulse" in r.message
    assert 0.0 <= r["residual_slip_m"] < 5e-5
    assert r["residual_top_offset_m"] < 5e-5 and r["residual_tilt_ratio"] < 1e-3


def test_a_collapsed_run_has_no_residual_state_and_other_models_none_at_all():
    """A block that overturned has no residual state (NaN: it is down); a model other
    than the contact engine has no residual key (NaN as an attribute)."""
    cfg = rbm.load_config({
        "name": "rock",
        "model": "bullet",
        "column": {"height": 2.0, "base_width": 0.5, "depth": 0.5},
        "interface": {"friction": 1.5},
        "excitation": {"type": "half-sine", "duration": 4.0},
    })  # fmt: skip
    r = rbm.run(cfg, 0.5, 1.0, record=False).result
    assert r.status == "collapsed"
    assert all(math.isnan(r[k]) for k in RESIDUAL)
    other = rbm.run(rbm.with_value(cfg, "model", "rbm"), 0.1, 1.0, record=False).result
    assert not any(k in other for k in RESIDUAL)
    assert math.isnan(other.residual_slip_m)


def _yaml(tmp_path, model):
    path = tmp_path / f"{model}.yaml"
    path.write_text(
        f"name: {model}\nmodel: {model}\n"
        "column: {height: 1.0, base_width: 1.0, depth: 1.0}\n"
        f"interface: {{friction: {MU}}}\n"
        "excitation: {type: half-sine, duration: 1.5}\n"
        "grid: {amplitudes: [0.1, 0.6], frequencies: [2.0]}\n"
    )
    return path


def test_domain_csv_and_summary_json_carry_the_residual_of_the_engine_only(tmp_path):
    """`rbm sweep` of the engine writes the three columns (0 for the cell below the
    sliding level, where the stack moves with the ground; the closed form's slip for the
    one above), `rbm run` writes them to summary.json; a sweep of model rbm writes none.
    A stored domain of the engine made before them still reads."""
    runner = CliRunner()
    res = runner.invoke(cli, ["sweep", str(_yaml(tmp_path, "bullet")), "-o", str(tmp_path)])
    assert res.exit_code == 0, res.output
    df = read_domain(tmp_path / "bullet" / "domain.csv")
    assert all(k in df.columns for k in RESIDUAL)
    still = df[df["amplitude_g"] == 0.1].iloc[0]
    slid = df[df["amplitude_g"] == 0.6].iloc[0]
    assert still["residual_slip_m"] == 0.0 and still["residual_top_offset_m"] == 0.0
    expected = coulomb_slip(AMPLITUDE_G, FREQUENCY_HZ, MU)
    assert slid["residual_slip_m"] == pytest.approx(expected, rel=5e-3)
    res = runner.invoke(cli, ["run", str(_yaml(tmp_path, "bullet")), "-a", "0.6", "-f", "2",
                              "-o", str(tmp_path / "run")])  # fmt: skip
    assert res.exit_code == 0, res.output
    assert "residual:" in res.output and "top offset" in res.output
    (summary,) = (tmp_path / "run").rglob("summary.json")
    values = json.loads(summary.read_text())
    assert values["residual_slip_m"] == pytest.approx(expected, rel=5e-3)
    assert values["residual_tilt_ratio"] < 1e-6
    res = runner.invoke(cli, ["run", str(_yaml(tmp_path, "rbm")), "-a", "0.6", "-f", "2",
                              "-o", str(tmp_path / "run_rbm")])  # fmt: skip
    assert res.exit_code == 0 and "residual:" not in res.output, res.output
    res = runner.invoke(cli, ["sweep", str(_yaml(tmp_path, "rbm")), "-o", str(tmp_path)])
    assert res.exit_code == 0, res.output
    header = pd.read_csv(tmp_path / "rbm" / "domain.csv", nrows=0).columns
    assert not any(k in header for k in RESIDUAL)
    stored = read_domain(RESULTS / "harmonic_monolithic_bullet" / "domain.csv")
    assert len(stored) > 0 and not any(k in stored.columns for k in RESIDUAL)
