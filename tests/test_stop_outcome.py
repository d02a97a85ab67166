"""solver.stop: outcome, the survival certificate of free motion.

A run of model rbm (formulation relative) may end as soon as its survival is certain: no
forcing left and the column's energy below every joint's collapse barrier (free motion
never gains energy, and reaching joint i's collapse costs at least its law's potential at
c theta_u). What is held here:

- the barrier is that least potential, by an integral of the laws' moments (scipy's quad,
  not the closed form the code sums);
- on whole domains (the CI band of the 8-drum record suite with the step kernel, a record's
  levels with the exact integrator) no cell's outcome changes; a run that collapses in the
  free tail still collapses there; a cell that is not stopped is the same to the byte; a
  stopped one stops after its record with peaks no larger than the full run's;
- a config that asks for it where no certificate exists is refused in one line, and the
  default leaves the hash of every stored domain as it was;
- the default stop (a monolith at a peak of free motion below its barrier) on a whole
  half-sine domain with each method: the same outcomes and peaks as runs to the end.
"""

from __future__ import annotations

import csv
import json
import math
import re

import numpy as np
import pytest
import yaml
from scipy.integrate import quad

from rbm_cli.api import load_config, run, sweep, with_values
from rbm_cli.base.errors import ConfigError
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.inputs.records import Record, read_record, write_at2
from rbm_cli.models.registry import make_runner
from rbm_cli.structures.arrays import survival_barrier
from rbm_cli.structures.assembly import model_from_config
from rbm_cli.study.sweep import config_hash

from .paths import CONFIGS, RESULTS

CI_BAND = CONFIGS / "ci" / "suite_multidrum_ci.yaml"
STOPPED = re.compile(r"stopped at ([0-9.e+-]+) s \(solver\.stop: outcome\)")
RECORD_S = 30.0  # the synthetic records' length [s]


def _raw(path=CI_BAND) -> dict:
    """The config file as a mapping (for the keys a Config cannot change)."""
    raw = yaml.safe_load(path.read_text())
    raw["interface"]["stiffness"]["normal"] = float(raw["interface"]["stiffness"]["normal"])
    files = raw["excitation"]["file"]
    raw["excitation"]["file"] = [str((path.parent / f).resolve()) for f in files]
    return raw


def _band(**values):
    """The CI band's config (its record paths as written) with values changed."""
    return with_values(load_config(CI_BAND), values)


def _rows(path) -> dict:
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    return {(r["record"], r["amplitude_g"]): r for r in rows}


# ---------------------------------------------------------------------------- the barrier


@pytest.mark.parametrize("xi, ratio", [(1.0, 1.0), (0.8, 0.9)])
def test_the_barrier_is_the_least_potential_of_a_joint_at_collapse(xi, ratio):
    raw = _raw()
    raw["interface"]["xi"] = xi
    raw["collapse"] = {"ratio": ratio}
    model = model_from_config(load_config(raw))
    by_quad = []
    for law, tu in zip(model.laws, model.column.rotation_capacity, strict=True):
        edges = [e for e in law.edges if e < ratio * tu]  # the kinks: quad's breakpoints
        value, err = quad(lambda x, law=law: float(law(x)), 0.0, ratio * tu, points=edges or None,
                          limit=200, epsabs=0.0, epsrel=1e-12)  # fmt: skip
        by_quad.append(value)
    assert survival_barrier(model) == pytest.approx(min(by_quad), rel=1e-9)
    # the top joint, the lightest load, is the weakest
    assert int(np.argmin(by_quad)) == model.n - 1


@pytest.mark.parametrize("formulation", ["geometric", "absolute"])
def test_no_barrier_where_the_energy_does_not_bound_the_joints(formulation):
    raw = _raw()
    raw["interface"]["formulation"] = formulation
    assert math.isnan(survival_barrier(model_from_config(load_config(raw))))


# ---------------------------------------------------------------------------- the config


@pytest.mark.parametrize(
    "change, words",
    [
        ({"solver": {"stop": "never"}}, ["solver.stop", "figures", "outcome"]),
        ({"solver": {"stop": "outcome"}, "interface": {"formulation": "geometric"}},
         ["solver.stop: outcome", "relative", "formulation geometric"]),
        ({"solver": {"stop": "outcome"}, "model": "housner", "column": {"drums": 1},
          "interface": None}, ["solver.stop: outcome", "model housner"]),
    ],
)  # fmt: skip
def test_a_stop_without_a_certificate_is_refused_in_one_line(change, words):
    raw = _raw()
    for key, value in change.items():
        if value is None:
            raw.pop(key)
        elif isinstance(value, dict) and isinstance(raw.get(key), dict):
            raw[key] = {**raw[key], **value}
        else:
            raw[key] = value
    with pytest.raises(ConfigError) as err:
        load_config(raw)
    text = str(err.value)
    assert "\n" not in text
    for word in words:
        assert word in text, text


def test_the_default_keeps_every_stored_hash_and_outcome_changes_it():
    plain = load_config(CI_BAND)
    stored = json.loads((RESULTS / "suite_multidrum_ci" / "meta.json").read_text())
    assert config_hash(plain) == stored["config_hash"].split("-")[0]  # "<hash>-ensemble16"
    assert config_hash(_band(**{"solver.stop": "figures"})) == config_hash(plain)
    assert config_hash(_band(**{"solver.stop": "outcome"})) != config_hash(plain)


# ---------------------------------------------------------------------------- free motion


def _free(
    stop: str,
    rotation: float,
    rate: float = 0.0,
    restitution: float = 0.9,
    implementation: str = "compiled",
) -> dict:
    """Two drums rocking as one stack (theta_u 0.25 rad at the base) from `rotation` of
    theta_u and `rate` [rad/s], damped."""
    return {
        "name": "two",
        "column": {"height": 2.0, "base_width": 0.5, "drums": 2},
        "interface": {"stiffness": {"normal": 5e8}, "damping": 0.05,
                      "restitution": restitution},
        "excitation": {"type": "free", "duration": 3.0,
                       "initial": {"rotations": [0.25 * rotation] * 2, "velocities": [rate] * 2}},
        "solver": {"stop": stop, "implementation": implementation},
    }  # fmt: skip


def _energy_over_barrier(raw: dict) -> float:
    cfg = load_config(raw)
    model = model_from_config(cfg)
    init = cfg.excitation.initial
    energy = model.energy(np.asarray(init.rotations), np.asarray(init.velocities))[0]
    return float(energy) / survival_barrier(model)


def test_free_motion_below_the_barrier_stops_at_once_and_survives():
    assert _energy_over_barrier(_free("outcome", 0.3)) < 0.6
    full = run(_free("figures", 0.3), amplitude_g=0.0, record=False).result
    quick = run(_free("outcome", 0.3), amplitude_g=0.0, record=False).result
    assert full["status"] == quick["status"] == "survived"
    assert full["n_impacts"] > 0  # it rocks
    t_stop = float(STOPPED.search(quick["message"]).group(1))
    assert 0.0 < t_stop < 0.01 and quick["n_steps"] <= 2 < full["n_steps"]
    # the same source uncompiled stops at the same step, to the bit
    plain = run(_free("outcome", 0.3, implementation="python"), amplitude_g=0.0,
                record=False).result  # fmt: skip
    for key in ("message", "max_rotation_ratio", "max_top_displacement_m", "n_steps"):
        assert plain[key] == quick[key], key


@pytest.mark.parametrize("restitution, status", [(0.7, "survived"), (0.9, "collapsed")])
def test_free_motion_above_the_barrier_stops_only_once_below_it(restitution, status):
    """Thrown back towards rest above the barrier: with e = 0.7 the first impact takes it
    below, and the run stops there; with e = 0.9 it goes over and collapses, as without
    the stop."""
    raw = _free("outcome", 0.5, -0.4, restitution)
    assert _energy_over_barrier(raw) > 1.05
    full = run(_free("figures", 0.5, -0.4, restitution), amplitude_g=0.0, record=False).result
    quick = run(raw, amplitude_g=0.0, record=False).result
    assert full["status"] == quick["status"] == status
    if status == "collapsed":
        for key in ("t_collapse_s", "n_steps", "max_rotation_ratio", "n_impacts"):
            assert quick[key] == full[key], key
    else:
        assert STOPPED.search(quick["message"]) is not None
        assert quick["n_impacts"] == 1 and quick["n_steps"] < full["n_steps"]


# ---------------------------------------------------------------------------- whole domains


def _check_domain(fresh: dict, full: dict, at_least: int) -> int:
    """fresh (stopped where it may) against full (the same runs to their end): every cell's
    outcome the same; a cell not stopped the same to the byte; a stopped one survived,
    after its record, with peaks no larger. Returns how many stopped."""
    assert fresh.keys() == full.keys()
    stopped = 0
    for key, row in fresh.items():
        old = full[key]
        assert row["status"] == old["status"], key
        found = STOPPED.search(row["message"])
        if found is None:
            for col, value in old.items():
                assert row[col] == value, (key, col)
            continue
        stopped += 1
        assert row["status"] == "survived"
        assert float(found.group(1)) >= RECORD_S
        for col in ("max_rotation_ratio", "max_top_displacement_m"):
            assert float(row[col]) <= float(old[col]), (key, col)
        assert int(row["n_steps"]) < int(old["n_steps"]), key
    assert stopped >= at_least
    return stopped


@pytest.mark.slow
def test_the_ci_band_keeps_every_outcome(tmp_path):
    """The 40 runs of the 8-drum band (the step kernel), stopped and not, against its own
    full runs; its robust cells' outcomes as stored (of the stored domain's 16 survivors,
    12 were below the barrier at the record's end, measured before the stop existed)."""
    sweep(_band(), tmp_path / "full", jobs=2)
    sweep(_band(**{"solver.stop": "outcome"}), tmp_path / "stop", jobs=2)
    full = _rows(tmp_path / "full" / "suite_multidrum_ci" / "domain.csv")
    stop = _rows(tmp_path / "stop" / "suite_multidrum_ci" / "domain.csv")
    _check_domain(stop, full, at_least=10)
    stored = _rows(RESULTS / "suite_multidrum_ci" / "domain.csv")
    for key, row in stored.items():
        if row["robust"] == "1":
            assert stop[key]["status"] == row["status"], key


def test_a_collapse_in_the_free_tail_is_kept(tmp_path):
    """A run that falls in its free tail, above every barrier, is never stopped: the 8-drum
    column of the stored suite under rdk_20 at 0.7 g (a collapse in every member of the
    stored ensemble) with the record cut 0.05 s before the collapse of the whole record:
    the column, already going over, falls after the cut, with solver.stop: outcome as with
    figures, to the bit (the stop only reads the state)."""
    cfg = with_values(load_config(CONFIGS / "suite_multidrum.yaml"),
                      {"excitation.file": "records/synthetic/rdk_20.AT2"})  # fmt: skip
    stored = _rows(RESULTS / "suite_multidrum" / "domain.csv")[("rdk_20", "0.7")]
    assert stored["status"] == "collapsed" and stored["robust"] == "1"
    whole = run(cfg, amplitude_g=0.7, record=False).result
    assert whole["status"] == "collapsed"
    record = read_record(CONFIGS / "records" / "synthetic" / "rdk_20.AT2")
    keep = record.t <= whole["t_collapse_s"] - 0.05
    assert np.max(np.abs(record.acceleration[keep])) == np.max(np.abs(record.acceleration))
    cut = write_at2(tmp_path / "rdk_20_cut.AT2",
                    Record(record.t[keep], record.acceleration[keep], "rdk_20_cut"))  # fmt: skip
    t_cut = record.t[keep][-1]
    cfg = with_values(cfg, {"excitation.file": str(cut)})
    ends = []
    for stop in ("figures", "outcome"):
        res = run(with_values(cfg, {"solver.stop": stop}), amplitude_g=0.7, record=False).result
        assert res["status"] == "collapsed" and res["t_collapse_s"] > t_cut, (stop, res)
        ends.append(res["t_collapse_s"])
    assert ends[0] == ends[1]


@pytest.mark.slow
def test_the_exact_integrator_keeps_every_outcome(tmp_path):
    """One record's ten levels with the exact integrator: stopped and not, against its own
    full runs."""
    one = {"excitation.file": ["../records/synthetic/rdk_01.AT2"], "solver.method": "exact"}
    sweep(_band(**one), tmp_path / "full", jobs=2)
    sweep(_band(**one, **{"solver.stop": "outcome"}), tmp_path / "stop", jobs=2)
    full = _rows(tmp_path / "full" / "suite_multidrum_ci" / "domain.csv")
    stop = _rows(tmp_path / "stop" / "suite_multidrum_ci" / "domain.csv")
    _check_domain(stop, full, at_least=2)


@pytest.mark.parametrize("method, stride", [("closed-form", 2), ("DOP853", 4), ("exact", 4)])
def test_the_monolith_stop_keeps_every_figure_on_a_whole_domain(method, stride):
    """solver.stop: figures, the monolith's stop at a peak of free motion below its collapse
    barrier, on the half-sine domain of the rigid monolith (every `stride`-th amplitude and
    frequency) with e = 0.9: each run stopped and run to its end has the same outcome,
    collapse time and peaks, to the bit (each impact takes energy, so the peak a run
    stops at is its last highest)."""
    cfg = with_values(load_config(CONFIGS / "housner_halfsine.yaml"),
                      {"solver.method": method, "interface.restitution": 0.9})  # fmt: skip
    runner = make_runner(cfg)
    stopped = 0
    for a in cfg.grid.amplitudes_g[::stride]:
        for f in cfg.grid.frequencies_hz[::stride]:
            motion = make_ground_motion(cfg.excitation, a, f)
            short = runner.run(motion, cfg.solver)
            full = runner.run(motion, cfg.solver, early_stop=False)
            assert short.status == full.status, (a, f)
            assert short.t_collapse == full.t_collapse or (
                math.isnan(short.t_collapse) and math.isnan(full.t_collapse)
            ), (a, f)
            assert np.max(short.max_ratio) == np.max(full.max_ratio), (a, f)
            assert short.max_top == full.max_top, (a, f)
            stopped += "stopped early" in short.message
    assert stopped >= 10
