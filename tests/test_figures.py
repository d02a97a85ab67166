"""The figures of a run (history.png, shapes.png) and of the benchmark (bench.png), read back
from their artists: the data of the lines and patches, the texts, the legends."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

from rbm_cli.config.load import parse_config
from rbm_cli.models.history import History
from rbm_cli.report.bench_figures import work_precision_figure
from rbm_cli.report.exaggeration import round_factor
from rbm_cli.report.plots import plot_joint_rotations, plot_shapes
from rbm_cli.report.run_figures import history_figure, run_column, run_title
from rbm_cli.report.run_folder import run_summary
from rbm_cli.structures.column import build_column
from rbm_cli.structures.outline import base_slip, drum_outlines
from rbm_cli.study.bench import PEAK_TARGET, PROBLEMS
from rbm_cli.study.simulate import simulate

TWO_DRUMS = {
    "name": "two",
    "column": {"height": 2.0, "base_width": 0.4, "drums": 2},
    "interface": {"stiffness": {"normal": 1e8}},
    "excitation": {"type": "harmonic", "duration": 1.5},
}


def _history(theta: np.ndarray, heights, u0=None) -> History:
    """A history whose nodes follow the RBM's u_{i+1} = u_i + h_i theta_i (plus a base u0)."""
    theta = np.atleast_2d(theta)
    k = theta.shape[0]
    u = np.hstack([np.zeros((k, 1)), np.cumsum(theta * np.asarray(heights), axis=1)])
    if u0 is not None:
        u = u + np.asarray(u0)[:, None]
    t = np.linspace(0.0, 1.0, k)
    return History(t, np.zeros(k), np.zeros(k), u, theta)


# --------------------------------------------------------------------------- shapes


@pytest.mark.parametrize(
    "target, expected", [(0.5, 1.0), (1.0, 1.0), (3.7, 2.0), (9.99, 5.0), (10.0, 10.0),
                         (49.0, 20.0), (730.0, 500.0), (math.inf, 1.0)]
)  # fmt: skip
def test_exaggeration_factors_are_round(target, expected):
    assert round_factor(target) == expected


def test_each_drum_sits_on_the_corner_of_the_drum_below_and_the_joint_opens_a_wedge():
    widths = np.array([0.6, 0.5, 0.4])
    heights = np.array([1.0, 0.8])
    theta = np.array([0.05, -0.03])  # drum 2 turns back: phi_2 = -0.08, pivot on the left
    lower, upper = drum_outlines(theta, widths, heights)
    # drum 1 rocks on its right corner, which stays on the ground where it was
    assert lower[1] == pytest.approx([0.3, 0.0])
    assert upper[0] == pytest.approx(lower[3])  # upper's bottom-left on lower's top-left
    # the faces at the joint meet at the angle phi_2 (the wedge), opening on the right
    slope = lambda a, b: math.atan2(-(b[1] - a[1]), b[0] - a[0])  # noqa: E731
    assert slope(upper[0], upper[1]) - slope(lower[3], lower[2]) == pytest.approx(-0.08)
    assert upper[1][1] > lower[2][1]  # the right corners part: the joint is open there
    # rigid: side lengths of the trapezoids unchanged
    assert np.linalg.norm(upper[2] - upper[1]) == pytest.approx(math.hypot(0.8, 0.05))


def test_a_column_at_rest_is_the_stack_of_its_trapezoids():
    outlines = drum_outlines(np.zeros(2), np.array([0.6, 0.5, 0.4]), np.array([1.0, 0.8]))
    assert outlines[0] == pytest.approx(np.array([[-0.3, 0], [0.3, 0], [0.25, 1], [-0.25, 1]]))
    assert outlines[1] == pytest.approx(np.array([[-0.25, 1], [0.25, 1], [0.2, 1.8], [-0.2, 1.8]]))


def test_a_base_that_slides_is_drawn_displaced_by_its_slip():
    theta = np.array([[0.0], [0.02], [0.02]])
    slip = np.array([0.0, 0.0, 0.004])
    # an engine's base node: rocking on the right corner moves it (B/2)(1 - cos theta)
    u0 = 0.3 * (1 - np.cos(theta[:, 0])) + slip
    hist = _history(theta, [2.0], u0=u0)
    assert base_slip(hist.node_displacements, theta[:, 0], 0.6) == pytest.approx(slip)
    ax = plot_shapes(hist, [0.6, 0.4], [1, 2], elevations=[0.0, 2.0], scale=10.0)
    first, second = (p.get_xy()[:4] for p in ax.patches)
    pitch = ax.texts[1].get_position()[0] - ax.texts[0].get_position()[0]
    assert second[:, 0] - pitch - first[:, 0] == pytest.approx(np.full(4, 10 * 0.004))
    assert "slip" in ax.get_title() and "slip +4 mm" in ax.texts[1].get_text()
    # the RBM's base never moves: no slip, none drawn
    rbm = _history(theta, [2.0])
    assert not np.any(base_slip(rbm.node_displacements, theta[:, 0], 0.6))
    assert "slip" not in plot_shapes(rbm, [0.6, 0.4], [1], elevations=[0, 2.0]).get_title()


# --------------------------------------------------------------------------- history


def test_joint_rotations_are_relative_rotations_over_their_limits():
    theta = np.array([[0.0, 0.0], [0.01, 0.03], [0.02, -0.01]])
    limits = np.array([0.1, 0.2])
    ax = plot_joint_rotations(_history(theta, [1.0, 1.0]), limits, collapse_ratio=0.9)
    joint1, joint2 = (ln for ln in ax.lines if ln.get_gid() in ("joint-1", "joint-2"))
    assert joint1.get_ydata() == pytest.approx([0.0, 0.1, 0.2])
    assert joint2.get_ydata() == pytest.approx([0.0, 0.1, -0.15])  # (theta_2 - theta_1) / 0.2
    levels = sorted(ln.get_ydata()[0] for ln in ax.lines if ln.get_gid() == "limit")
    assert levels == [-0.9, 0.9]
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert texts[:3] == ["joint 1", "joint 2", "collapse limit"]
    absolute = plot_joint_rotations(_history(theta, [1, 1]), limits, formulation="absolute")
    assert absolute.lines[1].get_ydata() == pytest.approx([0.0, 0.15, -0.05])
    with pytest.raises(ValueError, match="rotation_capacity"):
        plot_joint_rotations(_history(theta, [1, 1]), [0.1])


@pytest.fixture(scope="module")
def two_drum_run():
    cfg = parse_config(TWO_DRUMS)
    result = simulate(cfg, 0.4, 1.5, record=True)
    summary = run_summary(
        result, cfg, config_path=None, amplitude_g=0.4, frequency_hz=1.5, output_dt=None
    )
    return cfg, result, summary


def test_history_figure_names_the_config_and_the_cell_and_shows_the_joints(two_drum_run):
    cfg, result, summary = two_drum_run
    title = run_title(summary)
    assert title == "two (harmonic): A = 0.4 g, f = 1.5 Hz"
    joints = run_column(summary)
    column = build_column(cfg.column, cfg.interface)
    assert joints[0].rotation_capacity == pytest.approx(column.rotation_capacity)
    fig = history_figure(result.history, None, title, joints)
    assert fig._suptitle.get_text() == title
    assert len(fig.axes) == 3
    panel = fig.axes[2]
    theta = result.history.rotations
    phi2 = (theta[:, 1] - theta[:, 0]) / column.rotation_capacity[1]
    assert panel.lines[1].get_ydata() == pytest.approx(phi2)
    # a monolith keeps the two displacement panels; an unknown summary gives no title
    mono = _history(theta[:, :1], [2.0])
    assert len(history_figure(mono, None, None, None).axes) == 2
    assert run_title({"status": "x"}) is None and run_column({}) is None


# --------------------------------------------------------------------------- bench


@pytest.fixture(scope="module")
def bench_figure():
    rows = []
    for name, wall in (("slender", 1.0), ("multidrum", 100.0)):
        for rtol, err, frac in ((1e-6, 1e-6, 0.002), (1e-8, 1e-8, 0.0), (1e-10, 0.0, 0.0)):
            rows.append(
                dict(problem=name, implementation="compiled", method="DOP853", rtol=rtol,
                     domain_wall_s=wall * (2 - math.log10(rtol) / 10), peak_err_median=err,
                     fraction_differ=frac)
            )  # fmt: skip
    fig = work_precision_figure(pd.DataFrame(rows))
    fig.canvas.draw()  # the tick labels exist once drawn
    return fig


def test_bench_leaves_zeros_out_of_the_log_axes_and_says_so(bench_figure):
    ax_peak, ax_diff = bench_figure.axes[0], bench_figure.axes[2]
    peak = [ln for ln in ax_peak.lines if ln.get_gid() == "DOP853 (compiled)"][0]
    # sorted by rtol: 1e-10 (error 0: left out), 1e-8, 1e-6
    assert np.isnan(peak.get_ydata()[0]) and peak.get_ydata()[1:] == pytest.approx([1e-8, 1e-6])
    diff = [ln for ln in ax_diff.lines if ln.get_gid() == "DOP853 (compiled)"][0]
    assert diff.get_ydata()[2] == pytest.approx(0.002)
    assert np.all(np.isnan(diff.get_ydata()[:2]))  # not drawn as 1e-4
    (note,) = [t for t in ax_diff.texts if t.get_gid() == "none"]
    assert "2 of 3 runs" in note.get_text()


def test_bench_targets_are_labelled_and_rows_share_their_y_range(bench_figure):
    axes = bench_figure.axes
    targets = {p.name: p.max_cells for p in PROBLEMS}
    ((peak_target,),) = [[ln for ln in axes[0].lines if ln.get_gid() == "target"]]
    assert peak_target.get_ydata()[0] == PEAK_TARGET and "target" in peak_target.get_label()
    (cells_target,) = [ln for ln in axes[2].lines if ln.get_gid() == "target"]
    assert cells_target.get_ydata()[0] == targets["slender"]
    assert f"{targets['slender']:.1%}" in cells_target.get_label()
    legend = [t.get_text() for t in bench_figure.legends[0].get_texts()]
    assert any("accuracy target" in t for t in legend)
    assert axes[0].get_ylim() == axes[1].get_ylim()
    assert axes[2].get_ylim() == axes[3].get_ylim()


def test_bench_labels_only_the_decades(bench_figure):
    for ax in bench_figure.axes:
        minor = [t.get_text() for t in ax.xaxis.get_minorticklabels()]
        minor += [t.get_text() for t in ax.yaxis.get_minorticklabels()]
        assert not any(minor)
        for tick in ax.get_yticks():
            assert math.log10(tick) == pytest.approx(round(math.log10(tick)))


def test_figures_are_matplotlib_figures_not_pyplot_state(bench_figure):
    import matplotlib.pyplot as plt

    assert isinstance(bench_figure, Figure) and not plt.get_fignums()
