"""Motions given as arrays in the library against the same samples written as record files:
a motion (``rbm.motion_from_arrays``) takes the place of ``excitation.file`` and of nothing
else, so ``rbm.run(cfg, A, motion=m)`` and ``rbm.sweep(cfg, motions=[m])`` give the rows of
the config whose file holds m's samples, with its angle, processing and im_periods; a pair
(``acceleration_y``) gives the rows of ``excitation.file`` with ``excitation.file_y`` for
every model in three dimensions; the arrays are checked as a file's samples are, sizes
first and over whole arrays.

The column is a circular cylinder, H = 4 m, D = 1 m (alpha = atan(1/4); rigid, or for
rbm-3d on an elastic joint at k_n 5e9 Pa/m): under a ground motion along one azimuth it
rocks, and collapses, in the vertical plane of that azimuth (a symmetry of the cylinder,
which has no preferred direction), so a collapse azimuth of +-90 deg says the motion ran
along excitation.angle = 90 deg.
"""

from __future__ import annotations

import json
import sys

import numpy as np
import pandas as pd
import pytest

import rbm
import rbm_cli.config.motions as motions_module

T = np.round(np.arange(401) * 0.01, 10)  # [s]: 4 s at an even 0.01 s step
ENVELOPE = np.sin(np.pi * T / 4.0) ** 2
#: Two components [g] of a synthetic record of 4 s, the first with energy up to 9 Hz (a
#: band-pass at 8 Hz changes it), the second another mix of sines.
AX = ENVELOPE * (
    np.sin(2 * np.pi * 1.3 * T)
    + 0.4 * np.sin(2 * np.pi * 3.1 * T + 0.5)
    + 0.2 * np.sin(2 * np.pi * 9.0 * T)
)
AY = ENVELOPE * (np.cos(2 * np.pi * 1.1 * T) + 0.3 * np.sin(2 * np.pi * 2.3 * T + 1.0))
CYLINDER = {"height": 4.0, "base_width": 1.0, "section": "circular", "density": 2700.0}
#: Amplitudes [g] of the record's PGA, filtered at 8 Hz: housner-3d's cylinder survives the
#: first two and collapses at 1.5 g, rbm-3d's at 3 g.
AMPLITUDES = [0.3, 0.8, 1.5, 3.0]
#: Columns that name the record: the file's stem or the motion's name.
NAMES = ("record", "excitation.file")
FILTER = {"filter": {"low_hz": 0.2, "high_hz": 8.0}}


def csv_record(path, values):
    """A CSV record of T [s] and ``values`` [g], every digit kept."""
    rows = "".join(f"{t!r},{a!r}\n" for t, a in zip(T.tolist(), values.tolist(), strict=True))
    path.write_text("time_s,acceleration_g\n" + rows)
    return path


def config(model: str = "housner-3d", amplitudes=AMPLITUDES, **excitation) -> dict:
    interface = {"stiffness": "rigid", "restitution": 0.9}
    if model == "rbm-3d":
        interface = {"stiffness": {"normal": 5e9}, "restitution": 0.9}
    return {
        "name": "motions",
        "model": model,
        "column": dict(CYLINDER),
        "interface": interface,
        "excitation": {"type": "record", "units": "g", "free_time": 1.0, **excitation},
        "grid": {"amplitudes": list(amplitudes)},
    }


def same_rows(by_file: pd.DataFrame, by_arrays: pd.DataFrame) -> None:
    """Every column but the record's name (and the motions' axis) holds the same values,
    to the bit."""
    columns = [c for c in by_file.columns if c not in NAMES]
    assert columns == [c for c in by_arrays.columns if c not in NAMES]
    pd.testing.assert_frame_equal(by_file[columns], by_arrays[columns], check_exact=True)


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    folder = tmp_path_factory.mktemp("motions")
    return csv_record(folder / "x.csv", AX), csv_record(folder / "y.csv", AY)


# --------------------------------------------------------------------------- one component


@pytest.mark.parametrize("model", ["housner-3d", "rbm-3d"])
def test_a_motion_keeps_the_angle_processing_and_periods_of_a_record_config(records, model):
    """A record config at excitation.angle 90 deg with a band-pass and im_periods: swept
    with its own file, and with the file's samples given as arrays, the rows are the same
    to the bit, the Sa(0.5 s) column included; the collapse is in the plane of 90 deg.

    Guards against a motion that dropped the config's angle (the run at 0 deg: collapse
    azimuth 0 or 180), its processing (the unfiltered record: other figures, shown here to
    differ) and its im_periods (no sa_0p5s_g column)."""
    x, _ = records
    raw = config(model, file=str(x), angle=90.0, processing=FILTER, im_periods=[0.5])
    cfg = rbm.load_config(raw)
    motion = rbm.motion_from_arrays(T, AX, name="x-arrays")
    by_file = rbm.sweep(cfg)
    by_arrays = rbm.sweep(cfg, motions=[motion])
    same_rows(by_file, by_arrays)
    assert "sa_0p5s_g" in by_arrays.columns and by_arrays["record"].tolist() == ["x-arrays"] * 4
    collapsed = by_arrays[by_arrays["status"] == "collapsed"]
    assert len(collapsed) >= 1
    assert np.allclose(np.abs(collapsed["collapse_azimuth_deg"]), 90.0, atol=1e-6)
    unfiltered = rbm.sweep(rbm.load_config(config(model, file=str(x), angle=90.0)),
                           motions=[motion])  # fmt: skip
    assert not np.array_equal(
        unfiltered["max_rotation_ratio"].to_numpy(), by_arrays["max_rotation_ratio"].to_numpy()
    )
    # one cell: the run of the file's config, figure by figure
    one = rbm.run(cfg, 1.5, motion=motion, record=False)
    ref = rbm.run(cfg, 1.5, record=False)
    assert one.config.excitation.angle == 90.0 and one.config.excitation.processing is not None
    for key in ("status", "t_collapse_s", "max_rotation_ratio", "n_impacts", "n_steps"):
        assert np.array_equal([one.result[key]], [ref.result[key]], equal_nan=key[0] == "t"), key


def test_a_motion_keeps_the_angle_of_another_excitation():
    """A harmonic config at 90 deg: the motion replaces the harmonic (its type, duration,
    phase) and keeps the angle: the cylinder collapses in the plane of 90 deg."""
    raw = config(amplitudes=[1.5])
    raw["excitation"] = {"type": "harmonic", "duration": 2.0, "phase": 0.3, "angle": 90.0}
    motion = rbm.motion_from_arrays(T, AX, name="x")
    cell = rbm.run(rbm.load_config(raw), 1.5, motion=motion, record=False)
    assert cell.config.excitation.type == "record" and cell.config.excitation.angle == 90.0
    row = rbm.sweep(rbm.load_config(raw), motions=[motion]).iloc[0]
    assert row["status"] == "collapsed" == cell.status
    assert abs(row["collapse_azimuth_deg"]) == pytest.approx(90.0, abs=1e-6)


@pytest.mark.parametrize(
    "excitation, grid, words",
    [
        ({"file_y": "y.csv"}, {}, "excitation.file_y is a record file's second component"),
        ({"file": ["x.csv"], "file_y": ["y.csv"]}, {}, "excitation.file_y is a record file's"),
        ({}, {"linked": [{"excitation.file": ["x.csv"], "excitation.file_y": ["y.csv"]}]},
         "excitation.file_y is a record file's"),
    ],
    ids=["file_y", "suite-of-pairs", "linked-pairs"],
)  # fmt: skip
def test_a_file_for_the_second_component_beside_a_motion_is_refused(
    records, monkeypatch, excitation, grid, words
):
    """A config's y record cannot go with a motion's x (their times are not one): refused
    in one line that says how to give a pair as arrays."""
    monkeypatch.chdir(records[0].parent)
    raw = config(**{"file": "x.csv", **excitation})
    raw["grid"].update(grid)
    cfg = rbm.load_config(raw)
    motion = rbm.motion_from_arrays(T, AX, name="x")
    for call in (
        lambda: rbm.run(cfg, 0.3, motion=motion),
        lambda: rbm.sweep(cfg, motions=[motion]),
    ):
        with pytest.raises(rbm.ConfigError) as bad:
            call()
        message = str(bad.value)
        assert "\n" not in message and words in message and "acceleration_y" in message


def test_plot_domain_draws_a_sweep_of_motions_with_the_config_it_was_given():
    """rbm.plot_domain(df, config=cfg) after rbm.sweep(cfg, motions=...): drawn with the
    config swept (the motions from df.attrs), its uplift level B/H included; the config as
    the sweep ran it draws the same figure."""
    raw = {"name": "block", "column": {"height": 2.0, "base_width": 0.5},
           "interface": {"stiffness": "rigid", "restitution": 0.9},
           "grid": {"amplitudes": [0.1, 0.5, 2.0], "frequencies": [1.0]}}  # fmt: skip
    cfg = rbm.load_config(raw)
    t = np.linspace(0.0, 1.0, 401)
    motions = [rbm.motion_from_arrays(t, s * np.sin(np.pi * t), name=f"m{s}") for s in (1, 2)]
    df = rbm.sweep(cfg, motions=motions)
    ax = rbm.plot_domain(df, config=cfg)
    labels = [line.get_label() for line in ax.get_lines()]
    ran = rbm.load_config({**raw, "excitation": {"type": "record", "file": motions[0]},
                           "grid": {"amplitudes": [0.1, 0.5, 2.0],
                                    "excitation.file": motions}})  # fmt: skip
    same = rbm.plot_domain(df.copy(), config=ran)
    assert labels == [line.get_label() for line in same.get_lines()]
    texts = " ".join(labels + [t.get_text() for t in ax.texts])
    assert "0.25" in texts or any(
        np.allclose(line.get_ydata(), 0.25) for line in ax.get_lines() if len(line.get_ydata())
    ), labels


# --------------------------------------------------------------------------- pairs


@pytest.mark.parametrize("model", ["housner-3d", "rbm-3d", "bullet"])
def test_a_pair_given_as_arrays_runs_as_the_same_pair_of_record_files(records, model):
    """rbm.motion_from_arrays(t, ax, acceleration_y=ay) swept by each model in three
    dimensions gives the rows of excitation.file with excitation.file_y holding the same
    samples (scaled by one factor, the larger component's PGA to the amplitude; the
    intensity measures the larger of the two components'), to the bit."""
    x, y = records
    raw = config(model, amplitudes=[0.8, 1.5], file=str(x), file_y=str(y), angle=30.0)
    if model == "bullet":
        raw["solver"] = {"time_step": 1e-3}
    by_file = rbm.sweep(rbm.load_config(raw))
    del raw["excitation"]["file_y"]
    pair = rbm.motion_from_arrays(T, AX, name="pair", acceleration_y=AY)
    by_arrays = rbm.sweep(rbm.load_config(raw), motions=[pair])
    same_rows(by_file, by_arrays)
    assert by_arrays["pga_g"].tolist() == pytest.approx([0.8, 1.5], rel=1e-12)
    assert pair.pga_g == pytest.approx(max(np.abs(AX).max(), np.abs(AY).max()), rel=1e-12)
    if model != "bullet":  # the y component is run: without it the figures differ
        alone = rbm.sweep(rbm.load_config(raw), motions=[rbm.motion_from_arrays(T, AX)])
        assert not alone["max_rotation_ratio"].equals(by_arrays["max_rotation_ratio"])


def test_a_pair_is_refused_where_it_cannot_run(records):
    """A planar model, a config's own file_y, and a suite mixing pairs with motions of one
    component: each refused in one line naming the problem."""
    pair = rbm.motion_from_arrays(T, AX, name="pair", acceleration_y=AY)
    single = rbm.motion_from_arrays(T, AX, name="single")
    planar = rbm.load_config({"name": "b", "column": {"height": 2.0, "base_width": 0.5},
                              "grid": {"amplitudes": [0.5], "frequencies": [1.0]}})  # fmt: skip
    cases = [
        (lambda: rbm.run(planar, 0.5, motion=pair), "is a pair (acceleration_y"),
        (lambda: rbm.sweep(config(file=pair, file_y=str(records[1]))), "acceleration_y=..."),
        (lambda: rbm.sweep(config(file=single), motions=[single, pair]),
         "motions[1] is a pair (acceleration_y) and motions[0] has one component"),
    ]  # fmt: skip
    for call, words in cases:
        with pytest.raises(rbm.ConfigError) as bad:
            call()
        assert "\n" not in str(bad.value) and words in str(bad.value), str(bad.value)


def test_a_pair_is_known_by_both_components_in_a_folder_sweep(tmp_path):
    """A folder sweep of a pair stores its identity (both components in its SHA-256, two
    components); the same x with another y is another config."""
    raw = config(amplitudes=[0.3], file=rbm.motion_from_arrays(T, AX, name="seed"))
    pair = rbm.motion_from_arrays(T, AX, name="p", acceleration_y=AY)
    rbm.sweep(raw, output=tmp_path, motions=[pair])
    meta = json.loads((tmp_path / "motions" / "meta.json").read_text())
    (stored,) = meta["config_written"]["grid"]["excitation.file"]
    assert stored["sha256"] == pair.sha256 and stored["components"] == 2
    other = rbm.motion_from_arrays(T, AX, name="p", acceleration_y=0.5 * AY)
    assert other.sha256 != pair.sha256
    assert rbm.motion_from_arrays(T, AX, name="p").sha256 != pair.sha256
    with pytest.raises(rbm.RbmError, match="another config|force"):
        rbm.sweep(raw, output=tmp_path, motions=[other], resume=True)


# --------------------------------------------------------------------------- the arrays


@pytest.mark.parametrize(
    "kwargs, words",
    [
        ({"time_s": [[0.0, 0.1], [0.2]]}, "time must be a 1-d list or array of numbers"),
        ({"acceleration": [0.0, [0.1, 0.2]]}, "acceleration must be a 1-d list or array"),
        ({"acceleration": np.zeros((2, 1))}, "acceleration must be a 1-d list or array"),
        ({"acceleration": np.array([True, False])}, "sample 0: acceleration must be a number"),
        ({"time_s": None}, "time must be a 1-d list or array of numbers"),
        ({"acceleration_y": [0.0]}, "2 times but 1 values of acceleration_y"),
        ({"acceleration_y": [0.0, np.nan]}, "acceleration_y: sample 1: non-finite value nan"),
        ({"acceleration_y": [0.0, 1500.0]}, "more than 1000 g: not a ground motion"),
        ({"acceleration_y": [0.0, "0.1"]}, "sample 1: acceleration_y must be a number"),
    ],
)
def test_bad_arrays_of_a_motion_or_a_pair_are_refused_in_one_line(kwargs, words):
    args = {"time_s": [0.0, 0.1], "acceleration": [0.0, 0.2], "name": "m", **kwargs}
    with pytest.raises(rbm.ConfigError) as bad:
        rbm.motion_from_arrays(**args)
    message = str(bad.value)
    assert message.startswith("motion 'm': ") and "\n" not in message, message
    assert words in message, message


def test_the_size_is_checked_before_the_samples(monkeypatch):
    """Arrays longer than the limit are refused by their length, before a sample is read
    (a sample that is not a number comes after; here the limit is lowered to 10)."""
    monkeypatch.setattr(motions_module, "MAX_SAMPLES", 10)
    for series in (["x"] + [0.0] * 10, np.array(["x"] + ["0"] * 10)):
        with pytest.raises(rbm.ConfigError, match=r"time has 11 samples, more than the 10"):
            rbm.motion_from_arrays(series, [0.0] * 11)
    with pytest.raises(rbm.ConfigError, match=r"acceleration_y has 11 samples, more than"):
        rbm.motion_from_arrays([0.0, 1.0], [0.0, 1.0], acceleration_y=[True] * 11)


def _calls(f) -> int:
    """The calls Python makes (functions and C functions, at every depth) while f runs."""
    count = 0

    def profile(frame, event, arg):
        nonlocal count
        if event in ("call", "c_call"):
            count += 1

    sys.setprofile(profile)
    try:
        f()
    finally:
        sys.setprofile(None)
    return count


@pytest.mark.parametrize("pair", [False, True], ids=["one-component", "pair"])
@pytest.mark.parametrize("as_list", [True, False], ids=["lists", "arrays"])
def test_the_checks_do_not_loop_over_the_samples_in_python(as_list, pair):
    """The calls made to check a motion (or a pair) of 100,000 samples are those made for
    one of 1,000: every check runs over whole arrays. A loop over the samples in Python (a
    type check each) made 100 times more, about 56 s for 10^6 samples under load."""

    def make(n):
        t = np.linspace(0.0, 10.0, n)
        a, ay = 0.3 * np.sin(t), 0.2 * np.cos(t)
        if as_list:
            t, a, ay = t.tolist(), a.tolist(), ay.tolist()
        if pair:
            return lambda: rbm.motion_from_arrays(t, a, name="m", acceleration_y=ay)
        return lambda: rbm.motion_from_arrays(t, a, name="m")

    small, large = _calls(make(1_000)), _calls(make(100_000))
    assert large <= small + 20, (small, large)


def test_a_motion_refuses_the_analytic_second_component_it_would_drop():
    """A harmonic config's excitation.y is a second component of the harmonic: arrays that
    replace the harmonic would run without it, silently. Refused in one line that says where
    a second component of arrays goes."""
    second = {"amplitude_ratio": 0.5, "phase_deg": 90}
    cfg = rbm.load_config({"name": "c", "model": "housner-3d", "column": dict(CYLINDER),
                           "excitation": {"type": "harmonic", "y": second}})  # fmt: skip
    motion = rbm.motion_from_arrays(T, AX, name="x")
    for call in (lambda: rbm.run(cfg, 0.3, motion=motion),
                 lambda: rbm.sweep(cfg, motions=[motion])):  # fmt: skip
        with pytest.raises(rbm.ConfigError, match=r"excitation\.y .*acceleration_y") as err:
            call()
        assert "\n" not in str(err.value)
