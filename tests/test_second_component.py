"""An analytic second horizontal component (`excitation.y`) of a harmonic or a pulse, for
the models in three dimensions.

Checked against what does not follow its code:

- the rotational symmetry of a cylinder and of a column of circular drums: a circular
  motion gives one peak whatever its angle, and an elliptic motion turned by 90 degrees
  (written with its two amplitudes swapped) gives the run of the unturned one;
- a linear motion written as two components in phase is the motion of one component of
  amplitude A sqrt(1 + r^2) turned by atan(r): the same run;
- the same motion given as a pair of records sampled from the formula (an independent
  path through the models: the record pair's straight pieces) gives the same run to the
  sampling's error;
- a history's a_y is the formula written here;
- r = 0 is the run of one component, to the bit.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from rbm_cli.base.errors import ConfigError
from rbm_cli.config import parse_config
from rbm_cli.config.types import G
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.inputs.pulses import mp_peak, mp_shape
from rbm_cli.study.simulate import simulate

COLUMN = {"height": 4.0, "base_width": 1.0, "top_width": 0.8, "section": "circular",
          "density": 2700}  # fmt: skip
SOLVER = {"method": "DOP853", "rtol": 1e-10, "atol": 1e-12}
ELASTIC = {"stiffness": {"normal": 5e9}, "restitution": 0.9}


def config(model="housner-3d", kind="harmonic", y=None, drums=1, interface=None, **exc):
    excitation = {"type": kind, "duration": 3.0, **exc}
    if y is not None:
        excitation["y"] = y
    return parse_config({
        "name": "pair", "model": model, "column": {**COLUMN, "drums": drums},
        "interface": interface or {"restitution": 0.9}, "excitation": excitation,
        "solver": dict(SOLVER),
    })  # fmt: skip


def same_run(a, b, rel, events=True):
    """Two runs of one cell: the same outcome and impacts (if events), peaks (and collapse
    times) within rel."""
    assert a.status == b.status
    if events:
        assert (a.n_impacts, a.n_uplifts) == (b.n_impacts, b.n_uplifts)
    assert b.max_rotation_ratio == pytest.approx(a.max_rotation_ratio, rel=rel)
    if a.status == "collapsed":
        assert b.t_collapse_s == pytest.approx(a.t_collapse_s, rel=rel)


def differs(a, b) -> bool:
    """Two runs differ by more than 1e-3: outcome, peak, or collapse time."""
    if a.status != b.status or not math.isclose(a.max_rotation_ratio, b.max_rotation_ratio,
                                                rel_tol=1e-3):  # fmt: skip
        return True
    return a.status == "collapsed" and not math.isclose(a.t_collapse_s, b.t_collapse_s,
                                                        rel_tol=1e-3)  # fmt: skip


@pytest.mark.parametrize("cell", [(0.3, 1.0), (0.5, 1.5), (0.9, 1.0)])
def test_a_circular_motion_has_one_peak_at_every_angle(cell):
    """r = 1, phi = 90 deg: a = A (sin, cos) in the motion's axes, |a| = A at every time.
    The cylinder is the same turned about its axis, so the motion turned to any angle
    gives the same peak tilt, impacts and collapse time (1e-8): the angle turns both
    components together. The column wobbles (the lean's direction turns) and never passes
    through the vertical."""
    y = {"amplitude_ratio": 1.0, "phase_deg": 90.0}
    runs = [simulate(config(y=y, angle=angle), *cell) for angle in (0.0, 37.0, 90.0, -123.0)]
    for other in runs[1:]:
        same_run(runs[0], other, 1e-8)
    assert runs[0].wobble_turns > 0.5 or runs[0].status == "collapsed"


@pytest.mark.parametrize(
    ("model", "drums", "interface"),
    [("housner-3d", 1, None), ("rbm-3d", 1, None), ("rbm-3d", 3, ELASTIC)],
)
def test_an_elliptic_motion_turned_by_90_degrees_is_its_components_swapped(model, drums, interface):
    """a = (A sin psi, r A sin(psi + phi)), psi = omega t + phase, turned by 90 degrees is
    (-r A sin(psi + phi), A sin psi): the motion along x of amplitude r A and phase
    phase + phi + pi with a second component of ratio 1 / r and phase -(phi + pi). The
    three give the same run (rotational symmetry; 1e-8), and each differs from the motion
    of one component."""
    r, phi, phase = 0.5, 60.0, 0.3
    for amplitude, frequency in ((0.4, 1.0), (0.8, 1.5)):
        kw = dict(model=model, drums=drums, interface=interface)
        a = simulate(config(y={"amplitude_ratio": r, "phase_deg": phi}, phase=phase, **kw),
                     amplitude, frequency)  # fmt: skip
        turned = simulate(config(y={"amplitude_ratio": r, "phase_deg": phi}, phase=phase,
                                 angle=90.0, **kw), amplitude, frequency)  # fmt: skip
        y_swapped = {"amplitude_ratio": 1.0 / r, "phase_deg": -(phi + 180.0)}
        swapped = simulate(config(y=y_swapped, phase=phase + math.radians(phi) + math.pi, **kw),
                           r * amplitude, frequency)  # fmt: skip
        same_run(a, turned, 1e-8)
        same_run(a, swapped, 1e-8)
        one = simulate(config(phase=phase, **kw), amplitude, frequency)
        assert differs(one, a)


@pytest.mark.parametrize(("model", "drums", "interface", "amplitude"),
                         [("housner-3d", 1, None, 0.6), ("rbm-3d", 3, ELASTIC, 0.3)])  # fmt: skip
@pytest.mark.parametrize(("kind", "phi"), [("harmonic", 0.0), ("half-sine", 180.0),
                                           ("ricker", 180.0)])  # fmt: skip
def test_two_components_in_phase_are_one_turned_motion(model, drums, interface, amplitude,
                                                       kind, phi):  # fmt: skip
    """phi = 0 (or 180: -r): the motion is a line at atan(+-r) from x, of amplitude
    A sqrt(1 + r^2): the run of that one component turned there. Whole runs (recorded: no
    early stop, which a run in its motion's plane may take and a pair's may not). The
    cylinder: the same impacts, peaks within 1e-8. The elastic drums (on columns that stay
    in their plane: not a rigid monolith of the RBM, whose planar rocking leaves its plane
    on round-off, docs/guide/models.md): their chattering closures, 80-280 here, amplify
    round-off, and the line runs in its own frame while the pair runs at atan(r) to it, so
    the two round differently; their peaks agree within ten times what the line's own peak
    moves between rtol 1e-10 and 1e-11 (the integration's own error), and at least 1e-8.
    A half-sine pulse, positive first, that overturns the column does so away from it, at
    the azimuth atan(+-r) + 180 degrees (so the second component acts at +90 degrees from
    the first, counter-clockwise)."""
    r = 0.75
    sign = 1.0 if phi == 0.0 else -1.0
    angle = math.degrees(math.atan2(sign * r, 1.0))
    kw = dict(drums=drums, interface=interface)
    for frequency in (1.0, 2.0):
        pair = simulate(config(model, kind, y={"amplitude_ratio": r, "phase_deg": phi}, **kw),
                        amplitude, frequency, record=True)  # fmt: skip
        line_cfg = config(model, kind, angle=angle, **kw)
        line = simulate(line_cfg, amplitude * math.hypot(1.0, r), frequency, record=True)
        rel = 1e-8
        if model == "rbm-3d":
            tight = dataclasses.replace(line_cfg, solver=dataclasses.replace(
                line_cfg.solver, rtol=1e-11))  # fmt: skip
            other = simulate(tight, amplitude * math.hypot(1.0, r), frequency, record=True)
            moved = abs(other.max_rotation_ratio / line.max_rotation_ratio - 1.0)
            rel = max(rel, 10.0 * moved)
        same_run(line, pair, rel, events=model == "housner-3d")
        assert pair.n_uplifts > 0
    if kind == "half-sine":
        strong = simulate(config(model, kind, y={"amplitude_ratio": r, "phase_deg": phi}, **kw),
                          3.0, 1.0)  # fmt: skip
        assert strong.status == "collapsed"
        away = math.remainder(strong.collapse_azimuth_deg - (angle + 180.0), 360.0)
        assert abs(away) < 1e-6


def test_zero_ratio_is_the_one_component_run_to_the_bit():
    """r = 0 (any phase): the run of the first component alone, to the bit, for
    housner-3d and rbm-3d (rocking with impacts, and collapsing)."""
    for model, drums, interface in (("housner-3d", 1, None), ("rbm-3d", 3, ELASTIC)):
        for cell in ((0.4, 1.0), (0.9, 1.0)):
            kw = dict(model=model, drums=drums, interface=interface, angle=30.0)
            zero = simulate(config(y={"amplitude_ratio": 0.0, "phase_deg": 73.0}, **kw), *cell)
            one = simulate(config(**kw), *cell)
            assert (zero.status, zero.n_impacts, zero.n_uplifts) == (
                one.status, one.n_impacts, one.n_uplifts)  # fmt: skip
            assert zero.max_rotation_ratio == one.max_rotation_ratio
            assert zero.max_top_displacement_m == one.max_top_displacement_m
            assert zero.t_collapse_s == one.t_collapse_s or math.isnan(one.t_collapse_s)


def test_the_uncompiled_source_gives_the_same_bits():
    """rbm-3d under an ellipse and under a Mavroeidis-Papageorgiou pair with
    `solver.implementation: python` (the compiled run's own source, the second
    component's formula and the search for an uplift included): the same counts, steps,
    peaks and turns to the bit (a rigid monolith that lifts from rest, two elastic drums)."""
    import dataclasses

    from rbm_cli.models.registry import make_runner

    cases = [
        (1, None, "harmonic", {"y": {"amplitude_ratio": 0.5, "phase_deg": 60.0}}, (0.4, 1.0)),
        (2, ELASTIC, "mavroeidis-papageorgiou",
         {"y": {"amplitude_ratio": 0.8, "phase_deg": 90.0}, "gamma": 2.0, "nu": 0.5},
         (0.5, 1.0)),
    ]  # fmt: skip
    for drums, interface, kind, exc, cell in cases:
        cfg = config("rbm-3d", kind, drums=drums, interface=interface, angle=30.0, **exc)
        motion = make_ground_motion(cfg.excitation, *cell)
        runner = make_runner(cfg)
        a = runner.run(motion, cfg.solver)
        b = runner.run(motion, dataclasses.replace(cfg.solver, implementation="python"))
        assert a.n_uplifts > 0
        assert (a.status, a.n_impacts, a.n_uplifts, a.n_steps) == (
            b.status, b.n_impacts, b.n_uplifts, b.n_steps)  # fmt: skip
        assert np.array_equal(a.max_ratio, b.max_ratio) and a.max_top == b.max_top
        assert a.turns == b.turns


def _sampled_pair(tmp_path, motion, per_period=4000):
    """The motion's two components sampled on the pulse (or the harmonic's duration) as
    two CSV files [g], per_period samples a period: a record pair of the same motion."""
    end = min(motion.pulse_end, motion.t_end)
    count = int(round(per_period * motion.omega * end / (2.0 * math.pi)))
    t = np.linspace(0.0, end, count + 1)
    files = []
    for name, values in (("x.csv", motion.accel(t)), ("y.csv", motion.accel_y(t))):
        np.savetxt(tmp_path / name, np.c_[t, np.asarray(values) / G], delimiter=",",
                   header="time_s,acc_g", comments="", fmt="%.17g")  # fmt: skip
        files.append(name)
    return files


@pytest.mark.parametrize(
    ("model", "drums", "interface"),
    [
        pytest.param("housner-3d", 1, None, marks=pytest.mark.slow),
        ("rbm-3d", 1, None),
        ("rbm-3d", 3, ELASTIC),
    ],
)
def test_the_formula_is_the_pair_of_records_sampled_from_it(tmp_path, model, drums, interface):
    """A harmonic and a Mavroeidis-Papageorgiou pulse with their second components,
    against the same motions sampled 4000 times a period into a pair of record files
    (scale: factor 1, the run going as long): the record pair's straight pieces differ
    from the formula by at most h^2 max|a''| / 8, 3e-7 A, and the runs agree to 1e-4 in
    peak and collapse time (2.7e-7 measured)."""
    cases = [
        ("harmonic", {"y": {"amplitude_ratio": 0.6, "phase_deg": 70.0}, "duration": 2.0},
         0.45, 1.0),
        ("mavroeidis-papageorgiou", {"y": {"amplitude_ratio": 0.8, "phase_deg": 90.0},
                                     "gamma": 2.0, "nu": 0.5, "duration": 4.0}, 0.5, 1.0),
    ]  # fmt: skip
    for kind, exc, amplitude, frequency in cases:
        cfg = config(model, kind, drums=drums, interface=interface, **exc)
        motion = make_ground_motion(cfg.excitation, amplitude, frequency)
        x, y = _sampled_pair(tmp_path, motion)
        free = motion.t_end - min(motion.pulse_end, motion.t_end)
        rec = parse_config({
            "name": "rec", "model": model, "column": {**COLUMN, "drums": drums},
            "interface": interface or {"restitution": 0.9},
            "excitation": {"type": "record", "file": x, "file_y": y, "scale": "factor",
                           "free_time": free},
            "solver": dict(SOLVER),
        }, base_dir=tmp_path)  # fmt: skip
        a = simulate(cfg, amplitude, frequency)
        b = simulate(rec, 1.0, None)
        assert (a.status, a.n_impacts) == (b.status, b.n_impacts), kind
        assert b.max_rotation_ratio == pytest.approx(a.max_rotation_ratio, rel=1e-4), kind
        if a.status == "collapsed":
            assert b.t_collapse_s == pytest.approx(a.t_collapse_s, rel=1e-4), kind
        assert a.max_rotation_ratio > 0.05  # it rocks


def test_a_historys_second_component_is_the_formula():
    """history's ag_y_m_s2: r A g sin(omega t + phase + phi) for a harmonic; r times the
    Mavroeidis-Papageorgiou pulse of nu + phi with the first's velocity amplitude on the
    pulse, 0 after it; ag_m_s2 stays the first component's."""
    import rbm

    amplitude, f = 0.4, 1.25
    r, phi, phase = 0.6, 50.0, 0.4
    run = rbm.run(config(y={"amplitude_ratio": r, "phase_deg": phi}, phase=phase),
                  amplitude_g=amplitude, frequency_hz=f, output_dt=0.01)  # fmt: skip
    t = run.history["t_s"].to_numpy()
    w = 2.0 * math.pi * f
    a = amplitude * G
    expected = r * a * np.sin(w * t + phase + math.radians(phi))
    np.testing.assert_allclose(run.history["ag_y_m_s2"], expected, rtol=0, atol=1e-12 * a)
    np.testing.assert_allclose(run.history["ag_m_s2"], a * np.sin(w * t + phase), rtol=0,
                               atol=1e-12 * a)  # fmt: skip
    gamma, nu = 2.0, 0.5
    cfg = config("rbm-3d", "mavroeidis-papageorgiou", gamma=gamma, nu=nu, duration=3.0,
                 y={"amplitude_ratio": r, "phase_deg": phi})  # fmt: skip
    run = rbm.run(cfg, amplitude_g=amplitude, frequency_hz=f, output_dt=0.01)
    t = run.history["t_s"].to_numpy()
    end = gamma / f
    s = f * (t - 0.5 * end)
    peak_x = a / mp_peak(gamma, nu)  # V f of the first: its peak is A
    on = t <= end
    expected = np.where(on, r * peak_x * mp_shape(s, gamma, nu + math.radians(phi)), 0.0)
    np.testing.assert_allclose(run.history["ag_y_m_s2"], expected, rtol=0, atol=1e-9 * a)
    assert np.max(np.abs(run.history["ag_m_s2"])) == pytest.approx(a, rel=1e-3)


def test_a_grid_axis_over_the_second_component():
    """Axes over excitation.y.amplitude_ratio and excitation.y.phase_deg: every row is the
    run of its own config; r = 0 is the one-component run, r = 1 at phi = 0 the motion of
    amplitude sqrt(2) A at 45 degrees, at phi = 180 at -45 degrees."""
    import rbm

    cfg = config(y={"amplitude_ratio": 1.0, "phase_deg": 0.0})
    raw = dict(cfg.written, grid={"amplitudes": [0.4], "frequencies": [1.0],
                                  "excitation.y.amplitude_ratio": [0.0, 1.0],
                                  "excitation.y.phase_deg": [0.0, 180.0]})  # fmt: skip
    df = rbm.sweep(parse_config(raw))
    assert len(df) == 4
    one = simulate(config(), 0.4, 1.0)
    for _, row in df.iterrows():
        r, phi = row["excitation.y.amplitude_ratio"], row["excitation.y.phase_deg"]
        if r == 0.0:
            assert row.max_rotation_ratio == pytest.approx(one.max_rotation_ratio, rel=1e-11)
            continue
        line = simulate(config(angle=45.0 if phi == 0.0 else -45.0), 0.4 * math.sqrt(2.0), 1.0)
        assert row.status == line.status and row.n_impacts == line.n_impacts
        assert row.max_rotation_ratio == pytest.approx(line.max_rotation_ratio, rel=1e-8)


@pytest.mark.slow  # the contact engine's runs
def test_the_contact_engine_takes_a_second_component():
    """bullet with excitation.y runs free in three dimensions. The friction demand of a
    stack moving with the ground is max |a| / g: A / g for a circle, and for r = 1 at phi,
    |a|^2 = A^2 (1 - cos(phi) cos(2 psi + phi)), A sqrt(1 + |cos phi|) / g (1e-12). At 0.9
    of the engine's uplift level a circle leaves the stack at rest (no engine step), the
    ellipse of phi 45 degrees (1.18 of the level) rocks it. r = 0 is the run with the
    angle written (in three dimensions too), to the bit."""
    from rbm_cli.models.bullet.run import engine_uplift_g, ground_friction_demand

    def engine(y, angle=None):
        excitation = {"type": "harmonic", "duration": 2.0}
        excitation.update({} if y is None else {"y": y})
        excitation.update({} if angle is None else {"angle": angle})
        return parse_config({"name": "engine", "model": "bullet", "column": dict(COLUMN),
                             "interface": {"friction": 0.8}, "excitation": excitation})  # fmt: skip

    circle = {"amplitude_ratio": 1.0, "phase_deg": 90.0}
    ellipse = {"amplitude_ratio": 1.0, "phase_deg": 45.0}
    level = engine_uplift_g(engine(circle))
    amplitude = 0.9 * level
    for y, peak in ((circle, 1.0), (ellipse, math.sqrt(1.0 + math.cos(math.radians(45.0))))):
        for angle in (None, 30.0):
            motion = make_ground_motion(engine(y, angle).excitation, amplitude, 1.5)
            assert ground_friction_demand(motion) == pytest.approx(amplitude * peak, rel=1e-12)
    calm = simulate(engine(circle), amplitude, 1.5)
    assert calm.status == "survived" and calm.n_uplifts == 0 and "at rest" in calm.message
    rocks = simulate(engine(ellipse), amplitude, 1.5)
    assert rocks.three_d and rocks.n_uplifts > 0 and rocks.max_rotation_ratio > 0.01
    zero = simulate(engine({"amplitude_ratio": 0.0, "phase_deg": 90.0}), 0.5, 1.0)
    one = simulate(engine(None, angle=0.0), 0.5, 1.0)
    assert zero.three_d and one.three_d and zero.n_uplifts > 0
    assert (zero.status, zero.n_impacts, zero.max_rotation_ratio, zero.message) == (
        one.status, one.n_impacts, one.max_rotation_ratio, one.message)  # fmt: skip


NAN, INF = float("nan"), float("inf")


@pytest.mark.parametrize(
    ("excitation", "message"),
    [
        ({"type": "harmonic", "y": {"amplitude_ratio": -0.5}}, "excitation.y.amplitude_ratio"),
        ({"type": "harmonic", "y": {"amplitude_ratio": NAN}}, "excitation.y.amplitude_ratio"),
        ({"type": "harmonic", "y": {"amplitude_ratio": 20.0}}, "excitation.angle"),
        ({"type": "harmonic", "y": {"amplitude_ratio": "1"}}, "excitation.y.amplitude_ratio"),
        ({"type": "harmonic", "y": {"amplitude_ratio": 1.0, "phase_deg": INF}},
         "excitation.y.phase_deg"),
        ({"type": "harmonic", "y": {"amplitude_ratio": 1.0, "phase_deg": 400.0}},
         "excitation.y.phase_deg"),
        ({"type": "harmonic", "y": {"phase_deg": 90.0}}, "amplitude_ratio is required"),
        ({"type": "harmonic", "y": {"amplitude_ratio": 1.0, "phase": 90.0}}, "unknown key"),
        ({"type": "harmonic", "y": 0.5}, "excitation.y must be a mapping"),
        ({"type": "ricker", "y": {"amplitude_ratio": 1.0, "phase_deg": 90.0}}, "no phase"),
        ({"type": "free", "y": {"amplitude_ratio": 1.0}, "initial": {"rotations": [0.01]}},
         "excitation.y applies only"),
        ({"type": "record", "file": "x.csv", "y": {"amplitude_ratio": 1.0}}, "file_y"),
    ],
)  # fmt: skip
def test_a_bad_second_component_is_refused_in_one_line(excitation, message):
    raw = {"name": "bad", "model": "housner-3d", "column": dict(COLUMN), "excitation": excitation}
    with pytest.raises(ConfigError, match=message) as err:
        parse_config(raw)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("model", ["rbm", "housner", "housner-linear"])
def test_a_planar_model_refuses_a_second_component(model, tmp_path):
    """Through the command line: one line naming excitation.y and the models that take
    it, exit status 2, no traceback, no output folder."""
    from click.testing import CliRunner

    from rbm_cli.cli.main import cli

    path = tmp_path / "planar.yaml"
    path.write_text(
        f"name: planar\nmodel: {model}\ncolumn: {{height: 4.0, base_width: 1.0}}\n"
        "excitation: {type: harmonic, y: {amplitude_ratio: 1.0, phase_deg: 90}}\n"
    )
    res = CliRunner().invoke(cli, ["run", str(path), "--amplitude", "0.3", "--frequency", "1",
                                   "-o", str(tmp_path / "out")])  # fmt: skip
    lines = [line for line in res.output.splitlines() if line.strip()]
    assert res.exit_code == 2, res.output
    assert len(lines) == 1 and lines[0].startswith("Error:"), res.output
    assert "excitation.y" in lines[0] and "rbm-3d" in lines[0] and model in lines[0]
    assert "Traceback" not in res.output
    assert not (tmp_path / "out").exists()


def test_a_config_without_it_keeps_its_hash():
    """excitation.y absent: the config's resolved form holds its default, none (and a
    motion without a second component hashes as before it existed: rbm migrate); with it,
    the hash changes with r and phi."""
    from rbm_cli.study.sweep import config_hash

    plain = config()
    assert plain.resolved()["excitation"]["y"] is None
    hashes = {config_hash(plain)}
    for y in ({"amplitude_ratio": 0.0}, {"amplitude_ratio": 1.0},
              {"amplitude_ratio": 1.0, "phase_deg": 90.0}):  # fmt: skip
        hashes.add(config_hash(config(y=y)))
    assert len(hashes) == 4
