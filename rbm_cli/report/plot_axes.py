"""Drawing a domain as rbm_cli.report.domain_view lays it out: one plane, one panel per
point, or an overlay of the points' boundaries; in physical or dimensionless axes, with the
uplift level and the closed forms where they apply.

Over a categorical x (the records of a suite, or any named values) nothing joins one x to
the next: a boundary is a bar per category (plot_domain.py), an overlaid point's boundary
its marks alone, and the categories are the ticks, turned upright when they would overlap.

Every artist carries a gid, as in plot_domain.py: 'safe', 'unsafe', 'failed', 'boundary'
(one per panel), 'boundary-member0' (an ensemble's member 0, one per panel),
'boundary-<k>' (the k-th point's line of an overlay), 'member0-<k>' (its member 0's line
in an ensemble), 'compare-<k>',
'static' (or 'static-<k>' when the points' levels differ), 'housner', 'linear' (or
'linear-<k>', the k-th point's own curve in physical overlays).

Closed forms (half-sine pulse, rigid monolith): in dimensionless axes the curves
A / (g tan alpha) = f(omega / p) of rbm_cli.structures.closed_forms hold for every size at
once (tan alpha = theta_u of the RBM, as in rbm_cli.structures.similarity); in physical axes
they are each point's own, in g: against frequency, or at the grid's frequency joined
over an axis on x. The uplift level is the static multiplier [g], or
static_multiplier / tan alpha (1 for a monolith) in dimensionless axes.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from rbm_cli.config.types import Config
from rbm_cli.report.domain_view import DomainView, Point, row_configs
from rbm_cli.report.plot_domain import (
    CURVE_POINTS,
    MAJORITY_LABEL,
    draw_cells,
    draw_domain,
    finish_axes,
    fraction_colorbar,
    is_ensemble,
    legend_beside,
    plot_levels,
)
from rbm_cli.structures.closed_forms import (
    halfsine_threshold_curves,
    housner_halfsine_threshold,
    linear_halfsine_threshold,
)
from rbm_cli.structures.column import build_column
from rbm_cli.structures.frame import frame_column
from rbm_cli.study.domain import boundary
from rbm_cli.study.schema import C

#: Marker size [points] of the cells on a log x axis (marker_size assumes a linear one).
LOG_MARKER = 3.0
#: Opacity of the cells under an overlay's lines.
FAINT = 0.22
#: An overlaid ensemble's member 0 boundary: thin, no marks (the majority's: marks "o").
OVERLAY_MEMBER0 = dict(linewidth=0.9, linestyle=(0, (3, 1, 1, 1, 1, 1)), zorder=4)
OVERLAY_MEMBER0_LABEL = "member 0's boundary of each point (thin, no marks)"
OVERLAY_MEMBER0_MARKS = "member 0's lowest collapsed amplitude of each point (bars)"
#: Styles of the level and curves (as plot_domain.py draws them against frequency).
STATIC = dict(color="0.3", linestyle="--", linewidth=1.0)
HOUSNER = dict(color="tab:purple", linestyle="-.", linewidth=1.3)
LINEAR = dict(color="tab:cyan", linestyle="-", linewidth=1.5)
HOUSNER_LABEL = r"Housner (1963), $A/(g\tan\alpha)=\sqrt{1+(\omega/p)^2}$"
LINEAR_LABEL = "exact, linear model (rigid monolith)"


def uplift_level(config: Config) -> tuple[float, str]:
    """(level [g], label) at which the config's column starts to rock: the RBM's static
    multiplier (a frame's columns under its beam: rbm_cli.structures.frame.frame_column),
    or for `bullet` the engine's own level from its true solids."""
    if config.model == "bullet":
        # lazy: loads pybullet only where needed (docs/architecture.md, Start-up)
        from rbm_cli.models.bullet.run import engine_uplift_g

        return engine_uplift_g(config), "engine uplift level"
    column = build_column(config.column, config.interface)
    if config.frame is not None:
        column = frame_column(column, config.frame, config.interface)
    return column.static_multiplier, "static multiplier"


def closed_forms_apply(config: Config | None) -> bool:
    """The half-sine closed forms hold: a half-sine pulse on a rigid monolithic column."""
    if config is None or config.excitation.type != "half-sine":
        return False
    column = build_column(config.column, config.interface)
    return column.n == 1 and column.rigid


def _single_config(point: Point) -> Config | None:
    configs = [c for c in row_configs(point) if c is not None]
    return configs[0] if configs else None


def _dimensionless_levels(view: DomainView, rows: pd.DataFrame, configs: list):
    """(x, level) of each distinct point of ``rows`` in dimensionless axes, and whether the
    closed forms apply to every row."""
    level = rows[C.static_multiplier].to_numpy(float) / np.tan(rows[C.alpha_rad].to_numpy(float))
    x = rows[view.x].to_numpy(float)
    pairs = np.unique(np.column_stack([x, level]), axis=0)
    distinct = {id(c): c for c in configs}.values()  # one config per point, not per row
    apply = bool(distinct) and all(closed_forms_apply(c) for c in distinct)
    return pairs, apply


def _axis_levels(view: DomainView, point: Point):
    """Physical axes with an axis on x, at one frequency: (x, level [g], label) and
    (x, housner [g], linear [g]) over the point's distinct x (curves None unless every
    point is a rigid monolith under a half-sine)."""
    plane = view.plane(point.rows)
    rows = []
    for x, cfg, f in zip(plane[C.frequency_hz], row_configs(point), point.rows[C.frequency_hz],
                         strict=True):  # fmt: skip
        if cfg is not None:  # a record has no frequency (None or NaN)
            rows.append((float(x), cfg, np.nan if f is None else float(f)))
    seen = {}
    for x, cfg, f in rows:
        seen.setdefault(x, (cfg, f))
    if not seen:
        return None, None
    xs = np.array(sorted(seen))
    levels = [uplift_level(seen[x][0]) for x in xs]
    static = (xs, np.array([lv for lv, _ in levels]), levels[0][1])
    if not all(closed_forms_apply(seen[x][0]) for x in xs):
        return static, None
    curves = [halfsine_threshold_curves(build_column(c.column, c.interface), [f])
              for c, f in (seen[x] for x in xs)]  # fmt: skip
    housner = np.array([float(c["housner"][0]) for c in curves])
    linear = np.array([float(c["linear"][0]) for c in curves])
    return static, (xs, housner, linear)


def _constant(y) -> bool:
    """All values equal to 1e-9 (relative): one level."""
    y = np.asarray(y, float)
    return bool(np.ptp(y) <= 1e-9 * max(1.0, float(np.max(np.abs(y)))))


def _level_line(ax, x, y, label: str, gid: str, **style) -> None:
    """A level: a horizontal line where it is one value, else joined over x."""
    if _constant(y):
        ax.axhline(float(y[0]), label=label, gid=gid, **style)
    else:
        ax.plot(x, y, label=label, gid=gid, **style)


def draw_levels(ax, view: DomainView, point: Point, x_range) -> float | None:
    """The uplift level and the closed forms of one plane (a panel or the single axes);
    returns the highest level drawn (in the plane's y units) or None."""
    if view.dimensionless:
        configs = [c for c in row_configs(point) if c is not None]
        pairs, apply = _dimensionless_levels(view, point.rows, configs)
        y = pairs[:, 1]
        label = r"uplift level, static multiplier / $\tan\alpha$"
        if _constant(y):
            label += f" = {y[0]:.3g}"
        _level_line(ax, pairs[:, 0], y, label, "static", **STATIC)
        if apply:
            draw_dimensionless_curves(ax, x_range)
        return float(np.max(y))
    if view.line == C.frequency_hz:
        cfg = _single_config(point)
        if cfg is None:
            return None
        level, label = uplift_level(cfg)
        column = build_column(cfg.column, cfg.interface)
        return plot_levels(ax, [view.plane(point.rows)], column, cfg.excitation.type, level,
                           label)  # fmt: skip
    static, curves = _axis_levels(view, point)
    if static is None:
        return None
    xs, levels, label = static
    if _constant(levels):
        label = f"{label} {levels[0]:.3g} g"
    _level_line(ax, xs, levels, label, "static", **STATIC)
    if curves is not None:
        xs, housner, linear = curves
        ax.plot(xs, housner, label="Housner (1963), at each point", gid="housner", **HOUSNER)
        ax.plot(xs, linear, label="exact, linear model, at each point", gid="linear", **LINEAR)
    return float(np.max(levels))


def draw_dimensionless_curves(ax, x_range) -> None:
    """Housner's approximation and the exact linear threshold, A / (g tan alpha) against
    omega / p over ``x_range`` (lo, hi)."""
    lo, hi = x_range
    x = np.linspace(lo, hi, CURVE_POINTS) if hi > lo else np.array([lo])
    ax.plot(x, housner_halfsine_threshold(x), label=HOUSNER_LABEL, gid="housner", **HOUSNER)
    ax.plot(x, linear_halfsine_threshold(x), label=LINEAR_LABEL, gid="linear", **LINEAR)


def _x_range(plane: pd.DataFrame) -> tuple[float, float]:
    x = plane[C.frequency_hz].to_numpy(float)
    x = x[np.isfinite(x)]
    return (float(x.min()), float(x.max())) if x.size else (0.0, 1.0)


#: Most category names on an axis: beyond, every k-th is named (the ticks stay).
MAX_CATEGORY_TICKS = 60
#: Width of a tick label's character, in its font size (a mean over names in sans-serif).
CHAR_WIDTH = 0.6


def _finish_x(ax, view: DomainView) -> float:
    """A log x axis labelled 1, 2, 5, 10, ... in plain numbers; category names as ticks,
    upright when side by side they would not fit the axes' width, every k-th named
    beyond MAX_CATEGORY_TICKS, and half a category of margin at either end. Returns the
    height the upright names take beyond one line of text [points] (0 otherwise)."""
    if view.log_x:
        # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
        from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

        ax.set_xscale("log")
        ax.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.xaxis.set_minor_formatter(NullFormatter())
    if view.categories is not None:
        # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
        from matplotlib.font_manager import FontProperties

        n = len(view.categories)
        every = math.ceil(n / MAX_CATEGORY_TICKS)
        names = [name if k % every == 0 else "" for k, name in enumerate(view.categories)]
        size = FontProperties(size="small").get_size_in_points()
        width = ax.get_position().width * ax.figure.get_size_inches()[0] * 72.0  # [points]
        needed = sum(CHAR_WIDTH * size * (len(name) + 2) for name in names)
        upright = needed > width
        ax.set_xticks(range(n), names, fontsize="small", rotation=90 if upright else 0)
        ax.set_xlim(-0.5, n - 0.5)
        if upright:
            return CHAR_WIDTH * size * max(len(name) for name in names) - size
    return 0.0


def draw_plane(ax, view: DomainView, point: Point, compare=(), labels=None, colorbar=True,
               legend=True) -> list:  # fmt: skip
    """One plane: the point's cells and boundary, ``compare``'s boundaries (rows in the
    domain's columns), the level and curves; returns the ensemble's legend proxies."""
    plane = view.plane(point.rows)
    others = [view.plane(c) for c in compare]
    size = LOG_MARKER if view.log_x else None
    bars = view.category_word if view.categories is not None else None
    proxies = draw_domain(ax, plane, others, labels, False, size, bars)
    top = draw_levels(ax, view, point, _x_range(plane))
    finish_axes(ax, [plane, *others], top, proxies, view.labels, legend)
    names = _finish_x(ax, view)
    if colorbar and is_ensemble(plane):  # below the x axis's names, however tall they stand
        height = ax.get_position().height * ax.figure.get_size_inches()[1] * 72.0  # [points]
        fraction_colorbar(ax.figure, ax, pad=0.16 + names / height)
    return proxies


def point_colours(n: int, numeric: bool) -> list:
    """Colours of n overlaid points: ordered (viridis without its light end) for the
    values of one numeric axis, else distinct."""
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib import colormaps

    if numeric:
        return list(colormaps["viridis"](np.linspace(0.0, 0.8, max(n, 2))))[:n]
    return [colormaps["tab10"](k % 10) for k in range(n)]


def draw_overlay(ax, view: DomainView, numeric: bool = True) -> None:
    """One axes: the cells faint (once per place and status), each point's boundary a line
    of its own colour labelled by the point, the levels, and the closed forms that apply
    (module docstring)."""
    rows = pd.concat([p.rows for p in view.points])
    plane = view.plane(rows).drop(columns=[C.collapse_fraction], errors="ignore")
    # cells of several points at one place are drawn once per status (faint marks add up)
    cells = plane.drop_duplicates([C.frequency_hz, C.amplitude_g, C.status])
    draw_cells(ax, cells, size=LOG_MARKER if view.log_x else None)
    for artist in (*ax.lines, *ax.collections):
        artist.set_alpha(FAINT)
    colours = point_colours(len(view.points), numeric)
    ensemble = is_ensemble(rows)
    joined = view.categories is None  # over categories, marks alone: no line between them
    for k, (point, colour) in enumerate(zip(view.points, colours, strict=True)):
        bnd = boundary(view.plane(point.rows))
        f = bnd[C.frequency_hz].to_numpy(float)
        style = ("-", "--", "-.")[k // 10 % 3] if not numeric else "-"
        ax.plot(f, bnd["lowest_unsafe_g"].to_numpy(float),
                color=colour, linewidth=1.5, marker="o", markersize=3.5, label=point.label,
                linestyle=style if joined else "none", gid=f"boundary-{k}",
                zorder=4)  # fmt: skip
        if ensemble:
            member0 = dict(OVERLAY_MEMBER0) if joined else dict(
                linestyle="none", marker="_", markersize=7.0, zorder=4)  # fmt: skip
            ax.plot(f, bnd["member0_lowest_unsafe_g"].to_numpy(float), color=colour,
                    label=OVERLAY_MEMBER0_LABEL if k == 0 and joined
                    else OVERLAY_MEMBER0_MARKS if k == 0 else "_",
                    gid=f"member0-{k}", **member0)  # fmt: skip
    tops = [
        _overlay_levels(ax, view, point, k, colour)
        for k, (point, colour) in enumerate(zip(view.points, colours, strict=True))
    ]
    if view.dimensionless and all(t[1] for t in tops):
        draw_dimensionless_curves(ax, _x_range(plane))
    _overlay_static(ax, view, [t[0] for t in tops])
    label_static_levels(ax, view, [t[0] for t in tops])
    levels = [lv for t in tops for lv in t[0][1]]
    finish_axes(ax, [plane], max(levels) if levels else None, [], view.labels, legend=False)
    _finish_x(ax, view)
    handles = None
    if ensemble:  # the points' lines are the majority's: the legend says so first
        # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
        from matplotlib.lines import Line2D

        handles, _ = ax.get_legend_handles_labels()
        what = "lines with marks" if joined else "marks"
        majority = Line2D([], [], color="0.2", linewidth=1.5, marker="o", markersize=3.5,
                          linestyle="-" if joined else "none",
                          label=f"{what}: each point's {MAJORITY_LABEL}")  # fmt: skip
        handles = [majority, *handles]
    legend_beside(ax, handles=handles)


def _overlay_levels(ax, view: DomainView, point: Point, k: int, colour):
    """((x, levels), closed forms apply) of one overlaid point; in physical axes its own
    exact linear threshold is drawn dotted in its colour (gid 'linear-<k>')."""
    configs = [c for c in row_configs(point) if c is not None]
    if view.dimensionless:
        pairs, apply = _dimensionless_levels(view, point.rows, configs)
        return (pairs[:, 0], pairs[:, 1]), apply
    style = dict(color=colour, linestyle=":", linewidth=1.3, gid=f"linear-{k}")
    style["label"] = "exact linear threshold of each point (dotted)" if k == 0 else "_"
    if view.line != C.frequency_hz:
        static, curves = _axis_levels(view, point)
        if curves is not None:
            ax.plot(curves[0], curves[2], **style)
        return ((static[0], static[1]) if static else ([], [])), False
    cfg = configs[0] if configs else None
    if cfg is None:
        return ([], []), False
    level, _ = uplift_level(cfg)
    if closed_forms_apply(cfg):
        lo, hi = _x_range(view.plane(point.rows))
        f = np.linspace(lo, hi, CURVE_POINTS) if hi > lo else np.array([lo])
        ax.plot(f, halfsine_threshold_curves(build_column(cfg.column, cfg.interface), f)
                ["linear"], **style)  # fmt: skip
    return ([math.nan], [level]), False


def _overlay_static(ax, view: DomainView, levels: list) -> None:
    """The points' uplift levels: one line when they agree, else one per distinct value."""
    values = sorted({round(float(v), 12) for _, ys in levels for v in ys})
    unit = "" if view.dimensionless else " g"
    name = r"uplift level, static multiplier / $\tan\alpha$ =" if view.dimensionless else (
        "static multiplier")  # fmt: skip
    for j, value in enumerate(values):
        gid = "static" if len(values) == 1 else f"static-{j}"
        ax.axhline(value, label=f"{name} {value:.3g}{unit}" if j == 0 or len(values) < 4
                   else "_", gid=gid, **STATIC)  # fmt: skip


def label_static_levels(ax, view: DomainView, levels: list) -> None:
    """Each overlaid point's uplift level in its line's legend label: '<point>, static
    multiplier <level> g' (the engine's uplift level for bullet). Physical axes with
    frequency on x only (a level is one value per point there); an overlay in
    dimensionless axes or over another x keeps its labels."""
    if view.dimensionless or view.line != C.frequency_hz:
        return
    lines = {line.get_gid(): line for line in ax.lines}
    for k, (point, (_, ys)) in enumerate(zip(view.points, levels, strict=True)):
        line = lines.get(f"boundary-{k}")
        if line is None or len(ys) != 1 or not math.isfinite(float(ys[0])):
            continue
        cfg = _single_config(point)
        name = uplift_level(cfg)[1] if cfg is not None else "static multiplier"
        line.set_label(f"{point.label}, {name} {float(ys[0]):.3g} g")


def draw_panels(fig, view: DomainView, spec=None, compare=(), labels=None, colorbar=True) -> list:
    """One panel per point on a grid of shared axes (in ``spec``, a SubplotSpec, or the
    whole figure), titled by its point; one legend beside the top right panel and, for an
    ensemble, one colour bar below (unless ``colorbar`` is False: the caller places it).
    ``compare``: per point, the rows of each compared domain there (a list of lists, or
    empty). Returns the axes."""
    n = len(view.points)
    ncols = min(4, math.ceil(math.sqrt(n)))
    nrows = math.ceil(n / ncols)
    grid = spec.subgridspec(nrows, ncols) if spec is not None else fig.add_gridspec(nrows, ncols)
    axes, proxies, top = [], [], 0.0
    for k, point in enumerate(view.points):
        share = axes[0] if axes else None
        ax = fig.add_subplot(grid[k // ncols, k % ncols], sharex=share, sharey=share)
        others = compare[k] if compare else ()
        proxies = draw_plane(ax, view, point, others, labels, colorbar=False, legend=False)
        top = max(top, ax.get_ylim()[1])
        ax.set_title(point.label, fontsize="small")
        if k + ncols < n:  # a panel below: its x label says it
            ax.set_xlabel("")
        if k % ncols:
            ax.set_ylabel("")
        axes.append(ax)
    axes[0].set_ylim(0.0, top)
    _panel_legend(axes[min(ncols, n) - 1], axes, proxies)
    if colorbar and any(C.collapse_fraction in p.rows.columns for p in view.points):
        fraction_colorbar(fig, axes)
    return axes


def _panel_legend(ax, axes: list, proxies: list) -> None:
    """The legend of the panels: each label once; a level whose value differs from panel
    to panel is named without its value."""
    by_gid: dict = {}
    for a in axes:
        for h, text in zip(*a.get_legend_handles_labels(), strict=True):
            by_gid.setdefault(h.get_gid() or text, []).append((h, text))
    handles = []
    for entries in by_gid.values():
        h, text = entries[0]
        if len({t for _, t in entries}) > 1:
            name = text.rsplit(" ", 2)[0] if text.endswith(" g") else text.split(" = ")[0]
            h.set_label(f"{name} (each panel's own)")
        handles.append(h)
    legend_beside(ax, proxies, handles)
