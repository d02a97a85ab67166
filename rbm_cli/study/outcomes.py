"""Tables of per-run outcomes (record, intensity, collapsed, status): read, checked, counted.

The input of a fragility analysis and of an IDA figure: one row per run of a record scaled
to an intensity [g]. ``failed`` runs (the integrator gave up) are neither collapses nor
survivals: they are left out and counted (their ``collapsed`` is 0, as on every row whose
status is not ``collapsed``: the rule `rbm compare` applies, :func:`rbm_cli.study.domain.
check_collapsed`).
"""

from __future__ import annotations

import hashlib
import io
from pathlib import Path

import numpy as np
import pandas as pd

from rbm_cli.base.errors import RbmError
from rbm_cli.study.domain import check_collapsed

#: Intensity columns looked for, in order, when none is named.
INTENSITY_COLUMNS = ("intensity_g", "amplitude_g", "intensity")

#: Statuses a row may have; ``failed`` rows are left out of the fit and counted.
STATUSES = ("collapsed", "survived", "failed")


def intensity_column(df: pd.DataFrame, name: str | None = None) -> str | None:
    """``name``, or the first of :data:`INTENSITY_COLUMNS` in ``df``, or None."""
    return name or next((c for c in INTENSITY_COLUMNS if c in df.columns), None)


def prepare_outcomes(df: pd.DataFrame, name: str | None = None) -> tuple[pd.DataFrame, str]:
    """Validated runs and the name of the intensity column.

    Returns a table with columns record (str), x (intensity [g]), collapsed (0/1; 0 for
    failed runs) and failed (bool), one row per input row in order. Raises RbmError, one
    line naming the row, on: a missing column, an intensity that is not a number > 0,
    collapsed not 0/1, an unknown status, status and collapsed disagreeing (collapsed is 1
    exactly when status is collapsed: a failed run is not a collapse), two runs of one
    record at one intensity, no rows, only failed runs.
    """
    if not isinstance(df, pd.DataFrame):
        raise RbmError("fragility: the input must be a table (pandas DataFrame)")
    column = intensity_column(df, name)
    needed = ["record", column or "intensity_g", "collapsed"]
    missing = [c for c in needed if c not in df.columns]
    if missing:
        raise RbmError(
            f"fragility: missing column {missing[0]!r} (needs record, an intensity column "
            f"{' or '.join(INTENSITY_COLUMNS)}, collapsed; optional status)"
        )
    if df.empty:
        raise RbmError("fragility: the table has no rows")
    rows = pd.DataFrame({"record": df["record"].astype(str).to_numpy()})
    x = pd.to_numeric(df[column], errors="coerce").to_numpy(dtype=float)
    status = df["status"].astype(str).to_numpy() if "status" in df.columns else None
    failed = status == "failed" if status is not None else np.zeros(len(df), bool)
    collapsed = pd.to_numeric(df["collapsed"], errors="coerce").to_numpy(dtype=float)
    for i in range(len(df)):
        where = f"fragility: row {i + 1} (record {rows['record'].iat[i]!r})"
        if not (np.isfinite(x[i]) and x[i] > 0.0):
            raise RbmError(f"{where}: {column} must be a number > 0 [g], got {df[column].iat[i]!r}")
        if status is not None and status[i] not in STATUSES:
            raise RbmError(
                f"{where}: status must be one of {', '.join(STATUSES)}, got {status[i]!r}"
            )
        if collapsed[i] not in (0.0, 1.0):
            raise RbmError(f"{where}: collapsed must be 0 or 1, got {df['collapsed'].iat[i]!r}")
        if status is not None and (status[i] == "collapsed") != (collapsed[i] == 1.0):
            raise RbmError(f"{where}: status {status[i]!r} but collapsed = {int(collapsed[i])}")
    rows["x"], rows["collapsed"], rows["failed"] = x, collapsed, failed
    dup = rows.duplicated(["record", "x"])
    if dup.any():
        i = int(np.argmax(dup.to_numpy()))
        raise RbmError(
            f"fragility: row {i + 1}: a second run of record {rows['record'].iat[i]!r} at "
            f"{x[i]:.6g} g (one run per record and intensity)"
        )
    if failed.all():
        raise RbmError(f"fragility: all {len(df)} runs failed; nothing to fit")
    return rows, column


def level_table(rows: pd.DataFrame) -> pd.DataFrame:
    """Per intensity: intensity_g, n_records (non-failed), n_failed, n_collapsed, fraction."""
    ok = rows[~rows["failed"]]
    levels = np.unique(rows["x"].to_numpy())
    n = ok.groupby("x")["collapsed"].size().reindex(levels, fill_value=0).to_numpy()
    k = ok.groupby("x")["collapsed"].sum().reindex(levels, fill_value=0).to_numpy()
    nf = rows[rows["failed"]].groupby("x").size().reindex(levels, fill_value=0).to_numpy()
    with np.errstate(invalid="ignore", divide="ignore"):
        fraction = np.where(n > 0, k / np.maximum(n, 1), np.nan)
    return pd.DataFrame(
        {
            "intensity_g": levels,
            "n_records": n.astype(int),
            "n_failed": nf.astype(int),
            "n_collapsed": k.astype(int),
            "fraction": fraction,
        }
    )


def read_suite_domain(path: str | Path) -> pd.DataFrame:
    """Read the ``domain.csv`` of a record-suite sweep (records x intensities).

    The table of :func:`read_suite_domain_hashed` (see there).
    """
    return read_suite_domain_hashed(path)[0]


def read_suite_domain_hashed(path: str | Path) -> tuple[pd.DataFrame, str]:
    """Read the ``domain.csv`` of a record-suite sweep (records x intensities), and the
    SHA-256 of the very bytes read (a domain swept again meanwhile cannot be named).

    Parameters
    ----------
    path : str or pathlib.Path  The domain CSV (one row per run; domain.csv's columns
        plus ``record``, the name of the record of each row)

    Returns
    -------
    pandas.DataFrame  The rows as written, ``record`` as text, ``collapsed`` 0/1 agreeing
        with ``status``; checked further by :func:`prepare_outcomes` (intensities, status,
        one run per record and intensity)
    str  The SHA-256 of the file's bytes (hex)

    Raises
    ------
    RbmError  One line naming the file (and the line, header = line 1): missing or
        unreadable file, not a domain (no ``status`` column, or no rows), a domain of an
        amplitude x frequency sweep (no ``record`` column, or every record field empty),
        an empty record field on some line, a ``collapsed`` that is not 0 or 1 or says
        otherwise than ``status`` (as `rbm compare` refuses it).
    """
    path = Path(path)
    if not path.is_file():
        raise RbmError(f"domain file not found: {path}")
    try:
        data = path.read_bytes()
        df = pd.read_csv(
            io.BytesIO(data), dtype={"record": str}, keep_default_na=False, na_values=[""]
        )
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        reason = " ".join(str(exc).split())
        raise RbmError(f"cannot read {path} as a domain CSV: {reason}") from None
    except OSError as exc:
        raise RbmError(f"cannot read {path}: {exc.strerror or exc}") from None
    if "status" not in df.columns or not isinstance(df.index, pd.RangeIndex):
        raise RbmError(f"{path} is not a domain CSV (no status column, or ragged rows)")
    if df.empty:
        raise RbmError(f"{path} has no rows")
    empty = df["record"].isna().to_numpy() if "record" in df.columns else np.ones(len(df), bool)
    if empty.all():
        raise RbmError(
            f"{path} is the domain of an amplitude x frequency sweep, not of a record suite "
            "(no record column): fragility needs a sweep over records (excitation.type: "
            "record, excitation.file a list, a folder or a glob)"
        )
    if empty.any():
        raise RbmError(f"{path}: line {int(np.argmax(empty)) + 2}: the record field is empty")
    if "collapsed" in df.columns:
        check_collapsed(df, path)
    return df, hashlib.sha256(data).hexdigest()
