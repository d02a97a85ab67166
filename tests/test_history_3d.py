"""The history figures of a run in three dimensions draw the resultant and both components
(`rbm.plot_history`, and history.png's panels), read back from their lines.

Independent reasons: a column collapses where the magnitude of a joint's rotation (its
rotation vector's, whatever its direction) reaches its limit, so the resultant drawn for
the collapsing joint reaches the collapse ratio at the collapse while the rotation seen
in the motion's plane is only the cosine of the azimuth between them of it; a resultant
is the hypotenuse of its two components.
"""

from __future__ import annotations

import math

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import rbm  # noqa: E402
from rbm_cli.report.run_figures import history_figure  # noqa: E402
from rbm_cli.structures.column import build_column  # noqa: E402

from .paths import CONFIGS  # noqa: E402

RECORDS = CONFIGS / "records" / "synthetic"
PAPER = {"height": 5.0, "base_width": 0.96, "top_width": 0.66, "section": "circular",
         "density": 2700}  # fmt: skip


@pytest.fixture(scope="module")
def falling():
    """Two elastic drums under a pair of records at 0.5 g: the upper joint collapses with
    the column leaning some 77 degrees off the motion's plane (x)."""
    cfg = rbm.load_config({
        "name": "pair", "model": "rbm-3d", "column": {**PAPER, "drums": 2},
        "interface": {"stiffness": {"normal": 5e9}, "restitution": 0.9},
        "excitation": {"type": "record", "file": str(RECORDS / "rdk_01.AT2"),
                       "file_y": str(RECORDS / "rdk_02.AT2"), "units": "g", "free_time": 1.0},
    })  # fmt: skip
    cell = rbm.run(cfg, 0.5, output_dt=0.0005)
    assert cell.status == "collapsed" and cell.result.collapse_interface == 2
    assert abs(math.cos(math.radians(cell.result.collapse_azimuth_deg))) < 0.5
    return cfg, cell


def _line(ax, gid):
    (line,) = [ln for ln in ax.get_lines() if ln.get_gid() == gid]
    return np.asarray(line.get_ydata(), dtype=float)


def test_plot_history_draws_the_tops_resultant_and_both_components(falling):
    """rbm.plot_history of a run in three dimensions: the top's displacement in plan,
    its x and y components as the history keeps them and the resultant their
    hypotenuse; at the collapse the resultant is far above the component in the motion's
    plane (x), which alone was drawn."""
    _, cell = falling
    ax = rbm.plot_history(cell)
    top, x, y = _line(ax, "top"), _line(ax, "top-x"), _line(ax, "top-y")
    plan = cell.result.history.top_plan
    assert np.array_equal(x, plan[:, 0]) and np.array_equal(y, plan[:, 1])
    assert np.allclose(top, np.hypot(x, y), rtol=1e-15, atol=0.0)
    assert top[-1] > 1.5 * abs(x[-1])


def test_history_pngs_joint_panel_reaches_the_collapse_ratio_off_the_motions_plane(falling):
    """history.png's joint panel: the collapsing joint's resultant reaches the collapse
    ratio (1) at the last sample before the collapse, its component in the motion's plane
    the cosine of the collapse azimuth of it (it reached 0.23 where the resultant was drawn
    as that component)."""
    cfg, cell = falling
    history, r = cell.result.history, cell.result
    column = build_column(cfg.column, cfg.interface)
    fig = history_figure(history, r.t_collapse_s, joints=(column, "relative", 1.0),
                         ground=True)  # fmt: skip
    panel = next(ax for ax in fig.axes if any(ln.get_gid() == "joint-2" for ln in ax.get_lines()))
    resultant = _line(panel, "joint-2")
    along, across = _line(panel, "joint-2-along"), _line(panel, "joint-2-across")
    assert resultant[-1] == pytest.approx(1.0, abs=0.02)
    assert np.allclose(resultant, np.hypot(along, across), rtol=1e-15, atol=0.0)
    cosine = math.cos(math.radians(r.collapse_azimuth_deg))
    assert along[-1] == pytest.approx(cosine * resultant[-1], abs=0.02)
    assert abs(along[-1]) < 0.5
