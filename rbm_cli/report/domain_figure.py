"""The figure of a domain (domain.png): the domain in the frequency x amplitude plane with the
level at which the column starts to rock (the RBM's static multiplier, or the engine's own
uplift level for `bullet`) and the closed forms that apply."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from rbm_cli.config.types import Config
from rbm_cli.physics.column import build_column
from rbm_cli.report.plot_domain import plot_domain

if TYPE_CHECKING:  # matplotlib is imported when a figure is drawn, not with this module
    import pandas as pd
    from matplotlib.figure import Figure


def uplift_level(config: Config) -> tuple[float, str]:
    """(level [g], label) at which the config's column starts to rock: the RBM's static
    multiplier, or for `bullet` the engine's own level from its true solids."""
    if config.model == "bullet":
        from rbm_cli.models.bullet.run import engine_uplift_g

        return engine_uplift_g(config), "engine uplift level"
    column = build_column(config.column, config.interface)
    return column.static_multiplier, "static multiplier"


def domain_figure(
    df: pd.DataFrame,
    config: Config | None,
    compare: Sequence[pd.DataFrame] = (),
    labels: Sequence[str] | None = None,
) -> Figure:
    """The figure of domain.png (a Figure of its own, not held by pyplot).

    Parameters
    ----------
    df : DataFrame  The domain (domain.csv's rows)
    config : Config or None  The config it was swept with (None: the cells and boundaries only)
    compare : sequence of DataFrame  Other domains whose boundaries are drawn over it
    labels : sequence of str  Their legend labels
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9.5, 5))
    ax = fig.add_subplot()
    if config is None:  # a domain without its config: no column, no curves of it
        plot_domain(df, ax=ax, compare=compare, labels=labels)
        if labels:
            ax.set_title(f"{labels[0]}: safe-unsafe domain")
        fig.tight_layout()
        return fig
    column = build_column(config.column, config.interface)
    level, level_label = uplift_level(config)
    plot_domain(
        df,
        ax=ax,
        compare=compare,
        labels=labels,
        column=column,
        excitation_type=config.excitation.type,
        static_multiplier=level,
        static_label=level_label,
    )
    ax.set_title(f"{config.name}: safe-unsafe domain ({config.excitation.type})")
    fig.tight_layout()
    return fig
