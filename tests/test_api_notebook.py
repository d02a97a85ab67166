"""The notebook surface of `rbm`: ground motions given as arrays (rbm.motion_from_arrays),
run as a cell and swept as a suite, and the data behind `rbm info`, `rbm fragility` and
`rbm compare` (rbm.info, rbm.fragility, rbm.compare), checked against the commands.

The column is a rigid monolithic block, H = 2 m, B = 0.5 m (square, 2700 kg/m^3): it
starts to rock when |a_g| > g B/H = 0.25 g, so a pulse below that leaves it at rest and one
of several times that overturns it (Housner 1963; the pulse thresholds of
tests/test_api.py's docstring).
"""

from __future__ import annotations

import json
import math
import os
import re
import tempfile

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import rbm
from rbm_cli.cli.main import cli

H, B, RHO, G = 2.0, 0.5, 2700.0, 9.81  # [m], [m], [kg/m^3], [m/s^2]
UPLIFT_G = B / H  # [g]
#: Samples of a sampled half-sine pulse (intervals over its half period).
N_INTERVALS = 2000


def block(**excitation) -> dict:
    return {
        "name": "nb_block",
        "column": {"height": H, "base_width": B},
        "interface": {"stiffness": "rigid", "restitution": 0.9},
        "excitation": excitation or {"type": "harmonic", "duration": 4.0},
    }


def half_sine(f_hz: float, name: str | None = None, peak_g: float = 1.0) -> rbm.Motion:
    """A half-sine pulse of frequency f [Hz] and peak ``peak_g`` [g], sampled at
    N_INTERVALS + 1 points over its half period 1/(2f) (its peak, t = 1/(4f), is a
    sample)."""
    t = np.linspace(0.0, 0.5 / f_hz, N_INTERVALS + 1)
    return rbm.motion_from_arrays(t, peak_g * np.sin(2 * np.pi * f_hz * t), units="g", name=name)


def csv_record(path, t, a):
    """A CSV record file of times [s] and accelerations [g], every digit kept."""
    rows = "".join(f"{x!r},{y!r}\n" for x, y in zip(t, a, strict=True))
    path.write_text("time_s,acceleration_g\n" + rows)
    return path


def invoke(*args) -> str:
    result = CliRunner().invoke(cli, [str(a) for a in args])
    assert result.exit_code == 0, result.output
    return result.output


# --------------------------------------------------------------------------- motions


def test_a_sampled_half_sine_runs_as_the_half_sine_excitation():
    """A half-sine given as arrays in g (peak 0.37 g, scaled to the cell's PGA as a
    record's `scale: pga`: multiplied by A / 0.37) gives the outcome of
    `excitation.type: half-sine` at every cell, and the same collapse time to within a
    twentieth of the sampling step dt = 1/(2f N).

    Why that tolerance: between samples the arrays are linear, and a chord of A sin(w t)
    is below it by at most A (w dt)^2 / 8, a fraction (pi/N)^2/8 = 3e-7 of the peak for
    N = 2000: the forcing differs by that fraction, which moves an event time away from
    the domain's boundary by about that fraction of the time itself (< 1e-6 s here). A
    motion put on the wrong clock (a sample late or early, its times read as steps) or
    scaled by another peak moves the collapse by a step or more: dt/20 tells them apart.
    Both runs last the pulse plus 5 s of free motion (a record's default free_time)."""
    outcomes = set()
    for f in (0.5, 1.0, 2.0):  # [Hz]
        dt = 0.5 / f / N_INTERVALS
        cfg = rbm.load_config(block(type="half-sine", duration=0.5 / f + 5.0))
        motion = half_sine(f, name=f"half-sine {f:g} Hz", peak_g=0.37)
        for a in (1.2 * UPLIFT_G, 2 * UPLIFT_G, 4 * UPLIFT_G, 16 * UPLIFT_G):  # [g]
            pulse = rbm.run(cfg, a, f, record=False)
            given = rbm.run(cfg, a, motion=motion, record=False)
            assert given.status == pulse.status, (f, a)
            outcomes.add(pulse.status)
            if pulse.status == "collapsed":
                assert given.t_collapse_s == pytest.approx(pulse.t_collapse_s, abs=dt / 20)
                assert given.result["collapse_interface"] == 1
            assert given.config.excitation.type == "record"
    assert outcomes == {"collapsed", "survived"}  # the grid holds both outcomes


def test_a_record_config_scales_a_motion_as_it_scales_its_records(tmp_path):
    """A record config with `scale: factor` multiplies the motion by the amplitude, as it
    would its file: a half-sine of peak 0.37 g at factor L is the PGA-scaled one at
    0.37 L; the same arrays written as a CSV record file run the same cell to the same
    bits."""
    f = 1.0
    motion = half_sine(f, name="hs", peak_g=0.37)
    t, a = motion.time_s.tolist(), (motion.acceleration_m_s2 / G).tolist()
    csv = csv_record(tmp_path / "hs.csv", t, a)
    level = 16 * UPLIFT_G
    from_file = rbm.load_config(block(type="record", file=str(csv), scale="factor"))
    by_file = rbm.run(from_file, level, record=False)
    by_arrays = rbm.run(from_file, level, motion=motion, record=False)
    by_pga = rbm.run(rbm.load_config(block()), 0.37 * level, motion=motion, record=False)
    assert by_file.status == "collapsed"
    assert by_arrays.t_collapse_s == by_file.t_collapse_s
    assert by_pga.t_collapse_s == pytest.approx(by_file.t_collapse_s, rel=1e-12)
    with pytest.raises(rbm.ConfigError, match="motion must be|must be a motion"):
        rbm.run(from_file, level, motion=[0.0, 1.0])


def test_sweep_over_motions_gives_one_row_per_motion_and_amplitude(tmp_path, monkeypatch):
    """rbm.sweep(cfg, motions=[m1, m2]): a suite of two motions x three amplitudes, in the
    order of a suite (motion-major, then amplitude), each row's name in `record` and
    `excitation.file`, each outcome that of rbm.run of that motion; nothing written."""

    def refused(*args, **kwargs):
        raise AssertionError("a temporary file or folder was asked for")

    for name in ("mkdtemp", "mkstemp", "TemporaryDirectory", "NamedTemporaryFile"):
        monkeypatch.setattr(tempfile, name, refused)
    cfg = rbm.load_config(block() | {"grid": {"amplitudes": [0.1, 1.0, 4.0], "frequencies": [1]}})
    m1, m2 = half_sine(0.5, "slow"), half_sine(4.0, "fast")
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    work.chmod(0o555)
    try:
        df = rbm.sweep(cfg, motions=[m1, m2])
    finally:
        work.chmod(0o755)
    assert list(os.walk(tmp_path)) == [(str(tmp_path), ["work"], []), (str(work), [], [])]
    assert len(df) == 6
    assert df["record"].tolist() == ["slow"] * 3 + ["fast"] * 3
    assert df["excitation.file"].tolist() == df["record"].tolist()
    assert df["amplitude_g"].tolist() == [0.1, 1.0, 4.0] * 2
    assert df["frequency_hz"].isna().all()  # a record has no frequency
    for row in df.itertuples():
        motion = m1 if row.record == "slow" else m2
        assert row.status == rbm.run(cfg, row.amplitude_g, motion=motion, record=False).status
    assert df["status"].iloc[0] == "survived"  # 0.1 g < B/H: at rest
    assert df["status"].iloc[2] == "collapsed"  # 16 B/H at 0.5 Hz
    # the frame's types are domain.csv's: whole numbers int (nullable where empty)
    assert df["collapse_interface"].dtype == "Int64"
    assert df["collapse_interface"].isna().tolist() == (df["status"] != "collapsed").tolist()
    assert df["n_uplifts"].dtype == "int64" and df["max_rotation_ratio"].dtype == "float64"


def test_a_folder_sweep_of_motions_knows_them_by_content(tmp_path):
    """A folder sweep keeps the motions' SHA-256 in its config hash: the same arrays
    resume (nothing to do), other arrays under the same name are another config (refused
    without force), as another record file under the same path would be."""
    cfg = rbm.load_config(block() | {"grid": {"amplitudes": [0.1, 4.0]}})
    m1, m2 = half_sine(0.5, "a"), half_sine(4.0, "b")
    df = rbm.sweep(cfg, output=tmp_path, motions=[m1, m2])
    folder = tmp_path / "nb_block"
    meta = json.loads((folder / "meta.json").read_text())
    stored = meta["config_written"]["grid"]["excitation.file"]
    assert [m["sha256"] for m in stored] == [m1.sha256, m2.sha256]
    again = rbm.sweep(cfg, output=tmp_path, motions=[half_sine(0.5, "a"), m2], resume=True)
    pd.testing.assert_frame_equal(again.drop(columns="attrs", errors="ignore"), df)
    other = half_sine(0.6, "a")  # the same name, other samples
    assert other.sha256 != m1.sha256
    with pytest.raises(rbm.RbmError, match="another config|force"):
        rbm.sweep(cfg, output=tmp_path, motions=[other, m2], resume=True)
    assert json.loads((folder / "meta.json").read_text())["config_hash"] == meta["config_hash"]


@pytest.mark.parametrize(
    "time_s, acceleration, options, words",
    [
        ([0.0, 0.01, 0.02], [0.0, 0.1], {}, "3 times but 2 accelerations"),
        ([0.0], [0.0], {}, "needs at least 2 samples, has 1"),
        ([0.0, 0.01, math.nan], [0.0, 0.1, 0.0], {}, "sample 2: non-finite value nan"),
        ([0.0, 0.01, 0.02], [0.0, math.inf, 0.0], {}, "sample 1: non-finite value inf"),
        ([-0.01, 0.0, 0.01], [0.0, 0.1, 0.0], {}, "sample 0: time must be >= 0 [s], got -0.01"),
        ([0.0, 0.02, 0.02], [0.0, 0.1, 0.0], {}, "sample 2: time must increase, got 0.02 after"),
        ([0.0, 0.01, 0.02], [0.0, 2000.0, 0.0], {}, "more than 1000 g: not a ground motion"),
        ([0.0, 0.01], [0.0, 0.1], {"units": "ft/s2"}, "units must be 'g' or 'm/s2', got 'ft/s2'"),
        ([[0.0, 0.01]], [0.0, 0.1], {}, "time must be a 1-d list or array of numbers"),
        ([0.0, "0.01"], [0.0, 0.1], {}, "sample 1: time must be a number, got '0.01'"),
        ([0.0, 0.01], [0.0, 0.1], {"name": ""}, "name must be a non-empty string"),
    ],
)
def test_bad_arrays_are_refused_in_one_line_naming_the_problem(time_s, acceleration, options,
                                                               words):  # fmt: skip
    with pytest.raises(rbm.ConfigError) as bad:
        rbm.motion_from_arrays(time_s, acceleration, **options)
    message = str(bad.value)
    assert "\n" not in message and words in message, message
    assert message.startswith("motion")


def test_arrays_are_refused_with_the_message_a_csv_record_gets(tmp_path):
    """The same samples in a CSV record file and as arrays: the same problem, named in the
    same words; the file names its line, the arrays their sample."""
    cases = [
        ([0.0, 0.02, 0.01], [0.0, 0.1, 0.0]),
        ([0.0, 0.01, 0.02], [0.0, 0.1, math.nan]),
        ([-1.0, 0.0, 1.0], [0.0, 0.1, 0.0]),
        ([0.0, 0.01, 0.02], [0.0, 1500.0, 0.0]),
    ]
    for k, (t, a) in enumerate(cases):
        path = csv_record(tmp_path / f"r{k}.csv", t, a)
        with pytest.raises(rbm.ConfigError) as from_file:
            rbm.load_config(block(type="record", file=str(path)))
        with pytest.raises(rbm.ConfigError) as from_arrays:
            rbm.motion_from_arrays(t, a, name="m")
        file_text = str(from_file.value).split(f"{path}: ", 1)[1]
        array_text = str(from_arrays.value).split("motion 'm': ", 1)[1]
        file_problem = re.sub(r"^line \d+: ", "", file_text)
        array_problem = re.sub(r"^sample \d+: ", "", array_text)
        assert file_problem == array_problem, (file_text, array_text)


def test_motion_names_are_one_per_motion_and_motions_are_read_only():
    m = half_sine(1.0, "x")
    with pytest.raises(rbm.ConfigError, match="the name 'x' is also that of motions"):
        rbm.sweep(block() | {"grid": {"amplitudes": [0.5]}}, motions=[m, half_sine(2.0, "x")])
    with pytest.raises(rbm.ConfigError, match="non-empty list of motions"):
        rbm.sweep(block() | {"grid": {"amplitudes": [0.5]}}, motions=m)
    with pytest.raises(AttributeError):
        m.name = "y"
    with pytest.raises(ValueError):
        m.time_s[0] = 1.0
    assert m.pga_g == pytest.approx(1.0) and m.duration_s == pytest.approx(0.5)
    unnamed = rbm.motion_from_arrays([0.0, 0.1], [0.0, 0.2])
    assert unnamed.name == "motion-" + unnamed.sha256[:8]
    in_ms2 = rbm.motion_from_arrays([0.0, 0.1], [0.0, 0.2 * G], units="m/s2")
    assert in_ms2.sha256 == unnamed.sha256  # the same samples in SI
    uneven = rbm.motion_from_arrays([0.5, 0.51, 0.7, 2.0], [0.0, 0.1, -0.2, 0.0])  # as a CSV's
    assert uneven.duration_s == 2.0 and uneven.pga_g == pytest.approx(0.2)


# --------------------------------------------------------------------------- results


def test_cell_result_is_a_read_only_mapping_with_attributes():
    cfg = rbm.load_config(block())
    rough = rbm.run(cfg, amplitude_g=10 * UPLIFT_G, frequency_hz=0.5, record=False).result
    calm = rbm.run(cfg, amplitude_g=0.4 * UPLIFT_G, frequency_hz=0.5, record=False).result
    assert "max_rotation_ratio" in rough and "history" not in rough
    assert rough["max_rotation_ratio"] == rough.max_rotation_ratio >= 1.0  # collapsed
    assert type(rough["collapse_interface"]) is int and rough["collapse_interface"] == 1
    assert calm["collapse_interface"] is None and calm["n_uplifts"] == 0
    assert list(rough.keys()) == list(rough) and len(rough) == len(list(rough))
    assert dict(rough)["status"] == "collapsed"
    with pytest.raises(KeyError):
        rough["no_such_figure"]
    with pytest.raises((AttributeError, TypeError)):
        rough.status = "survived"
    with pytest.raises(TypeError):
        rough["status"] = "survived"
    assert rough.history is None  # the RunResult's attributes are kept


# --------------------------------------------------------------------------- commands


def test_info_agrees_with_the_text_of_rbm_info(tmp_path):
    """Every figure `rbm info` prints is the mapping's, at its 4 significant digits; and
    for the block the figures of hand: m = rho B^2 H, B/H, N = m g."""
    text_cfg = (
        "name: two\ncolumn: {height: 4.0, base_width: 1.0, top_width: 0.8, drums: 2}\n"
        "interface: {stiffness: {normal: 5.0e9}}\n"
    )
    (tmp_path / "two.yaml").write_text(text_cfg)
    figures = rbm.info(tmp_path / "two.yaml")
    text = invoke("info", tmp_path / "two.yaml")
    lines = dict(line.split(":", 1) for line in text.splitlines()[:10])
    for label, key, unit in [("total mass", "total_mass_kg", "kg"), ("height", "height_m", "m"),
                             ("static multiplier", "static_multiplier_g", "g"),
                             ("rocking p", "rocking_p_rad_s", "rad/s"),
                             ("rocking frequency", "rocking_frequency_hz", "Hz")]:  # fmt: skip
        assert lines[label].strip() == f"{figures[key]:.4g} {unit}", label
    freqs = ", ".join(f"{v:.4g}" for v in figures["elastic_frequencies_hz"])
    assert lines["elastic frequencies"].strip() == f"{freqs} Hz"
    table = figures["interfaces"]
    assert list(table["interface"]) == [1, 2]
    rows = [line.split() for line in text.splitlines() if re.match(r"\s+[12]\s", line)]
    for row, (_, expected) in zip(rows, table.iterrows(), strict=True):
        assert row[1] == f"{expected['width_m']:.4g}"
        assert row[5] == f"{expected['normal_force_N']:.4g}"
        assert row[9] == f"{expected['normal_stiffness_Pa_per_m']:.4g}"
    block_figures = rbm.info(block())
    mass = RHO * B * B * H  # [kg]
    assert block_figures["total_mass_kg"] == pytest.approx(mass)
    assert block_figures["static_multiplier_g"] == pytest.approx(B / H)
    assert block_figures["interfaces"]["normal_force_N"].iloc[0] == pytest.approx(mass * G)
    several = rbm.info([block(), tmp_path / "two.yaml"])
    assert list(several.index) == ["nb_block", "two"]
    assert several.loc["two", "total_mass_kg"] == figures["total_mass_kg"]


@pytest.fixture(scope="module")
def suite_domain(tmp_path_factory):
    """A suite domain on disk: five half-sine pulses (0.5-4 Hz) x eight PGAs [g]: the
    slower the pulse, the lower the PGA that overturns the block."""
    root = tmp_path_factory.mktemp("suite")
    motions = [half_sine(f, f"hs{f:g}") for f in (0.5, 1.0, 1.5, 2.5, 4.0)]
    cfg = rbm.load_config(
        block()
        | {"name": "suite", "grid": {"amplitudes": [0.3, 0.6, 1.0, 1.5, 2.2, 3.0, 4.5, 7.0]}}
    )
    df = rbm.sweep(cfg, output=root, motions=motions)
    return root / "suite" / "domain.csv", df


def test_fragility_agrees_with_what_rbm_fragility_stores(suite_domain, tmp_path):
    path, df = suite_domain
    collapsed = df.groupby("record")["collapsed"].sum()
    assert 0 < collapsed.min() and collapsed.max() < 8  # capacities inside the grid
    invoke("fragility", path, "-o", tmp_path, "--resamples", 40, "--seed", 3)
    stored = json.loads((tmp_path / "fragility.json").read_text())
    curve = pd.read_csv(tmp_path / "fragility_curve.csv")
    table = pd.read_csv(tmp_path / "fragility.csv")
    for source in (df, path):
        res = rbm.fragility(source, n_resamples=40, seed=3)
        assert res.fit.median_g == pytest.approx(stored["median_g"], rel=1e-12)
        assert res.fit.beta == pytest.approx(stored["beta"], rel=1e-12)
        assert list(res.median_ci_g) == pytest.approx(stored["median_ci_g"], rel=1e-12)
        assert (res.n_records, res.n_runs) == (stored["n_records"], stored["n_runs"]) == (5, 40)
        assert list(res.curve.columns) == list(curve.columns)
        np.testing.assert_allclose(res.curve.to_numpy(float), curve.to_numpy(float), rtol=1e-6)
        np.testing.assert_allclose(res.table["fraction"], table["fraction"], rtol=1e-12)
    # the fitted median lies between the smallest and largest PGA that overturned a pulse
    first = df[df.collapsed == 1].groupby("record")["amplitude_g"].min()
    assert first.min() <= res.fit.median_g <= first.max()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["fragility.csv", "fragility_curve.csv", "fragility.json", "fragility.png", "ida.png"]
    )
    with pytest.raises(rbm.RbmError, match="record"):
        rbm.fragility(df.drop(columns="record"))


def test_compare_agrees_with_rbm_compare(tmp_path):
    grid = {"amplitudes": [0.2, 0.3, 0.4, 0.6, 0.8], "frequencies": [1.0, 2.0]}
    a = rbm.load_config(block() | {"name": "a", "grid": grid})
    b = rbm.with_value(rbm.with_value(a, "name", "b"), "interface.restitution", 0.5)
    dom_a, dom_b = rbm.sweep(a, output=tmp_path), rbm.sweep(b, output=tmp_path)
    text = invoke("compare", tmp_path / "a" / "domain.csv", tmp_path / "b" / "domain.csv")
    got = rbm.compare(dom_a, dom_b)
    cells = re.search(r"cells: (\d+) in common, (\d+) differ .*only in A: (\d+), only in B: (\d+)",
                      text)  # fmt: skip
    assert tuple(map(int, cells.groups())) == (got.n_common, got.n_differ, got.only_a, got.only_b)
    shift = float(re.search(r"largest boundary shift: (\S+) g", text).group(1))
    assert shift == pytest.approx(got.max_shift_g, abs=5e-4 * max(1.0, shift))
    assert got.n_common == 10 and got.regression is None
    # by hand: the cells that differ are those whose collapsed flags differ
    assert got.n_differ == int((dom_a["collapsed"] != dom_b["collapsed"]).sum())
    assert list(got.shifts["frequency_hz"]) == [1.0, 2.0]
    same = rbm.compare(tmp_path / "a" / "domain.csv", dom_a)
    assert (same.n_differ, same.max_shift_g) == (0, 0.0)
