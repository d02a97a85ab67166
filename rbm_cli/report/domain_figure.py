"""The figure of a domain (domain.png): the domain in the frequency x amplitude plane with the
level at which the column starts to rock (the RBM's static multiplier, or the engine's own
uplift level for `bullet`) and the closed forms that apply; a domain over more axes as
panels or an overlay, and any domain in dimensionless axes (rbm_cli.report.domain_view
states the layout rule, rbm_cli.report.plot_axes what is drawn). A domain over the ground
motion's azimuth (an ``excitation.angle`` axis) is drawn in polar axes by default
(rbm_cli.report.plot_polar); asked for panels, an overlay or dimensionless axes, it is laid
out as any other."""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from rbm_cli.base.errors import RbmError
from rbm_cli.config.types import MODELS, Config
from rbm_cli.report.domain_view import DomainView, domain_view, with_scales
from rbm_cli.report.plot_axes import draw_overlay, draw_panels, draw_plane, uplift_level
from rbm_cli.report.plot_domain import fraction_colorbar, plot_domain
from rbm_cli.report.plot_polar import ANGLE_AXIS, draw_polar, has_angle_axis
from rbm_cli.structures.column import build_column
from rbm_cli.structures.frame import beam_box
from rbm_cli.structures.outline import drum_outlines
from rbm_cli.study.cells import nominal_config
from rbm_cli.study.domain import axis_columns
from rbm_cli.study.samples import majority_frame
from rbm_cli.study.schema import C

__all__ = ["POLAR_SIZE", "column_note", "domain_figure", "draw_domain_on", "uplift_level"]

#: Width and height [in] of the polar picture's figure (the legend beside the circle).
POLAR_SIZE = (11.0, 6.5)

if TYPE_CHECKING:  # matplotlib is imported when a figure is drawn, not with this module
    import pandas as pd
    from matplotlib.figure import Figure


def _metres(value: float) -> str:
    return f"{value:.4g} m"


def column_note(config: Config, model: bool = True) -> str:
    """The column a domain was swept with, in one line under its title: H, B (base and
    top width where they differ), drums, the joint stiffness (k_n, K_M or rigid), the
    restitution e, the joints' damping zeta where there is some, and interface.friction where
    model rbm's demand is checked against it; a frame's columns and beam before them.
    A grid over one of these says so ("over the grid") instead of one value, and an
    uncertain key ("uncertain", and the cells are said to be the majority of the samples:
    rbm_cli.study.samples), unless its distribution draws one value, which is shown.
    ``model`` False leaves the model out (a title that names it already)."""
    axes = set(config.grid.axis_paths)
    varying, samples = set(), 0
    if config.uncertain is not None:
        samples = config.uncertain.samples
        varying = {p for p, d in config.uncertain.keys if d.point_mass is None}
        config = nominal_config(config)
    col, itf = config.column, config.interface

    def value(path: str, text: str) -> str:
        sized = "column.size" in axes and path in ("column.height", "column.base_width")
        if path in varying:
            return "uncertain"
        return "over the grid" if path in axes or sized else text

    width = _metres(col.base_width)
    if col.top_width is not None and col.top_width != col.base_width:
        width = f"{_metres(col.base_width)} (top {_metres(col.top_width)})"
    stiffness = itf.stiffness
    if stiffness.kind == "normal":
        joint = f"k_n = {value('interface.stiffness.normal', f'{stiffness.values[0]:.3g} Pa/m')}"
    elif stiffness.kind == "moment":
        k_m = ", ".join(f"{v:.3g}" for v in stiffness.values)
        joint = f"K_M = {value('interface.stiffness.rotational', k_m + ' N m/rad')}"
    else:
        joint = "rigid joints"
    restitution = itf.restitution
    e = restitution if isinstance(restitution, str) else f"{restitution:.3g}"
    parts = [
        f"H = {value('column.height', _metres(col.height))}",
        f"B = {value('column.base_width', width)}",
        f"drums = {value('column.drums', str(col.n_drums))}",
        joint,
        f"e = {value('interface.restitution', e)}",
    ]
    if model:
        parts.append(f"model {config.model}")
    if varying:
        parts.append(f"each cell the majority of {samples} samples")
    if itf.damping > 0 or "interface.damping" in axes:
        parts.insert(5, f"damping zeta = {value('interface.damping', f'{itf.damping:.3g}')}")
    if MODELS[config.model].beam and itf.friction_limit is not None:
        parts.append(f"interface.friction = {itf.friction_limit:.3g}")
    frame = config.frame
    if frame is not None:
        beam = value("frame.beam_mass", f"{frame.beam_mass:.4g} kg")
        beam = f"(its mass {beam})" if beam == "over the grid" else f"of {beam}"
        return f"frame: {frame.columns} columns under a beam {beam}; each " + ", ".join(parts)
    return "column: " + ", ".join(parts)


def _plain(df: pd.DataFrame, dimensionless: bool, layout: str) -> bool:
    """Today's plot: physical axes, a domain with no axis beside amplitude and frequency."""
    return not dimensionless and layout == "auto" and not axis_columns(df.columns)


def _polar(df: pd.DataFrame, dimensionless: bool, layout: str) -> bool:
    """The polar picture: a domain over excitation.angle, physical axes, layout 'auto'."""
    return not dimensionless and layout == "auto" and has_angle_axis(df)


def _polar_axes(ax, df: pd.DataFrame, config: Config | None, compare, where: str):
    """The polar picture of the domain on ``ax`` (a polar axes in its place when it is
    not one; a new Figure's when None); returns the polar axes."""
    if list(compare):
        raise RbmError(
            f"the polar picture of {where} (over {ANGLE_AXIS}) draws one domain: compare"
            " domains in panels (--panels)"
        )
    if ax is None:
        # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
        from matplotlib.figure import Figure

        ax = Figure(figsize=POLAR_SIZE).add_subplot(projection="polar")
    elif ax.name != "polar":
        fig, spec = ax.figure, ax.get_subplotspec()
        if spec is None:
            raise RbmError(
                f"the polar picture of {where} takes the place of an axes on a grid:"
                " pass ax=None, a subplot or a polar axes"
            )
        ax.remove()
        ax = fig.add_subplot(spec, projection="polar")
    return draw_polar(ax, df, config, where)


def _config_options(config: Config | None) -> dict:
    """plot_domain's column, excitation type and uplift level of a config (of its nominal
    config where it has uncertain keys: rbm_cli.study.cells.nominal_config)."""
    if config is None:
        return {}
    config = nominal_config(config)
    level, label = uplift_level(config)
    return {
        "column": build_column(config.column, config.interface),
        "excitation_type": config.excitation.type,
        C.static_multiplier: level,
        "static_label": label,
    }


def _compared(view: DomainView, compare, labels, compare_configs, where):
    """The compared domains in the view's columns: all of each for one plane, per point for
    panels (a list per point); an overlay draws none."""
    compare = list(compare)
    if not compare:
        return []
    if view.layout == "overlay":
        raise RbmError(f"overlay draws one line per point of {where}: compare domains in panels")
    names = list(labels[1:]) if labels else [f"domain {k + 2}" for k in range(len(compare))]
    configs = list(compare_configs) if compare_configs else [None] * len(compare)
    if view.dimensionless:
        compare = [with_scales(c, cfg, name) for c, cfg, name in zip(compare, configs, names,
                                                                      strict=True)]  # fmt: skip
    for c, name in zip(compare, names, strict=True):
        missing = [col for col in (view.x, view.y) if col not in c.columns]
        if missing:
            raise RbmError(f"{name} has no column {missing[0]}: it cannot be drawn over {where}")
    if view.layout == "single":
        return compare
    return [[view.at_point(c, p, n) for c, n in zip(compare, names, strict=True)]
            for p in view.points]  # fmt: skip


def draw_domain_on(
    df: pd.DataFrame,
    ax=None,
    config: Config | None = None,
    *,
    dimensionless: bool = False,
    layout: str = "auto",
    compare: Sequence[pd.DataFrame] = (),
    labels: Sequence[str] | None = None,
    compare_configs: Sequence[Config | None] | None = None,
    where: str = "the domain",
    colorbar: bool = True,
    **options,
):
    """Draw a domain on an axes (a new Figure's when None), as domain_view lays it out.

    Returns the axes, or for panels the list of the panels' axes (they take the place of
    ``ax`` in its figure). ``options`` (column, excitation_type, static_multiplier,
    static_label of rbm_cli.report.plot_domain.plot_domain) apply to the plain plot only;
    ``config`` gives them otherwise. ``compare_configs``: the compared domains' configs,
    for dimensionless axes of domains written without their scale columns; ``colorbar``
    False: panels of an ensemble leave their colour bar to the caller. A domain over
    excitation.angle in physical axes with layout 'auto' is drawn in polar axes
    (rbm_cli.report.plot_polar), on ``ax`` if it is polar, else on a polar axes that takes
    its place; the polar axes is returned. A domain over samples of uncertain keys is
    drawn as its samples' majority (rbm_cli.study.samples)."""
    df, compare = majority_frame(df), [majority_frame(c) for c in compare]
    if _plain(df, dimensionless, layout):
        options = {**_config_options(config), **options}
        return plot_domain(df, ax=ax, compare=compare, labels=labels, **options)
    if options:
        raise RbmError(
            f"{', '.join(options)}: for the plain plot only; with dimensionless axes or"
            " more axes the config gives the column and its levels"
        )
    if _polar(df, dimensionless, layout):
        return _polar_axes(ax, df, config, compare, where)
    view = domain_view(df, config, dimensionless, layout, where)
    others = _compared(view, compare, labels, compare_configs, where)
    if ax is None:
        # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
        from matplotlib.figure import Figure

        ax = Figure(figsize=figure_size(view)).add_subplot()
    if view.layout == "panels":
        fig, spec = ax.figure, ax.get_subplotspec()
        if spec is None:
            raise RbmError("panels take the place of an axes on a grid: pass ax=None or a subplot")
        ax.remove()
        return draw_panels(fig, view, spec, others, labels, colorbar)
    if view.layout == "overlay":
        draw_overlay(ax, view, numeric=_numeric(view))
    else:
        draw_plane(ax, view, view.points[0], others, labels)
    return ax


def _numeric(view: DomainView) -> bool:
    """The overlaid points are the values of one numeric axis (linked ones count as one:
    the first value names the point), drawn in ordered colours."""
    first = [p.values[0] for p in view.points]
    numeric = all(isinstance(v, numbers.Real) and not isinstance(v, bool) for v in first)
    return numeric and len(set(first)) == len(first)


def figure_size(view: DomainView) -> tuple[float, float]:
    """Width and height [in] of a view's figure: panels 3.4 x 2.7 each, legend beside
    (a polar picture's: :data:`POLAR_SIZE`)."""
    if view.layout != "panels":
        return (9.5, 5.0)
    n = len(view.points)
    ncols = min(4, math.ceil(math.sqrt(n)))
    return (3.4 * ncols + 3.2, 2.7 * math.ceil(n / ncols) + 0.8)


def domain_figure(
    df: pd.DataFrame,
    config: Config | None,
    compare: Sequence[pd.DataFrame] = (),
    labels: Sequence[str] | None = None,
    *,
    dimensionless: bool = False,
    layout: str = "auto",
    compare_configs: Sequence[Config | None] | None = None,
    where: str = "the domain",
) -> Figure:
    """The figure of domain.png (a Figure of its own, not held by pyplot).

    Parameters
    ----------
    df : DataFrame  The domain (domain.csv's rows)
    config : Config or None  The config it was swept with (None: the cells and boundaries only)
    compare : sequence of DataFrame  Other domains whose boundaries are drawn over it
    labels : sequence of str  Their legend labels
    dimensionless : bool  A / (g tan alpha) against omega / p (rbm_cli.structures.similarity)
    layout : str  'auto', 'panels' or 'overlay' for a domain over more axes than amplitude
        and frequency (rbm_cli.report.domain_view: the rule of 'auto')
    compare_configs : sequence  The configs of ``compare`` (dimensionless axes of old domains)
    where : str  How messages name the domain (its file)

    A domain over samples of uncertain keys is drawn as its samples' majority, a cell per
    point of the grid (rbm_cli.study.samples: collapsed where half its samples or more
    collapsed).
    """
    df, compare = majority_frame(df), [majority_frame(c) for c in compare]
    if _plain(df, dimensionless, layout):
        return _plain_figure(df, config, compare, labels)
    if _polar(df, dimensionless, layout):
        return _polar_figure(df, config, compare, labels, where)
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.figure import Figure

    view = domain_view(df, config, dimensionless, layout, where)
    fig = Figure(figsize=figure_size(view))
    ax = fig.add_subplot()
    drawn = draw_domain_on(df, ax, config, dimensionless=dimensionless, layout=layout,
                           compare=compare, labels=labels, compare_configs=compare_configs,
                           where=where, colorbar=False)  # fmt: skip
    name = config.name if config is not None else (labels[0] if labels else "")
    kind = f" ({config.excitation.type})" if config is not None else ""
    title = (f"{name}: " if name else "") + f"safe-unsafe domain{kind}" + (
        ", dimensionless" if dimensionless else "")  # fmt: skip
    freqs = df[C.frequency_hz].dropna().unique()
    if view.line != C.frequency_hz and len(freqs) == 1:
        title += f", at {freqs[0]:g} Hz"
    if config is not None:
        title += "\n" + column_note(config)
    if isinstance(drawn, list):
        fig.suptitle(title)
    else:
        drawn.set_title(title)
    fig.tight_layout()
    if isinstance(drawn, list) and C.collapse_fraction in df.columns:
        _colorbar_below(fig, drawn)
    frame_sketch(fig, config)
    return fig


def frame_sketch(fig, config: Config | None) -> None:
    """A frame's columns and beam at rest, drawn small in the figure's lower right corner
    (the rule of rbm_cli.structures.frame.beam_box, as `rbm run`'s shapes.png draws them);
    nothing for a column standing alone."""
    if config is None or config.frame is None or config.frame.beam_mass == 0.0:
        return
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.patches import Polygon

    column = build_column(config.column, config.interface)
    resolved = config.resolved()
    spacing, length, height, _ = beam_box(resolved["column"], resolved["frame"])
    drums = drum_outlines(np.zeros(column.n), column.widths, column.heights)
    ax = fig.add_axes((0.87, 0.02, 0.12, 0.26))
    first = -(config.frame.columns - 1) * spacing / 2.0
    for c in range(config.frame.columns):
        for corners in drums:
            ax.add_patch(Polygon(corners + [first + c * spacing, 0.0], closed=True,
                                 facecolor="#c9b79c", edgecolor="0.2", linewidth=0.5))  # fmt: skip
    top, half = column.height, length / 2.0
    box = [[-half, top], [half, top], [half, top + height], [-half, top + height]]
    ax.add_patch(Polygon(box, closed=True, facecolor="#a89070", edgecolor="0.2", linewidth=0.5))
    ax.set_xlim(-half * 1.1, half * 1.1)
    ax.set_ylim(0.0, top + height)
    ax.set_aspect("equal")
    ax.axis("off")
    ax.set_title(f"{config.frame.columns} columns under a beam", fontsize="x-small")


def _colorbar_below(fig, axes: list) -> None:
    """The collapse fraction's colour bar in a band added below the panels (after the
    tight layout, which cannot place a colour bar shared by several axes)."""
    width, old = fig.get_size_inches()
    band = 0.85  # [in]: the bar, its ticks and label, under the panels' own margin
    height = old + band
    fig.set_size_inches(width, height)
    pars = fig.subplotpars
    top = 1.0 - (1.0 - pars.top) * old / height  # the margins keep their inches
    fig.subplots_adjust(bottom=(pars.bottom * old + band) / height, top=top)
    fig._suptitle.set_y(1.0 - (1.0 - fig._suptitle.get_position()[1]) * old / height)
    x0 = min(ax.get_position().x0 for ax in axes)
    x1 = max(ax.get_position().x1 for ax in axes)
    cax = fig.add_axes((x0, 0.45 / height, x1 - x0, 0.12 / height))
    fraction_colorbar(fig, None, cax=cax)


def _polar_figure(df, config, compare, labels, where) -> Figure:
    """The polar picture of a domain over excitation.angle, titled by its config and model
    (rbm_cli.report.plot_polar)."""
    ax = _polar_axes(None, df, config, compare, where)
    fig = ax.figure
    what = "critical amplitude against the azimuth of the ground motion"
    if config is None:
        name = labels[0] if labels else "domain"
        ax.set_title(f"{name}: {what}")
    else:
        ax.set_title(f"{config.name}, model {config.model}: {what} ({config.excitation.type})"
                     f"\n{column_note(config, model=False)}")  # fmt: skip
    fig.tight_layout()
    return fig


def _plain_figure(df, config, compare, labels) -> Figure:
    """A domain over amplitude and frequency only, in physical axes (as it always was)."""
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9.5, 5))
    ax = fig.add_subplot()
    if config is None:  # a domain without its config: no column, no curves of it
        plot_domain(df, ax=ax, compare=compare, labels=labels)
        if labels:
            ax.set_title(f"{labels[0]}: safe-unsafe domain")
        fig.tight_layout()
        return fig
    plot_domain(df, ax=ax, compare=compare, labels=labels, **_config_options(config))
    ax.set_title(f"{config.name}: safe-unsafe domain ({config.excitation.type})\n"
                 f"{column_note(config)}")  # fmt: skip
    fig.tight_layout()
    frame_sketch(fig, config)
    return fig
