"""Domains over more axes and in dimensionless axes: what the figures draw, read back from
the artists (gids, offsets, line data), against closed forms and the domain's own tables.

Expected values: a rigid rectangular RBM monolith of height H and base B maps to the
linear block with tan alpha = B / H and p^2 = 6 g H / (4 H^2 + B^2)
(rbm_cli.structures.closed_forms.linear_rocking_parameters, its docstring), so omega / p and
A / (g tan alpha) of every cell follow from the grid alone; the exact half-sine threshold
of that block is linear_halfsine_threshold, and the rigid RBM overturns at it (a size sweep
collapses onto it in dimensionless axes).
"""

from __future__ import annotations

import json
import math
import shutil

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402
from click.testing import CliRunner  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

import rbm  # noqa: E402
from rbm_cli.cli.main import cli  # noqa: E402
from rbm_cli.config.types import G  # noqa: E402
from rbm_cli.report.domain_figure import domain_figure  # noqa: E402
from rbm_cli.report.domain_view import axis_groups, domain_view  # noqa: E402
from rbm_cli.structures.closed_forms import (  # noqa: E402
    housner_halfsine_threshold,
    linear_halfsine_threshold,
    linear_rocking_parameters,
)
from rbm_cli.structures.column import build_column  # noqa: E402
from rbm_cli.study.domain import domain_config, read_domain  # noqa: E402
from rbm_cli.study.schema import SCALE_COLUMNS as SCALE_FIELDS  # noqa: E402

from .paths import RESULTS  # noqa: E402

H, B = 2.0, 0.5  # the block: slenderness H / B = 4
SIZES = (1.0, math.sqrt(20.0), 20.0)  # column.size: {start: 1, stop: 20, num: 3, log}
FREQS = (0.5, 1.0, 2.0)
STEP = 0.05  # amplitude step [g]

SIZE_SWEEP = {
    "name": "size_effect",
    "column": {"height": H, "base_width": B},
    "interface": {"stiffness": "rigid", "restitution": 1.0},
    "excitation": {"type": "half-sine", "duration": 10.0},
    "grid": {
        "amplitudes": {"start": STEP, "stop": 2.0, "step": STEP},
        "frequencies": list(FREQS),
        "column.size": {"start": 1, "stop": 20, "num": 3, "spacing": "log"},
    },
}


def rectangle_scales(height: float, base: float) -> tuple[float, float]:
    """(tan alpha, p [rad/s]) of a rigid rectangular RBM monolith (module docstring)."""
    return base / height, math.sqrt(6.0 * G * height / (4.0 * height**2 + base**2))


def sweep(tmp_path_factory, written: dict) -> pd.DataFrame:
    out = tmp_path_factory.mktemp("domains")
    rbm.sweep(written, out)
    return out / written["name"] / "domain.csv"


@pytest.fixture(scope="module")
def size_csv(tmp_path_factory):
    return sweep(tmp_path_factory, SIZE_SWEEP)


@pytest.fixture(scope="module")
def one_frequency_csv(tmp_path_factory):
    written = json.loads(json.dumps(SIZE_SWEEP))
    written["name"] = "size_at_2hz"
    written["grid"]["frequencies"] = [2.0]
    written["grid"]["column.size"]["num"] = 5
    return sweep(tmp_path_factory, written)


def drawn(ax, gid):
    return [a for a in (*ax.lines, *ax.collections) if a.get_gid() == gid]


def one(ax, gid):
    found = drawn(ax, gid)
    assert len(found) == 1, f"expected one artist {gid!r}, found {len(found)}"
    return found[0]


def xy(artist) -> np.ndarray:
    points = artist.get_offsets() if hasattr(artist, "get_offsets") else artist.get_xydata()
    return np.asarray(points, float).reshape(-1, 2)


def sorted_rows(points) -> np.ndarray:
    points = np.asarray(points, float).reshape(-1, 2)
    return points[np.lexsort((points[:, 1], points[:, 0]))]


def panels(fig) -> list:
    return [ax for ax in fig.axes if ax.get_title()]


# --------------------------------------------------------------------------- dimensionless


def test_dimensionless_cells_sit_at_the_scales_of_the_csv_and_of_the_rectangle(size_csv):
    df, cfg = read_domain(size_csv), domain_config(size_csv)
    axes = panels(domain_figure(df, cfg, dimensionless=True))
    assert len(axes) == len(SIZES)
    for gid, status in (("safe", "survived"), ("unsafe", "collapsed")):
        rows = df[df["status"] == status]
        want = rows[["omega_over_p", "a_over_g_alpha"]].to_numpy(float)
        got = np.vstack([xy(one(ax, gid)) for ax in axes])
        np.testing.assert_array_equal(sorted_rows(got), sorted_rows(want))
    ax = axes[-1]
    # the CSV's scales are those of the rectangle of each size
    tan_alpha, p = np.transpose([rectangle_scales(s, s * B / H) for s in df["column.size"]])
    np.testing.assert_allclose(df["omega_over_p"], 2 * np.pi * df["frequency_hz"] / p, rtol=1e-9)
    np.testing.assert_allclose(df["a_over_g_alpha"], df["amplitude_g"] / tan_alpha, rtol=1e-9)
    assert ax.get_xlabel() == r"$\omega / p$ [-]"
    assert ax.get_ylabel() == r"$A / (g \tan\alpha)$ [-]"


def test_the_closed_forms_are_drawn_in_the_dimensionless_axes(size_csv):
    df, cfg = read_domain(size_csv), domain_config(size_csv)
    for layout in ("overlay", "panels"):
        fig = domain_figure(df, cfg, dimensionless=True, layout=layout)
        for ax in fig.axes:
            x, y = one(ax, "linear").get_data()
            assert len(x) > 100
            np.testing.assert_allclose(y, [linear_halfsine_threshold(v) for v in x], rtol=1e-12)
            x, y = one(ax, "housner").get_data()
            np.testing.assert_allclose(y, np.sqrt(1.0 + np.asarray(x) ** 2), rtol=1e-12)
            # the uplift level of a monolith: A = g tan alpha
            np.testing.assert_allclose(one(ax, "static").get_ydata(), 1.0, rtol=1e-12)


def test_a_size_sweep_collapses_onto_the_exact_threshold(size_csv):
    """Dimensionless overlay: each size's boundary is at or above the exact linear threshold
    and less than one amplitude step (over tan alpha) above it: one curve for all sizes."""
    df, cfg = read_domain(size_csv), domain_config(size_csv)
    (ax,) = domain_figure(df, cfg, dimensionless=True, layout="overlay").axes
    for k, size in enumerate(SIZES):
        line = one(ax, f"boundary-{k}")
        assert line.get_label() == f"column.size = {size:.3g} m"
        x, y = (np.asarray(v, float) for v in line.get_data())
        tan_alpha, p = rectangle_scales(size, size * B / H)
        np.testing.assert_allclose(x, 2 * np.pi * np.asarray(FREQS) / p, rtol=1e-9)
        exact = np.asarray(linear_halfsine_threshold(x))
        seen = np.isfinite(y)
        assert seen.sum() >= 2, size
        assert np.all(y[seen] >= exact[seen] - 1e-9)
        assert np.all(y[seen] < exact[seen] + STEP / tan_alpha + 1e-9)


def test_an_old_domain_and_its_config_give_the_positions_of_a_fresh_one(size_csv, tmp_path):
    fresh = read_domain(size_csv)
    old = tmp_path / "old" / "domain.csv"
    old.parent.mkdir()
    fresh.drop(columns=list(SCALE_FIELDS)).to_csv(old, index=False)
    shutil.copy(size_csv.with_name("meta.json"), old.with_name("meta.json"))
    cfg = domain_config(old)
    (a,) = domain_figure(fresh, cfg, dimensionless=True, layout="overlay").axes
    (b,) = domain_figure(read_domain(old), cfg, dimensionless=True, layout="overlay").axes
    for gid in ("safe", "unsafe", "boundary-0", "boundary-2"):  # the CSV keeps 12 digits
        np.testing.assert_allclose(xy(one(b, gid)), xy(one(a, gid)), rtol=1e-11)


def test_a_stored_domain_without_scales_is_drawn_dimensionless_from_its_config():
    """results/housner_halfsine without its scale columns (as a domain written before they
    existed): the tapered monolith, tan alpha = B_1 / H = 0.96 / 5; x = 2 pi f / p of its
    linear model."""
    csv = RESULTS / "housner_halfsine" / "domain.csv"
    df, cfg = read_domain(csv), domain_config(csv)
    df = df.drop(columns=[c for c in SCALE_FIELDS if c in df.columns])
    fig = domain_figure(df, cfg, dimensionless=True)
    (ax,) = [a for a in fig.axes if a.get_xlabel() == r"$\omega / p$ [-]"]
    _, p = linear_rocking_parameters(build_column(cfg.column, cfg.interface))
    rows = df[df["status"] == "collapsed"]
    want = np.column_stack([2 * np.pi * rows["frequency_hz"] / p, rows["amplitude_g"] / 0.192])
    np.testing.assert_allclose(sorted_rows(xy(one(ax, "unsafe"))), sorted_rows(want), rtol=1e-12)
    x, y = one(ax, "linear").get_data()
    np.testing.assert_allclose(y, [linear_halfsine_threshold(v) for v in x], rtol=1e-12)


# --------------------------------------------------------------------------- panels and overlay


def test_panels_one_axes_per_point_titled_by_it(size_csv):
    df, cfg = read_domain(size_csv), domain_config(size_csv)
    fig = domain_figure(df, cfg)  # the sweep's domain.png: panels by default
    axes = panels(fig)
    assert [ax.get_title() for ax in axes] == ["column.size = 1 m", "column.size = 4.47 m",
                                               "column.size = 20 m"]  # fmt: skip
    bnd = pd.read_csv(size_csv.with_name("boundary.csv"))
    for ax, size in zip(axes, SIZES, strict=True):
        rows = df[np.isclose(df["column.size"], size)]
        n = sum(len(xy(one(ax, g))) for g in ("safe", "unsafe"))
        assert n == len(rows) == len(FREQS) * 40
        line = bnd[np.isclose(bnd["column.size"], size)]
        x, y = one(ax, "boundary").get_data()
        np.testing.assert_array_equal(x, line["frequency_hz"])
        np.testing.assert_array_equal(y, line["lowest_unsafe_g"])
        # the point's own closed form, in g: tan alpha times the dimensionless threshold
        tan_alpha, p = rectangle_scales(size, size * B / H)
        f, a = one(ax, "linear").get_data()
        np.testing.assert_allclose(a, tan_alpha * linear_halfsine_threshold(2 * np.pi * f / p),
                                   rtol=1e-12)  # fmt: skip
    assert axes[0].get_shared_x_axes().joined(axes[0], axes[2])
    assert axes[0].get_shared_y_axes().joined(axes[0], axes[1])
    title, note = fig._suptitle.get_text().split("\n")
    assert title == "size_effect: safe-unsafe domain (half-sine)"
    assert note.startswith("column: H = over the grid, B = over the grid")


def test_overlay_one_boundary_line_per_point_with_its_label(size_csv):
    df, cfg = read_domain(size_csv), domain_config(size_csv)
    (ax,) = domain_figure(df, cfg, layout="overlay").axes
    bnd = pd.read_csv(size_csv.with_name("boundary.csv"))
    lines = [ln for ln in ax.lines if str(ln.get_gid()).startswith("boundary-")]
    assert len(lines) == len(SIZES)
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    for k, size in enumerate(SIZES):
        line = one(ax, f"boundary-{k}")
        # each point's label names its static multiplier: tan alpha = B / H of every size
        assert line.get_label() == f"column.size = {size:.3g} m, static multiplier {B / H:.3g} g"
        assert line.get_label() in texts
        want = bnd[np.isclose(bnd["column.size"], size)]["lowest_unsafe_g"]
        np.testing.assert_array_equal(line.get_ydata(), want)
    # the cells are there, faint, under the lines: once per place and status (the sizes
    # share the grid, so each (frequency, amplitude) holds the marks its sizes disagree on)
    assert all(a.get_alpha() < 0.5 for g in ("safe", "unsafe") for a in drawn(ax, g))
    for gid, status in (("safe", "survived"), ("unsafe", "collapsed")):
        want = df[df["status"] == status][["frequency_hz", "amplitude_g"]].drop_duplicates()
        np.testing.assert_array_equal(sorted_rows(xy(one(ax, gid))), sorted_rows(want))
    assert len(drawn(ax, "linear-0")) == 1 and "boundary" not in [a.get_gid() for a in ax.lines]


def test_one_frequency_puts_the_size_on_a_log_x_axis(one_frequency_csv):
    df, cfg = read_domain(one_frequency_csv), domain_config(one_frequency_csv)
    fig = domain_figure(df, cfg)
    (ax,) = fig.axes
    assert ax.get_xscale() == "log" and ax.get_xlabel() == "column.size [m]"
    assert ax.get_ylabel() == "amplitude [g]" and ax.get_title().split("\n")[0].endswith("at 2 Hz")
    rows = df[df["status"] == "collapsed"]
    want = rows[["column.size", "amplitude_g"]].to_numpy(float)
    np.testing.assert_array_equal(sorted_rows(xy(one(ax, "unsafe"))), sorted_rows(want))
    sizes = np.unique(df["column.size"])
    x, y = one(ax, "linear").get_data()
    np.testing.assert_allclose(x, sizes)
    tan_alpha, p = np.transpose([rectangle_scales(s, s * B / H) for s in sizes])
    np.testing.assert_allclose(y, tan_alpha * linear_halfsine_threshold(4 * np.pi / p), rtol=1e-12)
    x, y = one(ax, "housner").get_data()
    np.testing.assert_allclose(y, tan_alpha * housner_halfsine_threshold(4 * np.pi / p))
    # Housner's size effect: the larger column needs the larger amplitude
    x, y = one(ax, "boundary").get_data()
    assert np.all(np.diff(np.asarray(y)[np.isfinite(y)]) >= 0) and y[-2] > y[0]


def test_many_points_are_an_overlay_and_linked_axes_are_one(tmp_path):
    """13 heights x 2 frequencies (no config): the sweep's figure is an overlay; linked
    columns (height and width together) are one axis and name each point together."""
    rows = []
    for h in np.linspace(1.0, 13.0, 13):
        for f in (1.0, 2.0):
            for a in (0.1, 0.5, 1.0):
                status = "collapsed" if a >= 0.5 * f else "survived"
                rows.append({"column.height": h, "column.base_width": h / 4, "amplitude_g": a,
                             "frequency_hz": f, "status": status})  # fmt: skip
    df = pd.DataFrame(rows)
    assert axis_groups(df) == [("column.height", "column.base_width")]
    (ax,) = domain_figure(df, None, labels=["heights"]).axes
    lines = [ln for ln in ax.lines if str(ln.get_gid()).startswith("boundary-")]
    assert len(lines) == 13
    assert lines[1].get_label() == "column.height = 2 m, column.base_width = 0.5 m"
    np.testing.assert_array_equal(lines[0].get_ydata(), [0.5, 1.0])
    fig = domain_figure(df.iloc[: 6 * 4], None, layout="panels")
    assert len(panels(fig)) == 4


def test_ensemble_panels_share_one_colour_bar_below_them():
    rows = [{"interface.restitution": e, "amplitude_g": a, "frequency_hz": f,
             "status": "collapsed" if a > 0.3 else "survived", "collapse_fraction": a}
            for e in (0.7, 0.8, 0.9) for f in (1.0, 2.0) for a in (0.2, 0.4, 0.6)]  # fmt: skip
    fig = domain_figure(pd.DataFrame(rows), None, labels=["restitution"])
    axes = panels(fig)
    assert [ax.get_title() for ax in axes] == [f"interface.restitution = {e}"
                                               for e in (0.7, 0.8, 0.9)]  # fmt: skip
    (bar,) = [ax for ax in fig.axes if ax not in axes]
    assert bar.get_xlabel() == "fraction of ensemble members that collapsed [-]"
    fig.canvas.draw()
    # the bar and its label lie below the panels' lowest tick labels [px], nothing overlaps
    assert bar.get_tightbbox().y1 < min(ax.get_tightbbox().y0 for ax in axes)


def test_a_non_numeric_axis_at_one_frequency_is_named_on_the_ticks():
    df = pd.DataFrame({"excitation.file": ["a.csv"] * 2 + ["b.csv"] * 2,
                       "amplitude_g": [0.1, 0.5] * 2, "frequency_hz": [np.nan] * 4,
                       "status": ["survived", "collapsed", "survived", "survived"]})  # fmt: skip
    view = domain_view(df)
    assert view.layout == "single" and view.line == "excitation.file"
    (ax,) = domain_figure(df, None).axes
    assert [t.get_text() for t in ax.get_xticklabels()] == ["a", "b"]  # the records' names
    np.testing.assert_array_equal(one(ax, "boundary").get_ydata(), [0.5, np.nan])
    assert one(ax, "boundary").get_linestyle() == "None"  # a bar per record, no line


# --------------------------------------------------------------------------- the API


def test_api_plot_domain_takes_dimensionless_and_layout(size_csv):
    df, cfg = read_domain(size_csv), domain_config(size_csv)
    fig = Figure()
    ax = fig.add_subplot()
    assert rbm.plot_domain(df, ax=ax, config=cfg, dimensionless=True, layout="overlay") is ax
    assert one(ax, "boundary-1").get_label() == "column.size = 4.47 m"
    fig = Figure()
    axes = rbm.plot_domain(df, ax=fig.add_subplot(), config=cfg, layout="panels")
    assert len(axes) == 3 and fig.axes == axes
    with pytest.raises(rbm.RbmError, match="overlay needs axes beyond amplitude"):
        rbm.plot_domain(df[df["column.size"] == 1.0].drop(columns="column.size"),
                        layout="overlay")  # fmt: skip


# --------------------------------------------------------------------------- refusals


def invoke(*args):
    return CliRunner().invoke(cli, [str(a) for a in args])


def refused(res, *words):
    assert res.exit_code == 2, res.output
    assert len(res.output.strip().splitlines()) == 1, res.output
    assert "Traceback" not in res.output
    for word in words:
        assert word in res.output, res.output


def test_bad_flags_are_refused_in_one_line(tmp_path, size_csv):
    plain = tmp_path / "plain" / "domain.csv"
    plain.parent.mkdir()
    stored = read_domain(RESULTS / "spanos_koh_slender" / "domain.csv")  # no meta.json, and
    stored.drop(columns=list(SCALE_FIELDS)).to_csv(plain, index=False)  # no scale columns
    refused(invoke("plot-domain", plain, "--overlay"), "--overlay needs axes beyond")
    refused(invoke("plot-domain", plain, "--panels"), "--panels needs axes beyond")
    refused(invoke("plot-domain", size_csv, "--panels", "--overlay"), "exclude each other")
    refused(invoke("plot-domain", plain, "--dimensionless"), "no config", "--config")
    record = tmp_path / "record" / "domain.csv"
    record.parent.mkdir()
    record.write_text("amplitude_g,frequency_hz,status\n0.1,,survived\n0.5,,collapsed\n")
    refused(invoke("plot-domain", record, "--dimensionless"), "frequency", str(record))
    refused(invoke("plot-domain", size_csv, "--overlay", "--compare", plain), "--overlay")
    assert sorted(p.name for p in plain.parent.iterdir()) == ["domain.csv"]
    assert not record.with_name("domain.png").exists()


def test_the_cli_draws_the_dimensionless_overlay(tmp_path, size_csv):
    out = tmp_path / "collapse.png"
    res = invoke("plot-domain", size_csv, "--dimensionless", "--overlay", "-o", out)
    assert res.exit_code == 0, res.output
    assert out.stat().st_size > 10_000
    plain = tmp_path / "slender.png"
    res = invoke("plot-domain", RESULTS / "spanos_koh_slender" / "domain.csv", "-o", plain,
                 "--dimensionless")  # fmt: skip
    assert res.exit_code == 0, res.output
