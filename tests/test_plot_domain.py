"""The domain plot: what it draws, from synthetic domains; it never writes files."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import math  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from rbm_cli.config.types import ColumnConfig, InterfaceConfig, StiffnessConfig  # noqa: E402
from rbm_cli.report.plot_domain import boundary, plot_domain  # noqa: E402
from rbm_cli.structures.closed_forms import halfsine_threshold_curves  # noqa: E402
from rbm_cli.structures.column import build_column  # noqa: E402

FREQS = (0.5, 1.0, 1.5, 2.0, 2.5)
AMPS = tuple(np.round(np.arange(0.1, 1.01, 0.1), 10))
#: Collapse threshold per frequency [g]; None: nothing collapses in the grid.
THRESHOLDS = {0.5: 0.3, 1.0: 0.4, 1.5: 0.6, 2.0: 0.8, 2.5: None}


def synthetic_domain(thresholds=THRESHOLDS, failed=(), island=None, fraction=False):
    """Grid domain: collapsed at and above the threshold; `failed` cells are failed runs;
    `island` (a, f) is an extra isolated collapsed cell below the threshold."""
    rows = []
    for f in FREQS:
        for a in AMPS:
            thr = thresholds[f]
            collapsed = (thr is not None and a >= thr - 1e-9) or (a, f) == island
            status = "collapsed" if collapsed else "survived"
            if (a, f) in failed:
                status = "failed"
            row = {
                "amplitude_g": a,
                "frequency_hz": f,
                "status": status,
                "collapsed": int(status == "collapsed"),
            }
            if fraction:
                row["collapse_fraction"] = 1.0 if collapsed else min(1.0, a / 2)
            rows.append(row)
    return pd.DataFrame(rows)


def _column(height=5.0, base=0.96, top=0.66, drums=1, stiffness=None):
    cfg = ColumnConfig(
        height=height, base_width=base, top_width=top, drum_heights=(height / drums,) * drums
    )
    return build_column(cfg, InterfaceConfig(stiffness=stiffness or StiffnessConfig()))


def _by_gid(ax, gid):
    return [a for a in (*ax.lines, *ax.collections) if a.get_gid() == gid]


def _line(ax, gid):
    found = [ln for ln in ax.lines if ln.get_gid() == gid]
    assert len(found) == 1, f"expected one line with gid {gid!r}, found {len(found)}"
    return found[0]


@pytest.fixture(autouse=True)
def _no_saving_and_close(monkeypatch, tmp_path):
    """The plot function must not save or show, nor write into the working tree."""

    def refuse(*args, **kwargs):
        raise AssertionError("plot_domain must not save or show")

    monkeypatch.setattr(Figure, "savefig", refuse)
    monkeypatch.setattr(plt, "show", refuse)
    monkeypatch.chdir(tmp_path)
    yield
    assert list(tmp_path.iterdir()) == [], "something was written to the working directory"
    plt.close("all")


# --------------------------------------------------------------------------- cells
def test_safe_and_unsafe_points_and_axes():
    df = synthetic_domain()
    ax = plot_domain(df)
    safe, unsafe = _line(ax, "safe"), _line(ax, "unsafe")
    n_unsafe = int((df.status == "collapsed").sum())
    assert len(unsafe.get_xdata()) == n_unsafe == 8 + 7 + 5 + 3
    assert len(safe.get_xdata()) == len(df) - n_unsafe
    assert safe.get_marker() == "o" and safe.get_markerfacecolor() == "none"
    assert unsafe.get_marker() == "x"
    assert not _by_gid(ax, "failed")
    assert ax.get_xlabel() == "frequency [Hz]"
    assert ax.get_ylabel() == "amplitude [g]"
    assert ax.get_ylim()[0] == 0.0


def test_given_axes_is_used_and_returned():
    fig, ax = plt.subplots()
    assert plot_domain(synthetic_domain(), ax=ax) is ax
    assert fig.axes == [ax]


def test_failed_cells_drawn_grey_with_legend_only_if_any():
    df = synthetic_domain(failed=((0.2, 1.0), (0.9, 2.5)))
    ax = plot_domain(df)
    failed = _line(ax, "failed")
    np.testing.assert_array_equal(failed.get_xdata(), [1.0, 2.5])
    np.testing.assert_array_equal(failed.get_ydata(), [0.2, 0.9])
    assert failed.get_marker() == "s"
    assert "failed run" in [t.get_text() for t in ax.get_legend().get_texts()]
    assert len(_line(ax, "safe").get_xdata()) + len(_line(ax, "unsafe").get_xdata()) == len(df) - 2

    ax2 = plot_domain(synthetic_domain())
    assert "failed run" not in [t.get_text() for t in ax2.get_legend().get_texts()]


# --------------------------------------------------------------------------- boundary
def test_boundary_line_is_lowest_unsafe_amplitude():
    df = synthetic_domain(island=(0.2, 1.5))  # non-monotonic: an isolated low collapse
    ax = plot_domain(df)
    line = _line(ax, "boundary")
    np.testing.assert_array_equal(line.get_xdata(), FREQS)
    np.testing.assert_allclose(line.get_ydata(), [0.3, 0.4, 0.2, 0.8, np.nan], equal_nan=True)


def test_boundary_table():
    bnd = boundary(synthetic_domain(island=(0.2, 1.5)).sample(frac=1.0, random_state=1))
    assert list(bnd.columns) == ["frequency_hz", "lowest_unsafe_g", "highest_safe_g"]
    np.testing.assert_array_equal(bnd.frequency_hz, FREQS)
    np.testing.assert_allclose(bnd.lowest_unsafe_g, [0.3, 0.4, 0.2, 0.8, np.nan], equal_nan=True)
    np.testing.assert_allclose(bnd.highest_safe_g, [0.2, 0.3, 0.1, 0.7, 1.0])


def test_compared_boundaries_have_labels_and_colours():
    main = synthetic_domain()
    other = synthetic_domain({0.5: 0.2, 1.0: 0.3, 1.5: 0.5, 2.0: None, 2.5: None})
    ax = plot_domain(main, compare=[other], labels=["RBM", "housner-linear"])
    line = _line(ax, "compare-0")
    np.testing.assert_allclose(line.get_ydata(), [0.2, 0.3, 0.5, np.nan, np.nan], equal_nan=True)
    assert line.get_color() != _line(ax, "boundary").get_color()
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "RBM: boundary" in texts and "housner-linear: boundary" in texts
    with pytest.raises(ValueError, match="labels"):
        plot_domain(main, compare=[other], labels=["only one"])


# --------------------------------------------------------------------------- static line
def test_static_multiplier_line():
    ax = plot_domain(synthetic_domain(), static_multiplier=0.192)
    np.testing.assert_allclose(_line(ax, "static").get_ydata(), [0.192, 0.192])
    assert _line(ax, "static").get_linestyle() == "--"
    assert not _by_gid(plot_domain(synthetic_domain()), "static")


def test_static_multiplier_defaults_to_the_column():
    col = _column()
    ax = plot_domain(synthetic_domain(), column=col, excitation_type="harmonic")
    np.testing.assert_allclose(_line(ax, "static").get_ydata(), col.static_multiplier)


# --------------------------------------------------------------------------- closed forms
def test_closed_form_curves_for_rigid_halfsine_monolith():
    col = _column()
    ax = plot_domain(synthetic_domain(), column=col, excitation_type="half-sine")
    housner, linear = _line(ax, "housner"), _line(ax, "linear")
    f = np.asarray(linear.get_xdata())
    assert f[0] == min(FREQS) and f[-1] == max(FREQS)
    curves = halfsine_threshold_curves(col, f)
    np.testing.assert_allclose(housner.get_ydata(), curves["housner"], rtol=1e-14)
    np.testing.assert_allclose(linear.get_ydata(), curves["linear"], rtol=1e-14)
    assert np.all(np.asarray(linear.get_ydata()) <= np.asarray(housner.get_ydata()))


@pytest.mark.parametrize(
    "column_kwargs, excitation",
    [
        ({}, "harmonic"),
        ({}, None),
        ({"stiffness": StiffnessConfig("normal", (5e9,))}, "half-sine"),
        ({"drums": 2, "stiffness": StiffnessConfig("normal", (5e9,))}, "half-sine"),
        (None, "half-sine"),
    ],
)
def test_no_closed_form_curves_elsewhere(column_kwargs, excitation):
    col = None if column_kwargs is None else _column(**column_kwargs)
    ax = plot_domain(synthetic_domain(), column=col, excitation_type=excitation)
    assert not _by_gid(ax, "housner") and not _by_gid(ax, "linear")


def test_closed_forms_do_not_stretch_the_amplitude_axis():
    """Housner's curve grows ~linearly with frequency; the axis follows the grid."""
    col = _column()
    df = synthetic_domain()
    df["frequency_hz"] = df["frequency_hz"] * 10  # up to 25 Hz: curves far above 1 g
    ax = plot_domain(df, column=col, excitation_type="half-sine")
    assert max(_line(ax, "housner").get_ydata()) > 5.0
    assert ax.get_ylim()[1] == pytest.approx(1.06 * max(AMPS))


# --------------------------------------------------------------------------- ensembles
def test_collapse_fraction_colours_points_with_colourbar():
    df = synthetic_domain(fraction=True, failed=((0.1, 0.5),))
    fig, ax = plt.subplots()
    plot_domain(df, ax=ax)
    (safe,), (unsafe,), (failed,) = (_by_gid(ax, g) for g in ("safe", "unsafe", "failed"))
    assert len(unsafe.get_offsets()) == int((df.status == "collapsed").sum())
    assert len(safe.get_offsets()) == int((df.status == "survived").sum())
    assert len(failed.get_offsets()) == 1
    assert len(fig.axes) == 2  # the colour bar
    cbar = fig.axes[1]  # below the axes (horizontal): the label is on its x axis
    assert cbar.get_xlabel() == "fraction of ensemble members that collapsed [-]"
    # colours follow the fraction: collapsed cells (fraction 1) share one colour
    assert len(np.unique(np.asarray(unsafe.get_facecolors()), axis=0)) == 1
    assert len(np.unique(np.asarray(safe.get_edgecolors()), axis=0)) > 1
    # the boundary is the majority's: at 2.5 Hz member 0 survives 1.0 g, which half of
    # the members (fraction 0.5) collapse; member 0's own boundary is drawn beside it
    np.testing.assert_allclose(
        _line(ax, "boundary").get_ydata(), [0.3, 0.4, 0.6, 0.8, 1.0], equal_nan=True
    )
    np.testing.assert_allclose(
        _line(ax, "boundary-member0").get_ydata(),
        [0.3, 0.4, 0.6, 0.8, math.nan],
        equal_nan=True,
    )


def test_rendered_png_is_written_only_where_asked(tmp_path_factory):
    """A full plot renders (Agg) to a file in a temporary folder only."""
    out = tmp_path_factory.mktemp("png") / "domain.png"
    fig, ax = plt.subplots(figsize=(7, 5))
    other = synthetic_domain({0.5: 0.2, 1.0: 0.3, 1.5: 0.5, 2.0: None, 2.5: None})
    plot_domain(
        synthetic_domain(failed=((0.5, 2.5),)),
        ax=ax,
        compare=[other],
        labels=["rbm", "other"],
        column=_column(),
        excitation_type="half-sine",
    )
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig).print_png(str(out))
    assert out.stat().st_size > 10_000
    # read back: the figure's size in pixels, and not blank (many colours drawn)
    image = plt.imread(str(out))
    assert image.shape[:2] == (5 * fig.dpi, 7 * fig.dpi)
    assert len(np.unique(image.reshape(-1, image.shape[-1]), axis=0)) > 10


# --------------------------------------------------------------------------- readability
def test_a_lone_boundary_is_labelled_by_what_it_is_not_by_a_file_name():
    ax = plot_domain(synthetic_domain(), labels=["spanos_koh_slender"])
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "boundary (lowest collapsed amplitude)" in texts
    assert not any("spanos_koh_slender" in t for t in texts)


@pytest.mark.parametrize("fraction", [False, True])
def test_cells_are_drawn_above_the_boundary_and_level_lines(fraction):
    ax = plot_domain(synthetic_domain(fraction=fraction), static_multiplier=0.2)
    cells = [a.get_zorder() for g in ("safe", "unsafe") for a in _by_gid(ax, g)]
    lines = [_line(ax, "boundary").get_zorder(), _line(ax, "static").get_zorder()]
    assert min(cells) > max(lines)


def test_ensemble_legend_says_marker_is_member_0_and_colour_the_fraction():
    ax = plot_domain(synthetic_domain(fraction=True))
    legend = ax.get_legend()
    texts = [t.get_text() for t in legend.get_texts()]
    assert "member 0 survived" in texts and "member 0 collapsed" in texts
    title = legend.get_title().get_text()
    assert "member 0" in title and "fraction" in title


def test_every_ensemble_mark_is_dark_enough_to_see_on_white():
    """Relative luminance of every drawn colour below 0.6 (white is 1; viridis's yellow 0.8)."""
    ax = plot_domain(synthetic_domain(fraction=True))
    colours = np.vstack([ax.collections[0].get_edgecolors(), ax.collections[1].get_facecolors()])
    rgb = colours[:, :3]
    lin = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
    luminance = lin @ [0.2126, 0.7152, 0.0722]
    assert luminance.max() < 0.6


def test_markers_shrink_with_a_denser_grid():
    """Marker size follows the grid spacing: a 30 x 59 grid gets smaller marks than 5 x 10,
    and neighbouring marks do not overlap (size below the spacing in points)."""
    from rbm_cli.report.plot_domain import marker_size

    fig = Figure(figsize=(9.5, 5))
    ax = fig.add_subplot()
    dense = pd.DataFrame(
        [(a, f) for f in np.linspace(0.1, 3.0, 30) for a in np.linspace(0.05, 3.0, 59)],
        columns=["amplitude_g", "frequency_hz"],
    )
    coarse = synthetic_domain()
    assert marker_size(ax, dense) < marker_size(ax, coarse)
    height_pt = ax.get_position().height * 5 * 72
    spacing_pt = height_pt * (2.95 / 58) / (1.06 * 3.0)
    assert marker_size(ax, dense) < spacing_pt
