"""The figure of a record suite's domain reads as one: the records named by their names
(never their paths) on a categorical axis whose names do not overlap, in panel titles
too; no boundary line joining unrelated records (a bar per record at its lowest collapsed
amplitude); and a legend that lists what is drawn, each mark once."""

from __future__ import annotations

import math

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402
from click.testing import CliRunner  # noqa: E402

import rbm  # noqa: E402
import rbm_cli.base.files  # noqa: E402
from rbm_cli.cli.main import cli  # noqa: E402
from rbm_cli.report.domain_figure import domain_figure  # noqa: E402

AMPLITUDES = (0.1, 0.2, 0.3, 0.4, 0.5)
#: 14 records, each its lowest collapsed amplitude (None: none collapses).
LOWEST = {f"rdk_{k:02d}": [0.3, 0.5, None, 0.2, 0.4, 0.1, 0.5][k % 7] for k in range(1, 15)}


def suite(folder: str = "/data/ground motions/synthetic suite", members: bool = False,
          ) -> pd.DataFrame:  # fmt: skip
    """A suite's domain as a sweep writes it: excitation.file the records' absolute paths,
    record their names, no frequency; a record survives below its lowest collapsed
    amplitude and collapses from it (member 0's outcome; the fraction 1 or 0)."""
    rows = []
    for name, low in LOWEST.items():
        for a in AMPLITUDES:
            collapsed = low is not None and a >= low
            row = {"excitation.file": f"{folder}/{name}.AT2", "record": name,
                   "amplitude_g": a, "frequency_hz": math.nan,
                   "status": "collapsed" if collapsed else "survived",
                   "collapsed": int(collapsed), "collapse_interface": 1 if collapsed else None,
                   "max_rotation_ratio": 1.0 if collapsed else 0.2}  # fmt: skip
            if members:
                row.update(collapse_fraction=float(collapsed), robust=1)
            rows.append(row)
    return pd.DataFrame(rows)


def legend_texts(ax) -> list[str]:
    return [t.get_text() for t in ax.get_legend().get_texts()]


def by_gid(ax, gid: str):
    return [ln for ln in ax.get_lines() if ln.get_gid() == gid]


def test_records_are_named_on_a_categorical_axis_that_reads():
    """Absolute paths were the x tick labels, overlapping, and the boundary a line across
    unrelated records. The ticks are the records' names (their `record` column), none
    overlapping another when drawn; the boundary is a bar per record at its lowest
    collapsed amplitude, nothing joining them, and none where a record never collapses."""
    df = suite()
    fig = domain_figure(df, None)
    (ax,) = fig.axes
    ticks = ax.get_xticklabels()
    assert [t.get_text() for t in ticks] == list(LOWEST)
    assert ax.get_xlabel() == "record"
    fig.canvas.draw()
    boxes = [t.get_window_extent() for t in ticks]
    assert not any(a.overlaps(b) for a, b in zip(boxes, boxes[1:], strict=False))
    (bars,) = by_gid(ax, "boundary")
    assert bars.get_linestyle() == "None" and bars.get_marker() == "_"
    np.testing.assert_array_equal(bars.get_xdata(), np.arange(len(LOWEST)))
    want = [np.nan if low is None else low for low in LOWEST.values()]
    np.testing.assert_array_equal(bars.get_ydata(), want)
    assert "a bar per record" in bars.get_label()
    texts = [ax.get_title(), fig.texts[0].get_text() if fig.texts else "", *legend_texts(ax)]
    assert not any("/" in t or ".AT2" in t for t in texts), texts


def test_the_command_line_draws_the_suite_by_its_names(tmp_path, monkeypatch):
    """`rbm plot-domain` of such a domain.csv: the same names, no path anywhere."""
    path = tmp_path / "domain.csv"
    suite(str(tmp_path / "records")).to_csv(path, index=False)
    drawn = []
    monkeypatch.setattr(rbm_cli.base.files, "save_figure_atomic",
                        lambda fig, out: drawn.append(fig))  # fmt: skip
    res = CliRunner().invoke(cli, ["plot-domain", str(path), "-o", str(tmp_path / "d.png")])
    assert res.exit_code == 0, res.output
    (fig,) = drawn
    ax = fig.axes[0]
    assert [t.get_text() for t in ax.get_xticklabels()] == list(LOWEST)
    assert str(tmp_path) not in " ".join(t.get_text() for t in ax.get_xticklabels())


def test_records_as_panels_are_titled_by_their_names():
    """A suite over a second axis after the records: one panel per record, titled
    'record rdk_01' (it was 'excitation.file = /data/.../rdk_01.AT2')."""
    df = pd.concat([suite().assign(**{"column.drums": d}) for d in (1, 8)])
    df = df[["excitation.file", "column.drums", *[c for c in df.columns
                                                   if c not in ("excitation.file",
                                                                "column.drums")]]]  # fmt: skip
    df = df[df["record"].isin(["rdk_01", "rdk_02", "rdk_03"])]
    fig = domain_figure(df, None, layout="panels")
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    assert titles == ["record rdk_01", "record rdk_02", "record rdk_03"]


def test_records_of_one_name_in_two_folders_are_told_apart():
    """Two records of one stem from two folders are two categories, named by the end of
    their paths."""
    a, b = suite("/suites/near"), suite("/suites/far")
    a = a[a["record"] == "rdk_01"]
    b = b[b["record"] == "rdk_01"]
    (ax,) = domain_figure(pd.concat([a, b]), None).axes
    assert [t.get_text() for t in ax.get_xticklabels()] == ["near/rdk_01", "far/rdk_01"]


def test_the_legend_lists_what_is_drawn_each_mark_once():
    """The legend listed 'collapsed at the base joint (cross alone)', the same red cross
    as 'unsafe (collapsed)', and a boundary not drawn: member 0's lying under the
    majority's, or a domain where nothing collapsed. Each mark is listed once, and only
    what is drawn."""
    df = suite()
    df.loc[(df["record"] == "rdk_04") & (df["status"] == "collapsed"), "collapse_interface"] = 3
    (ax,) = domain_figure(df, None).axes
    texts = legend_texts(ax)
    assert len(texts) == len(set(texts))
    crosses = [h for h in ax.get_legend().legend_handles
               if getattr(h, "get_marker", lambda: None)() == "x"]  # fmt: skip
    assert len(crosses) == 1, texts
    assert any("upper joint" in t and "cross alone" in t for t in texts)
    # nothing collapsed: no boundary drawn, none listed
    quiet = suite()
    quiet["status"], quiet["collapsed"], quiet["collapse_interface"] = "survived", 0, None
    (ax,) = domain_figure(quiet, None).axes
    assert not any("boundary" in t for t in legend_texts(ax))
    # an ensemble whose member 0 is its majority everywhere: one boundary, listed once
    ax = domain_figure(suite(members=True), None).axes[0]  # (and its colour bar)
    assert not by_gid(ax, "boundary-member0")
    assert sum("boundary" in t for t in legend_texts(ax)) == 1
    # where member 0 differs (it survives where the majority collapses), its bars are drawn
    # where they differ, and listed
    ens = suite(members=True)
    at = (ens["record"] == "rdk_07") & (ens["amplitude_g"] == 0.3)  # its lowest: 0.3 g
    ens.loc[at, ["status", "collapsed", "collapse_interface"]] = ["survived", 0, None]
    ax = domain_figure(ens, None).axes[0]
    (member0,) = by_gid(ax, "boundary-member0")
    y = member0.get_ydata()
    assert y[6] == pytest.approx(0.4) and np.isnan(np.delete(y, 6)).all()
    assert any("member 0" in t for t in legend_texts(ax))


def test_a_plain_sweep_keeps_its_boundary_line():
    """Over frequency (numbers) the boundary is still one line."""
    rows = [{"amplitude_g": a, "frequency_hz": f,
             "status": "collapsed" if a >= 0.2 * f else "survived"}
            for f in (1.0, 2.0) for a in (0.1, 0.2, 0.3, 0.4, 0.5)]  # fmt: skip
    ax = rbm.plot_domain(pd.DataFrame(rows))
    (line,) = by_gid(ax, "boundary")
    assert line.get_linestyle() == "-" and list(line.get_ydata()) == [0.2, 0.4]
