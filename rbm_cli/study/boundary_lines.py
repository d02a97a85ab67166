"""The boundary of a safe-unsafe domain (boundary.csv, the line of domain.png): per point of
the domain's axes and frequency, the lowest collapsed amplitude and the highest survived one
below it [g].

Order. An axis whose values are all numbers is ascending; an axis holding any other value
(a string such as ``housner``, a record file) is in the order the rows first hold its
values, which for a sweep's rows is the grid's order, the axis's values as written; then
frequency ascending (none last).

Ensembles. Where the domain is an ensemble (a ``collapse_fraction`` column), the boundary is
the majority's: a cell counts as collapsed where collapse_fraction >= :data:`MAJORITY`, as
survived below it, and as neither (as a failed run) where every member failed (no
fraction: collapse_fraction is the fraction of the members that did not fail). Member 0's
own boundary (the rows' status) is kept beside it in the columns :data:`MEMBER0_FIELDS`; a
domain without an ensemble has neither those columns nor any other change.

Plain Python over rows (dicts): a sweep writes boundary.csv without pandas.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from rbm_cli.config.uncertain import is_sample_column
from rbm_cli.study.schema import C

if TYPE_CHECKING:
    import pandas as pd

#: The boundary's columns after the point's: the majority's for an ensemble [g].
BOUNDARY_FIELDS = ("lowest_unsafe_g", "highest_safe_g")
#: The boundary's columns of an ensemble's member 0 (its rows' status) [g].
MEMBER0_FIELDS = ("member0_lowest_unsafe_g", "member0_highest_safe_g")
#: The collapse fraction [-] from which an ensemble's majority collapses.
MAJORITY = 0.5


def axis_columns(columns) -> tuple[str, ...]:
    """The columns of a domain that hold its point's axes: named by a dotted config path
    (not a sample's ``uncertain.<key>``, rbm_cli.config.uncertain)."""
    return tuple(c for c in columns if "." in str(c) and not is_sample_column(str(c)))


def line_row(by: list[str], values) -> dict:
    """A boundary line's group columns ``by`` with its ``values`` (frequency as a float,
    NaN for none)."""
    values = values if isinstance(values, tuple) else (values,)

    def freq(v) -> float:
        return math.nan if v is None else float(v)

    return {c: (freq(v) if c == C.frequency_hz else v) for c, v in zip(by, values, strict=False)}


def is_empty(value) -> bool:
    """None or NaN: an empty field (a record's frequency)."""
    return value is None or (isinstance(value, float | np.floating) and math.isnan(value))


def _number(value) -> bool:
    return isinstance(value, numbers.Real)


def line_order(idents: list[tuple]) -> Callable[[tuple], tuple]:
    """Sort key of boundary lines given by their group values ``idents`` (None where empty),
    as the module docstring orders them: a column whose values are all numbers ascending,
    any other in the order ``idents`` first holds its values; empty last."""
    ranks: list[dict | None] = []
    for column in zip(*idents, strict=True):
        present = [v for v in column if v is not None]
        if all(_number(v) for v in present):
            ranks.append(None)
        else:
            ranks.append({v: k for k, v in enumerate(dict.fromkeys(present))})

    def key(ident: tuple) -> tuple:
        return tuple(
            (1, 0) if v is None else (0, v if rank is None else rank[v])
            for v, rank in zip(ident, ranks, strict=True)
        )

    return key


def line_ident(values: tuple) -> tuple:
    """Group values with None for an empty field (NaN != NaN, so NaN cannot name a line)."""
    return tuple(None if is_empty(v) else v for v in values)


def majority_status(fraction) -> str:
    """The outcome of an ensemble's majority from a cell's collapse fraction [-] (of its
    members that did not fail): 'collapsed' from :data:`MAJORITY` up, 'survived' below,
    'failed' where there is none (every member failed: no outcome, so the cell is on
    neither side of the boundary, as a failed run)."""
    if is_empty(fraction):
        return "failed"
    return "collapsed" if float(fraction) >= MAJORITY else "survived"


def _lowest_highest(cells: list[tuple]) -> tuple[float, float]:
    """(lowest collapsed amplitude, highest survived one below it) [g] of one line's
    (status, amplitude_g) pairs; NaN where there is none."""
    unsafe = [a for s, a in cells if s == "collapsed" and not is_empty(a)]
    low = float(min(unsafe)) if unsafe else math.nan
    safe = [a for s, a in cells if s == "survived" and not is_empty(a)]
    if math.isfinite(low):
        safe = [a for a in safe if a < low]
    return low, (float(max(safe)) if safe else math.nan)


def boundary_table(rows: list[dict], columns) -> tuple[tuple[str, ...], list[dict]]:
    """The boundary of a domain given as rows (dicts) with the domain's ``columns``: its
    columns (the axis columns, frequency_hz, lowest_unsafe_g, highest_safe_g and, for an
    ensemble, member0_lowest_unsafe_g, member0_highest_safe_g) and its rows (:func:`boundary`
    says what they hold), in plain Python: a sweep writes boundary.csv from its rows
    without pandas."""
    by = (*axis_columns(columns), C.frequency_hz)
    ensemble = C.collapse_fraction in columns
    lines: dict[tuple, tuple[tuple, list]] = {}
    for row in rows:
        values = tuple(row.get(c) for c in by)
        status = row.get(C.status)
        outcome = majority_status(row.get(C.collapse_fraction)) if ensemble else status
        cells = lines.setdefault(line_ident(values), (values, []))[1]
        cells.append((outcome, status, row.get(C.amplitude_g)))
    out = []
    for ident in sorted(lines, key=line_order(list(lines))):
        values, cells = lines[ident]
        line = line_row(list(by), values)
        line.update(zip(BOUNDARY_FIELDS, _lowest_highest([(o, a) for o, _, a in cells]),
                        strict=True))  # fmt: skip
        if ensemble:
            line.update(zip(MEMBER0_FIELDS, _lowest_highest([(s, a) for _, s, a in cells]),
                            strict=True))  # fmt: skip
        out.append(line)
    return (*by, *BOUNDARY_FIELDS, *(MEMBER0_FIELDS if ensemble else ())), out


def boundary(df: pd.DataFrame) -> pd.DataFrame:
    """Lowest unsafe (collapsed) amplitude per frequency, and the highest safe one below it.

    Returns a DataFrame sorted by frequency with columns frequency_hz,
    lowest_unsafe_g (NaN where nothing collapses) and highest_safe_g (largest
    survived amplitude below lowest_unsafe_g; NaN if none). A domain with axes over
    config keys has one line per point and frequency, the axis columns first, in the
    order of the module docstring. For an ensemble (a collapse_fraction column) these two
    columns are the majority's (collapsed where collapse_fraction >= 0.5; a cell whose
    members all failed is neither) and member0_lowest_unsafe_g, member0_highest_safe_g
    the same of member 0 (the rows' status). The rows are :func:`boundary_table`'s, the
    one implementation of the rule.
    """
    # lazy: pandas loads only where needed (docs/architecture.md, Start-up)
    import pandas as pd

    columns, rows = boundary_table(df.to_dict("records"), df.columns)
    return pd.DataFrame(rows, columns=list(columns))


__all__ = [
    "BOUNDARY_FIELDS",
    "MAJORITY",
    "MEMBER0_FIELDS",
    "axis_columns",
    "boundary",
    "boundary_table",
    "is_empty",
    "line_ident",
    "line_order",
    "line_row",
    "majority_status",
]
