"""Figures read back from what they draw: ida.png in the field's convention, fragility.png's
legend, titles and warnings, a record run's titles and ground panel, and the two p's of
`rbm info`.

Expected values come from the data the tests make (capacities drawn here, so the intensity
at which each record first collapses is known before anything is drawn), from records
written here in closed form (a half-sine, a triangle), and from the closed forms of a
rectangular block (p^2 = 3 g / (4 R), and the RBM's g (H/2) / ((H^2 + B^2)/12 + H^2/4)).
"""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pandas as pd
import pytest
from matplotlib.legend import Legend

import rbm
from rbm_cli.api.cells import check_run_output, write_run_folder
from rbm_cli.config.load import parse_config
from rbm_cli.config.types import G
from rbm_cli.inputs.records import write_csv
from rbm_cli.report.fragility_report import plot_fragility, plot_ida
from rbm_cli.report.fragility_run import compare_title, fragility_figure, suite_name
from rbm_cli.report.info import describe, format_info
from rbm_cli.report.run_figures import history_figure, run_column, run_title, shapes_figure
from rbm_cli.study.fragility import MIN_BAND_RECORDS, fragility

LEVELS = np.round(np.arange(0.1, 1.0001, 0.1), 10)


def _suite(capacities, levels=LEVELS, revive=None):
    """Runs of records whose capacity [g] is given: collapsed at x >= capacity (ratio 1),
    else ratio x / capacity; ``revive`` = (record index, level) survives there anyway."""
    rows = []
    for r, c in enumerate(capacities):
        for x in levels:
            hit = x >= c and (revive is None or (r, x) != revive)
            rows.append(
                {
                    "record": f"r{r:02d}",
                    "amplitude_g": x,
                    "status": "collapsed" if hit else "survived",
                    "collapsed": int(hit),
                    "max_rotation_ratio": 1.0 if hit else x / c,
                }
            )
    return pd.DataFrame(rows)


def _legends(ax):
    return [a for a in ax.get_children() if isinstance(a, Legend)]


# --------------------------------------------------------------------------- ida.png


def test_ida_intensity_up_response_across_flat_after_the_first_collapse():
    capacities = [0.25, 0.55, 0.85, 2.0]  # the last never collapses on the levels
    df = _suite(capacities, revive=(0, 0.6)).sample(frac=1.0, random_state=3)
    ax = plot_ida(df)
    assert "intensity" in ax.get_ylabel() and "[g]" in ax.get_ylabel()
    assert ax.get_xlabel().startswith("peak rotation ratio")
    right = ax.get_xlim()[1]
    lines = {ln.get_gid(): ln for ln in ax.get_lines() if ln.get_gid()}
    for r, c in enumerate(capacities):
        x, y = (np.asarray(v, float) for v in lines[f"record:r{r:02d}"].get_data())
        below = LEVELS[LEVELS < c]
        assert np.all(np.diff(y) >= 0.0)  # intensity never falls along a curve
        if c > LEVELS[-1]:  # never collapsed: its runs, no flat end, no collapse mark
            np.testing.assert_allclose(y, LEVELS)
            np.testing.assert_allclose(x, LEVELS / c)
            assert f"collapse:r{r:02d}" not in lines
            continue
        first = LEVELS[LEVELS >= c][0]  # the first level at or above its capacity
        np.testing.assert_allclose(y, [*below, first, first])
        np.testing.assert_allclose(x, [*(below / c), 1.0, right])
        assert y[-1] == y[-2] and x[-1] == right  # flat out to the right edge
        mx, my = lines[f"collapse:r{r:02d}"].get_data()
        assert list(mx) == [1.0] and list(my) == [first]
    # record 0 survives at 0.6 g, above its first collapse at 0.3 g: off its curve
    ax_, ay_ = lines["above:r00"].get_data()
    assert list(ay_) == [0.6] and list(ax_) == pytest.approx([0.6 / 0.25])
    assert "above:r01" not in lines
    limit = lines["limit"]
    assert list(limit.get_xdata()) == [1.0, 1.0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == [f"r{r:02d}" for r in range(len(capacities))]
    key = next(lg for lg in _legends(ax) if lg is not ax.get_legend())
    keys = [t.get_text() for t in key.get_texts()]
    assert keys[0].startswith("collapse limit")
    assert any("flat" in k for k in keys) and any("above its first collapse" in k for k in keys)


def test_ida_many_records_a_compact_legend_each_record_its_own_style():
    """45 records: named in a legend beside the axes, in 2 columns of at most 25, and no
    two records share a colour and a line style."""
    rng = np.random.default_rng(4)
    df = _suite(list(0.5 * np.exp(0.4 * rng.standard_normal(45))))
    ax = plot_ida(df)
    legend = ax.get_legend()
    assert [t.get_text() for t in legend.get_texts()] == [f"r{r:02d}" for r in range(45)]
    assert legend._ncols == 2
    assert legend.get_title().get_text() == "45 records"
    styles = {(tuple(ln.get_color()), ln.get_linestyle()) for ln in ax.get_lines()
              if str(ln.get_gid()).startswith("record:")}  # fmt: skip
    assert len(styles) == 45
    fig = ax.figure
    fig.canvas.draw()
    box, frame = legend.get_window_extent(), ax.get_window_extent()
    assert box.x0 >= frame.x1  # beside the axes, over no curve


# --------------------------------------------------------------------------- fragility.png


def test_fragility_legend_off_the_points_and_the_axes():
    res = fragility(_suite([0.3, 0.45, 0.5, 0.7, 0.8, 0.35]), n_resamples=50, seed=1)
    ax = plot_fragility(res)
    ax.figure.canvas.draw()
    legend = ax.get_legend()
    box, frame = legend.get_window_extent(), ax.get_window_extent()
    assert box.x0 >= frame.x1  # outside the axes
    points = next(ln for ln in ax.get_lines() if ln.get_gid() == "observed")
    xy = ax.transData.transform(np.column_stack(points.get_data()))
    assert not any(box.contains(px, py) for px, py in xy)
    assert not [t for t in ax.texts if t.get_gid() == "few-records"]


def test_too_few_records_said_on_the_figure():
    """One record, below the MIN_BAND_RECORDS a bootstrap over records needs (the
    count rbm_cli.study.fragility warns at): said on the figure, in red, with the count."""
    assert MIN_BAND_RECORDS == 2
    df = _suite([0.45]).copy()
    revived = df["amplitude_g"] == 0.6  # a survival above a collapse: a finite fit
    df.loc[revived, ["collapsed", "status", "max_rotation_ratio"]] = [0, "survived", 0.9]
    df.loc[df["amplitude_g"] == 0.5, "max_rotation_ratio"] = 0.9
    res = fragility(df, n_resamples=20)
    assert res.n_records == 1 and res.fit is not None
    ax = plot_fragility(res)
    warned = [t for t in ax.texts if t.get_gid() == "few-records"]
    assert len(warned) == 1
    assert "too few records: a fit from 1 record," in warned[0].get_text()
    assert f"below the {MIN_BAND_RECORDS} a bootstrap" in warned[0].get_text()
    assert warned[0].get_color() == "tab:red"
    ax.figure.canvas.draw()  # under the axes, so over no point
    assert warned[0].get_window_extent().y1 <= ax.get_window_extent().y0
    two = fragility(_suite([0.35, 0.65]), n_resamples=20)
    assert not [t for t in plot_fragility(two).texts if t.get_gid() == "few-records"]


def test_compare_titled_by_its_suites():
    meta = {"config_written": {"excitation": {"file": "records/near/*.AT2"}}}
    assert suite_name(meta) == "records/near/*.AT2"
    listed = {"config_written": {"excitation": {"file": ["a.AT2", "b.AT2", "c.AT2"]}}}
    assert suite_name(listed) == "a.AT2 ... (3 files)"
    assert suite_name({}) == ""
    same = compare_title([("tall", "records/near/*.AT2"), ("squat", "records/near/*.AT2")])
    assert same == "fragility of tall, squat\nunder the suite records/near/*.AT2"
    mixed = compare_title([("tall", "records/near/*.AT2"), ("squat", "records/far/*.AT2")])
    assert "under different suites" in mixed
    assert "tall: records/near/*.AT2" in mixed and "squat: records/far/*.AT2" in mixed
    one = fragility(_suite([0.3, 0.5, 0.7, 0.4]), n_resamples=0)
    two = fragility(_suite([0.6, 0.8, 0.9]), n_resamples=0)
    fig = fragility_figure(one, "intensity: peak ground acceleration [g]", same, "tall",
                           [("squat", two)])  # fmt: skip
    ax = fig.axes[0]
    assert ax.get_title() == same
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any(t.startswith("tall (4 records): lognormal MLE") for t in labels)
    assert any(t.startswith("squat (3 records): lognormal MLE") for t in labels)


def test_rbm_fragility_compare_names_the_suites_of_the_stored_domains(tmp_path, monkeypatch):
    """End to end over two copies of a stored suite's domain, named apart in meta.json:
    the figures run_fragility renders are caught before they become PNG bytes."""
    from rbm_cli.report import fragility_run

    from .paths import RESULTS

    source = RESULTS / "suite_multidrum_ci"
    meta = json.loads((source / "meta.json").read_text())
    for name in ("left", "right"):
        (tmp_path / name).mkdir()
        (tmp_path / name / "domain.csv").write_bytes((source / "domain.csv").read_bytes())
        (tmp_path / name / "meta.json").write_text(json.dumps({**meta, "name": name}))
    drawn = []
    monkeypatch.setattr(fragility_run, "_png", lambda fig, dpi=150: drawn.append(fig) or b"")
    right = (tmp_path / "right" / "domain.csv",)
    fragility_run.run_fragility(tmp_path / "left" / "domain.csv", tmp_path / "out",
                                n_resamples=0, compare=right)  # fmt: skip
    files = meta["config_written"]["excitation"]["file"]  # the 4 records, listed
    frag, ida = (fig.axes[0] for fig in drawn)
    assert frag.get_title() == (
        f"fragility of left, right\nunder the suite {files[0]} ... ({len(files)} files)"
    )
    assert ida.get_title().startswith(f"IDA, left: {len(files)} records ({files[0]} ...")
    assert [t.get_text() for t in ida.get_legend().get_texts()] == [
        f"rdk_{k:02d}" for k in range(1, 5)
    ]


# --------------------------------------------------------------------------- record runs

TRIANGLE_PEAK_G = 0.5  # the vertical record: 0 at 0 s, 0.5 g at 0.5 s, 0 at 1 s
FACTOR = 0.1  # scale: factor; the half-sine's 1 g becomes 0.1 g, below the uplift level


@pytest.fixture(scope="module")
def record_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("records")
    t = np.linspace(0.0, 0.25, 2001)  # a 1 g half-sine of 2 Hz, its peak a sample
    write_csv(folder / "h.csv", (t, G * np.sin(np.pi * t / 0.25)), units="g")
    write_csv(folder / "v.csv", (np.array([0.0, 0.5, 1.0]),
                                 G * np.array([0.0, TRIANGLE_PEAK_G, 0.0])), units="g")  # fmt: skip
    data = {"name": "rec", "column": {"height": 2.0, "base_width": 0.5, "drums": 2},
            "interface": {"stiffness": {"normal": 5e9}},
            "excitation": {"type": "record", "file": str(folder / "h.csv"),
                           "vertical": str(folder / "v.csv"), "scale": "factor",
                           "free_time": 0.5}}  # fmt: skip
    cfg = parse_config(data)
    cell = rbm.run(cfg, amplitude_g=FACTOR)
    column = check_run_output(cfg, folder / "out")
    path = write_run_folder(cfg, column, cell.result, folder / "out", None, FACTOR, None, None)
    return cfg, cell, path


def _triangle(t):
    """The vertical record scaled by FACTOR [m/s^2], 0 outside [0, 1] s."""
    return FACTOR * G * TRIANGLE_PEAK_G * np.clip(1.0 - np.abs(t - 0.5) / 0.5, 0.0, None)


def test_history_csv_gains_the_vertical_acceleration(record_run):
    _, cell, path = record_run
    header = (path / "history.csv").read_text().splitlines()[0].split(",")
    assert header[:4] == ["t_s", "ag_m_s2", "av_m_s2", "ug_m"]
    table = pd.read_csv(path / "history.csv")
    np.testing.assert_allclose(table["av_m_s2"], _triangle(table["t_s"].to_numpy()),
                               rtol=1e-9, atol=1e-12)  # fmt: skip
    assert table["t_s"].iloc[-1] > 1.0  # the run outlasts the vertical record: a_v 0 there
    np.testing.assert_allclose(cell.history["av_m_s2"], table["av_m_s2"], rtol=1e-11)
    written = json.loads(json.dumps(record_run[0].written))
    del written["excitation"]["vertical"]
    horizontal = rbm.run(parse_config(written), amplitude_g=FACTOR).history
    assert "av_m_s2" not in horizontal.columns


def test_record_run_titled_with_its_ground_panel(record_run):
    cfg, cell, path = record_run
    summary = json.loads((path / "summary.json").read_text())
    assert summary["record"]["record"] == "h" and summary["record"]["vertical"] == "v"
    assert summary["record"]["pga_g"] == pytest.approx(FACTOR, rel=1e-12)
    assert summary["record"]["vertical_peak_g"] == pytest.approx(FACTOR * TRIANGLE_PEAK_G)
    title = run_title(summary)
    assert title == "rec: record h scaled to PGA 0.1 g (factor 0.1), with vertical record v " \
        "(peak 0.05 g)"  # fmt: skip
    history = cell.result.run_result.history
    av = cell.history["av_m_s2"].to_numpy()
    fig = history_figure(history, None, title, run_column(summary), ground=True, vertical=av)
    assert fig._suptitle.get_text() == title
    ground = fig.axes[0]
    assert ground.get_ylabel() == "ground acc. [g]"
    lines = {ln.get_gid(): ln for ln in ground.get_lines() if ln.get_gid()}
    t = np.asarray(history.t)
    half_sine = np.where(t <= 0.25, FACTOR * np.sin(np.pi * np.minimum(t, 0.25) / 0.25), 0.0)
    np.testing.assert_allclose(lines["a_g"].get_ydata(), half_sine, atol=1e-9)
    np.testing.assert_allclose(lines["a_v"].get_ydata(), _triangle(t) / G, atol=1e-12)
    labels = [tx.get_text() for tx in ground.get_legend().get_texts()]
    assert labels[:2] == ["$a_g$ (horizontal)", "$a_v$ (vertical, upward)"]
    panels = [a for a in fig.axes if a.get_ylabel() != "ground displacement [m]"]
    assert len(panels) == 4  # ground, displacements, top - base, the 2 joints
    assert panels[3].get_title() == "joint rotations against their limits"
    shapes = shapes_figure(history, [0.5, 0.5, 0.5], [0.0, 1.0, 2.0], None, title)
    assert shapes._suptitle.get_text() == title


def test_record_title_with_scale_pga_and_no_vertical():
    summary = {"config_written": {"name": "c", "excitation": {"type": "record"}},
               "inputs": {"amplitude_g": 0.35, "frequency_hz": None},
               "record": {"record": "rdk_07", "pga_g": 0.35, "scale": "pga",
                          "vertical": None, "vertical_peak_g": None}}  # fmt: skip
    assert run_title(summary) == "c: record rdk_07 scaled to PGA 0.35 g"


# --------------------------------------------------------------------------- the two p's


def test_info_names_both_ps_and_gives_the_true_solids_for_housner():
    """A rectangular block, B = 0.5 m, H = 2 m: the RBM's p^2 = g (H/2) / ((H^2 + B^2)/12
    + H^2/4); the true solid's p^2 = 3 g / (4 R), R = sqrt((B/2)^2 + (H/2)^2)."""
    b, h = 0.5, 2.0
    rbm_p = math.sqrt(G * (h / 2) / ((h * h + b * b) / 12 + h * h / 4))
    true_p = math.sqrt(3 * G / (4 * math.hypot(b / 2, h / 2)))
    for model, domain in (("rbm", rbm_p), ("housner", true_p)):
        cfg = parse_config({"name": "b", "model": model,
                            "column": {"height": h, "base_width": b}})  # fmt: skip
        info = describe(cfg)
        assert info["rocking_p_rad_s"] == pytest.approx(rbm_p, rel=1e-12)
        assert info["domain_p_rad_s"] == pytest.approx(domain, rel=1e-12)
        text = format_info(info)
        rows = dict(line.split(":", 1) for line in text.splitlines() if ":" in line)
        assert rows["rocking p"].strip() == f"{rbm_p:.4g} rad/s"
        assert rows["domain p_rad_s"].strip().startswith(f"{domain:.4g} rad/s, alpha_rad")
        assert "rocking p is" in rows
    assert "true solid" in rows["domain p_rad_s"] and "b/z_c" in rows["domain p_rad_s"]


def test_info_says_the_multidrum_domain_p_is_the_glued_monolith():
    cfg = parse_config({"name": "t", "column": {"height": 5.0, "base_width": 0.96,
                                                 "top_width": 0.66, "drums": 4},
                        "interface": {"stiffness": {"normal": 5e9}}})  # fmt: skip
    info = describe(cfg)
    glued = describe(rbm.with_value(cfg, "column.drums", 1))
    assert info["domain_p_rad_s"] == pytest.approx(glued["rocking_p_rad_s"], rel=1e-12)
    assert info["domain_p_rad_s"] != pytest.approx(info["rocking_p_rad_s"], rel=1e-3)
    text = format_info(info)
    assert re.search(r"rocking p is:\s+the RBM's 4 drums rocking as one rigid stack", text)
    assert "drums glued into one drum of height H" in text


def test_counts_are_of_trials_and_left_out_where_they_would_cover_each_other():
    """Beside each point the collapses over the trials that made it: every ensemble member
    of a record where members count; with one point per record and level (an intensity
    measure of each record's own) the labels would cover each other, and are left out."""
    from matplotlib.figure import Figure

    from rbm_cli.report.fragility_report import MAX_COUNT_LABELS, _plot_observed

    few = pd.DataFrame({"intensity_g": [0.1, 0.2, 0.3], "fraction": [0.0, 0.5, 1.0],
                        "n_collapsed": [0, 8, 32], "n_records": [2, 1, 2],
                        "n_trials": [32, 16, 32]})  # fmt: skip
    fig = Figure()
    ax = fig.add_subplot()
    _plot_observed(ax, few, "", None, True)
    assert [t.get_text() for t in ax.texts] == ["0/32", "8/16", "32/32"]
    assert ax.get_lines()[0].get_label().endswith("(collapsed/trials)")
    n = MAX_COUNT_LABELS + 1
    many = pd.DataFrame({"intensity_g": np.linspace(0.1, 1, n), "fraction": np.zeros(n),
                         "n_collapsed": np.zeros(n, int), "n_records": np.ones(n, int),
                         "n_trials": np.ones(n, int)})  # fmt: skip
    fig = Figure()
    ax = fig.add_subplot()
    _plot_observed(ax, many, "", None, True)
    assert not ax.texts and ax.get_lines()[0].get_label() == "observed fraction collapsed"
