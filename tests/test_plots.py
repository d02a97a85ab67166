"""Tests of the run plots (plots.py) and the atomic writers (output.py); tmp_path only."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure
from matplotlib.patches import Polygon

from rbm_cli.base.files import (
    OutputError,
    check_writable_dir,
    save_figure_atomic,
    write_csv_atomic,
    write_json_atomic,
)
from rbm_cli.config.load import load_config
from rbm_cli.models.history import History
from rbm_cli.report.plots import (
    exaggeration_factor,
    infer_elevations,
    plot_history,
    plot_shapes,
    plot_top_relative,
    top_relative_displacement,
)
from rbm_cli.report.run_folder import history_frame, run_folder_name, shape_instants, write_run
from rbm_cli.structures.column import build_column
from rbm_cli.study.simulate import simulate

THREE_DRUMS = """\
name: three
column: {height: 3.0, base_width: 0.6, top_width: 0.45, drums: [1.2, 1.0, 0.8]}
interface: {stiffness: {normal: 1e8}}
excitation: {type: harmonic, duration: 2.0}
"""


@pytest.fixture(scope="module")
def three_drum_run(tmp_path_factory):
    """A real recorded run of a tapered 3-drum column with unequal drums."""
    path = tmp_path_factory.mktemp("cfg") / "three.yaml"
    path.write_text(THREE_DRUMS)
    cfg = load_config(path)
    result = simulate(cfg, 0.3, 2.0, record=True)
    return cfg, build_column(cfg.column, cfg.interface), result


def synthetic_history(n_samples: int = 50, top: float = 0.01) -> History:
    """A single rigid block of height 2 m tilting linearly to top / 2 [rad]."""
    t = np.linspace(0.0, 1.0, n_samples)
    theta = (top / 2.0) * t
    u = np.column_stack([np.zeros_like(t), 2.0 * theta])
    ag = np.sin(2 * np.pi * t)
    return History(t, ag, -ag / (2 * np.pi) ** 2, u, theta[:, None])


# --------------------------------------------------------------------------- plots


def test_plot_history_draws_base_top_and_collapse_on_the_given_axes():
    hist = synthetic_history()
    ax = Figure().subplots()
    assert plot_history(hist, ax=ax, t_collapse=0.7) is ax
    base, top, collapse = ax.get_lines()
    np.testing.assert_allclose(base.get_ydata(), hist.ground_displacement)
    np.testing.assert_allclose(
        top.get_ydata(), hist.ground_displacement + hist.node_displacements[:, -1]
    )
    assert collapse.get_xdata()[0] == pytest.approx(0.7)


def test_plot_history_without_axes_makes_its_own_and_skips_a_nan_collapse():
    ax = plot_history(synthetic_history(), t_collapse=float("nan"))
    assert ax is not None and len(ax.get_lines()) == 2


def test_top_relative_is_top_minus_base():
    hist = synthetic_history()
    hist.node_displacements[:, 0] = 0.001  # a base that moves relative to the ground
    ax = plot_top_relative(hist)
    expected = hist.node_displacements[:, -1] - 0.001
    np.testing.assert_allclose(top_relative_displacement(hist), expected)
    np.testing.assert_allclose(ax.get_lines()[0].get_ydata(), expected)


def test_exaggeration_is_a_round_number_within_a_quarter_of_the_height():
    small = synthetic_history(top=0.01)  # 0.25 * 2 m / 0.01 m = 50 exactly: round already
    idx = [10, 49]
    assert exaggeration_factor(small, idx, 2.0) == pytest.approx(50.0)
    # 0.25 * 2 / 0.003 = 166.7: the round factor below it is 100
    assert exaggeration_factor(synthetic_history(top=0.003), idx, 2.0) == pytest.approx(100.0)
    large = synthetic_history(top=1.5)  # already beyond 25 % of the height
    assert exaggeration_factor(large, idx, 2.0) == 1.0
    assert exaggeration_factor(synthetic_history(top=0.0), idx, 2.0) == 1.0
    assert exaggeration_factor(small, [], 2.0) == 1.0


def test_shapes_draw_each_drum_rigid_turned_by_its_rotation(three_drum_run):
    _, column, result = three_drum_run
    hist = result.history
    z = np.concatenate([column.bottoms, [column.height]])
    idx = shape_instants(hist.t)
    ax = plot_shapes(hist, column.widths, idx, elevations=z, scale=3.0)
    polys = [p for p in ax.patches if isinstance(p, Polygon)]
    assert len(polys) == column.n * len(idx)
    assert "x3" in ax.get_title()
    k = idx[0]  # drawn at x offset 0
    for i, poly in enumerate(polys[: column.n]):
        xy = poly.get_xy()[:4]
        # rigid: the end faces keep their widths and the axis its height
        assert np.linalg.norm(xy[1] - xy[0]) == pytest.approx(column.widths[i])
        assert np.linalg.norm(xy[2] - xy[3]) == pytest.approx(column.widths[i + 1])
        axis = xy[2:4].mean(axis=0) - xy[:2].mean(axis=0)
        assert np.linalg.norm(axis) == pytest.approx(column.heights[i])
        # turned by 3 theta_i: the bottom face's slope, and the axis leans the same way
        face = xy[1] - xy[0]
        angle = -np.arctan2(face[1], face[0])
        assert angle == pytest.approx(3.0 * hist.rotations[k, i], abs=1e-12)
        # nodes where the small-rotation RBM puts them, to first order
        assert xy[:2].mean(axis=0)[0] == pytest.approx(
            3.0 * hist.node_displacements[k, i], abs=1e-3 * column.height
        )


def test_shapes_title_states_the_automatic_round_exaggeration(three_drum_run):
    _, column, result = three_drum_run
    idx = shape_instants(result.history.t)
    z = np.concatenate([column.bottoms, [column.height]])
    ax = plot_shapes(result.history, column.widths, idx, elevations=z)
    factor = exaggeration_factor(result.history, idx, column.height)
    mantissa = factor / 10.0 ** np.floor(np.log10(factor))
    assert min(abs(mantissa - m) for m in (1.0, 2.0, 5.0)) < 1e-9
    assert f"x{factor:g}" in ax.get_title()
    assert ax.get_xticks().size == 0 and ax.get_ylabel() == "height [m]"


def test_elevations_are_recovered_from_the_history(three_drum_run):
    """Guards plot_shapes called without elevations on unequal drums."""
    _, column, result = three_drum_run
    z = np.concatenate([column.bottoms, [column.height]])
    np.testing.assert_allclose(infer_elevations(result.history), z, rtol=1e-9, atol=1e-12)


def test_elevations_of_a_column_at_rest_cannot_be_inferred():
    with pytest.raises(ValueError, match="never rotates"):
        infer_elevations(synthetic_history(top=0.0))


def test_shapes_reject_widths_that_do_not_match_the_nodes():
    hist = synthetic_history()
    with pytest.raises(ValueError, match="n\\+1"):
        plot_shapes(hist, [1.0, 1.0, 1.0], [49], elevations=[0.0, 2.0])


# --------------------------------------------------------------------------- output


@pytest.mark.parametrize("n_samples", [1, 2, 7, 1000])
def test_shape_instants_are_sorted_unique_and_end_at_the_last_sample(n_samples):
    t = np.linspace(0.0, 3.0, n_samples)
    idx = shape_instants(t)
    assert idx == sorted(set(idx)) and idx[-1] == n_samples - 1 and len(idx) <= 6
    assert shape_instants([]) == []


@pytest.mark.parametrize(
    "amplitude,frequency,kind,expected",
    [
        (0.5, 1.0, "harmonic", "run_A0.5_f1"),
        (0.25, 0.1, "half-sine", "run_A0.25_f0.1"),
        (1.0, 2.5, "harmonic", "run_A1_f2.5"),
        (0.0, 0.0, "free", "run_free"),
    ],
)
def test_run_folder_names_are_compact(amplitude, frequency, kind, expected):
    assert run_folder_name(amplitude, frequency, kind) == expected


def test_history_csv_columns_and_twelve_significant_digits(tmp_path):
    hist = synthetic_history()
    hist.ground_displacement[0] = -0.0
    frame = history_frame(hist)
    assert list(frame.columns) == ["t_s", "ag_m_s2", "ug_m", "u1_m", "u2_m", "theta1_rad"]
    frame.loc[1, "t_s"] = 1.0 / 3.0
    path = write_csv_atomic(tmp_path / "h.csv", frame)
    lines = path.read_text().splitlines()
    assert lines[2].split(",")[0] == "0.333333333333"
    assert ",-0," not in "".join(lines)
    assert pd.read_csv(path).shape == frame.shape
    assert [p.name for p in tmp_path.iterdir()] == ["h.csv"]  # no temporary left


def test_a_failed_atomic_write_keeps_the_old_file_and_leaves_no_temporary(tmp_path):
    path = tmp_path / "summary.json"
    write_json_atomic(path, {"a": 1})

    class Unserialisable:
        pass

    with pytest.raises(TypeError):
        write_json_atomic(path, {"a": Unserialisable()})
    assert json.loads(path.read_text()) == {"a": 1}
    assert [p.name for p in tmp_path.iterdir()] == ["summary.json"]


def test_json_is_strict_with_nan_and_inf_as_null(tmp_path):
    path = write_json_atomic(
        tmp_path / "x.json", {"nan": math.nan, "inf": np.float64(np.inf), "v": np.arange(2)}
    )
    text = path.read_text()
    assert "NaN" not in text and "Infinity" not in text
    assert json.loads(text) == {"nan": None, "inf": None, "v": [0, 1]}


def test_figures_are_saved_atomically_as_png(tmp_path):
    fig = Figure()
    plot_history(synthetic_history(), ax=fig.subplots())
    path = save_figure_atomic(fig, tmp_path / "h.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in tmp_path.iterdir()] == ["h.png"]


def test_output_folder_checks_create_nothing(tmp_path):
    deep = tmp_path / "a" / "b" / "c"
    assert check_writable_dir(deep) == deep and not (tmp_path / "a").exists()
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(OutputError, match="not a folder"):
        check_writable_dir(blocker / "sub")


def test_write_run_replaces_an_existing_run_and_leaves_no_staging(tmp_path, three_drum_run):
    cfg, column, result = three_drum_run
    z = np.concatenate([column.bottoms, [column.height]])
    for status in ("first", "second"):
        folder = write_run(
            tmp_path,
            cfg.name,
            "run_A0.3_f2",
            result,
            {"status": status},
            widths=column.widths,
            elevations=z,
        )
        assert json.loads((folder / "summary.json").read_text()) == {"status": status}
    assert sorted(p.name for p in folder.iterdir()) == [
        "history.csv",
        "history.png",
        "shapes.png",
        "summary.json",
    ]
    assert [p.name for p in (tmp_path / cfg.name).iterdir()] == ["run_A0.3_f2"]
    frame = pd.read_csv(folder / "history.csv")
    assert list(frame.columns)[-3:] == ["theta1_rad", "theta2_rad", "theta3_rad"]
    assert len(frame) == len(result.history.t)
