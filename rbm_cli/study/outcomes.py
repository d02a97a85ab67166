"""Tables of per-run outcomes (record, intensity, collapsed, status): read, checked, counted.

The input of a fragility analysis and of an IDA figure: one row per run of a record scaled
to an intensity [g]. ``failed`` runs (the integrator gave up) are neither collapses nor
survivals: they are left out and counted (their ``collapsed`` is 0, as on every row whose
status is not ``collapsed``: the rule `rbm compare` applies, :func:`rbm_cli.study.domain.
check_collapsed`).

The intensity may be any positive column: the amplitude (the scaled PGA [g], the default)
or a record's intensity measure (rbm_cli.study.intensities: pgv_m_s, arias_m_s, sa_t1_g,
...), its unit read from its name.

An ensemble domain (a ``collapse_fraction`` column: each cell run by MEMBERS perturbed
members, rbm_cli.study.robustness; its row is member 0's) is counted by
:data:`ENSEMBLE_OUTCOMES`:

- ``members`` (the default): every member is a trial, so a cell is n = MEMBERS trials of
  which n x collapse_fraction collapsed. The domain stores the fraction over the members
  that did not fail, not their count: a cell where some failed is taken as MEMBERS
  trials at that fraction (its collapses need not then be a whole number). Without the
  number of members (a domain without its meta.json), each cell weighs 1 with the
  fraction as its collapses: the same fit, since the likelihood of MEMBERS equal trials
  per cell is that of one such cell to the power MEMBERS;
- ``majority``: the cell is one trial, collapsed when collapse_fraction >= 0.5 (the
  majority's boundary of the domain figure);
- ``member0``: the cell is its row, member 0's run, one trial.

A row whose ``status`` is ``failed`` never enters a fit, however it is counted: under
``members`` and ``majority`` it is left out even when its ``collapse_fraction`` holds the
fraction of the other members (member 0's run, the row's, failed), and so is a cell whose
members all failed (collapse_fraction empty).
"""

from __future__ import annotations

import hashlib
import io
from pathlib import Path

import numpy as np
import pandas as pd

from rbm_cli.base.errors import RbmError
from rbm_cli.config.uncertain import SAMPLE
from rbm_cli.study.domain import check_collapsed
from rbm_cli.study.schema import DEFAULT_INTENSITIES, C
from rbm_cli.study.schema import unit as schema_unit

#: Intensity columns looked for, in order, when none is named.
INTENSITY_COLUMNS = DEFAULT_INTENSITIES

#: Statuses a row may have; ``failed`` rows are left out of the fit and counted.
STATUSES = ("collapsed", "survived", "failed")
#: How the runs of an ensemble domain's cells count (module docstring); the first is the
#: default.
ENSEMBLE_OUTCOMES = ("members", "majority", "member0")
#: Unit of an intensity column the schema lacks (a table of an older rbm's or a user's), by
#: the end of its name (the first that matches).
UNITS = (("_m_s", "m/s"), ("_g", "g"), ("_m", "m"), ("_s", "s"), ("intensity", "g"))


def intensity_unit(column: str) -> str:
    """The unit of an intensity column: the schema's (rbm_cli.study.schema: ``pgv_m_s``:
    m/s, ``amplitude_g``: g, ``pga_over_g_tan_alpha``: -), else by the end of its name."""
    known = schema_unit(column)
    if known:
        return known
    for end, unit in UNITS:
        if column.endswith(end):
            return unit
    return "-"


def is_ensemble(df: pd.DataFrame) -> bool:
    """Whether a domain is an ensemble's (it has a collapse_fraction column)."""
    return C.collapse_fraction in df.columns


def intensity_column(df: pd.DataFrame, name: str | None = None) -> str | None:
    """``name``, or the first of :data:`INTENSITY_COLUMNS` in ``df``, or None."""
    return name or next((c for c in INTENSITY_COLUMNS if c in df.columns), None)


def prepare_outcomes(
    df: pd.DataFrame,
    name: str | None = None,
    ensemble_outcome: str = ENSEMBLE_OUTCOMES[0],
    n_members: int | None = None,
) -> tuple[pd.DataFrame, str]:
    """Validated runs and the name of the intensity column.

    Returns a table with columns record (str), x (the intensity, in its column's unit),
    collapsed (0/1; 0 for failed runs), failed (bool), trials and hits (the Bernoulli
    trials the row stands for and how many collapsed: 1 and collapsed, or for an ensemble
    domain as ``ensemble_outcome`` says, module docstring; 0 and 0 for a failed row), one
    row per input row in order. ``n_members``: the ensemble's members per cell (None:
    unknown, module docstring). Raises RbmError, one line naming the row, on: a missing
    column, an intensity that is not a number > 0, collapsed not 0/1, an unknown status,
    status and collapsed disagreeing (collapsed is 1 exactly when status is collapsed: a
    failed run is not a collapse), two runs of one record at one intensity, no rows, only failed
    runs, an unknown ``ensemble_outcome``.
    """
    if ensemble_outcome not in ENSEMBLE_OUTCOMES:
        raise RbmError(
            f"fragility: ensemble_outcome must be one of {', '.join(ENSEMBLE_OUTCOMES)}, "
            f"got {str(ensemble_outcome)[:40]!r}"
        )
    if not isinstance(df, pd.DataFrame):
        raise RbmError("fragility: the input must be a table (pandas DataFrame)")
    column = intensity_column(df, name)
    needed = [C.record, column or "intensity_g", C.collapsed]
    missing = [c for c in needed if c not in df.columns]
    if missing:
        raise RbmError(
            f"fragility: missing column {missing[0]!r} (needs record, an intensity column "
            f"{' or '.join(INTENSITY_COLUMNS)}, collapsed; optional status)"
        )
    if df.empty:
        raise RbmError("fragility: the table has no rows")
    rows = pd.DataFrame({C.record: df[C.record].astype(str).to_numpy()})
    x = pd.to_numeric(df[column], errors="coerce").to_numpy(dtype=float)
    status = df[C.status].astype(str).to_numpy() if C.status in df.columns else None
    failed = status == "failed" if status is not None else np.zeros(len(df), bool)
    collapsed = pd.to_numeric(df[C.collapsed], errors="coerce").to_numpy(dtype=float)
    for i in range(len(df)):
        where = f"fragility: row {i + 1} (record {rows['record'].iat[i]!r})"
        if not (np.isfinite(x[i]) and x[i] > 0.0):
            raise RbmError(
                f"{where}: {column} must be a number > 0 [{intensity_unit(column)}], got "
                f"{df[column].iat[i]!r}"
            )
        if status is not None and status[i] not in STATUSES:
            raise RbmError(
                f"{where}: status must be one of {', '.join(STATUSES)}, got {status[i]!r}"
            )
        if collapsed[i] not in (0.0, 1.0):
            raise RbmError(f"{where}: collapsed must be 0 or 1, got {df['collapsed'].iat[i]!r}")
        if status is not None and (status[i] == "collapsed") != (collapsed[i] == 1.0):
            raise RbmError(f"{where}: status {status[i]!r} but collapsed = {int(collapsed[i])}")
    rows["x"], rows[C.collapsed], rows["failed"] = x, collapsed, failed
    rows["trials"], rows["hits"] = np.where(failed, 0.0, 1.0), np.where(failed, 0.0, collapsed)
    if is_ensemble(df) and ensemble_outcome != "member0":
        _ensemble_trials(rows, df, ensemble_outcome, n_members)
        failed = rows["failed"].to_numpy()
    # a domain over samples of uncertain keys has a run per record, intensity and sample
    sample = [SAMPLE] if SAMPLE in df.columns else []
    if sample:
        rows[SAMPLE] = df[SAMPLE].to_numpy()
    dup = rows.duplicated([C.record, "x", *sample])
    if dup.any():
        i = int(np.argmax(dup.to_numpy()))
        raise RbmError(
            f"fragility: row {i + 1}: a second run of record {rows['record'].iat[i]!r} at "
            f"{x[i]:.6g} {intensity_unit(column)} (one run per record and intensity: "
            f"{column} must grow with the record's scale)"
        )
    if failed.all():
        raise RbmError(f"fragility: all {len(df)} runs failed; nothing to fit")
    return rows, column


def _ensemble_trials(rows: pd.DataFrame, df: pd.DataFrame, outcome: str, n_members) -> None:
    """The trials and hits of an ensemble domain's rows, in place (module docstring): a
    failed row (its status) stays failed, and a cell whose members all failed (no
    fraction) is one too."""
    fraction = pd.to_numeric(df[C.collapse_fraction], errors="coerce").to_numpy(dtype=float)
    bad = ~np.isnan(fraction) & ((fraction < 0.0) | (fraction > 1.0))
    if bad.any():
        i = int(np.argmax(bad))
        raise RbmError(f"fragility: row {i + 1}: collapse_fraction must be in [0, 1], "
                       f"got {df[C.collapse_fraction].iat[i]!r}")  # fmt: skip
    failed = np.isnan(fraction) | rows["failed"].to_numpy(dtype=bool)
    if outcome == "majority":
        trials, hits = np.ones(len(df)), (fraction >= 0.5).astype(float)
    else:
        if not (isinstance(n_members, int | np.integer) and n_members >= 1):
            n_members = 1  # the same fit: every cell has the same weight (module docstring)
        trials, hits = np.full(len(df), float(n_members)), fraction * n_members
    rows["failed"] = failed
    rows[C.collapsed] = np.where(failed, 0.0, (fraction >= 0.5).astype(float))
    rows["trials"] = np.where(failed, 0.0, trials)
    rows["hits"] = np.where(failed, 0.0, hits)


def level_table(rows: pd.DataFrame, trials: bool = False) -> pd.DataFrame:
    """Per intensity: intensity_g (the intensity, in its column's unit), n_records
    (non-failed), n_failed, n_collapsed, fraction; with ``trials`` (an ensemble counted
    by its members) also n_trials, and n_collapsed and fraction count the trials."""
    ok = rows[~rows["failed"]]
    levels = np.unique(rows["x"].to_numpy())
    n = ok.groupby("x")["collapsed"].size().reindex(levels, fill_value=0).to_numpy()
    column = "hits" if trials else "collapsed"
    k = ok.groupby("x")[column].sum().reindex(levels, fill_value=0).to_numpy()
    nt = ok.groupby("x")["trials"].sum().reindex(levels, fill_value=0).to_numpy()
    nf = rows[rows["failed"]].groupby("x").size().reindex(levels, fill_value=0).to_numpy()
    with np.errstate(invalid="ignore", divide="ignore"):
        fraction = np.where(nt > 0, k / np.maximum(nt, 1), np.nan)
    whole = np.allclose(k, np.round(k), rtol=0.0, atol=1e-9)
    table = {
        "intensity_g": levels,
        "n_records": n.astype(int),
        "n_failed": nf.astype(int),
        "n_collapsed": np.round(k).astype(int) if whole else k,
        "fraction": fraction,
    }
    if trials:
        table["n_trials"] = np.round(nt).astype(int)
    return pd.DataFrame(table)


#: A suite swept over the ground motion's azimuth (a model in three dimensions) has a row
#: per angle: its fragility takes, per record and intensity, the worst angle's run.
ANGLE_AXIS = "excitation.angle"


def worst_angle(df: pd.DataFrame) -> pd.DataFrame:
    """A suite's rows with one run per record and intensity: where the table has an
    ``excitation.angle`` column, the worst angle's row of each record and amplitude_g (a
    collapse before a failed run before a survival; then the larger collapse_fraction,
    then the larger max_rotation_ratio), in the order of their first rows; the table as
    it is otherwise."""
    if not {ANGLE_AXIS, C.amplitude_g, C.record, C.collapsed} <= set(df.columns):
        return df  # (a table without them is refused, in one line, by prepare_outcomes)
    df = df.reset_index(drop=True)
    status = df[C.status].astype(str) if C.status in df.columns else None
    collapsed = pd.to_numeric(df[C.collapsed], errors="coerce").fillna(0.0)
    rank = 2.0 * collapsed + (status == "failed").astype(float) if status is not None else collapsed
    keys = pd.DataFrame({"_rank": rank.to_numpy()}, index=df.index)
    for column in (C.collapse_fraction, C.max_rotation_ratio):
        if column in df.columns:
            keys[column] = pd.to_numeric(df[column], errors="coerce").fillna(-np.inf)
    order = keys.sort_values(list(keys.columns), ascending=False, kind="stable").index
    by = [C.record, C.amplitude_g, *(c for c in df.columns if c == SAMPLE)]  # and a sample
    worst = df.loc[order].drop_duplicates(by, keep="first")
    cells = list(zip(*(df[c] for c in by), strict=True))
    position = {cell: i for i, cell in enumerate(dict.fromkeys(cells))}  # first rows' order
    at = [position[cell] for cell in zip(*(worst[c] for c in by), strict=True)]
    return worst.iloc[np.argsort(at, kind="stable")].reset_index(drop=True)


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
        with ``status``, a suite over ``excitation.angle`` reduced to its worst angle per
        record and intensity (:func:`worst_angle`); checked further by
        :func:`prepare_outcomes` (intensities, status, one run per record and intensity)
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
            io.BytesIO(data), dtype={C.record: str}, keep_default_na=False, na_values=[""]
        )
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        reason = " ".join(str(exc).split())
        raise RbmError(f"cannot read {path} as a domain CSV: {reason}") from None
    except OSError as exc:
        raise RbmError(f"cannot read {path}: {exc.strerror or exc}") from None
    if C.status not in df.columns or not isinstance(df.index, pd.RangeIndex):
        raise RbmError(f"{path} is not a domain CSV (no status column, or ragged rows)")
    if df.empty:
        raise RbmError(f"{path} has no rows")
    empty = df[C.record].isna().to_numpy() if C.record in df.columns else np.ones(len(df), bool)
    if empty.all():
        raise RbmError(
            f"{path} is the domain of an amplitude x frequency sweep, not of a record suite "
            "(no record column): fragility needs a sweep over records (excitation.type: "
            "record, excitation.file a list, a folder or a glob)"
        )
    if empty.any():
        raise RbmError(f"{path}: line {int(np.argmax(empty)) + 2}: the record field is empty")
    if C.collapsed in df.columns:
        check_collapsed(df, path)
    return worst_angle(df), hashlib.sha256(data).hexdigest()
