"""`rbm-3d`: the Rigid Beam Model of circular drums in two horizontal directions.

Checked against what does not follow its code:

- along x it is the planar RBM (the compiled step kernel, a separate integrator of the
  planar equations): the same outcome, impacts and uplifts on every cell of a grid where
  the planar runs at two tolerances agree (robust), peaks and collapse times to 1e-8;
  every formulation, a law with a cap (xi < 1), an elastic or rigid joint, damping;
- isotropy: the motion turned to any azimuth gives the same resultant response;
- a steady wobble of the rigid monolith derived by hand (a circular orbit of the rotation
  vector in the central law f(|phi|)) stays on its orbit and counts its turns;
- the energy of free motion in three dimensions (kinetic + the laws' potential of |phi|,
  written here) is conserved with e = 1 across kinks and closures;
- a pair of records with a zero second component is the one-component run, and swapping
  the components with the angle turned by 90 degrees gives the same run.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from rbm_cli.base.errors import ConfigError
from rbm_cli.config import parse_config
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.structures.assembly import model_from_config
from rbm_cli.study.simulate import simulate

COLUMN = {"height": 5.0, "base_width": 0.96, "top_width": 0.66, "section": "circular",
          "density": 2700}  # fmt: skip
ELASTIC = {"normal": 5e9}


def config(model="rbm-3d", drums=1, stiffness="rigid", rtol=1e-12, angle=0.0, kind="harmonic",
           duration=3.0, interface=None, **exc):  # fmt: skip
    excitation = {"type": kind, "duration": duration, **exc}
    if angle:
        excitation["angle"] = angle
    return parse_config({
        "name": "beam3d", "model": model, "column": {**COLUMN, "drums": drums},
        "interface": {"stiffness": stiffness, "restitution": 0.9, **(interface or {})},
        "excitation": excitation, "solver": {"method": "DOP853", "rtol": rtol, "atol": 1e-12},
    })  # fmt: skip


#: (drums, stiffness, interface): a rigid monolith (with a cap: xi 0.7), an elastic one,
#: three elastic drums in every formulation and with damping
COLUMNS = [
    (1, "rigid", {}),
    (1, "rigid", {"xi": 0.7}),
    (1, ELASTIC, {}),
    (3, ELASTIC, {}),
    (3, ELASTIC, {"formulation": "absolute"}),
    (3, ELASTIC, {"formulation": "geometric"}),
    (3, ELASTIC, {"damping": 0.05, "restitution": 1.0}),
]
#: uplift and rocking with impacts, rocking at a higher frequency, collapse
CELLS = [(0.4, 1.0), (0.6, 1.5), (1.0, 0.5)]


def _robust(a, b) -> bool:
    """Two runs of the same cell at two tolerances agree: the cell is not sensitive."""
    return (a.status, a.n_impacts) == (b.status, b.n_impacts) and (
        abs(a.max_rotation_ratio / b.max_rotation_ratio - 1.0) < 1e-8
    )


@pytest.fixture(scope="module")
def along_x():
    """{(column, cell): (planar at rtol 1e-10, planar at 1e-12, rbm-3d along x)}."""
    out = {}
    for c, (drums, stiffness, interface) in enumerate(COLUMNS):
        for cell in CELLS:
            runs = [simulate(config("rbm", drums, stiffness, rtol, interface=interface), *cell)
                    for rtol in (1e-10, 1e-12)]  # fmt: skip
            runs.append(simulate(config("rbm-3d", drums, stiffness, interface=interface), *cell))
            out[c, cell] = runs
    return out


def test_along_x_it_is_the_planar_rbm(along_x):
    """On every robust cell: the same outcome, impacts and uplifts as the planar kernel,
    peak ratios and collapse times within 1e-8, the friction demand's peak within 1e-6 (21 cells;
    at least 18 robust, 9 collapse)."""
    robust = collapsed = friction = 0
    for key, (coarse, planar, beam) in along_x.items():
        if not _robust(coarse, planar):
            continue
        robust += 1
        assert (beam.status, beam.n_impacts, beam.n_uplifts) == (
            planar.status, planar.n_impacts, planar.n_uplifts), key  # fmt: skip
        assert beam.max_rotation_ratio == pytest.approx(planar.max_rotation_ratio, rel=1e-8), key
        if planar.status == "survived":  # at collapse: the state at the collapse time
            assert beam.max_top_displacement_m == pytest.approx(
                planar.max_top_displacement_m, rel=1e-8), key  # fmt: skip
        # the friction demand's peak is sampled at step ends (as in the plane): compared
        # where the planar runs' own samples agree
        fr, fr_coarse = planar.max_friction_demand_peak, coarse.max_friction_demand_peak
        if abs(fr_coarse / fr - 1.0) < 1e-8:
            friction += 1
            assert beam.max_friction_demand_peak == pytest.approx(fr, rel=1e-6), key
        if planar.status == "collapsed":
            collapsed += 1
            assert beam.t_collapse_s == pytest.approx(planar.t_collapse_s, rel=1e-8), key
            assert beam.collapse_interface == planar.collapse_interface, key
        assert beam.wobble_turns == 0.0 or planar.status == "collapsed", key
    assert robust >= 18 and collapsed >= 9 and friction >= 8


#: A turned run leaves its plane where its open joints' direction sweeps this many turns
#: or more (3.6 degrees; a run that stays in its plane sweeps round-off, 1e-13 .. 2e-4).
LEAVES_PLANE = 0.01


def test_a_turned_motion_gives_the_same_response(along_x):
    """Isotropy on the rigid and elastic monoliths and the three elastic drums, turned to
    37, 90 and -123 degrees: where the run stays in its plane, the same outcome and
    impacts, peaks and collapse times within 1e-8, the collapse azimuth turned by the
    angle. Planar rocking of the rigid monolith is unstable out of its plane: a closure's
    pinned direction carries the round-off of the state there (1e-17 rad over a pinned
    distance of 1e-6 theta_u) into the next excursion, each excursion over the pinned
    distance amplifies it, and after two to four impacts the column rolls (measured: 5 of
    the 27 turned runs, all of the rigid monolith; every elastic joint stays in its plane)."""
    stays = left = 0
    for c in (0, 2, 3):
        drums, stiffness, interface = COLUMNS[c]
        for cell in CELLS:
            a = along_x[c, cell][2]
            for angle in (37.0, 90.0, -123.0):
                b = simulate(config(drums=drums, stiffness=stiffness, angle=angle,
                                    interface=interface), *cell)  # fmt: skip
                if b.wobble_turns >= LEAVES_PLANE:
                    left += 1
                    assert drums == 1 and stiffness == "rigid", (c, cell, angle)
                    continue
                stays += 1
                assert (a.status, a.n_impacts, a.n_uplifts) == (
                    b.status, b.n_impacts, b.n_uplifts), (c, cell, angle)  # fmt: skip
                assert b.max_rotation_ratio == pytest.approx(a.max_rotation_ratio, rel=1e-8)
                if a.status == "collapsed":
                    assert b.t_collapse_s == pytest.approx(a.t_collapse_s, rel=1e-8)
                    turned = math.remainder(b.collapse_azimuth_deg - a.collapse_azimuth_deg, 360)
                    assert turned == pytest.approx(math.remainder(angle, 360.0), abs=1e-6)
    assert stays >= 20 and stays + left == 27


def test_a_steady_wobble_of_the_rigid_monolith_stays_on_its_orbit():
    """With xi = 1 the rigid joint's moment is central, f(r) = M_u (1 - r / theta_u) toward
    phi = 0, so phi can turn on a circle of radius r0 at Omega^2 = f(r0) / (J r0), J the
    monolith's rotary inertia about its base (the 1 x 1 mass matrix). Started on it, in
    free motion over three turns: the peak ratio stays r0 / theta_u (1e-9), the turns are
    3 (1e-8), the rotation ends where it started (1e-7 theta_u), and no impact."""
    from rbm_cli.models.rbm3d.runner import integrate3d

    cfg = config()
    model = model_from_config(cfg)
    mu, tu = float(model.column.moment_capacity[0]), float(model.column.rotation_capacity[0])
    j = float(model.mass[0, 0])
    r0 = 0.3 * tu
    omega = math.sqrt(mu * (1.0 - r0 / tu) / (j * r0))
    period = 2.0 * math.pi / omega
    motion = make_ground_motion(config(duration=3 * period).excitation, 0.0, 1.0)
    end = []
    out = integrate3d(model, motion, np.zeros(1), np.zeros(1), cfg.solver,
                      state=np.array([r0, 0.0, 0.0, omega * r0]), end=end)  # fmt: skip
    assert out.status == "survived" and out.n_impacts == 0
    assert out.max_ratio[0] == pytest.approx(r0 / tu, rel=1e-9)
    assert out.turns == pytest.approx(3.0, rel=1e-8)
    assert abs(end[0][0] - r0) < 1e-7 * tu and abs(end[0][1]) < 1e-7 * tu


def _energy(model, y):
    """Kinetic energy in both directions plus each joint law's potential of |phi| [J]."""
    n = model.n
    tx, ty, vx, vy = y[:n], y[n : 2 * n], y[2 * n : 3 * n], y[3 * n :]
    kinetic = 0.5 * (vx @ model.mass @ vx + vy @ model.mass @ vy)
    r = np.hypot(model.arg_map @ tx, model.arg_map @ ty)
    return kinetic + sum(float(law.potential(r[i])) for i, law in enumerate(model.laws))


def test_free_motion_in_three_dimensions_conserves_energy():
    """Three elastic drums, e = 1, started rocking in x with rotations and rates across it
    of 1e-3 of those along it: the joints open and close (kinks of the law, silent
    closures), the motion turns into a wobble, and its energy stays constant to 1e-9
    over 4 s."""
    from rbm_cli.models.rbm3d.runner import integrate3d

    cfg = config(drums=3, stiffness=ELASTIC, interface={"restitution": 1.0}, duration=4.0)
    model = model_from_config(cfg)
    tu = float(model.column.rotation_capacity.min())
    across = 1e-3
    y0 = tu * np.array([0.3, 0.0, -0.1, 0.0, 0.15 * across, 0.05 * across,
                        0.0, 0.25, 0.0, 0.15 * across, 0.0, -0.2 * across])  # fmt: skip
    motion = make_ground_motion(cfg.excitation, 0.0, 1.0)
    end = []
    out = integrate3d(model, motion, np.zeros(3), np.zeros(3), cfg.solver, state=y0, end=end)
    assert out.status == "survived" and out.n_uplifts > 5 and out.n_impacts > 5
    assert out.turns > 1.0
    assert _energy(model, end[0]) == pytest.approx(_energy(model, y0), rel=1e-9)


def pair_config(folder, model="rbm-3d", **exc):
    return parse_config({
        "name": "pair", "model": model, "column": dict(COLUMN),
        "interface": {"restitution": 0.9},
        "excitation": {"type": "record", "units": "g", "free_time": 2.0, **exc},
        "solver": {"method": "DOP853", "rtol": 1e-10, "atol": 1e-12},
    }, base_dir=folder)  # fmt: skip


def test_records_along_x_a_zero_second_component_and_swapped_components(pair_dir):
    """The rigid monolith under rdk_01: with a y record of zeros, the x record's run to
    the bit; the planar RBM's impacts and peak (1e-8). Under (rdk_01, rdk_02) against
    (rdk_02, rdk_01) turned by 90 degrees: the same outcome, impacts and peak (1e-9)."""
    one = simulate(pair_config(pair_dir, file="rdk_01.AT2"), 0.5, None)
    zero = simulate(pair_config(pair_dir, file="rdk_01.AT2", file_y="zero.csv"), 0.5, None)
    planar = simulate(pair_config(pair_dir, "rbm", file="rdk_01.AT2"), 0.5, None)
    assert (zero.status, zero.n_impacts, zero.max_rotation_ratio) == (
        one.status, one.n_impacts, one.max_rotation_ratio)  # fmt: skip
    assert (planar.status, planar.n_impacts) == (one.status, one.n_impacts)
    assert one.max_rotation_ratio == pytest.approx(planar.max_rotation_ratio, rel=1e-8)
    assert one.n_impacts > 20
    a = simulate(pair_config(pair_dir, file="rdk_01.AT2", file_y="rdk_02.AT2"), 0.3, None)
    b = simulate(pair_config(pair_dir, file="rdk_02.AT2", file_y="rdk_01.AT2", angle=90.0),
                 0.3, None)  # fmt: skip
    assert (a.status, a.n_impacts, a.n_uplifts) == (b.status, b.n_impacts, b.n_uplifts)
    assert b.max_rotation_ratio == pytest.approx(a.max_rotation_ratio, rel=1e-9)


def test_the_config_refuses_what_the_model_cannot_take():
    """A rectangular section (its capacity is not the same in every direction) and a
    rigid joint between drums are refused in one line."""
    with pytest.raises(ConfigError, match="column.section: circular"):
        parse_config({"name": "x", "model": "rbm-3d",
                      "column": {**COLUMN, "section": "rectangular"}})  # fmt: skip
    with pytest.raises(ConfigError, match="rigid needs a monolithic column"):
        parse_config({"name": "x", "model": "rbm-3d", "column": {**COLUMN, "drums": 3},
                      "interface": {"stiffness": "rigid"}})  # fmt: skip


def test_the_uncompiled_source_gives_the_same_bits():
    """`solver.implementation: python` runs the compiled run's own source: the same
    outcome, counts, peaks and collapse time to the bit (a rigid monolith rocking with
    impacts and at rest; two elastic drums turned to 30 degrees)."""
    import dataclasses

    from rbm_cli.models.registry import make_runner

    for drums, stiffness, cell in ((1, "rigid", (0.4, 1.0)), (2, ELASTIC, (0.6, 1.5))):
        cfg = config(drums=drums, stiffness=stiffness, rtol=1e-8, angle=30.0, duration=2.0)
        motion = make_ground_motion(cfg.excitation, *cell)
        runner = make_runner(cfg)
        a = runner.run(motion, cfg.solver)
        b = runner.run(motion, dataclasses.replace(cfg.solver, implementation="python"))
        assert a.n_impacts > 0
        assert (a.status, a.n_impacts, a.n_uplifts, a.n_steps) == (
            b.status, b.n_impacts, b.n_uplifts, b.n_steps)  # fmt: skip
        assert np.array_equal(a.max_ratio, b.max_ratio) and a.max_top == b.max_top
        assert a.t_collapse == b.t_collapse or (np.isnan(a.t_collapse) and np.isnan(b.t_collapse))
        assert a.turns == b.turns


def test_a_recorded_run_keeps_both_elevations():
    """A recorded run keeps the rotations seen across the motion's plane: zero to the bit
    for a motion along x, round-off along 30 degrees (three elastic drums), not zero under
    a pair; history.csv has them, and shapes.png draws two elevations."""
    from rbm_cli.models.registry import make_runner
    from rbm_cli.report.run_figures import shapes_figure
    from rbm_cli.report.run_folder import history_columns
    from rbm_cli.structures.column import build_column

    for angle in (0.0, 30.0):
        cfg = config(drums=3, stiffness=ELASTIC, angle=angle, rtol=1e-8)
        planar = make_runner(cfg).run(make_ground_motion(cfg.excitation, 0.6, 1.5),
                                      cfg.solver, record=True).history  # fmt: skip
        peak = np.abs(planar.rotations).max()
        assert planar.rotations_across.shape == planar.rotations.shape and peak > 0.01
        across = np.abs(planar.rotations_across).max()
        assert across == 0.0 if angle == 0.0 else across < 1e-6 * peak  # round-off at 30
    folder = Path(__file__).resolve().parents[1] / "configs" / "records" / "synthetic"
    pair = parse_config({
        "name": "pair", "model": "rbm-3d", "column": {**COLUMN, "drums": 3},
        "interface": {"stiffness": ELASTIC, "restitution": 0.9},
        "excitation": {"type": "record", "units": "g", "free_time": 1.0,
                       "file": str(folder / "rdk_01.AT2"), "file_y": str(folder / "rdk_02.AT2")},
    })  # fmt: skip
    out = make_runner(pair).run(make_ground_motion(pair.excitation, 0.3), pair.solver,
                                record=True)  # fmt: skip
    history = out.history
    assert np.abs(history.rotations_across).max() > 1e-4
    columns = history_columns(history)
    assert np.array_equal(columns["theta2_across_rad"], history.rotations_across[:, 1])
    widths = build_column(pair.column, pair.interface).widths
    fig = shapes_figure(history, widths, None, out.t_collapse)
    titles = [ax.get_title() for ax in fig.axes]
    assert len(titles) == 2 and "across the motion's plane" in titles[1]


def test_a_pairs_intensity_measures_are_its_larger_components(pair_dir):
    """A pair is scaled by one factor (its larger PGA to the amplitude) and each measure of
    its row is the larger of its two components' measured on the records scaled so, here
    by inputs.intensity on the arrays: PGA is then the amplitude."""
    from rbm_cli.config.types import G
    from rbm_cli.inputs.intensity import record_measures
    from rbm_cli.inputs.records import read_record
    from rbm_cli.structures.similarity import rocking_scales
    from rbm_cli.study.intensities import column_period, measure_values

    cfg = pair_config(pair_dir, file="rdk_01.AT2", file_y="rdk_02.AT2", scale="pga",
                      im_periods=[0.5])  # fmt: skip
    t1 = column_period(cfg)
    row = measure_values(cfg, 0.4, rocking_scales(cfg), t1)
    x, y = (read_record(str(pair_dir / f"{r}.AT2")) for r in ("rdk_01", "rdk_02"))
    factor = 0.4 * G / max(np.abs(x.acceleration).max(), np.abs(y.acceleration).max())
    mx, my = (record_measures(r.t, factor * r.acceleration, (0.5,)) for r in (x, y))
    assert row["pga_g"] == pytest.approx(0.4, rel=1e-12)
    assert row["pgv_m_s"] == pytest.approx(max(mx.pgv, my.pgv), rel=1e-12)
    assert row["arias_m_s"] == pytest.approx(max(mx.arias, my.arias), rel=1e-12)
    assert row["sa_0p5s_g"] == pytest.approx(max(mx.sa[0.5], my.sa[0.5]) / G, rel=1e-12)
    assert mx.pgv != my.pgv  # the two components differ: the larger one is taken
