"""A frame as drawn: `rbm run`'s shapes.png draws its columns side by side and its beam
resting level on their tops, domain.png a sketch of it; a column standing alone (or under
a beam of no mass) is drawn as before."""

from __future__ import annotations

from rbm_cli.api import load_config, run
from rbm_cli.report.domain_figure import domain_figure
from rbm_cli.report.plots import plot_shapes
from rbm_cli.report.run_figures import drawn_frame
from rbm_cli.structures.frame import beam_box
from rbm_cli.study.domain import read_domain

from .paths import RESULTS

COLUMN = {"height": 2.0, "base_width": 0.4, "drums": 3}


def _config(beam_mass):
    return load_config({
        "name": "bay", "column": COLUMN, "interface": {"stiffness": {"normal": 5e9}},
        "excitation": {"type": "harmonic", "duration": 2.0},
        "frame": {"columns": 2, "beam_mass": beam_mass},
    })  # fmt: skip


def test_shapes_draw_every_column_and_the_beam_on_the_tops():
    cfg = _config(1000.0)
    summary = {"config": cfg.resolved()}
    frame = drawn_frame(summary)
    spacing, length, height, depth = beam_box(
        summary["config"]["column"], summary["config"]["frame"]
    )
    assert frame == (2, spacing, height) and spacing == 2.5 * 0.4
    # the beam's box holds its mass at the columns' density
    assert abs(2700.0 * length * depth * height / 1000.0 - 1.0) < 1e-12
    history = run(cfg, 0.4, 2.0, record=True).result.history
    ax = plot_shapes(history, [0.4] * 4, [0, 10, 20], frame=frame, elevations=[0, 2 / 3, 4 / 3, 2])
    drums = [p for p in ax.patches if p.get_gid() == "drum"]
    beams = [p for p in ax.patches if p.get_gid() == "beam"]
    assert len(drums) == 3 * 2 * 3 and len(beams) == 3
    for beam in beams:  # level, and resting on the highest top corner of the instant's drums
        xy = beam.get_xy()
        assert xy[0, 1] == xy[1, 1] and abs((xy[2, 1] - xy[1, 1]) - height) < 1e-12


def test_no_beam_is_drawn_without_a_mass():
    assert drawn_frame({"config": _config(0.0).resolved()}) is None
    assert drawn_frame({"config": load_config({"name": "c", "column": COLUMN,
                                               "interface": {"stiffness": {"normal": 5e9}}}
                                              ).resolved()}) is None  # fmt: skip


def test_domain_png_sketches_the_frame():
    df = read_domain(RESULTS / "colonnade_harmonic_ci" / "domain.csv")
    cfg = load_config(RESULTS.parent / "configs" / "ci" / "colonnade_harmonic_ci.yaml")
    titles = [ax.get_title() for ax in domain_figure(df, cfg).axes]
    assert "2 columns under a beam" in titles
    alone = load_config(RESULTS.parent / "configs" / "harmonic_multidrum.yaml")
    column = read_domain(RESULTS / "harmonic_multidrum" / "domain.csv")
    assert "2 columns under a beam" not in [
        a.get_title() for a in domain_figure(column, alone).axes
    ]
