"""Safe-unsafe domain plot in the frequency [Hz] x amplitude [g] plane (paper figs. 5, 8, 9, 12).

A pure plot function: it takes ``ax=None`` (a new figure is made if omitted)
and returns the axes; it never saves or shows (the CLI and the sweep do).
Every artist it draws carries a ``gid`` ('safe', 'unsafe', 'failed', 'upper-joint',
'slides', 'boundary', 'boundary-member0', 'compare-<k>', 'static', 'housner', 'linear'), so
callers and tests can find them. In an ensemble domain (a collapse_fraction column)
'boundary' is the majority's and 'boundary-member0' member 0's
(:func:`rbm_cli.study.domain.boundary`), drawn where it differs from the majority's.

The legend lists what is drawn, each mark once: a boundary with no point (nothing
collapsed) is not listed, nor member 0's where it is the majority's everywhere. Over a
categorical x (the records of a suite, rbm_cli.report.domain_view) the boundary is not a
line, which would join unrelated records, but a bar per record at its lowest collapsed
amplitude (:data:`BAR_LABEL`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from rbm_cli.structures.closed_forms import halfsine_threshold_curves
from rbm_cli.structures.column import Column
from rbm_cli.study.domain import MAJORITY, boundary
from rbm_cli.study.schema import C
from rbm_cli.study.schema import label as column_label

__all__ = [
    "BAR_LABEL",
    "BAR_MAJORITY_LABEL",
    "BAR_MEMBER0_LABEL",
    "MAJORITY_LABEL",
    "MEMBER0_LABEL",
    "boundary",
    "draw_cells",
    "draw_domain",
    "finish_axes",
    "fraction_colorbar",
    "is_ensemble",
    "legend_beside",
    "mark_cells",
    "plot_domain",
    "plot_levels",
]

#: Colours of compared domains' boundaries (the main boundary is black).
COMPARE_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:pink")
#: Colour map of the collapse fraction of ensemble sweeps, and the part of it used: plasma
#: without its light yellow end, so every mark stays visible on white.
FRACTION_CMAP = ("plasma", 0.0, 0.82)
#: Legend and colour-bar wording of ensemble domains.
FRACTION_LABEL = column_label(C.collapse_fraction)
#: Legend title of ensemble domains: what marker and colour say.
FRACTION_TITLE = "marker: member 0's outcome\ncolour: fraction collapsed"
#: Label of the boundary line of a domain.
BOUNDARY_LABEL = "boundary (lowest collapsed amplitude)"
#: Labels of an ensemble's two boundary lines: the majority's and member 0's.
MAJORITY_LABEL = f"boundary of the majority (collapse fraction >= {MAJORITY:g})"
MEMBER0_LABEL = "member 0's boundary (its own outcome)"
#: Style of member 0's boundary line (the majority's is solid).
MEMBER0_STYLE = dict(linestyle=":", linewidth=1.6)
#: Labels of the boundary over a categorical x: a bar per category (``{}``: what one
#: category is, e.g. "record"), the majority's and member 0's of an ensemble.
BAR_LABEL = "boundary (lowest collapsed amplitude), a bar per {}"
BAR_MAJORITY_LABEL = "boundary of the majority (fraction >= {:g}), a bar per {}"
BAR_MEMBER0_LABEL = "member 0's boundary where it differs (grey bar)"
#: Style of those bars (member 0's thinner, in grey), their width in cell marker sizes.
BAR_STYLE = dict(linestyle="none", marker="_", markeredgewidth=2.0)
BAR_MEMBER0_STYLE = dict(linestyle="none", marker="_", markeredgewidth=1.4, color="0.55")
BAR_WIDTH = 3.0
#: The column of domain.csv marking cells whose friction demand exceeds interface.friction.
SLIDES = C.slides
#: Legend labels of the marks over the cells (mark_cells).
UPPER_JOINT_LABEL = "collapsed at an upper joint (in a triangle; a cross alone: at the base)"
SLIDES_LABEL = "slides: max |T/N| > interface.friction"
#: Marker size range [points] and its share of the grid spacing on screen.
MARKER_MAX, MARKER_MIN, MARKER_SHARE = 5.0, 1.5, 0.75
#: z-order of the cells: above the boundary and level lines.
CELL_Z = 3
#: Points of the closed-form curves over the frequency range.
CURVE_POINTS = 300


def _new_axes(ax):
    if ax is not None:
        return ax
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.figure import Figure

    return Figure(figsize=(7, 5)).subplots()


def _fraction_cmap():
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib import colormaps

    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.colors import ListedColormap

    name, lo, hi = FRACTION_CMAP
    return ListedColormap(colormaps[name](np.linspace(lo, hi, 256)), name=f"{name}-dark")


def marker_size(ax, df: pd.DataFrame) -> float:
    """Marker size [points] of the cells: MARKER_SHARE of the smaller on-screen spacing of
    the grid's distinct frequencies and amplitudes, within [MARKER_MIN, MARKER_MAX].

    The spacing is estimated from the axes' size in the figure and the ranges of the grid."""
    bbox = ax.get_position()
    width_in, height_in = ax.figure.get_size_inches()
    points = []
    for column, extent in (
        (C.frequency_hz, bbox.width * width_in),
        (C.amplitude_g, bbox.height * height_in),
    ):
        values = np.unique(df[column].to_numpy(float))
        values = values[np.isfinite(values)]
        if values.size > 1:
            span = 1.1 * (values[-1] - values[0]) if column == C.frequency_hz else 1.06 * values[-1]
            step = float(np.min(np.diff(values)))
            points.append(72.0 * extent * step / span)
    if not points:
        return MARKER_MAX
    return float(np.clip(MARKER_SHARE * min(points), MARKER_MIN, MARKER_MAX))


def _masks(df: pd.DataFrame):
    """Boolean masks of the safe, unsafe and failed cells."""
    status = df[C.status].astype(str)
    unsafe = (status == "collapsed").to_numpy()
    failed = (status == "failed").to_numpy()
    return ~unsafe & ~failed, unsafe, failed


def _plot_cells(ax, df: pd.DataFrame, size: float | None = None) -> None:
    """Safe cells as open circles, unsafe as crosses, failed as grey squares, above the
    lines; ``size`` [points] defaults to :func:`marker_size`."""
    f = df[C.frequency_hz].to_numpy(float)
    a = df[C.amplitude_g].to_numpy(float)
    safe, unsafe, failed = _masks(df)
    size = marker_size(ax, df) if size is None else size
    style = dict(linestyle="none", markersize=size, zorder=CELL_Z)
    ax.plot(f[safe], a[safe], marker="o", markerfacecolor="none", color="tab:green",
            label="safe (survived)", gid="safe", **style)  # fmt: skip
    ax.plot(f[unsafe], a[unsafe], marker="x", color="tab:red", label="unsafe (collapsed)",
            gid="unsafe", **style)  # fmt: skip
    if failed.any():
        ax.plot(f[failed], a[failed], marker="s", color="0.45", label="failed run",
                gid="failed", **style)  # fmt: skip


def _plot_fraction_cells(ax, df: pd.DataFrame, colorbar: bool = True, size=None) -> list:
    """Cells of an ensemble domain: the marker is member 0's outcome (the domain's row),
    the colour the fraction of members that collapsed, with a colour bar (unless
    ``colorbar`` is False: panels share one, :func:`fraction_colorbar`).

    Returns dark legend proxies of the markers (the points' colours vary)."""
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.colors import Normalize

    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.lines import Line2D

    cmap, norm = _fraction_cmap(), Normalize(0.0, 1.0)
    f = df[C.frequency_hz].to_numpy(float)
    a = df[C.amplitude_g].to_numpy(float)
    frac = df[C.collapse_fraction].to_numpy(float)
    safe, unsafe, failed = _masks(df)
    colours = cmap(norm(np.nan_to_num(frac, nan=0.0)))
    size = marker_size(ax, df) if size is None else size
    width = max(0.6, size / 4.0)
    ax.scatter(f[safe], a[safe], marker="o", facecolors="none", edgecolors=colours[safe],
               s=size**2, linewidths=width, gid="safe", zorder=CELL_Z)  # fmt: skip
    ax.scatter(f[unsafe], a[unsafe], marker="x", c=colours[unsafe], s=size**2,
               linewidths=width, gid="unsafe", zorder=CELL_Z)  # fmt: skip
    proxy = dict(linestyle="none", color="0.2", markersize=5)
    handles = [
        Line2D([], [], marker="o", markerfacecolor="none", label="member 0 survived", **proxy),
        Line2D([], [], marker="x", label="member 0 collapsed", **proxy),
    ]
    if failed.any():
        ax.scatter(f[failed], a[failed], marker="s", c="0.45", s=(0.8 * size) ** 2,
                   gid="failed", zorder=CELL_Z)  # fmt: skip
        handles.append(Line2D([], [], marker="s", label="failed run", **{**proxy, "color": "0.45"}))
    if colorbar:
        fraction_colorbar(ax.figure, ax)
    return handles


def fraction_colorbar(fig, axes, cax=None, pad: float = 0.16) -> None:
    """The colour bar of the collapse fraction, below ``axes`` (one or a list; the legend
    sits beside them; ``pad``: the gap, in the axes' height), or in ``cax``."""
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.cm import ScalarMappable

    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.colors import Normalize

    mappable = ScalarMappable(norm=Normalize(0.0, 1.0), cmap=_fraction_cmap())
    if cax is not None:
        fig.colorbar(mappable, cax=cax, label=FRACTION_LABEL, orientation="horizontal")
        return
    fig.colorbar(mappable, ax=axes, label=FRACTION_LABEL, location="bottom", pad=pad,
                 fraction=0.06, aspect=40)  # fmt: skip


def is_ensemble(df: pd.DataFrame) -> bool:
    """A domain of an ensemble sweep: its boundary is the majority's."""
    return C.collapse_fraction in df.columns


def _listed(label: str, y: np.ndarray) -> str:
    """A legend label for a mark with values ``y``, hidden ('_' first) when none is finite:
    the legend lists only what is drawn."""
    return label if np.isfinite(y).any() else f"_{label}"


def _plot_boundary(ax, df: pd.DataFrame, colour, label: str, gid: str, member0=None,
                   bars: float | None = None) -> None:  # fmt: skip
    """The boundary under the cells: a line (no markers of its own), or with ``bars`` (a
    categorical x: the bar's width [points]) a bar at each x, nothing joining them.
    ``member0``: the label of member 0's boundary of an ensemble, drawn dotted (grey bars)
    beside the majority's where the two differ, and not at all where they never do."""
    bnd = boundary(df)
    f = bnd[C.frequency_hz].to_numpy(float)
    y = bnd["lowest_unsafe_g"].to_numpy(float)
    style = dict(color=colour, linewidth=1.4) if bars is None else dict(
        color=colour, markersize=bars, **BAR_STYLE)  # fmt: skip
    ax.plot(f, y, label=_listed(label, y), gid=gid, zorder=2, **style)
    if member0 is None or "member0_lowest_unsafe_g" not in bnd.columns:
        return
    y0 = bnd["member0_lowest_unsafe_g"].to_numpy(float)
    differs = ~((y0 == y) | (np.isnan(y0) & np.isnan(y)))
    if not differs.any():
        return  # the same boundary: one line, one legend entry
    if bars is None:
        ax.plot(f, y0, color=colour, label=member0, gid=f"{gid}-member0", zorder=2,
                **MEMBER0_STYLE)  # fmt: skip
    else:
        y0 = np.where(differs, y0, np.nan)
        ax.plot(f, y0, markersize=bars, label=_listed(member0, y0), gid=f"{gid}-member0",
                zorder=2, **BAR_MEMBER0_STYLE)  # fmt: skip


def _plot_closed_forms(ax, column: Column, frequencies_hz: np.ndarray) -> None:
    lo, hi = float(np.min(frequencies_hz)), float(np.max(frequencies_hz))
    f = np.linspace(lo, hi, CURVE_POINTS) if hi > lo else np.array([lo])
    curves = halfsine_threshold_curves(column, f)
    ax.plot(
        f,
        curves["housner"],
        color="tab:purple",
        linestyle="-.",
        linewidth=1.3,
        label=r"Housner (1963), $A/\alpha=\sqrt{1+(\omega/p)^2}$",
        gid="housner",
    )
    ax.plot(
        f,
        curves["linear"],
        color="tab:cyan",
        linestyle="-",
        linewidth=1.5,
        label="exact, linear model (rigid RBM)",
        gid="linear",
    )


def _labels(labels: Sequence[str] | None, domains: list[pd.DataFrame],
            bars: str | None = None) -> tuple[list, str]:  # fmt: skip
    """The legend labels of the boundaries (the domain's, then one per compared domain),
    and of member 0's boundary of an ensemble domain.

    Alone, the domain's line is the BOUNDARY_LABEL (what the line is; the figure's title
    names the study), or for an ensemble the MAJORITY_LABEL. With compared domains each
    line is '<name>: boundary', '<name>: boundary of the majority' for an ensemble. With
    ``bars`` (what one category of a categorical x is) the boundary is a bar per category:
    BAR_LABEL, BAR_MAJORITY_LABEL and BAR_MEMBER0_LABEL say so."""
    if bars is not None:
        alone = [BAR_MAJORITY_LABEL.format(MAJORITY, bars) if is_ensemble(d)
                 else BAR_LABEL.format(bars) for d in domains]  # fmt: skip
        if len(domains) == 1:
            return alone, BAR_MEMBER0_LABEL
        names = list(labels) if labels else [f"domain {k + 1}" for k in range(len(domains))]
        if len(names) != len(domains):
            raise ValueError(
                f"labels needs {len(domains)} entries (the domain, then one per compared "
                f"domain), got {len(names)}"
            )
        return ([f"{name}: {text}" for name, text in zip(names, alone, strict=True)],
                f"{names[0]}: {BAR_MEMBER0_LABEL}")  # fmt: skip
    n_compare = len(domains) - 1
    if labels is None:
        labels = ["domain 1"] + [f"domain {k + 2}" for k in range(n_compare)]
    labels = list(labels)
    if len(labels) != 1 + n_compare:
        raise ValueError(
            f"labels needs {1 + n_compare} entries (the domain, then one per compared "
            f"domain), got {len(labels)}"
        )
    if n_compare == 0:
        return [MAJORITY_LABEL if is_ensemble(domains[0]) else BOUNDARY_LABEL], MEMBER0_LABEL
    texts = [f"{name}: boundary" + (" of the majority" if is_ensemble(d) else "")
             for name, d in zip(labels, domains, strict=True)]  # fmt: skip
    return texts, f"{labels[0]}: {MEMBER0_LABEL}"


def finish_axes(
    ax,
    domains: list,
    static_multiplier: float | None,
    proxies: list,
    labels: tuple[str, str] = (column_label(C.frequency_hz), column_label(C.amplitude_g)),
    legend: bool = True,
) -> None:
    """Amplitude range (from 0 to just above the largest amplitude or level), the axis
    ``labels`` (x, y), grid and (if ``legend``) the legend beside the axes."""
    amplitudes = np.concatenate([d[C.amplitude_g].to_numpy(float) for d in domains])
    top = max([float(np.nanmax(amplitudes))] if len(amplitudes) else [1.0])
    if static_multiplier is not None:
        top = max(top, float(static_multiplier))
    ax.set_ylim(0.0, 1.06 * top)
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    ax.grid(True, alpha=0.3)
    if legend:
        legend_beside(ax, proxies)


def legend_beside(ax, proxies: list = (), handles=None) -> None:
    """The legend beside the axes (never over the cells): ``proxies`` (an ensemble's
    markers, under its title) first, then ``handles`` (default: the axes' labelled artists)."""
    proxies = list(proxies)
    if handles is None:
        handles, _ = ax.get_legend_handles_labels()
    texts = [h.get_label() for h in handles]
    ax.legend(
        title=FRACTION_TITLE if proxies else None,
        title_fontsize="small",
        handles=proxies + handles,
        labels=[h.get_label() for h in proxies] + texts,
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),  # beside the axes: never over the cells
        borderaxespad=0.0,
        fontsize="small",
    )


def plot_levels(ax, domains, column, excitation_type, static_multiplier, static_label):
    """The static multiplier (or the level given) and, for a rigid monolith under a
    half-sine, the closed-form thresholds; returns the level drawn [g] (or None)."""
    if static_multiplier is None and column is not None:
        static_multiplier = column.static_multiplier
    if static_multiplier is not None:
        ax.axhline(
            static_multiplier,
            color="0.3",
            linestyle="--",
            linewidth=1.0,
            label=f"{static_label} {static_multiplier:.3g} g",
            gid="static",
        )

    frequencies = np.concatenate([d[C.frequency_hz].to_numpy(float) for d in domains])
    if (
        column is not None
        and column.n == 1
        and column.rigid
        and excitation_type == "half-sine"
        and len(frequencies)
    ):
        _plot_closed_forms(ax, column, frequencies)

    return static_multiplier


def draw_cells(ax, df: pd.DataFrame, colorbar: bool = True, size=None) -> list:
    """The cells of ``df`` (see :func:`plot_domain`) at its frequency_hz (x) and
    amplitude_g (y), with the marks of :func:`mark_cells`; returns the ensemble's legend
    proxies ([] for a plain domain)."""
    size = marker_size(ax, df) if size is None else size
    if C.collapse_fraction in df.columns:
        proxies = _plot_fraction_cells(ax, df, colorbar, size)
    else:
        _plot_cells(ax, df, size)
        proxies = []
    mark_cells(ax, df, size)
    return proxies


def _flag(df: pd.DataFrame, column: str) -> np.ndarray:
    """A 0/1 (or empty) column of df as a boolean array (empty: False)."""
    return pd.to_numeric(df[column], errors="coerce").fillna(0).to_numpy(float) == 1.0


def mark_cells(ax, df: pd.DataFrame, size: float) -> None:
    """Marks over the cells: the mechanism of a collapse, where the domain says which
    interface collapsed (collapse_interface, 1 at the ground: a cross alone is a collapse
    at the base joint, a cross in a triangle at an upper joint; gid 'upper-joint', whose
    legend entry says both), and
    the cells whose friction demand exceeds interface.friction (slides = 1: an open
    diamond around the cell; gid 'slides')."""
    f = df[C.frequency_hz].to_numpy(float)
    a = df[C.amplitude_g].to_numpy(float)
    _, unsafe, _ = _masks(df)
    style = dict(linestyle="none", markerfacecolor="none", zorder=CELL_Z + 1)
    if C.collapse_interface in df.columns and unsafe.any():
        where = pd.to_numeric(df[C.collapse_interface], errors="coerce").to_numpy(float)
        upper = unsafe & (where > 1)
        if upper.any():  # (a cross alone is the collapse's own entry: not listed twice)
            ax.plot(f[upper], a[upper], marker="^", color="tab:red", markersize=1.5 * size,
                    label=UPPER_JOINT_LABEL, gid="upper-joint", **style)  # fmt: skip
    if SLIDES in df.columns:
        slides = _flag(df, SLIDES)
        if slides.any():
            ax.plot(f[slides], a[slides], marker="D", color="tab:orange",
                    markersize=1.5 * size, markeredgewidth=1.1, label=SLIDES_LABEL,
                    gid=C.slides, **style)  # fmt: skip


def draw_domain(
    ax, df: pd.DataFrame, compare=(), labels=None, colorbar: bool = True, size=None,
    bars: str | None = None,
) -> list:  # fmt: skip
    """Cells of ``df`` and the boundaries of it and of ``compare`` (see :func:`plot_domain`),
    from its amplitude_g and frequency_hz columns; returns the ensemble's legend proxies.
    ``bars``: x is categorical, each category one ``bars`` ("record"): the boundaries are
    bars, one per category, not lines."""
    compare = list(compare)
    texts, member0 = _labels(labels, [df, *compare], bars)
    size = marker_size(ax, df) if size is None else size
    proxies = draw_cells(ax, df, colorbar, size)
    width = BAR_WIDTH * size if bars is not None else None
    _plot_boundary(ax, df, "black", texts[0], "boundary", member0 if is_ensemble(df) else None,
                   width)  # fmt: skip
    for k, (other, label) in enumerate(zip(compare, texts[1:], strict=True)):
        colour = COMPARE_COLOURS[k % len(COMPARE_COLOURS)]
        _plot_boundary(ax, other, colour, label, f"compare-{k}", bars=width)
    return proxies


def plot_domain(
    df: pd.DataFrame,
    ax=None,
    compare: Sequence[pd.DataFrame] = (),
    labels: Sequence[str] | None = None,
    column: Column | None = None,
    excitation_type: str | None = None,
    static_multiplier: float | None = None,
    static_label: str = "static multiplier",
):
    """Plot a safe-unsafe domain: cells, boundary, static multiplier, closed forms.

    Parameters
    ----------
    df : pandas.DataFrame
        A domain table (domain.csv): amplitude_g [g], frequency_hz [Hz],
        status ('collapsed', 'survived' or 'failed'); optionally
        collapse_fraction [-] in [0, 1] (ensemble sweeps), which colours the
        cells and adds a colour bar
    ax : matplotlib Axes, optional
        Axes to draw on; a new figure is made if omitted
    compare : sequence of pandas.DataFrame, optional
        Other domains whose boundaries are drawn in other colours
    labels : sequence of str, optional
        Legend labels of the boundaries: labels[0] for ``df``, then one per
        ``compare`` entry
    column : rbm_cli.structures.column.Column, optional
        The column of ``df``; with n = 1, a rigid law and a half-sine
        excitation, the closed-form half-sine thresholds are drawn
    excitation_type : str, optional
        'harmonic', 'half-sine' or 'free'
    static_multiplier : float, optional
        Uplift acceleration [g], drawn as a dashed horizontal line; defaults
        to ``column.static_multiplier`` when a column is given
    static_label : str, optional
        Legend name of that line (the contact engine's is its 'uplift level')

    Returns
    -------
    matplotlib Axes

    Notes
    -----
    Safe cells are open circles, unsafe (collapsed) cells crosses, failed runs
    grey squares (in the legend only if there are any), drawn above the lines and
    sized to the grid's spacing on screen (:func:`marker_size`). A collapse at an upper
    joint (collapse_interface > 1) has a triangle around its cross, and a cell whose
    friction demand exceeds interface.friction (slides = 1) an orange diamond
    (:func:`mark_cells`; each in the legend where the domain has one). In an ensemble
    domain the marker is member 0's outcome (the row's status) and the colour the
    fraction of members that collapsed (a colour map without a light end, so
    every mark shows on white), as the legend's title and the colour bar say.
    Alone, the domain's line is labelled "boundary (lowest collapsed amplitude)";
    with compared domains each line is "<label>: boundary". The boundary is the
    lowest collapsed amplitude per frequency (:func:`rbm_cli.study.domain.boundary`;
    gaps where nothing collapses; not listed in the legend when nothing does). In an
    ensemble domain it is the majority's (a cell collapsed where collapse_fraction >=
    0.5), labelled so, and member 0's boundary is drawn beside it, dotted in the same
    colour, labelled "member 0's boundary", where the two differ anywhere. The
    closed forms use the mapping of the RBM's rigid monolith to the linear block
    (:func:`rbm_cli.structures.closed_forms.linear_rocking_parameters`): the rigid RBM
    monolith is the piecewise-linear block with alpha = B_1/H.
    The amplitude axis starts at 0 and stops just above the largest amplitude
    of the grids, so a steep closed-form curve does not squash the domain.
    """
    compare = list(compare)
    ax = _new_axes(ax)
    proxies = draw_domain(ax, df, compare, labels)
    static_multiplier = plot_levels(
        ax, [df, *compare], column, excitation_type, static_multiplier, static_label
    )
    finish_axes(ax, [df, *compare], static_multiplier, proxies)
    return ax
