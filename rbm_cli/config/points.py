"""The points of a grid's axes over config keys, each a validated config of its own.

A point sets each axis's path (rbm_cli.config.grid) in a copy of the config as written,
then the copy is validated as any config is, so a bad value is refused with the message
the key itself gives, prefixed by the point (``grid point column.height = -1: ...``).
The point's config has the excitation's grid (amplitudes, frequencies) and no other axes.
"""

from __future__ import annotations

import copy
import itertools
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from rbm_cli.base.errors import ConfigError
from rbm_cli.config.grid import EXCITATION_AXES, point_label
from rbm_cli.config.types import Config
from rbm_cli.config.uncertain import SAMPLE, config_path
from rbm_cli.config.validate import describe, is_number

#: Column lengths a ``column.size`` axis scales [m] (``drums`` when it lists heights).
COLUMN_LENGTHS = ("height", "base_width", "top_width", "depth")


@dataclass(frozen=True)
class GridPoint:
    """One point of the axes: the values by path, in axis order, and its config."""

    values: tuple[tuple[str, Any], ...]
    config: Config

    @property
    def label(self) -> str:
        return point_label(tuple(p for p, _ in self.values), tuple(v for _, v in self.values))


def point_values(config: Config) -> list[tuple[tuple[str, Any], ...]]:
    """The points of a config's axes over config keys, outermost axis first: each a
    tuple of (path, value); one empty point when the grid has no such axes."""
    axes = config.grid.axes
    out = []
    for combo in itertools.product(*(axis.points for axis in axes)):
        out.append(
            tuple(
                (p, v)
                for axis, point in zip(axes, combo, strict=False)
                for p, v in zip(axis.paths, point, strict=False)
            )
        )
    return out


def expand(config: Config, parse: Callable[..., Config], **parse_kw) -> list[GridPoint]:
    """Every point of the config's axes with its validated config (``parse`` is
    rbm_cli.config.load.parse_config, passed in to keep this module below it), each point
    once per sample of the ``uncertain`` section (rbm_cli.config.uncertain: the point's
    values then ``sample`` and the sample's value of each key, by domain.csv's column); a
    config without such axes and without uncertain keys is its own single point."""
    uncertain = config.uncertain
    if not config.grid.axes and uncertain is None:
        return [GridPoint((), config)]
    if config.written is None:
        raise ConfigError("a config with grid axes needs the mapping it was written as")
    samples = [()] if uncertain is None else [uncertain.point(s) for s in range(uncertain.samples)]
    out = []
    for values in (v + s for v in point_values(config) for s in samples):
        label = point_label(tuple(p for p, _ in values), tuple(v for _, v in values))
        try:
            data = point_written(config.written, values)
        except ConfigError as exc:
            raise ConfigError(f"grid point {label}: {exc}") from None
        out.append(GridPoint(values, parse(data, f"grid point {label}", **parse_kw)))
    return out


def point_written(written: Mapping[str, Any], values: tuple[tuple[str, Any], ...]) -> dict:
    """A copy of the written config with the point's values set, the grid reduced to
    the excitation's axes and no uncertain section (a sample's values are among the
    point's: ``sample`` sets nothing, ``uncertain.<path>`` sets the path)."""
    data = copy.deepcopy(dict(written))
    data.pop("uncertain", None)
    grid = data.get("grid")
    grid = grid if isinstance(grid, Mapping) else {}
    data["grid"] = {k: grid[k] for k in EXCITATION_AXES if k in grid}
    if not data["grid"]:
        del data["grid"]
    virtual = {}
    for path, value in values:
        if path == SAMPLE:
            continue
        path = config_path(path) or path
        if path in ("column.size", "column.slenderness"):
            virtual[path] = value
        else:
            _set(data, path.split("."), value)
    if "column.size" in virtual:
        _scale_column(data, virtual["column.size"])
    if "column.slenderness" in virtual:
        _set_slenderness(data, virtual["column.slenderness"])
    return data


def _set(data: dict, keys: list[str], value: Any) -> None:
    """data[k0][k1]...[kn] = value, making a mapping of any level that is not one (an
    ``interface.stiffness.normal`` axis over ``stiffness: rigid``)."""
    node = data
    for key in keys[:-1]:
        if not isinstance(node.get(key), Mapping):
            node[key] = {}
        node[key] = dict(node[key])
        node = node[key]
    node[keys[-1]] = value


def _column(data: dict, path: str, value: Any) -> dict | None:
    """The column mapping, or None when the parse will refuse it anyway."""
    column = data.get("column")
    if not isinstance(column, Mapping) or not is_number(column.get("height")):
        return None
    if not (is_number(value) and value > 0):
        raise ConfigError(f"{path} must be a number > 0, got {describe(value)}")
    return column


def _scale_column(data: dict, size: Any) -> None:
    """Scale every length of the column so that its height is ``size`` [m] (a capital's
    too, a top mass's height with them and its mass with the volume)."""
    column = _column(data, "column.size", size)
    if column is None:
        return
    ratio = float(size) / float(column["height"])
    for key in COLUMN_LENGTHS:
        if is_number(column.get(key)):
            column[key] = column[key] * ratio
    column["height"] = float(size)
    drums = column.get("drums")
    if isinstance(drums, list) and all(is_number(h) for h in drums):
        column["drums"] = [h * ratio for h in drums]
    _scale_keys(column, "capital", ("height", "width", "depth"), ratio)
    # a similar top mass: its lever scales with the lengths, its mass as the volume
    _scale_keys(column, "top_mass", ("height_of_centre",), ratio)
    _scale_keys(column, "top_mass", ("mass",), ratio**3)


def _scale_keys(column: dict, key: str, names: tuple[str, ...], ratio: float) -> None:
    """Scale the numbers ``names`` of the mapping column[key] (a capital, a top mass)."""
    if not isinstance(column.get(key), Mapping):
        return
    sub = column[key] = dict(column[key])
    for name in names:
        if is_number(sub.get(name)):
            sub[name] = sub[name] * ratio


def _set_slenderness(data: dict, slenderness: Any) -> None:
    """Base width = height / slenderness; top width and depth (and a capital's width and
    depth) scale with it."""
    column = _column(data, "column.slenderness", slenderness)
    if column is None or not is_number(column.get("base_width")):
        return
    base = float(column["height"]) / float(slenderness)
    ratio = base / float(column["base_width"]) if column["base_width"] else 1.0
    for key in ("top_width", "depth"):
        if is_number(column.get(key)):
            column[key] = column[key] * ratio
    column["base_width"] = base
    _scale_keys(column, "capital", ("width", "depth"), ratio)


__all__ = ["GridPoint", "expand", "point_values", "point_written"]
