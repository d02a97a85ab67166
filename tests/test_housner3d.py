"""`housner-3d`: the rigid cylinder rocking and rolling on its rim in three dimensions.

Checked against what does not follow its code:

- in a vertical plane its equations are Housner's (the closed form of the planar block,
  rbm_cli.structures.block's geometry), and a whole run is `housner`'s (an independent
  integrator of the planar equation) on a grid: outcome, peak and collapse time;
- its energy is conserved in free rolling, where the cylinder moves in three dimensions;
- a steady wobble derived by hand here (the centre of mass at rest, the axis precessing at
  a constant tilt: the balance of angular momentum about the centre gives the rate) stays
  on its solution;
- isotropy: the same motion turned to any azimuth gives the same response;
- the side it lifts to is away from the ground's acceleration, in any direction.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import solve_ivp

from rbm_cli.base.errors import RbmError
from rbm_cli.config import parse_config
from rbm_cli.config.types import G
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.structures.cylinder import (
    cylinder_energy,
    cylinder_geometry,
    rolling_rates,
    tilt,
)
from rbm_cli.study.simulate import simulate
from rbm_cli.study.sweep import config_hash

COLUMN = {"height": 4.0, "base_width": 1.0, "top_width": 0.8, "section": "circular",
          "density": 2700}  # fmt: skip
SOLVER = {"rtol": 1e-10, "atol": 1e-12}


def config(model: str = "housner-3d", angle: float = 0.0, kind: str = "harmonic", **exc):
    excitation = {"type": kind, "duration": 4.0, **exc}
    if angle:
        excitation["angle"] = angle
    return parse_config({
        "name": "cyl", "model": model, "column": dict(COLUMN),
        "interface": {"stiffness": "rigid", "restitution": 0.9},
        "excitation": excitation, "solver": dict(SOLVER),
    })  # fmt: skip


@pytest.fixture(scope="module")
def geo():
    return cylinder_geometry(config().column)


def test_in_a_vertical_plane_the_equations_are_housners(geo):
    """theta'' = -p^2 [sin(alpha - theta) + (a/g) cos(alpha - theta)] for a lean and rate
    in the x plane, to round-off; nothing leaves the plane."""
    alpha, p = geo.slenderness, geo.block.frequency_parameter
    for theta, rate, a in [(0.05, 0.3, 1.2), (0.2, -0.5, -3.0), (0.0, 0.4, 2.0), (0.26, 0.0, 0.0)]:
        y = np.zeros(7)
        y[0], y[3] = math.sin(theta), rate
        dy = rolling_rates(geo, y, np.array([1.0, 0.0]), np.array([-a, 0.0, -G]))
        housner = -p * p * (math.sin(alpha - theta) + a / G * math.cos(alpha - theta))
        assert dy[3] == pytest.approx(housner, rel=1e-13, abs=1e-13)
        assert dy[0] == pytest.approx(rate * math.cos(theta), rel=1e-15)
        assert dy[1] == 0.0 and dy[2] == 0.0 and dy[4] == 0.0 and dy[6] == 0.0


def test_energy_is_conserved_in_free_rolling(geo):
    """A lean, a tilt rate, a rolling rate and a spin: the motion is three-dimensional
    (the lean turns), its energy constant to 1e-11 of its kinetic energy at the start."""
    y0 = np.zeros(7)
    y0[0], y0[2:5] = math.sin(0.1), (0.3, 0.1, 0.5)
    c0, ge = np.array([1.0, 0.0]), np.array([0.0, 0.0, -G])
    sol = solve_ivp(lambda t, y: rolling_rates(geo, y, c0, ge), (0.0, 0.4), y0,
                    method="DOP853", rtol=1e-12, atol=1e-14, dense_output=True)  # fmt: skip
    ys = sol.sol(np.linspace(0.0, 0.4, 9))
    turned = math.atan2(ys[1, -1], ys[0, -1])
    assert abs(turned) > 0.05  # the lean has turned: the motion is not planar
    energies = [cylinder_energy(geo, ys[:, i], c0) for i in range(ys.shape[1])]
    kinetic0 = energies[0] - cylinder_energy(geo, np.r_[y0[:2], 0.0, 0.0, 0.0, 0.0, 0.0], c0)
    assert max(energies) - min(energies) < 1e-11 * kinetic0


@pytest.mark.parametrize("theta", [0.05, 0.15])
def test_a_steady_wobble_stays_on_its_solution(geo, theta):
    """The centre of mass at rest, the axis at a constant tilt theta precessing at Omega
    about the vertical: w = lambda r (v_G = w x r = 0) with lambda = Omega sin(theta) / R,
    and Omega e_z x (I_G w) = m r x g_e gives, with the cylinder's h, R, I_t, I_a,

        Omega^2 = m g R (R cos theta - h sin theta) / (sin theta (I_t R cos theta
                  - I_a h sin theta)).

    Over three turns the tilt stays theta to 1e-12, the lean turns at Omega and the
    centre stays put."""
    m, rad, h = geo.mass, geo.radius, geo.centre_height
    i_t, i_a = geo.transverse, geo.axial
    st, ct = math.sin(theta), math.cos(theta)
    omega = math.sqrt(m * G * rad * (rad * ct - h * st) / (st * (i_t * rad * ct - i_a * h * st)))
    n = np.array([st, 0.0, ct])
    u = np.array([ct, 0.0, -st])
    y0 = np.zeros(7)
    y0[0], y0[2:5] = st, omega * st / rad * (h * n - rad * u)
    c0, ge = np.array([1.0, 0.0]), np.array([0.0, 0.0, -G])
    period = 2.0 * math.pi / omega
    sol = solve_ivp(lambda t, y: rolling_rates(geo, y, c0, ge), (0.0, 3 * period), y0,
                    method="DOP853", rtol=1e-12, atol=1e-14, dense_output=True)  # fmt: skip
    ts = np.linspace(0.0, 3 * period, 25)
    ys = sol.sol(ts)
    for i, t in enumerate(ts):
        assert abs(tilt(ys[0:2, i]) - theta) < 1e-12
        turned = math.atan2(ys[1, i], ys[0, i]) - omega * t
        assert abs(math.remainder(turned, 2 * math.pi)) < 1e-10
        assert np.hypot(ys[5, i], ys[6, i]) < 1e-12


#: A grid across uplift, rocking with many impacts, and collapse.
GRID = [(0.3, 1.0), (0.4, 1.0), (0.3, 2.0), (0.6, 1.5), (0.8, 2.5), (1.0, 0.5), (0.5, 0.7)]


@pytest.fixture(scope="module")
def planar():
    return {cell: simulate(config("housner"), *cell) for cell in GRID}


@pytest.fixture(scope="module")
def along_x():
    return {cell: simulate(config(), *cell) for cell in GRID}


def test_along_x_it_is_housners_block(planar, along_x):
    """The same outcome, impacts and uplifts on every cell; peaks and collapse times to
    1e-8 relative (the planar runs agree with each other to that on these cells)."""
    collapsed = 0
    for cell in GRID:
        a, b = planar[cell], along_x[cell]
        assert (a.status, a.n_impacts, a.n_uplifts) == (b.status, b.n_impacts, b.n_uplifts), cell
        assert b.max_rotation_ratio == pytest.approx(a.max_rotation_ratio, rel=1e-8), cell
        if a.status == "collapsed":
            collapsed += 1
            assert b.t_collapse_s == pytest.approx(a.t_collapse_s, rel=1e-8), cell
    assert 0 < collapsed < len(GRID)


@pytest.mark.parametrize("angle", [37.0, 90.0, -123.0])
def test_a_turned_motion_gives_the_same_response(along_x, angle):
    """Isotropy: the motion turned to any azimuth, the same outcome, impacts, peak and
    collapse time to 1e-8 on every cell of the grid (the motion stays in its plane: no
    cell here leaves it through round-off)."""
    for cell in GRID:
        a, b = along_x[cell], simulate(config(angle=angle), *cell)
        assert (a.status, a.n_impacts, a.n_uplifts) == (b.status, b.n_impacts, b.n_uplifts), cell
        assert b.max_rotation_ratio == pytest.approx(a.max_rotation_ratio, rel=1e-8), cell
        if a.status == "collapsed":
            assert b.t_collapse_s == pytest.approx(a.t_collapse_s, rel=1e-8), cell


@pytest.mark.parametrize("angle", [0.0, 37.0, -123.0])
def test_it_lifts_and_falls_away_from_the_grounds_acceleration(angle):
    """A strong half-sine pulse (positive first) overturns the column toward the opposite
    of the motion's direction: the azimuth of collapse is angle + 180 degrees."""
    cfg = config(angle=angle, kind="half-sine")
    motion = make_ground_motion(cfg.excitation, 3.0, 1.0)
    from rbm_cli.models.registry import make_runner

    out = make_runner(cfg).run(motion, cfg.solver)
    assert out.status == "collapsed"
    expected = math.radians(angle + 180.0)
    assert abs(math.remainder(out.azimuth - expected, 2 * math.pi)) < 1e-9


def test_the_config_refuses_what_the_model_cannot_take():
    """A rectangular column for housner-3d, and a turned motion for a planar model, are
    refused in one line; an angle of 0 leaves a config's hash as it was."""
    raw = {"name": "c", "model": "housner-3d", "column": {"height": 4.0, "base_width": 1.0}}
    with pytest.raises(RbmError, match="needs column.section: circular") as err:
        parse_config(raw)
    assert "\n" not in str(err.value)
    planar = {"name": "c", "model": "housner", "column": dict(COLUMN),
              "excitation": {"type": "harmonic", "angle": 30.0}}  # fmt: skip
    with pytest.raises(RbmError, match="excitation.angle turns the motion") as err:
        parse_config(planar)
    assert "housner-3d" in str(err.value) and "\n" not in str(err.value)
    with pytest.raises(RbmError, match="excitation.angle"):
        parse_config({**planar, "model": "housner-3d",
                      "excitation": {"type": "harmonic", "angle": 400.0}})  # fmt: skip
    zero = parse_config({**planar, "excitation": {"type": "harmonic", "angle": 0.0}})
    none = parse_config({**planar, "excitation": {"type": "harmonic"}})
    assert config_hash(zero) == config_hash(none)
    turned = parse_config({**planar, "model": "housner-3d"})
    assert config_hash(turned) != config_hash(
        parse_config({**planar, "model": "housner-3d", "excitation": {"type": "harmonic"}})
    )


def test_a_wobble_counts_its_turns_and_a_planar_motion_none(geo):
    """Started on the steady wobble (above) in free motion for three of its periods, a run
    reports a peak tilt of theta, no impact, and 3 turns of its lean; a planar rocking run
    (impacts and all) sweeps no angle but round-off's (a lean 2e-6 sin(alpha) from the
    vertical points within 1e-16 / 2e-6 rad of the motion's plane)."""
    from rbm_cli.inputs.motion import GroundMotion
    from rbm_cli.models.housner3d.runner import cylinder_run

    theta = 0.1
    m, rad, h = geo.mass, geo.radius, geo.centre_height
    i_t, i_a = geo.transverse, geo.axial
    st, ct = math.sin(theta), math.cos(theta)
    omega = math.sqrt(m * G * rad * (rad * ct - h * st) / (st * (i_t * rad * ct - i_a * h * st)))
    n, u = np.array([st, 0.0, ct]), np.array([ct, 0.0, -st])
    y0 = np.zeros(7)
    y0[0], y0[2:5] = st, omega * st / rad * (h * n - rad * u)
    period = 2.0 * math.pi / omega
    free = GroundMotion("free", 0.0, 1.0, 0.0, 0.0, 3 * period)
    cfg = config()
    out = cylinder_run(geo, free, 0.9, solver=cfg.solver, state=y0)
    assert out.status == "survived" and out.n_impacts == 0
    assert out.max_ratio[0] == pytest.approx(theta / geo.slenderness, rel=1e-9)
    assert out.turns == pytest.approx(3.0, rel=1e-8)
    rocking = simulate(config(angle=37.0), 0.3, 2.0)
    assert rocking.n_impacts > 10 and rocking.wobble_turns < 1e-6  # round-off only
    assert math.isnan(rocking.collapse_azimuth_deg)


def test_a_domain_of_the_cylinder_has_its_azimuth_and_turns(tmp_path):
    """domain.csv of housner-3d carries collapse_azimuth_deg (the motion's azimuth plus 180
    degrees for a harmonic that starts positive, where it collapses before any impact) and
    wobble_turns; a planar model's domain has neither column."""
    import rbm

    cfg = config(angle=30.0)
    cfg = dataclasses.replace(cfg, grid=parse_config({
        "name": "g", "column": dict(COLUMN), "grid": {"amplitudes": [0.3, 1.2],
                                                      "frequencies": [0.5]}}).grid)  # fmt: skip
    df = rbm.sweep(cfg)
    assert list(df.columns[df.columns.get_loc("max_top_displacement_m") + 1:][:2]) == [
        "collapse_azimuth_deg", "wobble_turns"]  # fmt: skip
    fast = df[df.amplitude_g == 1.2].iloc[0]
    assert fast.status == "collapsed" and fast.n_impacts == 0
    assert fast.collapse_azimuth_deg == pytest.approx(-150.0, abs=1e-9)
    planar = rbm.sweep(dataclasses.replace(config("housner"), grid=cfg.grid))
    assert "collapse_azimuth_deg" not in planar.columns and "wobble_turns" not in planar.columns


RECORDS = Path(__file__).resolve().parents[1] / "configs" / "records" / "synthetic"


def pair_config(tmp_path, model: str = "housner-3d", **exc):
    return parse_config({
        "name": "pair", "model": model, "column": dict(COLUMN),
        "interface": {"restitution": 0.9},
        "excitation": {"type": "record", "units": "g", "free_time": 2.0, **exc},
        "solver": dict(SOLVER),
    }, base_dir=tmp_path)  # fmt: skip


def test_a_pair_with_a_zero_second_record_is_the_one_component_run(pair_dir):
    """x record plus a y record of zeros: the run of the x record alone, to the bit (on
    cells that rock with impacts and that collapse), and Housner's block along x: the same
    impacts, peaks within 1e-8."""
    for amplitude in (0.5, 0.8):
        one = simulate(pair_config(pair_dir, file="rdk_01.AT2"), amplitude, None)
        pair = simulate(pair_config(pair_dir, file="rdk_01.AT2", file_y="zero.csv"),
                        amplitude, None)  # fmt: skip
        planar = simulate(pair_config(pair_dir, "housner", file="rdk_01.AT2"), amplitude, None)
        assert (pair.status, pair.n_impacts) == (one.status, one.n_impacts)
        assert pair.max_rotation_ratio == one.max_rotation_ratio
        assert pair.t_collapse_s == one.t_collapse_s or math.isnan(one.t_collapse_s)
        assert (planar.status, planar.n_impacts) == (one.status, one.n_impacts)
        assert one.max_rotation_ratio == pytest.approx(planar.max_rotation_ratio, rel=1e-8)
        assert one.n_impacts > 20


@pytest.mark.slow
def test_swapping_the_components_with_the_angle_turned_gives_the_same_run(pair_dir):
    """(x, y) = (rdk_01, rdk_02) against (rdk_02, rdk_01) turned by 90 degrees (rdk_01
    then acts along -x: the mirror image): the same outcome, impacts, peak and collapse
    time to 1e-9, wobbling turns to 1e-6."""
    for amplitude in (0.3, 0.8):
        a = simulate(pair_config(pair_dir, file="rdk_01.AT2", file_y="rdk_02.AT2"),
                     amplitude, None)  # fmt: skip
        b = simulate(pair_config(pair_dir, file="rdk_02.AT2", file_y="rdk_01.AT2", angle=90.0),
                     amplitude, None)  # fmt: skip
        assert (a.status, a.n_impacts, a.n_uplifts) == (b.status, b.n_impacts, b.n_uplifts)
        assert b.max_rotation_ratio == pytest.approx(a.max_rotation_ratio, rel=1e-9)
        # the turns add the angle between the leans at step ends: a step in which the
        # lean's direction turns back counts its net turn, so two step sequences (the
        # turned run's round-off) differ where it does (6e-8 of 38 turns measured)
        assert b.wobble_turns == pytest.approx(a.wobble_turns, rel=1e-6)
        if a.status == "collapsed":
            assert b.t_collapse_s == pytest.approx(a.t_collapse_s, rel=1e-9)


def test_a_pair_is_scaled_by_its_larger_pga(pair_dir):
    """scale: pga takes the larger of the two components' PGAs to the amplitude; both are
    multiplied by the same factor."""
    from rbm_cli.inputs.records import read_record

    x = read_record(str(pair_dir / "rdk_01.AT2")).acceleration
    y = read_record(str(pair_dir / "rdk_02.AT2")).acceleration
    cfg = pair_config(pair_dir, file="rdk_01.AT2", file_y="rdk_02.AT2")
    motion = make_ground_motion(cfg.excitation, 0.4)
    factor = 0.4 * G / max(np.max(np.abs(x)), np.max(np.abs(y)))
    np.testing.assert_allclose(motion.values, x * factor, rtol=1e-15)
    np.testing.assert_allclose(motion.values_y, y * factor, rtol=1e-15)
    assert max(np.max(np.abs(motion.values)), np.max(np.abs(motion.values_y))) == pytest.approx(
        0.4 * G, rel=1e-15
    )


def test_a_second_component_is_refused_where_it_cannot_apply(pair_dir, tmp_path):
    """file_y for a planar model, sampled otherwise than file, or for a type that is not
    a record: one line each."""
    with pytest.raises(RbmError, match="excitation.file_y is a second horizontal") as err:
        pair_config(pair_dir, "housner", file="rdk_01.AT2", file_y="rdk_02.AT2")
    assert "\n" not in str(err.value)
    short = pair_dir / "short.csv"
    np.savetxt(short, np.c_[np.arange(10) * 0.01, np.ones(10) * 0.1], delimiter=",",
               header="time_s,acc_g", comments="")  # fmt: skip
    with pytest.raises(RbmError, match="must be sampled as excitation.file"):
        pair_config(pair_dir, file="rdk_01.AT2", file_y="short.csv")
    with pytest.raises(RbmError, match="file_y"):
        parse_config({"name": "c", "model": "housner-3d", "column": dict(COLUMN),
                      "excitation": {"type": "harmonic", "file_y": "x.csv"}})  # fmt: skip


def test_a_suite_of_pairs_is_a_linked_axis(pair_dir):
    """Two pairs as a linked grid axis over excitation.file and excitation.file_y: each row
    is the run of its own pair."""
    import rbm

    for name in ("rdk_03", "rdk_04"):
        (pair_dir / f"{name}.AT2").write_bytes((RECORDS / f"{name}.AT2").read_bytes())
    pairs = [("rdk_01.AT2", "rdk_02.AT2"), ("rdk_03.AT2", "rdk_04.AT2")]
    raw = {
        "name": "pairs", "model": "housner-3d", "column": dict(COLUMN),
        "interface": {"restitution": 0.9},
        "excitation": {"type": "record", "file": pairs[0][0], "file_y": pairs[0][1],
                       "free_time": 1.0},
        "solver": dict(SOLVER),
        "grid": {"amplitudes": [0.8], "linked": [{"excitation.file": [x for x, _ in pairs],
                                                  "excitation.file_y": [y for _, y in pairs]}]},
    }  # fmt: skip
    df = rbm.sweep(parse_config(raw, base_dir=pair_dir))
    assert list(zip(df["excitation.file"], df["excitation.file_y"], strict=True)) == pairs
    for (x, y), (_, row) in zip(pairs, df.iterrows(), strict=True):
        one = dict(raw, excitation=dict(raw["excitation"], file=x, file_y=y))
        del one["grid"]
        alone = simulate(parse_config(one, base_dir=pair_dir), 0.8, None)
        assert row.status == alone.status
        # a domain's numbers have 12 significant digits
        assert row.max_rotation_ratio == pytest.approx(alone.max_rotation_ratio, rel=1e-11)
        assert row.wobble_turns == pytest.approx(alone.wobble_turns, rel=1e-11)


def test_a_recorded_run_draws_the_tops_path_in_plan(geo):
    """A run of housner-3d keeps the top's path in plan: under a motion turned to 30 degrees
    it stays on that line through where the column stood, as far out as the top
    displacement; history.csv has it as top_x_m, top_y_m and history.png draws it."""
    import rbm
    from rbm_cli.report.run_figures import history_figure

    cfg = config(angle=30.0)
    run = rbm.run(cfg, amplitude_g=0.4, frequency_hz=1.0, output_dt=0.01)
    history, result = run.result.history, run.result
    plan = history.top_plan
    assert plan is not None and plan.shape == (history.t.size, 2)
    assert np.all(plan[0] == 0.0)
    across = -plan[:, 0] * math.sin(math.radians(30.0)) + plan[:, 1] * math.cos(math.radians(30))
    assert np.max(np.abs(across)) < 1e-9 * np.max(np.abs(plan))  # on the motion's line
    reach = np.max(np.hypot(plan[:, 0], plan[:, 1]))
    assert (
        0.5 * result.max_top_displacement_m < reach <= result.max_top_displacement_m * (1 + 1e-12)
    )
    table = run.history  # history.csv's table
    np.testing.assert_array_equal(table[["top_x_m", "top_y_m"]].to_numpy(), plan + 0.0)
    fig = history_figure(history, None)
    (line,) = [a for ax in fig.axes for a in ax.get_lines() if a.get_gid() == "top_plan"]
    np.testing.assert_array_equal(np.c_[line.get_xdata(), line.get_ydata()], plan)


def test_a_pair_runs_history_and_title_name_both_records(pair_dir):
    """A recorded run of a pair keeps a_y beside a_x (history.csv's ag_y_m_s2, the y record
    as scaled), and its title names both records and the pair's PGA (the larger)."""
    import rbm
    from rbm_cli.inputs.records import read_record
    from rbm_cli.report.run_figures import record_title
    from rbm_cli.report.run_folder import record_of_run

    cfg = pair_config(pair_dir, file="rdk_01.AT2", file_y="rdk_02.AT2")
    run = rbm.run(cfg, amplitude_g=0.8, output_dt=0.01)
    table = run.history
    motion = make_ground_motion(cfg.excitation, 0.8)
    t = table["t_s"].to_numpy()
    np.testing.assert_array_equal(table["ag_y_m_s2"].to_numpy(), motion.accel_y(t) + 0.0)
    x = read_record(str(pair_dir / "rdk_01.AT2")).acceleration
    y = read_record(str(pair_dir / "rdk_02.AT2")).acceleration
    factor = 0.8 * G / max(np.max(np.abs(x)), np.max(np.abs(y)))
    at = int(np.searchsorted(t, 5.0))  # inside the record: a sample time
    assert table["ag_y_m_s2"][at] == pytest.approx(y[int(round(t[at] / 0.01))] * factor)
    info = record_of_run(cfg, 0.8)
    assert info["record_y"] == "rdk_02" and info["pga_g"] == pytest.approx(0.8, rel=1e-12)
    title = record_title("pair", info, 0.8)
    assert "rdk_01 (x)" in title and "rdk_02 (y)" in title and "0.8 g" in title


def test_with_a_vertical_record_along_x_it_is_housners_block(pair_dir):
    """g + a_v(t) in the weight and in the uplift level: along x the same impacts as
    housner and peaks within 1e-8 (rdk_01 horizontal, rdk_03 vertical at 0.4 g)."""
    (pair_dir / "rdk_03.AT2").write_bytes((RECORDS / "rdk_03.AT2").read_bytes())
    exc = {"file": "rdk_01.AT2", "vertical": "rdk_03.AT2", "free_time": 1.0}
    a = simulate(pair_config(pair_dir, "housner", **exc), 0.4, None)
    b = simulate(pair_config(pair_dir, **exc), 0.4, None)
    assert (a.status, a.n_impacts, a.n_uplifts) == (b.status, b.n_impacts, b.n_uplifts)
    assert a.n_impacts > 50
    assert b.max_rotation_ratio == pytest.approx(a.max_rotation_ratio, rel=1e-8)


def test_a_suites_fragility_takes_each_records_worst_angle():
    """Two records x three intensities x two angles, outcomes set by hand: each record and
    intensity counts as collapsed when either angle collapsed, failed when one failed and
    none collapsed; the per-intensity counts are those, and the fit is of them."""
    from rbm_cli.study.fragility import fragility
    from rbm_cli.study.outcomes import worst_angle

    rows = []
    outcome = {  # (record, amplitude) -> statuses at 0 and 90 degrees
        ("a", 0.2): ("survived", "survived"), ("a", 0.4): ("survived", "collapsed"),
        ("a", 0.6): ("collapsed", "collapsed"), ("b", 0.2): ("survived", "failed"),
        ("b", 0.4): ("survived", "survived"), ("b", 0.6): ("collapsed", "survived"),
    }  # fmt: skip
    for (record, amplitude), statuses in outcome.items():
        for angle, status in zip((0.0, 90.0), statuses, strict=True):
            rows.append({"excitation.angle": angle, "record": record, "amplitude_g": amplitude,
                         "status": status, "collapsed": int(status == "collapsed"),
                         "max_rotation_ratio": 1.0 if status == "collapsed" else 0.1})  # fmt: skip
    df = pd.DataFrame(rows)
    worst = worst_angle(df)
    assert list(zip(worst.record, worst.amplitude_g, worst.status, strict=True)) == [
        ("a", 0.2, "survived"), ("a", 0.4, "collapsed"), ("a", 0.6, "collapsed"),
        ("b", 0.2, "failed"), ("b", 0.4, "survived"), ("b", 0.6, "collapsed"),
    ]  # fmt: skip
    table = fragility(df, n_resamples=0).table
    assert table["n_collapsed"].tolist() == [0, 1, 2]
    assert table["n_records"].tolist() == [1, 2, 2]  # the failed run is left out
    assert worst_angle(df.drop(columns="excitation.angle")).equals(
        df.drop(columns="excitation.angle"))  # fmt: skip
