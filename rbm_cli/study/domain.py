"""Safe-unsafe domains as tables: rows, CSV text, boundary, comparison.

A domain is a pandas DataFrame with the columns of domain.csv (their schema:
rbm_cli.study.schema), one row per (amplitude, frequency) cell, or
the list of its rows (dicts) a sweep makes. pandas is imported where a DataFrame is built
or read, not with this module: a sweep writes domain.csv and boundary.csv from its rows
(:func:`csv_text`, :func:`boundary_table`) without it.

The boundary (boundary.csv) is rbm_cli.study.boundary_lines': its table, the order of its
lines and, for an ensemble, the majority's rule. This module names them too.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from rbm_cli.base.errors import RbmError
from rbm_cli.config.load import parse_config
from rbm_cli.config.motions import holds_stored_motions
from rbm_cli.config.types import Config
from rbm_cli.config.uncertain import SAMPLE
from rbm_cli.study.boundary_lines import BOUNDARY_FIELDS as BOUNDARY_FIELDS
from rbm_cli.study.boundary_lines import MAJORITY as MAJORITY
from rbm_cli.study.boundary_lines import MEMBER0_FIELDS as MEMBER0_FIELDS
from rbm_cli.study.boundary_lines import axis_columns as axis_columns
from rbm_cli.study.boundary_lines import boundary as boundary
from rbm_cli.study.boundary_lines import boundary_table as boundary_table
from rbm_cli.study.boundary_lines import line_ident, line_order, line_row
from rbm_cli.study.result import CSV_FIELDS, STATUSES
from rbm_cli.study.samples import majority_frame
from rbm_cli.study.schema import C, columns

if TYPE_CHECKING:
    import pandas as pd

#: Columns a domain CSV must have for plotting and comparing.
REQUIRED = (C.amplitude_g, C.frequency_hz, C.status)


def format_value(value) -> str:
    """CSV text of one value: floats with 12 significant digits, empty for None/NaN."""
    if value is None:
        return ""
    if isinstance(value, float | np.floating):
        if not math.isfinite(value):
            return ""
        return f"{float(value):.12g}"
    if isinstance(value, int | np.integer):
        return str(int(value))
    text = str(value)
    if any(c in text for c in ',"\n'):
        text = '"' + text.replace('"', '""').replace("\n", " ") + '"'
    return text


def format_row(row: dict, fields=CSV_FIELDS) -> str:
    return ",".join(format_value(row.get(k)) for k in fields)


def csv_text(rows: list[dict], fields=CSV_FIELDS) -> str:
    return ",".join(fields) + "\n" + "".join(format_row(r, fields) + "\n" for r in rows)


def domain_frame(rows: list[dict], fields=CSV_FIELDS) -> pd.DataFrame:
    """The DataFrame of a domain's rows (dicts) with the columns ``fields`` (pandas is
    imported here, when a table is asked for)."""
    # lazy: pandas loads only where needed (docs/architecture.md, Start-up)
    import pandas as pd

    return pd.DataFrame(rows, columns=list(fields))


def _key_text(value) -> str:
    if value is None or (isinstance(value, float | np.floating) and math.isnan(value)):
        return ""
    if isinstance(value, int | float | np.integer | np.floating) and not isinstance(value, bool):
        return f"{float(value):.12g}"
    return str(value)


def cell_key(amplitude_g: float, frequency_hz: float | None, *values) -> tuple[str, ...]:
    """Identity of a grid cell, stable through a CSV round trip: amplitude, frequency
    (empty for none) and the values of its point's axes (rbm_cli.study.cells)."""
    return (_key_text(amplitude_g), _key_text(frequency_hz), *(_key_text(v) for v in values))


def row_key(row, paths: tuple[str, ...] = ()) -> tuple[str, ...]:
    """The cell identity of a domain or journal row whose point is in the columns ``paths``."""
    return cell_key(row.get(C.amplitude_g), row.get(C.frequency_hz), *(row.get(p) for p in paths))


def identity_columns(columns) -> tuple[str, ...]:
    """The columns besides amplitude and frequency that tell a domain's rows apart: its
    axes, and ``sample`` where it has samples of uncertain keys (rbm_cli.config.uncertain)."""
    return (*axis_columns(columns), *(c for c in columns if c == SAMPLE))


def keys_of(df: pd.DataFrame) -> list[tuple[str, ...]]:
    """The cell identity of every row of a domain table (its axis columns and its sample
    included)."""
    paths = identity_columns(df.columns)
    cols = [df[C.amplitude_g], df[C.frequency_hz], *(df[p] for p in paths)]
    return [cell_key(*vals) for vals in zip(*cols, strict=True)]


def read_domain(path: str | Path) -> pd.DataFrame:
    """Read a domain CSV; a missing file or missing columns is an RbmError."""
    path = Path(path)
    if not path.is_file():
        raise RbmError(f"domain file not found: {path}")
    return parse_domain(path, path)


def parse_domain(source, path: str | Path) -> pd.DataFrame:
    """A domain CSV read from ``source`` (a path or a text buffer), checked as
    :func:`read_domain` checks a file; ``path`` names it in an error (RbmError)."""
    # lazy: pandas loads only where needed (docs/architecture.md, Start-up)
    import pandas as pd

    try:
        df = pd.read_csv(source, keep_default_na=True)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        reason = " ".join(str(exc).split())
        raise RbmError(f"cannot read {path} as a domain CSV: {reason}") from None
    except OSError as exc:  # unreadable (permissions), I/O error
        raise RbmError(f"cannot read {path}: {exc.strerror or exc}") from None
    missing = [c for c in REQUIRED if c not in df.columns]
    if missing:
        raise RbmError(f"{path} is not a domain CSV: missing column(s) {', '.join(missing)}")
    if not isinstance(df.index, pd.RangeIndex):
        raise RbmError(
            f"{path} is not a domain CSV: some rows have more fields than its header"
            f" ({len(df.columns)})"
        )
    if df.empty:
        raise RbmError(f"{path} has no rows")
    _check_cells(df, path)
    if C.collapsed not in df.columns:
        df[C.collapsed] = (df[C.status] == "collapsed").astype(int)
    _set_types(df)
    return df


def integer_columns() -> tuple[str, ...]:
    """domain.csv's columns of whole numbers (a failed run, or a run without collapse for
    collapse_interface, leaves them empty), by the schema's dtypes."""
    return tuple(c.name for c in columns() if c.dtype in ("int", "0/1"))


def float_columns() -> tuple[str, ...]:
    """domain.csv's columns of real numbers, by the schema's dtypes (amplitude and
    frequency are checked and converted by _check_cells; a measure per period, written
    sa_<T>s_g, is left as read)."""
    return tuple(
        c.name
        for c in columns()
        if c.dtype == "float" and c.name not in REQUIRED and c.name.isidentifier()
    )


def _set_types(df: pd.DataFrame) -> None:
    """The columns' types as domain.csv writes them, in place: whole numbers as int64, or
    as pandas' nullable Int64 where a field is empty (collapse_interface without a
    collapse: <NA>, not a float nan); real numbers as float64 (a column whose fields all
    happen to be whole, max_rotation_ratio = 1 at every collapse, stays float). A column
    that does not hold such numbers is left as read."""
    # lazy: pandas loads only where needed (docs/architecture.md, Start-up)
    import pandas as pd

    for col in integer_columns():
        if col in df.columns and pd.api.types.is_numeric_dtype(df[col]):
            values = df[col]
            whole = values.dropna()
            if len(whole) and not (whole == whole.round()).all():
                continue
            df[col] = values.astype("Int64" if values.isna().any() else "int64")
    for col in float_columns():
        if col in df.columns and pd.api.types.is_numeric_dtype(df[col]):
            df[col] = df[col].astype("float64")


def _check_cells(df: pd.DataFrame, path: Path) -> None:
    """Values of the required columns: amplitude_g finite >= 0 [g], frequency_hz
    finite > 0 [Hz], status one of STATUSES, and each cell once. Raises an
    RbmError naming the first bad line (the header is line 1); converts the two
    numeric columns to float in place."""
    # lazy: pandas loads only where needed (docs/architecture.md, Start-up)
    import pandas as pd

    def got(value) -> str:
        return "an empty field" if pd.isna(value) else repr(str(value))

    for col, unit, positive in ((C.amplitude_g, "g", False), (C.frequency_hz, "Hz", True)):
        raw = df[col]
        x = pd.to_numeric(raw, errors="coerce").to_numpy(float)
        with np.errstate(invalid="ignore"):
            bad = ~np.isfinite(x) | ((x <= 0.0) if positive else (x < 0.0))
        if positive and raw.isna().all():
            bad[:] = False  # no frequency at all: an excitation without one (a record)
        if bad.any():
            i = int(np.argmax(bad))
            rng = "> 0" if positive else ">= 0"
            raise RbmError(
                f"{path}: line {i + 2}: {col} must be a finite number {rng} [{unit}],"
                f" got {got(raw.iloc[i])}"
            )
        df[col] = x
    bad = ~df[C.status].isin(STATUSES).to_numpy()
    if bad.any():
        i = int(np.argmax(bad))
        raise RbmError(
            f"{path}: line {i + 2}: status must be one of {', '.join(STATUSES)},"
            f" got {got(df['status'].iloc[i])}"
        )
    if C.collapsed in df.columns:
        _check_collapsed(df, path, got)
    if C.collapse_fraction in df.columns:
        _check_fraction(df, path, got)
    seen: dict[tuple[str, ...], int] = {}
    paths = identity_columns(df.columns)
    for i, key in enumerate(keys_of(df)):
        if key in seen:
            point = "".join(f", {p} {v}" for p, v in zip(paths, key[2:], strict=False))
            raise RbmError(
                f"{path}: line {i + 2} repeats the cell of line {seen[key] + 2}"
                f" (amplitude {key[0]} g, frequency {key[1] or 'none'} Hz{point})"
            )
        seen[key] = i


def _check_fraction(df: pd.DataFrame, path: Path, got) -> None:
    """collapse_fraction is a number in [0, 1] or empty (every member failed): the boundary
    of an ensemble is drawn from it. Converts it to float in place."""
    # lazy: pandas loads only where needed (docs/architecture.md, Start-up)
    import pandas as pd

    raw = df[C.collapse_fraction]
    x = pd.to_numeric(raw, errors="coerce").to_numpy(float)
    with np.errstate(invalid="ignore"):
        bad = (np.isnan(x) & raw.notna().to_numpy()) | np.isinf(x) | (x < 0.0) | (x > 1.0)
    if bad.any():
        i = int(np.argmax(bad))
        raise RbmError(
            f"{path}: line {i + 2}: collapse_fraction must be a number in [0, 1] or empty"
            f" (every member failed), got {got(raw.iloc[i])}"
        )
    df[C.collapse_fraction] = x


def _check_collapsed(df: pd.DataFrame, path: Path, got) -> None:
    """collapsed is 0 or 1 on every row and says what status says (collapsed <=> 1):
    compare counts cells from collapsed and draws boundaries from status, so a row where
    they disagree would make the two disagree quietly. Converts it to int."""
    # lazy: pandas loads only where needed (docs/architecture.md, Start-up)
    import pandas as pd

    raw = df[C.collapsed]
    x = pd.to_numeric(raw, errors="coerce").to_numpy(float)
    bad = ~np.isin(x, (0.0, 1.0))
    if bad.any():
        i = int(np.argmax(bad))
        raise RbmError(f"{path}: line {i + 2}: collapsed must be 0 or 1, got {got(raw.iloc[i])}")
    flags = x.astype(int)
    disagree = flags != (df[C.status] == "collapsed").to_numpy(int)
    if disagree.any():
        i = int(np.argmax(disagree))
        raise RbmError(
            f"{path}: line {i + 2}: status {df['status'].iloc[i]!r} but collapsed {flags[i]}:"
            " the two columns disagree (collapsed is 1 exactly when status is collapsed)"
        )
    df[C.collapsed] = flags


def _groups(df: pd.DataFrame):
    """(group columns, groupby) of a domain's boundary lines: one per point of its axes
    and frequency (NaN frequency kept: a record's), in the order the rows first hold them
    (:func:`line_order` orders them: an axis may mix strings and numbers)."""
    by = [*axis_columns(df.columns), C.frequency_hz]
    return by, df.groupby(by if len(by) > 1 else by[0], sort=False, dropna=False)


@dataclass(frozen=True)
class Comparison:
    """How two domains differ.

    n_common : cells present in both (matched on amplitude and frequency)
    n_differ : common cells whose collapsed flag differs
    fraction : n_differ / n_common
    max_shift_g : largest |boundary shift| over frequencies [g]
    shifts : per frequency: frequency_hz, boundary_a_g, boundary_b_g, shift_g
    only_a, only_b : cells present in one domain only
    first_missing : (amplitude, frequency) text of the first such cell, in grid order
    """

    n_common: int
    n_differ: int
    fraction: float
    max_shift_g: float
    shifts: pd.DataFrame
    only_a: int
    only_b: int
    first_missing: tuple[str, str] | None = None


def _edges(df: pd.DataFrame) -> tuple[list[str], dict]:
    """The boundary amplitude [g] of each boundary line (compare's rule), by its key; of a
    domain over samples of uncertain keys, its samples' majority's (rbm_cli.study.samples),
    as boundary.csv and domain.png have it."""
    by, groups = _groups(majority_frame(df))
    out = {}
    for values, grp in groups:
        values = values if isinstance(values, tuple) else (values,)
        amps = np.sort(grp[C.amplitude_g].to_numpy(float))
        unsafe = grp.loc[grp[C.status] == "collapsed", C.amplitude_g]
        if len(unsafe):
            edge = float(unsafe.min())
        else:
            step = float(np.min(np.diff(amps))) if len(amps) > 1 else 0.0
            edge = float(amps[-1]) + step
        row = line_row(by, values)
        out[tuple(_key_text(row[c]) for c in by)] = (row, edge, line_ident(values))
    return by, out


def compare(a: pd.DataFrame, b: pd.DataFrame) -> Comparison:
    """Compare two domains cell by cell and boundary by boundary.

    Where one domain has no collapsed cell at a frequency, its boundary is
    taken as one grid step above its highest amplitude there (just above the
    grid), so a boundary that leaves the grid counts as a finite shift. Cells are
    matched on amplitude, frequency, the values of any axes over config keys and the
    sample of uncertain keys; boundaries are the samples' majority's.
    """
    # lazy: pandas loads only where needed (docs/architecture.md, Start-up)
    import pandas as pd

    def flags(df):
        return dict(zip(keys_of(df), df[C.collapsed].astype(int), strict=True))

    ka, kb = flags(a), flags(b)
    common = ka.keys() & kb.keys()
    differ = sum(ka[k] != kb[k] for k in common)
    by, ea = _edges(a)
    _, eb = _edges(b)
    rows = []
    order = line_order([line[2] for line in ea.values()])
    for k in sorted(ea.keys() & eb.keys(), key=lambda k: order(ea[k][2])):
        row, edge_a, _ = ea[k]
        rows.append({**row, "boundary_a_g": edge_a, "boundary_b_g": eb[k][1],
                     "shift_g": eb[k][1] - edge_a})  # fmt: skip
    columns = [*by, "boundary_a_g", "boundary_b_g", "shift_g"]
    shifts = pd.DataFrame(rows, columns=columns)
    max_shift = float(shifts["shift_g"].abs().max()) if len(shifts) else 0.0
    return Comparison(
        n_common=len(common),
        n_differ=int(differ),
        fraction=differ / len(common) if common else math.nan,
        max_shift_g=max_shift,
        shifts=shifts,
        only_a=len(ka.keys() - kb.keys()),
        only_b=len(kb.keys() - ka.keys()),
        first_missing=min(ka.keys() ^ kb.keys(), key=_grid_order, default=None),
    )


def _grid_order(key: tuple[str, ...]):
    """Sort key of a cell key: point, then frequency, then amplitude (numbers as numbers)."""

    def num(text: str):
        try:
            return (0, float(text), "")
        except ValueError:
            return (1, 0.0, text)

    return (*[num(t) for t in key[2:]], num(key[1]), num(key[0]))


def domain_config(domain_csv: str | Path) -> Config | None:
    """The config a domain was swept with, from the meta.json beside its domain.csv.

    It is the config as the user wrote it (meta.json's ``config_written``), validated
    again: every setting the sweep had (a bullet domain's friction, the solver's
    settings), none rebuilt from derived values. None when there is no meta.json, it
    predates ``config_written``, or the config ran motions given as arrays; RbmError when
    the stored config no longer validates.
    """
    meta = Path(domain_csv).with_name("meta.json")
    try:
        stored = json.loads(meta.read_text(encoding="utf-8"))
        written, where = stored.get("config_written"), stored.get("config_dir")
    except (OSError, ValueError, AttributeError):
        return None
    if not isinstance(written, dict) or holds_stored_motions(written):
        return None  # (motions given as arrays are stored by identity, not samples)
    base = meta.parent / where if isinstance(where, str) else None  # relative record paths
    return parse_config(written, source=str(meta), base_dir=base)


def check_collapsed(df: pd.DataFrame, path: str | Path) -> None:
    """The rule `rbm compare` applies (:func:`read_domain`), for other readers of a domain
    (`rbm fragility`, which would count a failed run marked collapsed as a collapse):
    collapsed is 0 or 1 on every row, and 1 exactly when status is collapsed. Converts it
    to int in place; RbmError naming the file and the first bad line (header: line 1)."""
    # lazy: pandas loads only where needed (docs/architecture.md, Start-up)
    import pandas as pd

    def got(value) -> str:
        return "an empty field" if pd.isna(value) else repr(str(value))

    _check_collapsed(df, Path(path), got)
