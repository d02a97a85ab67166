"""Where a domain's cells go in a figure: its coordinates, what a boundary line runs along,
and which points are drawn as panels or as overlaid lines. No drawing here (plot_axes.py).

Coordinates. Physical: amplitude [g] on y against the *line variable* on x; dimensionless:
A / (g tan alpha) on y against omega / p on x (rbm_cli.structures.similarity), read from
domain.csv's scale columns or, for domains written before them, computed from the config
of each point.

Layout rule. The axes over config keys (domain.csv's dotted columns; linked axes, whose
values go one to one, count as one axis) and the frequencies decide:

- the *line variable* (along a boundary line, on the physical x axis) is the frequency
  when the domain has more than one; with one frequency (or none: a record) it is the
  innermost (last) axis over a config key, on a log x axis when that axis is
  ``column.size`` or log-spaced: a domain over (size, amplitude);
- the *points* are the values of the remaining axes: none gives one plane ('single');
  else one panel per point ('panels', the default up to :data:`MAX_AUTO_PANELS` points)
  or one axes with each point's boundary as a line ('overlay', the default beyond);
- asking for 'panels' or 'overlay' where no axis is left for the points puts the
  frequency back on the line (each point then a panel, or one mark per frequency);
  a domain without axes over config keys has no points and refuses both.

A record axis (``excitation.file``, ``excitation.file_y`` or ``excitation.vertical``: a
suite) is named by its records, not their paths: the ``record`` column of domain.csv (the
file's stem, or a motion's name), or the file's stem, with as many of its folders as tell
two records of one stem apart (:func:`record_names`). On x it is a categorical axis
("record"), along which a boundary is one mark per record, never a line joining unrelated
records (rbm_cli.report.plot_axes); as a point, a panel is titled ``record rdk_01``.

In dimensionless axes x is omega / p whatever the line variable: a size axis at one
frequency spreads along omega / p (p falls as the size grows) in one plane, and an overlay
of a size sweep over several frequencies puts every size's boundary on one curve. The
sweep's domain.png follows the same rule (rbm_cli.report.domain_figure).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import PurePath

import numpy as np
import pandas as pd

from rbm_cli.base.errors import RbmError
from rbm_cli.config.grid import RECORD_PATHS
from rbm_cli.config.types import Config
from rbm_cli.structures.similarity import rocking_scales
from rbm_cli.study.cells import grid_points, nominal_config
from rbm_cli.study.domain import axis_columns, cell_key, keys_of
from rbm_cli.study.schema import SCALE_COLUMNS, C, scale_values
from rbm_cli.study.schema import label as column_label

#: Layouts a caller asks for: 'auto' (the rule of the module docstring), 'panels' or
#: 'overlay' (a view's own layout is one of these two or 'single').
LAYOUTS = ("auto", "panels", "overlay")
#: The most points 'auto' draws as panels (more: an overlay); the most 'panels' draws.
MAX_AUTO_PANELS, MAX_PANELS = 12, 48
#: Units of the config keys an axis commonly varies (legends and axis labels).
UNITS = {
    "column.size": "m", "column.height": "m", "column.base_width": "m",
    "column.top_width": "m", "column.depth": "m", "column.density": "kg/m^3",
    "interface.stiffness.normal": "Pa/m", "interface.stiffness.rotational": "N m/rad",
    "excitation.duration": "s", "excitation.phase": "rad",
}  # fmt: skip
#: Axis labels of the dimensionless plane.
DIMENSIONLESS_LABELS = (column_label(C.omega_over_p), column_label(C.a_over_g_alpha))
#: The physical axes' labels (rbm_cli.study.schema).
FREQUENCY_LABEL, AMPLITUDE_LABEL = column_label(C.frequency_hz), column_label(C.amplitude_g)
#: What the records of a record axis are called in a panel's title.
RECORD_WORDS = {"excitation.file": "record", "excitation.file_y": "y record",
                "excitation.vertical": "vertical record"}  # fmt: skip


@dataclass(frozen=True)
class Point:
    """One point of the remaining axes (a panel or an overlaid line): its label
    (``column.size = 4.47 m``; '' for a plain domain), its rows (all the domain's columns)
    and, when the config is known, the config of every cell's point by :func:`point_key`."""

    label: str
    rows: pd.DataFrame
    configs: dict = field(default_factory=dict)
    values: tuple = ()


@dataclass(frozen=True)
class DomainView:
    """How to draw a domain (module docstring): ``layout`` 'single', 'panels' or 'overlay';
    ``line`` the column along a boundary line (frequency_hz or an axis path), ``x`` and
    ``y`` the columns on the axes; ``log_x`` for a log axis, ``categories`` the tick labels
    of a non-numeric axis (x then holds their positions, ``category_of`` the position of
    each value, by its text) and ``category_word`` what one category is ("record" on a
    record axis); ``points`` in grid order, each a value of the columns ``point_paths``."""

    layout: str
    dimensionless: bool
    line: str
    x: str
    y: str
    labels: tuple[str, str]
    log_x: bool
    categories: tuple[str, ...] | None
    points: list[Point]
    point_paths: tuple[str, ...] = ()
    category_of: dict = field(default_factory=dict)
    category_word: str = "value"

    def at_point(self, other: pd.DataFrame, point: Point, where: str) -> pd.DataFrame:
        """The rows of another domain at ``point`` (matched on the point's columns)."""
        missing = [p for p in self.point_paths if p not in other.columns]
        if missing:
            raise RbmError(f"{where} has no column {missing[0]}: it cannot be drawn per point")
        if not self.point_paths:
            return other
        keys = [point_key(v) for v in other[list(self.point_paths)].itertuples(index=False)]
        return other.loc[[k == point_key(point.values) for k in keys]]

    def plane(self, rows: pd.DataFrame) -> pd.DataFrame:
        """``rows`` in the plane's coordinates, as the domain plot reads them: x in
        frequency_hz, y in amplitude_g (the axis and scale columns dropped)."""
        out = rows.drop(columns=[*axis_columns(rows.columns), C.frequency_hz, C.amplitude_g])
        x = rows[self.x]
        if self.categories is not None:  # a value no category holds (another domain's): nan
            x = x.map(lambda v: self.category_of.get(str(v), math.nan))
        out.insert(0, C.frequency_hz, pd.to_numeric(x).to_numpy(float))
        out.insert(0, C.amplitude_g, rows[self.y].to_numpy(float))
        return out


def value_text(value, path: str = "") -> str:
    """A point's value as a legend shows it (``4.47 m``)."""
    if isinstance(value, float | int | np.floating | np.integer) and not isinstance(value, bool):
        text = f"{float(value):.3g}"
    else:
        text = str(value)
    unit = UNITS.get(path)
    return f"{text} {unit}" if unit else text


def record_names(values, names=None) -> dict[str, str]:
    """{value as text: its name} of a record axis's values (file paths, or motions' names),
    in the order met: ``names`` (a mapping from the value's text, e.g. domain.csv's
    ``record`` column) or the file's stem; where two values share a name, each is named
    by the end of its path, as many folders as tell them apart (``x/rdk_01``,
    ``y/rdk_01``), and by its whole text where nothing shorter does."""
    keys = list(dict.fromkeys(str(v) for v in values))
    names = dict(names or {})
    labels = {k: str(names.get(k) or PurePath(k).stem or k) for k in keys}
    if len(set(labels.values())) == len(keys):
        return labels
    parts = {k: PurePath(k).parent.parts + (PurePath(k).stem,) for k in keys}
    for depth in range(2, max(len(p) for p in parts.values()) + 1):
        labels = {k: "/".join(parts[k][-depth:]) for k in keys}
        if len(set(labels.values())) == len(keys):
            return labels
    return {k: k for k in keys}


def axis_names(df: pd.DataFrame) -> dict[str, dict[str, str]]:
    """The names of the records of each record axis of a domain (:func:`record_names`):
    {path: {value as text: name}}; ``excitation.file`` named by the ``record`` column."""
    out = {}
    for path in RECORD_PATHS:
        if path in df.columns:
            named = None
            if path == "excitation.file" and C.record in df.columns:
                named = dict(zip(df[path].astype(str), df[C.record].astype(str), strict=True))
            out[path] = record_names(df[path], named)
    return out


def _point_text(path: str, value, names: dict) -> str:
    """A point's value as a panel's title or a legend shows it: ``record rdk_01`` on a
    record axis, else ``path = value unit``."""
    if path in names:
        return f"{RECORD_WORDS[path]} {names[path][str(value)]}"
    return f"{path} = {value_text(value, path)}"


def point_key(values) -> tuple[str, ...]:
    """Identity of a point from its axis values (as rbm_cli.study.domain.cell_key)."""
    return cell_key(0.0, None, *values)[2:]


def axis_groups(df: pd.DataFrame) -> list[tuple[str, ...]]:
    """The axes over config keys of a domain, in column order: linked columns (whose
    values go one to one over the rows) grouped as one axis."""
    groups: list[list[str]] = []
    for col in axis_columns(df.columns):
        for group in groups:
            pairs = df[[group[0], col]].astype(str).drop_duplicates()
            if pairs[group[0]].is_unique and pairs[col].is_unique:
                group.append(col)
                break
        else:
            groups.append([col])
    return [tuple(g) for g in groups]


def point_configs(df: pd.DataFrame, config: Config | None) -> dict:
    """{point_key: Config} of every point of the domain's axes, from the config it was
    swept with ({} without one); an RbmError if the config lacks a point of the domain.
    A config with uncertain keys: its nominal config's points (rbm_cli.study.cells
    .nominal_config; the domain drawn is its samples' majority, rbm_cli.study.samples)."""
    if config is None:
        return {}
    paths = axis_columns(df.columns)
    configs = {}
    for point in grid_points(nominal_config(config)):
        values = dict(point.values)
        if set(values) != set(paths):
            raise RbmError(
                f"the config {config.name} varies {', '.join(values) or 'no config key'},"
                f" the domain {', '.join(paths) or 'no config key'}: it is not its config"
            )
        configs[point_key(values[p] for p in paths)] = point.config
    for key in {k[2:] for k in keys_of(df)} - configs.keys():
        raise RbmError(
            f"the config {config.name} has no point {', '.join(key)} of the domain"
            f" ({', '.join(paths)}): it is not its config"
        )
    return configs


def with_scales(df: pd.DataFrame, config: Config | None, where: str = "the domain") -> pd.DataFrame:
    """The domain with its scale columns (SCALE_COLUMNS: alpha_rad, p_rad_s,
    static_multiplier, a_over_g_alpha, omega_over_p): as written, or computed from the
    config of each cell's point for a domain written before them. RbmError (one line) when
    they are missing and there is no config, or when the domain has no frequency."""
    if df[C.frequency_hz].isna().all():
        raise RbmError(
            f"dimensionless axes need the excitation's frequency (omega / p): {where} has none"
            " (an excitation without one, such as a record)"
        )
    if all(c in df.columns for c in SCALE_COLUMNS):
        return df
    if config is None:
        raise RbmError(
            f"dimensionless axes need the column's scales: {where} has no {SCALE_COLUMNS[0]}"
            " ... omega_over_p columns (written before them) and no config to compute them"
            " from (give its config: --config)"
        )
    configs = point_configs(df, config)
    scales = {k: rocking_scales(c) for k, c in configs.items()}
    keys = [k[2:] for k in keys_of(df)]
    amps, freqs = df[C.amplitude_g].to_numpy(float), df[C.frequency_hz].to_numpy(float)
    rows = [scale_values(scales[k], a, f) for k, a, f in zip(keys, amps, freqs, strict=True)]
    return df.assign(**pd.DataFrame(rows, index=df.index)[list(SCALE_COLUMNS)])


def _frequencies(df: pd.DataFrame) -> int:
    return int(df[C.frequency_hz].dropna().nunique())


def _split(df, groups, layout, where) -> tuple[str, list]:
    """(line variable, the axes left for the points) of the layout rule."""
    if layout in ("panels", "overlay") and not groups:
        thing = "panel" if layout == "panels" else "boundary line"
        raise RbmError(
            f"{layout} needs axes beyond amplitude and frequency (one {thing} per point of"
            f" them): {where} has none"
        )
    n_freq = _frequencies(df)
    if n_freq > 1 or not groups:
        return C.frequency_hz, groups
    if layout in ("panels", "overlay") and len(groups) == 1:
        if n_freq == 0:
            raise RbmError(
                f"{layout}: {where} has no frequency and one axis ({', '.join(groups[0])}),"
                " drawn against amplitude in a single plane: leave out the layout"
            )
        return C.frequency_hz, groups
    return groups[-1][0], groups[:-1]


def _log_axis(values, path: str, config: Config | None) -> bool:
    """A log x axis: a size axis, an axis written with ``spacing: log``, or positive values
    evenly spaced in log but not in linear (three or more)."""
    if path == "column.size":
        return True
    written = (config.written or {}).get("grid", {}) if config is not None else {}
    spec = written.get(path) if isinstance(written, dict) else None
    if isinstance(spec, dict) and spec.get("spacing") == "log":
        return True
    v = np.unique(np.asarray(values, float))
    if v.size < 3 or v[0] <= 0.0:
        return False
    step, ratio = np.diff(v), np.diff(np.log(v))
    return bool(np.ptp(ratio) < 1e-6 * abs(ratio.mean()) and np.ptp(step) > 1e-6 * step.mean())


def _coordinates(df, line, dimensionless, config, group=(), names=None) -> dict:
    """x, y, axis labels, log x and categories of the view (``group``: the linked paths of
    the line's axis; ``names``: the records' names of the record axes)."""
    if dimensionless:
        return dict(x=C.omega_over_p, y=C.a_over_g_alpha, labels=DIMENSIONLESS_LABELS,
                    log_x=False, categories=None)  # fmt: skip
    if line == C.frequency_hz:
        return dict(x=line, y=C.amplitude_g, labels=(FREQUENCY_LABEL, AMPLITUDE_LABEL),
                    log_x=False, categories=None)  # fmt: skip
    names = names or {}
    if line in names:  # a suite: its records by name, one category each
        words = "record pair (x record)" if "excitation.file_y" in group else RECORD_WORDS[line]
        keys = list(names[line])
        categories = tuple(names[line][k] for k in keys)
        return dict(x=line, y=C.amplitude_g, labels=(words, AMPLITUDE_LABEL), log_x=False,
                    categories=categories, category_of={k: i for i, k in enumerate(keys)},
                    category_word="record")  # fmt: skip
    unit = UNITS.get(line)
    label = f"{line} [{unit}]" if unit else line
    numeric = pd.to_numeric(df[line], errors="coerce")
    if numeric.notna().all():
        log = _log_axis(numeric, line, config)
        return dict(x=line, y=C.amplitude_g, labels=(label, AMPLITUDE_LABEL), log_x=log,
                    categories=None)  # fmt: skip
    categories = tuple(dict.fromkeys(value_text(v) for v in df[line]))
    category_of = {str(v): categories.index(value_text(v)) for v in df[line]}
    return dict(x=line, y=C.amplitude_g, labels=(label, AMPLITUDE_LABEL), log_x=False,
                categories=categories, category_of=category_of)  # fmt: skip


def domain_view(
    df: pd.DataFrame,
    config: Config | None = None,
    dimensionless: bool = False,
    layout: str = "auto",
    where: str = "the domain",
) -> DomainView:
    """How to draw a domain (module docstring).

    Parameters
    ----------
    df : DataFrame  A domain (domain.csv's rows)
    config : Config or None  The config it was swept with (its grid's axes included)
    dimensionless : bool  A / (g tan alpha) against omega / p instead of amplitude [g]
        against frequency [Hz] (or the axis)
    layout : str  One of :data:`LAYOUTS`
    where : str  How messages name the domain (its file)
    """
    if layout not in LAYOUTS:
        raise RbmError(f"layout must be one of {', '.join(LAYOUTS)}, got {layout!r}")
    if dimensionless:
        df = with_scales(df, config, where)
    groups = axis_groups(df)
    line, rest = _split(df, groups, layout, where)
    paths = [p for g in rest for p in g]
    configs = point_configs(df, config)
    names = axis_names(df)
    if paths:
        grouped = df.groupby(paths, sort=False, dropna=False)
        points = []
        for values, rows in grouped:
            values = values if isinstance(values, tuple) else (values,)
            label = ", ".join(_point_text(p, v, names) for p, v in zip(paths, values, strict=True))
            points.append(Point(label, rows, configs, values))
    else:
        points = [Point("", df, configs)]
    if layout == "auto":
        many = len(points) > MAX_AUTO_PANELS
        layout = "single" if not paths else "overlay" if many else "panels"
    if layout == "panels" and len(points) > MAX_PANELS:
        raise RbmError(
            f"panels: {where} has {len(points)} points, too many panels (at most"
            f" {MAX_PANELS}): use overlay"
        )
    group = next((g for g in groups if line in g), ())
    coordinates = _coordinates(df, line, dimensionless, config, group, names)
    return DomainView(layout=layout, dimensionless=dimensionless, line=line, points=points,
                      point_paths=tuple(paths), **coordinates)  # fmt: skip


def row_configs(point: Point) -> list:
    """The config of each row of a point's rows (None where unknown)."""
    if not point.configs:
        return [None] * len(point.rows)
    return [point.configs.get(k[2:]) for k in keys_of(point.rows)]


__all__ = [
    "DIMENSIONLESS_LABELS",
    "LAYOUTS",
    "DomainView",
    "Point",
    "RECORD_WORDS",
    "axis_groups",
    "axis_names",
    "domain_view",
    "point_configs",
    "point_key",
    "record_names",
    "row_configs",
    "value_text",
    "with_scales",
]
