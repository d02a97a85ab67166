"""Domains for the library and ``rbm plot-domain`` / ``rbm compare``: read a stored one,
find the config stored beside it, compare two, check the regression rule, draw one."""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from rbm_cli.api.configs import as_config
from rbm_cli.api.motions import motion_config
from rbm_cli.base import files
from rbm_cli.base.errors import RbmError
from rbm_cli.config.types import Config
from rbm_cli.study.domain import REQUIRED, axis_columns, domain_config
from rbm_cli.study.domain import compare as compare_domains
from rbm_cli.study.domain import read_domain as _read_domain
from rbm_cli.study.fingerprint import migrate as _migrate
from rbm_cli.study.result import STATUSES
from rbm_cli.study.schema import C

if TYPE_CHECKING:
    import pandas as pd

__all__ = [
    "DomainComparison",
    "axis_columns",
    "check_regression",
    "compare",
    "compare_domains",
    "domain_config",
    "draw_domain",
    "has_robustness",
    "migrate",
    "plot_domain",
    "read_domain",
    "save_figure",
]


def has_robustness(df) -> bool:
    """Whether a domain table holds an ensemble's robustness (its ``robust`` column)."""
    return C.robust in df.columns


def save_figure(fig, path: str | os.PathLike) -> Path:
    """Save a matplotlib figure to ``path`` in one step (rbm_cli.base.files.save_figure_atomic:
    its type from the suffix, 150 dpi); returns the path."""
    return files.save_figure_atomic(fig, path)


def check_regression(a: pd.DataFrame, b: pd.DataFrame):
    """The regression rule of domain B against the reference A (rbm_cli.study.regression.check:
    robust cells must not differ; B an ensemble within its bound of sensitive cells)."""
    # lazy: loads pandas only where needed (docs/architecture.md, Start-up)
    from rbm_cli.study.regression import check

    return check(a, b)


def draw_domain(df: pd.DataFrame, config: Config | None, **options):
    """domain.png's figure of a domain (rbm_cli.report.domain_figure.domain_figure: compare,
    labels, dimensionless, layout, compare_configs, where); matplotlib imported here."""
    # lazy: loads pandas and matplotlib only where needed (docs/architecture.md, Start-up)
    from rbm_cli.report.domain_figure import domain_figure

    return domain_figure(df, config, **options)


def plot_domain(
    df: pd.DataFrame,
    ax=None,
    config: Config | str | os.PathLike | Mapping[str, Any] | None = None,
    *,
    dimensionless: bool = False,
    layout: str = "auto",
    **options,
):
    """Draw a safe-unsafe domain (frequency [Hz] x amplitude [g]) on a matplotlib axes.

    Parameters
    ----------
    df : pandas.DataFrame  A domain: :func:`sweep`'s or :func:`read_domain`'s
    ax : matplotlib Axes, optional  None: a new Figure, not held by pyplot
    config : Config, path or mapping, optional  The config swept: adds the level [g] where
        the column starts to rock (B/H for a rigid monolith) and the closed forms that apply.
        For the domain of ``rbm.sweep(cfg, motions=[...])`` the config given to it
        (``cfg``): the motions it was swept with are read from ``df.attrs["motions"]``
    dimensionless : bool  Axes omega / p and A / (g tan alpha) instead (read from the domain's
        scale columns, or computed from ``config`` for domains written before them)
    layout : str  A domain over more axes than amplitude and frequency: 'panels' (one per
        point of the others), 'overlay' (each point's boundary a line) or 'auto'
        (rbm_cli.report.domain_view: with one frequency the innermost axis goes on x)
    **options  For rbm_cli.report.plot_domain.plot_domain (compare, labels, ...)

    Returns
    -------
    matplotlib Axes  (panels: the list of their axes, in the place of ``ax``; a domain over
        ``excitation.angle``: a polar axes, in the place of ``ax`` unless it is polar)

    Notes
    -----
    A domain over the ground motion's azimuth (an ``excitation.angle`` axis: models
    housner-3d and rbm-3d) is drawn in polar axes with layout 'auto' in physical axes: per
    angle [deg], the lowest amplitude that collapsed (solid) and the highest below it that
    survived (dashed) [g] as radii, the band between them shaded, one curve per frequency
    and point of any other axis; an angle where nothing collapsed is drawn open on a ring
    beyond the largest amplitude; failed runs count as neither and the legend says how
    many were left out (rbm_cli.report.plot_polar.polar_boundary computes the radii).
    'panels', 'overlay' or ``dimensionless`` lay it out as any other domain.

    Examples
    --------
    >>> import rbm
    >>> ax = rbm.plot_domain(rbm.read_domain("out/block/domain.csv"))  # doctest: +SKIP
    """
    # lazy: loads pandas and matplotlib only where needed (docs/architecture.md, Start-up)
    from rbm_cli.report.domain_figure import draw_domain_on

    cfg = None if config is None else as_config(config)
    motions = getattr(df, "attrs", {}).get("motions")
    if cfg is not None and motions and "excitation.file" not in cfg.grid.axis_paths:
        cfg = motion_config(cfg, motions, axis=True)  # the config with them, as swept
    return draw_domain_on(df, ax, cfg, dimensionless=dimensionless, layout=layout, **options)


@dataclass(frozen=True)
class DomainComparison:
    """What ``rbm compare A B`` reports of two domains, as data.

    n_common : int  Cells in both (matched on amplitude, frequency and any other axes)
    n_differ : int  Common cells whose collapsed flag differs
    fraction : float  n_differ / n_common [-] (nan without common cells)
    only_a, only_b : int  Cells in one domain only
    max_shift_g : float  Largest |boundary shift| [g]
    shifts : pandas.DataFrame  One row per boundary line (frequency_hz [Hz], and the other
        axes' values): boundary_a_g, boundary_b_g, shift_g [g] (a frequency without a
        collapsed cell: one grid step above the highest amplitude)
    regression : RegressionCheck or None  The regression rule, when A is an ensemble
        domain (a ``robust`` column): ``.ok``, ``.summary()``, ``robust_differ`` ...

    Examples
    --------
    >>> import pandas as pd, rbm
    >>> a = pd.DataFrame({"amplitude_g": [0.1, 0.3], "frequency_hz": 1.0,
    ...                   "status": ["survived", "collapsed"]})
    >>> same = rbm.compare(a, a)
    >>> isinstance(same, rbm.DomainComparison), same.n_differ, same.max_shift_g
    (True, 0, 0.0)
    """

    n_common: int
    n_differ: int
    fraction: float
    only_a: int
    only_b: int
    max_shift_g: float
    shifts: pd.DataFrame
    regression: Any = None


def compare(a: pd.DataFrame | str | os.PathLike, b: pd.DataFrame | str | os.PathLike
            ) -> DomainComparison:  # fmt: skip
    """Compare two domains cell by cell and boundary by boundary, as ``rbm compare`` does.

    Where ``rbm compare`` refuses two domains that do not cover the same cells (or have
    none in common), this returns the counts (``only_a``, ``only_b``, ``n_common``) and
    leaves the judgement to the caller; its limits (``--max-cells``, ``--max-shift``) are
    comparisons of ``fraction`` and ``max_shift_g``.

    Parameters
    ----------
    a, b : pandas.DataFrame or path  Domains (:func:`sweep`'s or :func:`read_domain`'s
        rows, or a domain.csv); A is the reference

    Returns
    -------
    DomainComparison  Counts of cells in common, differing and in one domain only, the
        boundary shift per line [g], and the regression rule when A has ``robust``

    Raises
    ------
    RbmError  A domain that cannot be read, or that is not a domain: a value that is not
        a DataFrame or a path, a frame without amplitude_g, frequency_hz or status, a bad
        value in them (one line naming the argument, ``a`` or ``b``, and the row)

    Examples
    --------
    >>> import pandas as pd, rbm
    >>> a = pd.DataFrame({"amplitude_g": [0.1, 0.2, 0.3], "frequency_hz": 1.0,
    ...                   "status": ["survived", "collapsed", "collapsed"]})
    >>> b = a.assign(status=["survived", "survived", "collapsed"])
    >>> c = rbm.compare(a, b)
    >>> c.n_common, c.n_differ, round(c.max_shift_g, 6)  # the boundary moves up 0.1 g
    (3, 1, 0.1)
    """
    frames = [_domain_frame(x, which) for x, which in ((a, "a"), (b, "b"))]
    for k, df in enumerate(frames):
        if C.collapsed not in df.columns:
            frames[k] = df.assign(collapsed=(df[C.status] == "collapsed").astype(int))
    cmp = compare_domains(*frames)
    rule = check_regression(*frames) if C.robust in frames[0].columns else None
    return DomainComparison(n_common=cmp.n_common, n_differ=cmp.n_differ, fraction=cmp.fraction,
                            only_a=cmp.only_a, only_b=cmp.only_b, max_shift_g=cmp.max_shift_g,
                            shifts=cmp.shifts, regression=rule)  # fmt: skip


def _domain_frame(value: Any, which: str) -> pd.DataFrame:
    """A domain for :func:`compare`: read from a path, or a DataFrame checked to hold a
    domain's cells (amplitude_g >= 0 [g], frequency_hz > 0 [Hz] or empty on every row,
    status one of STATUSES); an RbmError naming the argument and the row otherwise."""
    # lazy: pandas loads only where needed (docs/architecture.md, Start-up)
    import pandas as pd

    if isinstance(value, str | os.PathLike):
        return read_domain(value)
    where = f"compare: {which}"
    if not isinstance(value, pd.DataFrame):
        raise RbmError(
            f"{where} must be a domain (a DataFrame of rbm.sweep or rbm.read_domain, or the"
            f" path of a domain.csv), got {type(value).__name__}"
        )
    missing = [c for c in REQUIRED if c not in value.columns]
    if missing:
        raise RbmError(
            f"{where} is not a domain: no column {', '.join(map(repr, missing))} (a domain's"
            " rows have amplitude_g [g], frequency_hz [Hz] and status)"
        )
    if value.empty:
        raise RbmError(f"{where} has no rows")
    for col, unit, positive in ((C.amplitude_g, "g", False), (C.frequency_hz, "Hz", True)):
        x = pd.to_numeric(value[col], errors="coerce").to_numpy(float)
        with np.errstate(invalid="ignore"):
            bad = ~np.isfinite(x) | ((x <= 0.0) if positive else (x < 0.0))
        if positive and np.isnan(x).all():
            bad[:] = False  # no frequency at all: a record's domain
        if bad.any():
            i = int(np.argmax(bad))
            raise RbmError(
                f"{where}: row {i}: {col} must be a finite number {'> 0' if positive else '>= 0'}"
                f" [{unit}], got {value[col].iloc[i]!r}"
            )
    bad = ~value[C.status].isin(STATUSES).to_numpy()
    if bad.any():
        i = int(np.argmax(bad))
        raise RbmError(
            f"{where}: row {i}: status must be one of {', '.join(STATUSES)}, got"
            f" {value['status'].iloc[i]!r}"
        )
    return value


def read_domain(path: str | os.PathLike) -> pd.DataFrame:
    """A stored domain (a sweep's domain.csv) as a DataFrame, checked.

    Parameters
    ----------
    path : str or path-like  The domain.csv

    Returns
    -------
    pandas.DataFrame  One row per cell: amplitude_g [g], frequency_hz [Hz] (empty for a
        record), status, collapsed (0/1), t_collapse_s [s], collapse_interface (Int64,
        <NA> without a collapse), max_rotation_ratio [-], max_top_displacement_m [m],
        the counts (int), and the axes' and scales' columns; the types are those of
        :func:`sweep`'s frame

    Raises
    ------
    RbmError  A missing file, missing columns, a bad value or a cell twice (one line
        naming the file and line)

    Examples
    --------
    >>> import rbm
    >>> rbm.read_domain("no/such/domain.csv")
    Traceback (most recent call last):
    ...
    rbm_cli.base.errors.RbmError: domain file not found: no/such/domain.csv
    >>> df = rbm.read_domain("out/block/domain.csv")  # doctest: +SKIP
    """
    return _read_domain(path)


def migrate(folder: str | os.PathLike) -> str:
    """Bring a domain stored by an earlier rbm (its meta.json under an earlier schema of the
    config hash) to this version's hash, so that this version resumes, compares and keeps
    it as its own; its rows (amplitudes [g], frequencies [Hz], ...) and figures are not
    touched. It checks first that the domain was made by the config this version reads
    from it (the same settings, no cell that ran out of a budget, the method this version
    runs: docs/reproducibility.md) and refuses otherwise. Its rows stay those of the rbm
    that made them (meta.json's provenance); the regression rule (``rbm compare``) is
    what compares them with this version's.

    Returns a one-line note; RbmError (one line) when it cannot (re-make the domain).

    Examples
    --------
    >>> import rbm
    >>> rbm.migrate("results/suite_multidrum")  # doctest: +SKIP
    'results/suite_multidrum: schema 3 -> 4, hash ...-ensemble16 -> ...'
    """
    return _migrate(folder)
