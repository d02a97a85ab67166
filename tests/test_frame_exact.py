"""`solver.method: exact` and `exact-first` on the Rigid Beam Model's frame of drums: n drums
and m = n + 1 joints, the beam's joint (argument -theta_n, a cap, no descending branch) on the
top drum (rbm_cli.structures.frame; rbm_cli.models.rbm.exact).

Expected values from a second path to the same answer:

- the step kernel (DOP853 at rtol 1e-11 and 1e-12, atol 1e-15 and 1e-16) on the same cells,
  tests/test_exact_records.py's rule: where the two tolerances agree (same outcome and
  events, peak rotation ratio, top displacement and collapse time within 1e-9), the same
  outcome, collapsed joint and events, and peak rotation ratio, top displacement and
  collapse time within 1e-8 of rtol 1e-12; the held friction demand of every joint, the
  beam's included, within 1e-6 (the step kernel's samples of it lie on its steps' quintic
  interpolants: rtol 1e-11 and 1e-12 differ by up to 2e-7 there);
- a beam of no mass is the free column (frame_column returns it), to the bit;
- free motion with e = 1 (`relative` and `geometric`: their equations derive from an
  energy) keeps the energy of the frame's equations (structures.equations.Model.energy,
  written in Python from the laws, the beam joint's included) on the exact integrator's
  samples, within what its event convention moves it: an event is located EVENT_EPS
  theta_u past its bound and projected back, which changes the energy by at most
  M_u EVENT_EPS theta_u per event;
- `exact-first` is the step kernel's run, bit for bit, where a joint opens, and the exact
  integrator's (the step kernel's outcome and peaks within 1e-8) where none does.
"""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

from rbm_cli.base.events import EVENT_EPS
from rbm_cli.cli.main import cli
from rbm_cli.config.load import parse_config
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.models.registry import make_runner
from rbm_cli.study.simulate import simulate

from .converged import assert_agrees, converged
from .paths import CONFIGS

pytestmark = pytest.mark.timeout(900)

H, B, TOP, RHO = 4.0, 0.8, 0.6, 2700.0
M = RHO * B * B * H  # a prismatic column of the base's section [kg]: the beam's scale
RECORD = CONFIGS / "records" / "synthetic" / "rdk_01.AT2"
HARMONIC = {"type": "harmonic", "duration": 4.0}
HALF_SINE = {"type": "half-sine", "duration": 4.0}
#: Harmonic and half-sine cells (amplitude [g], frequency [Hz]): elastic, rocking, collapsing.
CELLS = [(a, f) for f in (0.5, 1.0, 2.0, 3.0) for a in (0.1, 0.2, 0.3, 0.5, 0.8)]


def _frame(drums, gamma, excitation, method, interface=None, rtol=1e-12):
    """An RBM frame of two tapered columns of drums under a beam of gamma times their mass
    (DOP853 at rtol, atol rtol 1e-4; None: the default tolerances)."""
    solver = {"method": method}
    if method == "DOP853" and rtol is not None:
        solver.update(rtol=rtol, atol=rtol * 1e-4)
    data = {
        "name": "frame",
        "model": "rbm",
        "column": {"height": H, "base_width": B, "top_width": TOP, "drums": drums},
        "interface": {"stiffness": {"normal": 5e9}, **(interface or {})},
        "excitation": excitation,
        "frame": {"columns": 2, "beam_mass": 2 * M * gamma},
        "solver": solver,
    }
    return parse_config(data)


def _assert_same(step, exact, cell):
    assert_agrees(step, exact, cell)
    assert exact.collapse_interface == step.collapse_interface, cell
    held, ref = np.array(exact.friction_demand), np.array(step.friction_demand)
    assert held.size == ref.size == len(exact.friction_demand_peak)
    assert np.all(np.abs(held - ref) <= 1e-6 * ref), (cell, held, ref)


def _compare(drums, gamma, excitation, cells, interface=None):
    """(converged cells compared, their results with the exact method) of a frame."""
    runs = []
    for method, rtol in (("DOP853", 1e-11), ("DOP853", 1e-12), ("exact", 1e-12)):
        cfg = _frame(drums, gamma, excitation, method, interface, rtol)
        runner = make_runner(cfg)
        runs.append([simulate(cfg, a, f, runner=runner) for a, f in cells])
    compared = []
    for cell, k11, k12, exact in zip(cells, *runs, strict=True):
        assert len(exact.friction_demand) == drums + 1  # the beam's joint last
        if converged(k11, k12):
            _assert_same(k12, exact, cell)
            compared.append(exact)
    return compared


@pytest.mark.parametrize(
    ("drums", "gamma", "excitation", "interface"),
    [
        (3, 1.0, HARMONIC, {"restitution": 1.0}),
        (4, 1.0, HARMONIC, {"restitution": 0.9}),
        (3, 0.5, HARMONIC, {"restitution": 0.9, "formulation": "geometric"}),
        (3, 1.0, HARMONIC, {"restitution": 0.9, "xi": 0.8}),
        (4, 1.0, HALF_SINE, {"restitution": 1.0}),
        (3, 2.0, HALF_SINE, {"restitution": 0.8}),
    ],
    ids=["3-drums-e1", "4-drums-e0.9", "geometric", "xi-0.8", "half-sine-4", "half-sine-3"],
)
def test_a_frame_of_drums_agrees_with_the_step_kernel(drums, gamma, excitation, interface):
    """On the cells where the step kernel has converged (at least a third of them): the
    same outcome, joint and events, the same peaks, collapse times and held friction
    demand; the cells compared hold collapses, rocking that survives and elastic motion."""
    compared = _compare(drums, gamma, excitation, CELLS, interface)
    assert len(compared) >= len(CELLS) // 3
    assert {r.status for r in compared} == {"collapsed", "survived"}
    assert any(r.status == "survived" and r.n_uplifts > 10 for r in compared)
    assert any(r.n_uplifts == 0 for r in compared)


def test_a_frame_of_drums_under_a_record_agrees_with_the_step_kernel():
    """A synthetic record (rdk_01, 0.01 s samples) at four PGAs, 3 drums, e 0.9."""
    excitation = {"type": "record", "file": str(RECORD), "units": "g", "free_time": 2.0}
    cells = [(a, None) for a in (0.03, 0.06, 0.1, 0.2)]
    compared = _compare(3, 0.5, excitation, cells, {"restitution": 0.9})
    assert len(compared) >= 2 and any(r.n_uplifts > 0 for r in compared)


def _bits(result) -> dict:
    out = result.summary()
    out.pop("wall_time_s")
    return {k: repr(v) for k, v in out.items()}


def test_a_beam_of_no_mass_is_the_free_column_to_the_bit():
    free = parse_config({"name": "f", "column": {"height": H, "base_width": B, "top_width": TOP,
                                                 "drums": 3},
                         "interface": {"stiffness": {"normal": 5e9}, "restitution": 0.9},
                         "excitation": HARMONIC, "solver": {"method": "exact"}})  # fmt: skip
    frame = parse_config({**free.written, "frame": {"columns": 2, "beam_mass": 0.0}})
    for amplitude, frequency in [(0.1, 1.0), (0.3, 1.0), (0.8, 2.0)]:
        a, b = simulate(frame, amplitude, frequency), simulate(free, amplitude, frequency)
        assert a.method == "exact" and _bits(a) == _bits(b)


@pytest.mark.parametrize("formulation", ["relative", "geometric"])
def test_free_motion_of_a_frame_keeps_its_energy(formulation):
    """e = 1, the three drums thrown at 0.08 rad/s for 3 s: the base and the beam joint rock
    (past their elastic branches, some 400 uplifts); the energy of every sample equals the
    first within the events' bound (module docstring)."""
    cfg = _frame(3, 1.0, {"type": "free", "duration": 3.0,
                          "initial": {"velocities": [0.08, 0.08, 0.08]}}, "exact",
                 {"restitution": 1.0, "formulation": formulation})  # fmt: skip
    runner = make_runner(cfg)
    model = runner.model
    motion = make_ground_motion(cfg.excitation, 0.0, None)
    out = runner.run(motion, cfg.solver, record=True, output_dt=0.001, early_stop=False)
    theta = np.array([s[1] for s in out.samples])
    energy = model.energy(theta, np.array([s[2] for s in out.samples]))
    beam = model.laws[-1]
    assert np.abs(theta @ model.arg_map[-1]).max() > 5.0 * beam.edges[0]  # the beam joint opens
    assert out.status == "survived" and out.n_uplifts > 100
    per_event = EVENT_EPS * float(np.max(model.column.moment_capacity * model.argument_scale))
    bound = (out.n_uplifts + out.n_impacts) * per_event + 1e-12 * energy[0]
    assert np.abs(energy - energy[0]).max() <= bound


def test_exact_first_on_a_frame_is_exact_or_the_step_kernel():
    """A cell where no joint opens (0.05 g) is the exact integrator's; one where the frame
    rocks (0.3 g) is the step kernel's run, bit for bit."""
    first, alone, tight = (_frame(3, 1.0, HARMONIC, m, {"restitution": 0.9}, rtol)
                           for m, rtol in (("exact-first", None), ("DOP853", None),
                                           ("DOP853", 1e-12)))  # fmt: skip
    still = [simulate(c, 0.05, 1.0) for c in (first, alone, tight)]
    assert still[0].method == "exact"
    assert {r.status for r in still} == {"survived"}
    assert still[0].n_uplifts == still[1].n_uplifts == still[2].n_uplifts == 0
    for name in ("max_rotation_ratio", "max_top_displacement_m"):
        assert getattr(still[0], name) == pytest.approx(getattr(still[2], name), rel=1e-8)
    rocking = [simulate(c, 0.3, 1.0) for c in (first, alone)]
    assert rocking[0].method == "DOP853" and rocking[1].n_uplifts > 0
    assert rocking[0].row() == rocking[1].row()


def test_rbm_run_takes_a_frame_of_drums_with_the_exact_method(tmp_path):
    import yaml

    cfg = _frame(4, 1.0, HARMONIC, "exact").written
    path = tmp_path / "c.yaml"
    path.write_text(yaml.safe_dump(cfg))
    res = CliRunner().invoke(cli, ["run", str(path), "-a", "0.3", "-f", "1.0", "-o",
                                   str(tmp_path / "out")])  # fmt: skip
    assert res.exit_code == 0, res.output
    assert (tmp_path / "out" / "frame" / "run_A0.3_f1" / "summary.json").is_file()
