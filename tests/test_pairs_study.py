"""tools/make_pairs_study.py: the planar assessment of a pair is the worse of its two
components, a cell's outcome its members' majority (tables set by hand), and the figure of
the stored studies is drawn."""

from __future__ import annotations

import pandas as pd
import pytest

from .paths import RESULTS, tool_script


@pytest.fixture(scope="module")
def study():
    return tool_script("make_pairs_study")


def test_a_cell_collapses_when_most_of_its_members_did(study):
    domain = pd.DataFrame({
        "record": ["a", "a", "a", "a"], "amplitude_g": [0.1, 0.2, 0.3, 0.4],
        "status": ["survived", "collapsed", "collapsed", "failed"],
        "collapsed": [0, 1, 1, 0], "collapse_fraction": [0.4375, 0.5, 1.0, 0.0],
    })  # fmt: skip
    out = study.majority(domain)
    assert list(out["collapsed"]) == [0, 1, 1] and list(out["amplitude_g"]) == [0.1, 0.2, 0.3]
    assert list(out["status"]) == ["survived", "collapsed", "collapsed"]


def test_a_pair_collapses_in_the_plane_when_either_component_does(study):
    pairs = pd.DataFrame({"excitation.file": ["r/x1.AT2", "r/x2.AT2"],
                          "excitation.file_y": ["r/y1.AT2", "r/y2.AT2"]})  # fmt: skip
    planar = pd.DataFrame({
        "record": ["x1", "y1", "x1", "y1", "x2", "y2", "x2", "y2"],
        "amplitude_g": [0.1, 0.1, 0.2, 0.2, 0.1, 0.1, 0.2, 0.2],
        "collapsed": [0, 0, 0, 1, 1, 0, 1, 1],
    })  # fmt: skip
    worse = study.worse_of_pairs(planar, pairs).sort_values(["record", "amplitude_g"])
    assert list(worse["record"]) == ["x1", "x1", "x2", "x2"]
    assert list(worse["collapsed"]) == [0, 1, 1, 1]
    with pytest.raises(SystemExit):
        study.worse_of_pairs(planar.iloc[:-1], pairs)


def test_the_figure_of_the_stored_studies(study, tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(study, "RESAMPLES", 50)
    out = tmp_path / "pairs.png"
    study.main(out)
    assert out.stat().st_size > 10_000
    text = capsys.readouterr().out
    assert "1 drum:" in text and "8 drums:" in text and "of 100 pair-levels" in text
    assert (RESULTS / "suite_pairs" / "meta.json").is_file()


@pytest.fixture(scope="module")
def engine_study():
    return tool_script("make_pairs_engine")


def test_the_engine_is_compared_on_robust_cells_only(engine_study):
    """tools/make_pairs_engine.py: an 8-drum rbm-3d cell is robust or not by its members;
    only robust cells count for agreement, and a difference is put down to the side that
    collapsed (a table set by hand; the 1-drum cells and a failed run left out)."""
    beam = pd.DataFrame({
        "column.drums": [8, 8, 8, 8, 1],
        "record": ["a", "a", "b", "b", "a"], "amplitude_g": [0.2, 0.4, 0.2, 0.4, 0.2],
        "collapse_fraction": [0.0, 1.0, 0.5, 1.0, 1.0], "robust": [1, 1, 0, 1, 1],
        "t_collapse_s": [float("nan"), 3.0, 4.0, 2.0, 1.0],
    })  # fmt: skip
    engine = pd.DataFrame({
        "record": ["a", "a", "b", "b", "c"], "amplitude_g": [0.2, 0.4, 0.2, 0.4, 0.2],
        "status": ["collapsed", "collapsed", "survived", "failed", "survived"],
        "t_collapse_s": [5.0, 3.1, float("nan"), float("nan"), float("nan")],
    })  # fmt: skip
    both = engine_study.compare(engine, beam)
    assert list(both["rbm3d"]) == ["survived", "collapsed", "sensitive"]
    assert list(both["agree"].fillna(-1)) == [0.0, 1.0, -1]
    s = engine_study.summary(both)
    assert s == {"cells": 3, "robust": 2, "agree": 1, "engine_only": 1, "rbm3d_only": 0}


def test_the_stored_engine_study_compares(engine_study):
    """The stored domains make the comparison the docs give: every cell of the engine's
    study is one of rbm-3d's 8-drum cells."""
    engine = pd.read_csv(RESULTS / "suite_pairs_bullet" / "domain.csv")
    both = engine_study.compare(engine, pd.read_csv(RESULTS / "suite_pairs" / "domain.csv"))
    assert len(both) == len(engine[engine["status"] != "failed"]) == 25
