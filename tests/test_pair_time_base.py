"""A pair of records sampled at other times (uneven CSVs with the same count and ends but
other interior times) runs each component as its file describes it: both on the union of
their sample times, linear between, so the ground motion of the run is each record's own
linear interpolation, to round-off. The intensity measures (each record on its own
times) are then those of the motion run."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rbm_cli.config.types import G

COLUMN = {"height": 4.0, "base_width": 1.0, "top_width": 0.8, "section": "circular",
          "density": 2700}  # fmt: skip
#: x and y: 7 samples each from 0 to 1.2 s, the same count and ends, other interior times.
TIMES_X = np.array([0.0, 0.1, 0.25, 0.5, 0.6, 0.9, 1.2])
TIMES_Y = np.array([0.0, 0.35, 0.4, 0.7, 0.8, 1.05, 1.2])
VALUES_X = np.array([0.0, 0.3, -0.2, 0.1, 0.25, -0.15, 0.0])  # [g]
VALUES_Y = np.array([0.0, -0.1, 0.3, -0.3, 0.05, 0.2, 0.0])  # [g]


def write(path, t, a):
    path.write_text("time_s,acceleration_g\n" + "".join(f"{float(x)!r},{float(v)!r}\n" for x, v in
                                                        zip(t, a, strict=True)))  # fmt: skip
    return str(path)


def pair_config(tmp_path, model: str = "housner-3d"):
    import rbm

    return rbm.load_config({
        "name": "pair", "model": model, "column": dict(COLUMN),
        "interface": {"stiffness": "rigid", "restitution": 0.9},
        "excitation": {"type": "record", "units": "g", "free_time": 0.5,
                       "file": write(tmp_path / "x.csv", TIMES_X, VALUES_X),
                       "file_y": write(tmp_path / "y.csv", TIMES_Y, VALUES_Y)},
        "grid": {"amplitudes": [0.1]},
    })  # fmt: skip


def test_each_component_of_the_run_is_its_own_record(tmp_path):
    """The history's a_x and a_y at every output time are the x and the y record, each
    linear between its own samples and scaled by one factor (the pair's larger PGA to the
    amplitude): paired by sample index, y would take x's times (0.13 g off here on a 0.3 g peak)."""
    import rbm

    amplitude = 0.1  # [g]: below the block's uplift (tan alpha about 0.2): it rests
    cell = rbm.run(pair_config(tmp_path), amplitude_g=amplitude, output_dt=0.005)
    h = cell.history
    t = h["t_s"].to_numpy()
    factor = amplitude * G / (G * max(np.max(np.abs(VALUES_X)), np.max(np.abs(VALUES_Y))))
    inside = t <= TIMES_X[-1]
    assert inside.sum() > 200
    for column, times, values in (("ag_m_s2", TIMES_X, VALUES_X),
                                  ("ag_y_m_s2", TIMES_Y, VALUES_Y)):  # fmt: skip
        expected = factor * G * np.interp(t[inside], times, values)
        np.testing.assert_allclose(h[column].to_numpy()[inside], expected, rtol=0.0,
                                   atol=1e-12 * G)  # fmt: skip
    assert np.all(h["ag_y_m_s2"].to_numpy()[~inside] == 0.0)


def test_the_motion_keeps_every_sample_of_both(tmp_path):
    """The run's knots are the union of both records' times; at each knot each component
    is its record's value (its own sample, or its interpolation between two)."""
    from rbm_cli.inputs.excitation import make_ground_motion

    cfg = pair_config(tmp_path)
    motion = make_ground_motion(cfg.excitation, 0.3)
    union = np.union1d(TIMES_X, TIMES_Y)
    np.testing.assert_array_equal(motion.knots, union)
    scale = 0.3 * G / 0.3  # the pair's larger PGA is 0.3 g
    np.testing.assert_allclose(motion.values, scale * np.interp(union, TIMES_X, VALUES_X),
                               rtol=1e-15, atol=1e-15)  # fmt: skip
    np.testing.assert_allclose(motion.values_y, scale * np.interp(union, TIMES_Y, VALUES_Y),
                               rtol=1e-15, atol=1e-15)  # fmt: skip
    # the resultant's peak is at a knot (each component linear between knots)
    fine = np.linspace(0.0, TIMES_X[-1], 24001)
    resultant = np.hypot(scale * np.interp(fine, TIMES_X, VALUES_X),
                         scale * np.interp(fine, TIMES_Y, VALUES_Y))  # fmt: skip
    assert motion.amplitude == pytest.approx(np.max(resultant), rel=1e-6)
    assert motion.amplitude >= np.max(resultant)


def test_a_pair_on_one_time_base_is_run_as_read(tmp_path):
    """Both records on the same times: the knots are those times and the values the
    samples, scaled (nothing interpolated)."""
    import rbm
    from rbm_cli.inputs.excitation import make_ground_motion

    cfg = rbm.with_value(pair_config(tmp_path), "excitation.file_y",
                         write(tmp_path / "y_same.csv", TIMES_X, VALUES_Y))  # fmt: skip
    motion = make_ground_motion(cfg.excitation, 0.3)
    assert motion.knots is not None and np.array_equal(motion.knots, TIMES_X)
    np.testing.assert_allclose(motion.values_y, VALUES_Y * G, rtol=1e-15)  # PGA 0.3 g as read


def test_the_run_says_which_time_base_it_took(tmp_path):
    """`rbm run` of the pair: its summary.json says the pair was put on the union of both
    records' times; a pair on one time base says 'shared'."""
    import json

    import yaml
    from click.testing import CliRunner

    from rbm_cli.cli.main import cli

    def run(file_y: str) -> dict:
        name = f"pair_{Path(file_y).stem}"
        config = tmp_path / f"{name}.yaml"
        config.write_text(yaml.safe_dump({
            "name": name, "model": "housner-3d", "column": dict(COLUMN),
            "interface": {"stiffness": "rigid", "restitution": 0.9},
            "excitation": {"type": "record", "units": "g", "free_time": 0.5,
                           "file": write(tmp_path / "x.csv", TIMES_X, VALUES_X),
                           "file_y": file_y},
        }))  # fmt: skip
        res = CliRunner().invoke(cli, ["run", str(config), "-a", "0.1", "-o", str(tmp_path)])
        assert res.exit_code == 0, res.output
        (summary,) = (tmp_path / name).glob("*/summary.json")
        return json.loads(summary.read_text())["record"]

    union = run(write(tmp_path / "y.csv", TIMES_Y, VALUES_Y))
    shared = run(write(tmp_path / "y_same.csv", TIMES_X, VALUES_Y))
    assert union["pair_times"] == "union" and shared["pair_times"] == "shared"
