"""A domain over the samples of uncertain keys (rbm_cli.config.uncertain) seen one row per
cell: the samples' majority, for the figure (domain.png) and the boundary (boundary.csv).

domain.csv keeps a row per cell and sample. Where one outcome per cell is drawn, a cell
counts as collapsed where at least :data:`MAJORITY` of its samples that did not fail
collapsed, as survived below it, and as failed where every sample failed (the rule of an
ensemble's majority, rbm_cli.study.boundary_lines). The cell's row is its first sample's
(the lowest ``sample``) of that outcome, without the sample's columns, and with
``sample_collapse_fraction`` beside it only where :func:`majority_rows` is asked for it:
so a domain whose samples all agree (a point mass) draws the figure and the boundary of
the same sweep without uncertain keys, byte for byte.

Plain Python over rows (dicts): a sweep draws and writes without pandas.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from rbm_cli.config.uncertain import SAMPLE, is_sample_column
from rbm_cli.study.boundary_lines import MAJORITY, axis_columns
from rbm_cli.study.schema import C

if TYPE_CHECKING:
    import pandas as pd

#: The column of the fraction of a cell's samples that collapsed (of those that did not fail).
FRACTION = "sample_collapse_fraction"


def has_samples(columns) -> bool:
    """Whether a domain's columns hold samples of uncertain keys (a ``sample`` column)."""
    return SAMPLE in [str(c) for c in columns]


def _cell(row: dict, paths: tuple[str, ...]) -> tuple:
    """A row's cell: amplitude, frequency and axis values (an empty field, None or NaN as
    a table reads it, as None: NaN equals nothing, itself included)."""
    values = (row.get(C.amplitude_g), row.get(C.frequency_hz), *(row.get(p) for p in paths))
    return tuple(None if isinstance(v, float) and math.isnan(v) else v for v in values)


def majority_rows(
    rows: list[dict], fields: tuple[str, ...], fraction: bool = False
) -> tuple[list[dict], tuple[str, ...]]:
    """(rows, fields): one row per cell, the samples' majority (module docstring), in the
    order of the cells' first rows; the rows and fields as given for a domain without
    samples. ``fraction``: add :data:`FRACTION` (empty where every sample failed)."""
    if not has_samples(fields):
        return rows, tuple(fields)
    paths = axis_columns(fields)
    cells: dict[tuple, list[dict]] = {}
    for row in rows:
        cells.setdefault(_cell(row, paths), []).append(row)
    out = []
    for group in cells.values():
        ran = [r for r in group if r.get(C.status) != "failed"]
        share = sum(r.get(C.status) == "collapsed" for r in ran) / len(ran) if ran else None
        status = (
            "failed" if share is None else "collapsed" if share >= MAJORITY else "survived"
        )  # fmt: skip
        first = min((r for r in group if r.get(C.status) == status), key=_sample)
        row = {k: v for k, v in first.items() if not is_sample_column(k)}
        if fraction:
            row[FRACTION] = share
        out.append(row)
    kept = tuple(f for f in fields if not is_sample_column(f))
    return out, (*kept, FRACTION) if fraction else kept


def _sample(row: dict) -> int:
    value = row.get(SAMPLE)
    return int(value) if value is not None and value == value else 0


def majority_frame(df: pd.DataFrame, fraction: bool = False) -> pd.DataFrame:
    """:func:`majority_rows` of a domain table (the table itself without samples)."""
    if not has_samples(df.columns):
        return df
    # lazy: pandas loads only where needed (docs/architecture.md, Start-up)
    import pandas as pd

    rows, fields = majority_rows(df.to_dict("records"), tuple(df.columns), fraction)
    out = pd.DataFrame(rows, columns=list(fields))
    for col in out.columns:
        if col in df.columns:
            out[col] = out[col].astype(df[col].dtype)
    return out


__all__ = ["FRACTION", "has_samples", "majority_frame", "majority_rows"]
