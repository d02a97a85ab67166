"""The cells of a sweep: the points of the axes over config keys x frequencies x amplitudes.

A cell is ``(amplitude_g, frequency_hz, values)``: values are the (path, value) pairs of its
point (rbm_cli.config.points), empty for a plain amplitude x frequency grid; frequency_hz
is None for an excitation without one (a record). Cells are listed point-major, then
frequency-major, so a plain grid lists its cells as it always did. A domain.csv row
carries its point as one column per path, named by the path (the dots tell them from the
result's columns), the scales of its column (rbm_cli.structures.similarity) and, for a
record, the record's intensity measures (rbm_cli.study.intensities).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from rbm_cli.config.load import parse_config
from rbm_cli.config.motions import Motion
from rbm_cli.config.points import GridPoint, expand, point_written
from rbm_cli.config.types import Config
from rbm_cli.structures.similarity import rocking_scales
from rbm_cli.study.domain import cell_key, row_key
from rbm_cli.study.intensities import column_period, measure_values
from rbm_cli.study.schema import C, domain_columns, scale_values

Cell = tuple  # (amplitude_g, frequency_hz or None, ((path, value), ...))


def grid_points(config: Config) -> list[GridPoint]:
    """The points of a config's axes over config keys, each with its validated config."""
    return expand(config, parse_config, base_dir=config.base_dir)


def nominal_config(config: Config) -> Config:
    """The config without its uncertain section, each uncertain key whose distribution
    draws one value (a point mass) set to it, the others as written: the column a figure
    of a domain over samples draws its levels for (rbm_cli.report.domain_figure)."""
    if config.uncertain is None:
        return config
    fixed = tuple(
        (path, d.point_mass) for path, d in config.uncertain.keys if d.point_mass is not None
    )
    if config.written is None:
        return dataclasses.replace(config, uncertain=None)
    written = point_written(config.written, fixed)
    if isinstance(config.written.get("grid"), Mapping):
        written["grid"] = config.written["grid"]
    return parse_config(written, base_dir=config.base_dir)


def frequencies(config: Config) -> tuple:
    """The grid's frequencies [Hz], or (None,) for an excitation without one."""
    return config.grid.frequencies_hz or (None,)


def grid_cells(config: Config, points: list[GridPoint] | None = None) -> list[Cell]:
    """Every cell of the grid: point-major, then frequency-major (module docstring)."""
    points = grid_points(config) if points is None else points
    return [
        (a, f, point.values)
        for point in points
        for f in frequencies(config)
        for a in config.grid.amplitudes_g
    ]


def count_cells(config: Config) -> int:
    """The number of cells, counted without listing them: a cell per sample of the
    uncertain keys (rbm_cli.config.uncertain)."""
    samples = 1 if config.uncertain is None else config.uncertain.samples
    return config.grid.n_cells * samples


def key(cell: Cell) -> tuple[str, ...]:
    """The identity of a cell (rbm_cli.study.domain.cell_key of its values)."""
    a, f, values = cell
    return cell_key(a, f, *(v for _, v in values))


def has_records(config: Config) -> bool:
    """Whether the config's ground motion is a record (or a suite of records)."""
    return config.excitation.type == "record"


def record_name(config: Config) -> str:
    """The name of a record config's record in a domain's ``record`` column: its file's
    stem, or the name of a motion given as arrays."""
    motion = config.excitation.motion
    return motion.name if motion is not None else Path(str(config.excitation.file)).stem


def domain_fields(config: Config, fields: tuple[str, ...] | None = None) -> tuple[str, ...]:
    """domain.csv's columns without an ensemble's (rbm_cli.study.schema.domain_columns):
    the axis paths, ``record`` (the record's name, for record excitations), the result's
    columns (of those every domain has, ``fields`` only when given; ``slides`` after
    friction_demand when model rbm's demand is checked against interface.friction; the
    collapse azimuth and the wobbling turns after max_top_displacement_m for a model in
    three dimensions), the scales, the record's intensity measures (record excitations
    only)."""
    return domain_columns(config, 1, fields)


def tasks(
    config: Config, points: list[GridPoint], todo: list[Cell], jobs: int
) -> list[tuple[Config, list[Cell]]]:
    """The cells still to do in chunks of one point each (one column per chunk, so a
    worker assembles it once): (the point's config, cells), in grid order."""
    by_point: dict[tuple, list[Cell]] = {}
    for cell in todo:
        by_point.setdefault(cell[2], []).append(cell)
    configs = {p.values: p.config for p in points}
    size = int(np.clip(len(todo) // max(1, 16 * jobs), 1, 32))
    out = []
    for values, cells in by_point.items():
        out.extend((configs[values], cells[i : i + size]) for i in range(0, len(cells), size))
    return out


def max_drums(points: list[GridPoint]) -> int:
    """The most joints of any point's column (the journal's collapse_interface range): its
    drums, and a frame's beam joint where the beam has a mass (rbm_cli.structures.frame)."""
    return max(p.config.column.n_drums + _beam_joint(p.config) for p in points)


def _beam_joint(config) -> int:
    return int(config.frame is not None and config.frame.beam_mass > 0.0)


#: add_point's period not given: computed from the config.
_FROM_CONFIG = object()


def add_point(row: dict, config: Config, cell: Cell, scales=None, period=_FROM_CONFIG) -> dict:
    """The row with its point's values, its column's scales and, for a record, the
    record's intensity measures (``period``: the column's first elastic period [s], None
    for a rigid column; computed when not given)."""
    a, f, values = cell
    row.update({p: str(v) if isinstance(v, Motion) else v for p, v in values})
    if has_records(config):
        row[C.record] = record_name(config)
    scales = scales or rocking_scales(config)
    row.update(scale_values(scales, a, f))
    if has_records(config):
        t1 = column_period(config) if period is _FROM_CONFIG else period
        row.update(measure_values(config, a, scales, t1))
    return row


__all__ = [
    "Cell",
    "add_point",
    "count_cells",
    "domain_fields",
    "frequencies",
    "grid_cells",
    "grid_points",
    "has_records",
    "key",
    "max_drums",
    "nominal_config",
    "record_name",
    "row_key",
    "tasks",
]
