"""`rbm-3d`'s friction demand against `interface.friction`, its energy account, and the
figures of a run in three dimensions in its result, through the public API and the CLI.

Independent reasons:

- a rigid column at rest on the ground carries T = m a_h on N = m g, a_h the horizontal
  acceleration in any direction: under a harmonic A sin(omega t) below its uplift level its
  demand is A / g exactly and first exceeds mu < A / g at asin(mu g / A) / omega; under a
  pair of records its demand is the largest resultant |a_h| / g of the samples (straight
  between them), and it first exceeds mu where |a_h| = mu g;
- along x the demand of a rocking column is the planar model's (the planar kernel);
- the energy balance: the work the ground did is what the column kept (kinetic and the
  laws' potential, written here from the state) plus what its damping and impacts took;
  along x each term is the planar model's.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from click.testing import CliRunner

import rbm
from rbm_cli.cli.main import cli

from .paths import CONFIGS

RECORDS = CONFIGS / "records" / "synthetic"
PAPER = {"height": 5.0, "base_width": 0.96, "top_width": 0.66, "section": "circular",
         "density": 2700}  # fmt: skip
ELASTIC = {"normal": 5e9}
FREQ = 1.3  # Hz
UPLIFT_G = 0.96 / 5.0  # the RBM monolith's uplift level B / H [g]


def config(model="rbm-3d", drums=1, interface=None, **excitation):
    return rbm.load_config({
        "name": "friction3d", "model": model, "column": {**PAPER, "drums": drums},
        "interface": {"restitution": 0.9, **(interface or {})},
        "excitation": {"type": "harmonic", "duration": 3.0, **excitation},
        "solver": {"method": "DOP853"},
    })  # fmt: skip


def test_rbm3d_takes_interface_friction_and_flags_sliding():
    """interface.friction is a model with the RBM's joints' option: rbm-3d takes it (it was
    refused: "computes no friction demand"), checks its demand against it and its domain
    has the slides column; housner-3d, which computes none, still refuses it."""
    cfg = config(interface={"friction": 0.1}, angle=30.0)
    cell = rbm.run(cfg, 0.15, FREQ, record=False).result
    assert cell.friction_limit == 0.1 and cell.slip is not None
    df = rbm.sweep(rbm.with_value(cfg, "grid", {"amplitudes": [0.05, 0.15],
                                                "frequencies": [FREQ]}))  # fmt: skip
    assert df.slides.tolist() == [0, 1]
    with pytest.raises(rbm.ConfigError, match="interface.friction applies only to models"):
        rbm.load_config({"name": "c", "model": "housner-3d", "column": PAPER,
                         "interface": {"friction": 0.1}})  # fmt: skip


@pytest.mark.parametrize("angle", [0.0, 30.0, -135.0])
def test_at_rest_the_demand_is_a_over_g_and_it_slips_at_the_closed_form_time(angle):
    """The rigid monolith below its uplift level, the motion at any azimuth: demand A / g
    to 1e-12 and the first exceedance of mu at asin(mu / A) / omega to 1e-9 s (the demand
    at rest was not computed: 0)."""
    mu = 0.12
    for a in (0.05, 0.15, 0.18):
        r = rbm.run(config(interface={"friction": mu}, angle=angle), a, FREQ,
                    record=False).result  # fmt: skip
        assert r.n_uplifts == 0 and r.status == "survived" and a < UPLIFT_G
        assert r.friction_demand[0] == pytest.approx(a, rel=1e-12)
        if a > mu:
            t_slip, where = r.slip
            assert where == 1
            assert t_slip == pytest.approx(math.asin(mu / a) / (2 * math.pi * FREQ), abs=1e-9)
            assert r.slides == 1
        else:
            assert r.slip is None and r.slides == 0


def _pair(tmp_path, seconds=6.0):
    """Two records of the project, their first seconds, as CSV files [g]."""
    out = []
    for name in ("rdk_01", "rdk_02"):
        lines = (RECORDS / f"{name}.AT2").read_text().splitlines()[4:]
        data = np.array([float(v) for line in lines for v in line.split()])
        t = 0.01 * np.arange(data.size)  # the synthetic records' step (NPTS, DT header)
        keep = t <= seconds
        path = tmp_path / f"{name}.csv"
        np.savetxt(path, np.c_[t[keep], data[keep]], delimiter=",", header="time_s,acc_g",
                   comments="")  # fmt: skip
        out.append((path, t[keep], data[keep]))
    return out


def test_at_rest_under_a_pair_the_demand_is_the_largest_resultant(tmp_path):
    """A pair scaled to 0.15 g (its larger PGA), below the uplift level: the demand is the
    largest |a_h| / g over the samples (the pair is straight between them), and the slip
    is where |a_h| first reaches mu g, inside the first interval whose end exceeds it."""
    (fx, t, ax), (fy, _, ay) = _pair(tmp_path)
    mu, amplitude = 0.1, 0.15
    cfg = rbm.load_config({
        "name": "pair", "model": "rbm-3d", "column": PAPER, "interface": {"friction": mu},
        "excitation": {"type": "record", "file": str(fx), "file_y": str(fy), "units": "g",
                       "scale": "pga", "free_time": 0.5},
    })  # fmt: skip
    r = rbm.run(cfg, amplitude, record=False).result
    scale = amplitude / max(np.max(np.abs(ax)), np.max(np.abs(ay)))
    resultant = scale * np.hypot(ax, ay)
    assert r.n_uplifts == 0 and np.max(resultant) < UPLIFT_G
    assert r.friction_demand[0] == pytest.approx(np.max(resultant), rel=1e-12)
    t_slip, where = r.slip
    k = int(np.argmax(resultant > mu))  # the first sample beyond mu
    assert where == 1 and t[k - 1] <= t_slip <= t[k]
    s = (t_slip - t[k - 1]) / (t[k] - t[k - 1])
    at_slip = scale * np.hypot(ax[k - 1] + s * (ax[k] - ax[k - 1]),
                               ay[k - 1] + s * (ay[k] - ay[k - 1]))  # fmt: skip
    assert at_slip == pytest.approx(mu, rel=1e-9)


def test_along_x_a_rocking_columns_demand_is_the_planar_models():
    """Rocking columns of two and three elastic drums (one collapses): the demand of every
    joint within 1e-6 of the planar kernel's (both are taken at step ends; on these cells
    the planar runs at rtol 1e-10 and 1e-12 agree to 1e-8), and the same verdict on
    sliding, one each way."""
    verdicts = set()
    for drums, cell in ((2, (0.3, 2.0)), (3, (0.4, 1.0))):
        interface = {"stiffness": ELASTIC, "friction": 0.5}
        planar = rbm.run(config("rbm", drums, interface), *cell, record=False).result
        beam = rbm.run(config("rbm-3d", drums, interface), *cell, record=False).result
        assert planar.n_uplifts > 0
        assert np.allclose(beam.friction_demand, planar.friction_demand, rtol=1e-6, atol=0.0)
        assert beam.slides == planar.slides and (beam.slip is None) == (planar.slip is None)
        if planar.slip is not None:  # at the same interface
            assert beam.slip[1] == planar.slip[1]
        verdicts.add(planar.slides)
    assert verdicts == {0, 1}


def test_the_cli_says_where_rbm3d_slides(tmp_path):
    """`rbm run` of an rbm-3d config with interface.friction prints where the demand first
    exceeded it, as for rbm."""
    path = tmp_path / "slide3d.yaml"
    path.write_text(
        "name: slide3d\nmodel: rbm-3d\n"
        "column: {height: 5.0, base_width: 0.96, top_width: 0.66, section: circular}\n"
        "interface: {stiffness: rigid, friction: 0.12}\n"
        "excitation: {type: harmonic, duration: 2.0, angle: 45}\n"
    )
    res = CliRunner().invoke(cli, ["run", str(path), "-a", "0.15", "-f", str(FREQ), "-o",
                                   str(tmp_path)])  # fmt: skip
    assert res.exit_code == 0, res.output
    expected = math.asin(0.12 / 0.15) / (2 * math.pi * FREQ)
    line = next(ln for ln in res.output.splitlines() if ln.strip().startswith("slides"))
    assert "|T/N| > interface.friction 0.12 first at t =" in line
    assert float(line.split("t =")[1].split()[0]) == pytest.approx(expected, rel=1e-5)


def _pair_config(tmp_path, model="rbm-3d", **interface):
    (fx, _, _), (fy, _, _) = _pair(tmp_path)
    return rbm.load_config({
        "name": "energy3d", "model": model, "column": {**PAPER, "drums": 3},
        "interface": {"stiffness": ELASTIC, "restitution": 0.9, "damping": 0.05, **interface},
        "excitation": {"type": "record", "file": str(fx), "file_y": str(fy), "units": "g",
                       "scale": "pga", "free_time": 1.0},
    })  # fmt: skip


def test_rbm3d_keeps_an_energy_account_that_balances(tmp_path):
    """Three elastic drums, damped, e = 0.9, under a pair (their motion in three
    dimensions): the ground's work is what the column kept plus what the damping and the
    impacts took, to 1e-8 of the work at the default tolerances (the planar model's stated
    balance); every term at work. It was None."""
    r = rbm.run(_pair_config(tmp_path), 0.35).result
    e = r.energy
    assert r.n_impacts > 5 and r.wobble_turns > 0.0  # it rocks and its joints turn
    assert e["ground_work_J"] > 0 and e["damping_J"] > 0 and e["impacts_J"] > 0
    kept = e["final_J"] - e["initial_J"]
    balance = kept - (e["ground_work_J"] - e["damping_J"] - e["impacts_J"])
    assert balance == pytest.approx(e["residual_J"], abs=1e-12 * e["ground_work_J"])
    assert abs(balance) <= 1e-8 * e["ground_work_J"], e


def test_along_x_the_energy_account_is_the_planar_models():
    """A damped column of three elastic drums, e = 0.9, shaken to uplift along x: each
    term of the account within 1e-7 of the ground's work of the planar kernel's (an
    integrator of its own, the same quadrature rule)."""
    interface = {"stiffness": ELASTIC, "damping": 0.05}
    planar = rbm.run(config("rbm", 3, interface), 0.3, 2.0).result
    beam = rbm.run(config("rbm-3d", 3, interface), 0.3, 2.0).result
    assert (beam.n_impacts, beam.n_uplifts) == (planar.n_impacts, planar.n_uplifts)
    work = planar.energy["ground_work_J"]
    assert planar.n_impacts > 5 and work > 0
    for k in ("final_J", "ground_work_J", "damping_J", "impacts_J"):
        assert abs(beam.energy[k] - planar.energy[k]) < 1e-7 * work, k


@pytest.mark.parametrize("model", ["rbm-3d", "housner-3d"])
def test_a_3d_runs_result_holds_its_azimuth_and_wobbling_turns(model):
    """CellRun.result of a model in three dimensions holds collapse_azimuth_deg and
    wobble_turns where domain.csv has them (after max_top_displacement_m), with the
    sweep's values for the same cells; a planar run's result has neither."""
    cfg = rbm.with_value(config(model, angle=30.0), "grid",
                         {"amplitudes": [0.3, 1.2], "frequencies": [1.0]})  # fmt: skip
    df = rbm.sweep(cfg)
    assert set(df.status) == {"survived", "collapsed"}
    for _, row in df.iterrows():
        cell = rbm.run(cfg, row.amplitude_g, row.frequency_hz, record=False).result
        keys = list(cell)
        at = keys.index("max_top_displacement_m") + 1
        assert keys[at : at + 2] == ["collapse_azimuth_deg", "wobble_turns"]
        assert cell["wobble_turns"] == row.wobble_turns
        assert cell["collapse_azimuth_deg"] == pytest.approx(row.collapse_azimuth_deg,
                                                             abs=1e-9, nan_ok=True)  # fmt: skip
    planar = rbm.run(config("rbm"), 0.3, 1.0, record=False).result
    assert "wobble_turns" not in planar and "collapse_azimuth_deg" not in planar
