"""Records as excitation (``excitation.type: record``) through the config, the models and the CLI.

Expected values come from a second path to the same answer: a half-sine written to an
.AT2 and a CSV file and run as a record must give what the analytic half-sine excitation
gives (outcome, collapse time within 1e-3 s, peak ratio) in every model; uplift times
from the straight line between two samples; a config's hash that depends on the record's
bytes, not on where the files live; one-line refusals of every malformed record.
"""

from __future__ import annotations

import json
import math
import shutil

import numpy as np
import pytest
from click.testing import CliRunner

from rbm_cli.base.errors import ConfigError
from rbm_cli.cli.main import cli
from rbm_cli.config.excitation import resolve_record_path, with_record
from rbm_cli.config.load import load_config, parse_config
from rbm_cli.config.types import G
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.inputs.ground import next_uplift
from rbm_cli.inputs.records import Record, write_at2, write_csv
from rbm_cli.models.registry import make_runner
from rbm_cli.study.sweep import config_hash

#: The paper's tapered monolithic column, rigid (its half-sine study, housner_halfsine)
COLUMN = {"height": 5.0, "base_width": 0.96, "top_width": 0.66, "drums": 1}
DURATION = 20.0  # s, the half-sine's maximum simulated time
AMPLITUDES = (0.15, 0.3, 0.5, 0.8, 1.5)  # g: 0.15 is below uplift (B/H = 0.192)
FREQUENCIES = (0.5, 1.0, 2.0)  # Hz
SAMPLES = 2000  # samples of the half-sine pulse: interpolation error (pi/2000)^2/8 = 3e-7
MODELS = [("rbm", "compiled"), ("rbm", "python"), ("housner", "compiled"),
          ("housner-linear", "compiled")]  # fmt: skip


def _config(model, impl, excitation, **extra):
    data = {
        "name": "rec",
        "model": model,
        "column": COLUMN,
        "excitation": excitation,
        "solver": {"implementation": impl},
        **extra,
    }
    return parse_config(data)


def _record_config(path):
    return parse_config({"name": "r", "column": COLUMN,
                         "excitation": {"type": "record", "file": str(path)}})  # fmt: skip


def _half_sine_files(folder, f):
    """A unit (1 g) half-sine of frequency f [Hz] as an .AT2, a CSV in m/s2 and a CSV with
    uneven time steps; the record ends with the pulse."""
    end = 0.5 / f
    t = np.linspace(0.0, end, SAMPLES + 1)
    a = G * np.sin(np.pi * t / end)
    a[0] = a[-1] = 0.0
    rec = Record(t, a, name="hs")
    at2 = write_at2(folder / f"hs_{f}.AT2", rec)
    csv = write_csv(folder / f"hs_{f}.csv", rec, units="m/s2")
    rng = np.random.default_rng(17)
    tu = np.sort(np.concatenate([[0.0, end], rng.uniform(0.0, end, SAMPLES - 1)]))
    au = G * np.sin(np.pi * tu / end)
    au[0] = au[-1] = 0.0
    uneven = write_csv(folder / f"hs_{f}_uneven.csv", (tu, au), units="g")
    return end, {"at2": (at2, "g"), "csv": (csv, "m/s2"), "uneven": (uneven, "g")}


@pytest.fixture(scope="module")
def half_sines(tmp_path_factory):
    folder = tmp_path_factory.mktemp("records")
    return {f: _half_sine_files(folder, f) for f in FREQUENCIES}


@pytest.mark.parametrize(
    "model, impl",
    [pytest.param(*m, marks=pytest.mark.slow) if m == ("rbm", "python") else m for m in MODELS],
)
def test_half_sine_record_equals_the_analytic_half_sine(half_sines, model, impl):
    """On a whole grid (below uplift, survived, collapsed): the same outcome, the collapse
    time within 1e-3 s (found: ~1e-6 s) and the peak ratio within 1e-4, for the .AT2, the
    CSV and (rbm compiled) an uneven-step CSV, scaled to the grid's PGA."""
    analytic = _config(model, impl, {"type": "half-sine", "duration": DURATION})
    runner = make_runner(analytic)
    outcomes = set()
    kinds = ("at2", "csv", "uneven") if (model, impl) == ("rbm", "compiled") else ("at2", "csv")
    for f in FREQUENCIES:
        end, files = half_sines[f]
        want = {a: runner.run(make_ground_motion(analytic.excitation, a, f), analytic.solver)
                for a in AMPLITUDES}  # fmt: skip
        for kind in kinds:
            path, units = files[kind]
            exc = {"type": "record", "file": str(path), "units": units, "free_time": DURATION - end}
            cfg = _config(model, impl, exc)
            rec_runner = make_runner(cfg)
            for a in AMPLITUDES:
                motion = make_ground_motion(cfg.excitation, a, None)
                assert motion.amplitude == pytest.approx(a * G, rel=1e-7)
                got = rec_runner.run(motion, cfg.solver)
                ref = want[a]
                where = (model, impl, kind, a, f)
                assert got.status == ref.status, where
                outcomes.add(ref.status)
                if ref.status == "collapsed":
                    assert abs(got.t_collapse - ref.t_collapse) < 1e-3, where
                else:
                    assert got.max_ratio[0] == pytest.approx(ref.max_ratio[0], abs=1e-4), where
                if a * G < G * 0.96 / 5.0 * 0.99:  # below uplift for every model: at rest
                    assert got.max_ratio[0] == 0.0 and got.n_uplifts == 0, where
    assert outcomes == {"survived", "collapsed"}


@pytest.mark.parametrize(
    "drums, stiffness, amplitude, moved",
    [pytest.param(8, {"normal": 5e9}, 0.1, 1e-4, marks=pytest.mark.slow), (1, "rigid", 0.5, 0.5)],
)
def test_record_kernel_matches_python_loop(half_sines, drums, stiffness, amplitude, moved):
    """The compiled kernel and the Python loop take the same steps under a record (an
    8-drum elastic column, no impact; the rigid monolith rocking, with impacts and rests)
    over the pulse and 1 s of free motion."""
    end, files = half_sines[1.0]
    path, _ = files["at2"]
    outs = []
    for impl in ("compiled", "python"):
        data = {"name": "md", "column": {**COLUMN, "drums": drums},
                "interface": {"stiffness": stiffness},
                "excitation": {"type": "record", "file": str(path), "free_time": 1.0},
                "solver": {"method": "DOP853", "implementation": impl}}  # fmt: skip
        cfg = parse_config(data)
        motion = make_ground_motion(cfg.excitation, amplitude)
        outs.append(make_runner(cfg).run(motion, cfg.solver, early_stop=False))
    a, b = outs
    assert a.status == b.status == "survived"
    assert (a.n_steps, a.n_events, a.n_impacts) == (b.n_steps, b.n_events, b.n_impacts)
    np.testing.assert_allclose(a.max_ratio, b.max_ratio, rtol=1e-7, atol=1e-13)
    assert a.max_ratio.max() > moved  # it moved


# --------------------------------------------------------------------------- uplift times


def _ramp_motion(tmp_path, t0=0.0, first=0.0, units="g"):
    """a_g = 0 -> 2 g over [t0, t0 + 1] s (from `first` g at t0), then back to 0 at t0 + 2."""
    t = np.array([t0, t0 + 1.0, t0 + 2.0])
    a = np.array([first, 2.0, 0.0]) * (G if units == "m/s2" else 1.0)
    path = write_csv(tmp_path / "ramp.csv", (t, a * (1.0 if units == "m/s2" else G)), units=units)
    cfg = parse_config(
        {"name": "ramp", "column": COLUMN,
         "excitation": {"type": "record", "file": str(path), "scale": "factor", "units": units}}
    )  # fmt: skip
    return make_ground_motion(cfg.excitation, 1.0)


@pytest.mark.parametrize("level_g", [0.3, 1.0, 1.9])
def test_uplift_time_on_a_straight_piece(tmp_path, level_g):
    """|a_g| first exceeds L at t = L / 2 on the ramp 2 g t (closed form), in the
    GroundMotion and in the kernel alike; after the ramp's top, the falling side."""
    motion = _ramp_motion(tmp_path)
    level = level_g * G
    assert motion.next_exceedance(0.0, level) == pytest.approx(level_g / 2.0, abs=1e-12)
    t_above = 1.0 + (2.0 - level_g) / 4.0  # on the falling side, a_g = (2 + L) / 2 > L
    assert motion.next_exceedance(t_above, level) == t_above
    t_fall = 2.0 - level_g / 2.0  # 2 g (2 - t) = L
    assert motion.next_exceedance(t_fall + 1e-9, level) is None
    gr = (motion.form, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    knots, values, none = np.array(motion.knots), np.array(motion.values), np.zeros(0)
    t_kernel = next_uplift(0.0, level, motion.amplitude, gr, knots, values, none, motion.pulse_end)
    assert t_kernel == pytest.approx(level_g / 2.0, abs=1e-12)
    assert motion.uplift_side(level_g / 2.0) == -1  # a_g > 0: it lifts on the -theta side


def test_jump_at_the_first_sample(tmp_path):
    """A CSV starting at t0 = 0.5 s with 1 g: the ground rests before, the acceleration
    jumps there; a rigid block lifts exactly at t0, the integrator restarts there."""
    motion = _ramp_motion(tmp_path, t0=0.5, first=1.0)
    assert motion.segments()[:2] == [(0.0, 0.5), (0.5, 2.5)]
    assert motion.next_exceedance(0.0, 0.5 * G) == 0.5
    assert motion.accel(0.25) == 0.0 and motion.accel(0.5) == pytest.approx(G)


# --------------------------------------------------------------------------- config


def test_scale_pga_and_factor(tmp_path):
    """scale pga: the scaled record's PGA is the amplitude [g]; scale factor: the record
    times the amplitude. A record whose PGA is 0 cannot be scaled to a PGA."""
    t = np.arange(5) * 0.01
    a = np.array([0.0, 0.2, -0.5, 0.1, 0.0]) * G
    path = write_at2(tmp_path / "r.AT2", Record(t, a))
    for scale, amp, peak in (("pga", 0.3, 0.3 * G), ("factor", 2.0, 1.0 * G)):
        exc = {"type": "record", "file": str(path), "scale": scale}
        cfg = parse_config({"name": "s", "column": COLUMN, "excitation": exc})
        motion = make_ground_motion(cfg.excitation, amp)
        assert motion.amplitude == pytest.approx(peak, rel=1e-12)
        assert motion.t_end == pytest.approx(0.04 + 5.0)  # the record, then 5 s free
    zero = write_at2(tmp_path / "z.AT2", Record(t, 0.0 * a))
    with pytest.raises(ConfigError, match="cannot be scaled to a PGA"):
        _record_config(zero)


def test_relative_path_from_the_config_folder(tmp_path, monkeypatch):
    """A relative excitation.file is taken from the config file's folder (not the current
    directory); for a mapping config from the current directory."""
    (tmp_path / "cfg" / "recs").mkdir(parents=True)
    write_at2(tmp_path / "cfg" / "recs" / "r.AT2", np.array([0.0, 1.0, 0.0]) * G, dt=0.1)
    text = (
        f"name: r\ncolumn: {json.dumps(COLUMN)}\nexcitation: {{type: record, file: recs/r.AT2}}\n"
    )
    (tmp_path / "cfg" / "c.yaml").write_text(text)
    monkeypatch.chdir(tmp_path)
    cfg = load_config("cfg/c.yaml")
    assert cfg.excitation.file == "recs/r.AT2"
    assert cfg.excitation.file_path == str(tmp_path / "cfg" / "recs" / "r.AT2")
    assert cfg.excitation.duration == pytest.approx(0.2 + 5.0)
    with pytest.raises(ConfigError, match="no such file"):
        parse_config({"name": "r", "column": COLUMN,
                      "excitation": {"type": "record", "file": "recs/r.AT2"}})  # fmt: skip
    monkeypatch.chdir(tmp_path / "cfg")
    _record_config("recs/r.AT2")
    assert resolve_record_path("/a/b.AT2", "/x") == resolve_record_path("b.AT2", "/a")


def test_hash_of_a_record_config(tmp_path):
    """The config's hash holds the path as written and the record's bytes (SHA-256), not
    where the files live: two copies in two folders hash alike; other bytes differ."""
    hashes = []
    for folder in ("one", "two"):
        (tmp_path / folder).mkdir()
        write_at2(tmp_path / folder / "r.AT2", np.array([0.0, 1.0, -0.5, 0.0]) * G, dt=0.01)
        text = f"name: r\ncolumn: {json.dumps(COLUMN)}\nexcitation: {{type: record, file: r.AT2}}\n"
        (tmp_path / folder / "c.yaml").write_text(text)
        cfg = load_config(tmp_path / folder / "c.yaml")
        resolved = json.dumps(cfg.resolved(), default=str)
        assert str(tmp_path) not in resolved and "file_path" not in resolved
        hashes.append(config_hash(cfg))
    assert hashes[0] == hashes[1]
    write_at2(tmp_path / "two" / "r.AT2", np.array([0.0, 1.0, -0.4, 0.0]) * G, dt=0.01)
    assert config_hash(load_config(tmp_path / "two" / "c.yaml")) != hashes[0]
    other = with_record(cfg.excitation, "r.AT2", tmp_path / "one")
    assert other.file_sha256 == load_config(tmp_path / "one" / "c.yaml").excitation.file_sha256


def test_record_moved_after_loading(tmp_path):
    """A record file changed after the config was loaded is refused when the run starts."""
    path = write_at2(tmp_path / "r.AT2", np.array([0.0, 1.0, 0.0]) * G, dt=0.1)
    cfg = _record_config(path)
    write_at2(path, np.array([0.0, 2.0, 0.0]) * G, dt=0.1)
    with pytest.raises(Exception, match="changed since the config was loaded"):
        make_ground_motion(cfg.excitation, 0.3)


# --------------------------------------------------------------------------- refusals

AT2_HEAD = "rbm\ntest\nACCELERATION TIME SERIES IN UNITS OF G\n"
MALFORMED = [
    ("bad header", "r.AT2", AT2_HEAD + "NPTS is five\n0.1 0.2\n", "g", ["line 4", "NPTS"]),
    ("NPTS mismatch", "r.AT2", AT2_HEAD + "NPTS= 4, DT= 0.01 SEC\n0.1 0.2 0.3\n", "g",
     ["line 4", "NPTS = 4 but the file has 3 values"]),
    ("non-finite value", "r.AT2", AT2_HEAD + "NPTS= 3, DT= 0.01 SEC\n0.1 nan 0.3\n", "g",
     ["line 5", "non-finite"]),
    ("non-increasing time", "r.csv", "time_s,acceleration_g\n0,0.1\n0.2,0.3\n0.1,0.2\n", "g",
     ["line 4", "time must increase"]),
    ("empty file", "r.csv", "", "g", ["empty file"]),
    ("empty AT2", "r.AT2", "", "g", ["empty file"]),
    ("unknown units", "r.csv", "time_s,a\n0,0.1\n0.1,0.2\n", "gal", ["excitation.units", "gal"]),
    ("m/s2 with an AT2", "r.AT2", AT2_HEAD + "NPTS= 2, DT= 0.01 SEC\n0.1 0.2\n", "m/s2",
     ["an .AT2 file is in g"]),
    ("missing file", None, None, "g", ["no such file"]),
]  # fmt: skip


def _malformed(tmp_path, fname, text, units):
    name = fname or "nowhere.AT2"
    if text is not None:
        (tmp_path / name).write_text(text)
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"name: r\ncolumn: {json.dumps(COLUMN)}\n"
        f"excitation: {{type: record, file: {name}, units: {units}}}\n"
    )
    return cfg, tmp_path / name


@pytest.mark.parametrize("label, fname, text, units, needles", MALFORMED)
def test_malformed_record_refused_by_the_config(tmp_path, label, fname, text, units, needles):
    """load_config refuses it in one line naming the key, the file (and the line)."""
    cfg, path = _malformed(tmp_path, fname, text, units)
    with pytest.raises(ConfigError) as err:
        load_config(cfg)
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith(str(cfg))
    assert "excitation." in msg
    if label != "unknown units":
        assert str(path) in msg
    for needle in needles:
        assert needle in msg, (needle, msg)


@pytest.mark.parametrize("command", ["run", "sweep", "info"])
@pytest.mark.parametrize("label, fname, text, units, needles", MALFORMED)
def test_malformed_record_refused_by_the_cli(tmp_path, command, label, fname, text, units, needles):
    """Every command that loads the config: exit 2, one line 'Error: ...', no traceback."""
    cfg, path = _malformed(tmp_path, fname, text, units)
    args = {"run": ["run", cfg, "-a", "0.3"], "sweep": ["sweep", cfg, "-o", tmp_path / "o"],
            "info": ["info", cfg]}[command]  # fmt: skip
    res = CliRunner().invoke(cli, [str(a) for a in args])
    lines = [line for line in res.output.splitlines() if line.strip()]
    assert res.exit_code == 2, res.output
    assert len(lines) == 1 and lines[0].startswith("Error:"), res.output
    assert "Traceback" not in res.output
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])


@pytest.mark.parametrize(
    "excitation, needle",
    [
        ({"type": "record"}, "excitation.file is required"),
        ({"type": "record", "file": ["a.AT2", "b.AT2"]}, "a.AT2: no such file"),  # a suite
        ({"type": "record", "file": "x.AT2", "duration": 10}, "duration does not apply"),
        ({"type": "harmonic", "file": "x.AT2"}, "excitation.file applies only to type record"),
        ({"type": "half-sine", "free_time": 3}, "excitation.free_time applies only"),
        ({"type": "record", "file": "x.AT2", "scale": "peak"}, "excitation.scale must be one of"),
        ({"type": "record", "file": "x.AT2", "free_time": -1}, "excitation.free_time must be"),
        ({"type": "record", "file": "x.txt"}, "unknown record format"),
    ],
)
def test_record_keys_validated(tmp_path, excitation, needle):
    (tmp_path / "x.txt").write_text("time,a\n0,1\n1,2\n")
    with pytest.raises(ConfigError) as err:
        parse_config({"name": "r", "column": COLUMN, "excitation": excitation}, "c.yaml", tmp_path)
    assert needle in str(err.value) and "\n" not in str(err.value)


# --------------------------------------------------------------------------- CLI


def test_rbm_run_a_record_without_frequency(tmp_path, half_sines):
    """`rbm run CONFIG --amplitude A` runs a record with no --frequency."""
    end, files = half_sines[1.0]
    shutil.copy(files["at2"][0], tmp_path / "hs.AT2")
    (tmp_path / "c.yaml").write_text(
        f"name: r\ncolumn: {json.dumps(COLUMN)}\nexcitation: {{type: record, file: hs.AT2}}\n"
    )
    res = CliRunner().invoke(
        cli, ["run", str(tmp_path / "c.yaml"), "-a", "0.8", "-o", str(tmp_path / "o")]
    )
    assert res.exit_code == 0, res.output
    summary = json.loads(next((tmp_path / "o" / "r").glob("run_*/summary.json")).read_text())
    assert summary["status"] == "collapsed"
    assert math.isfinite(summary["t_collapse_s"])
