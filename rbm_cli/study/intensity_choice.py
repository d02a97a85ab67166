"""Which intensity measure: one suite's fragility fitted on every measure its domain carries.

Every measure of the registry (rbm_cli.study.intensities) that grows with the record's
scale and is a column of the domain with a number > 0 on every run that did not fail is
an intensity the suite may be fitted on; :func:`compare_intensities` fits the same runs on
each, with the single-state fit of :func:`rbm_cli.study.fragility.fragility` and the same
options (so each row is what ``rbm fragility --intensity COLUMN`` gives), and ranks them
by their dispersion beta: the lower, the more *efficient* the measure (the less the
capacities of the records scatter once expressed in it; Luco and Cornell 2007). Beta is
dimensionless, so measures in different units compare. A measure proportional to another
for one column (PGA / (g tan alpha) to PGA, PGV p / (g tan alpha) to PGV) has the same
beta on a domain of one column; the two differ across columns.

The best is the measure of the lowest beta; :attr:`IntensityComparison.statement` says so
(with any measure of the same beta to :data:`TIE_DIGITS` decimals, ranked in the
domain's order) and names the measures whose bootstrap interval of beta overlaps its own
(which the suite does not tell apart from it). A measure the domain carries but cannot be fitted on
(an empty column: Sa(T1) of a rigid column; values not > 0; outcomes that allow no fit)
is listed with the reason, last.

References
----------
.. [1] N. Luco and C. A. Cornell (2007). Structure-specific scalar intensity measures for
   near-source and ordinary earthquake ground motions. Earthquake Spectra 23(2), 357-392.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from rbm_cli.base.errors import RbmError
from rbm_cli.study.fragility import FragilityResult, fragility
from rbm_cli.study.intensities import fragility_measures, label, measure_of
from rbm_cli.study.schema import C

#: The columns of the comparison's table, in order.
TABLE_COLUMNS = (
    "rank",
    "intensity_column",
    "quantity",
    "unit",
    "beta",
    "beta_ci_low",
    "beta_ci_high",
    "median",
    "median_ci_low",
    "median_ci_high",
    "n_runs",
    "note",
)


#: Decimals to which two betas are the same: PGA / (g tan alpha) is PGA times a constant on
#: a domain of one column, and their fits agree to the optimiser's tolerance only.
TIE_DIGITS = 6


@dataclass(frozen=True)
class IntensityComparison:
    """The fragility of one suite on each intensity measure its domain carries.

    table : one row per measure (:data:`TABLE_COLUMNS`), the fitted ones by beta
        (lowest first, rank 1), then those with no fit (rank nan, ``note`` why)
    results : {column: FragilityResult} of the measures fitted or tried
    best : the column of the lowest beta, "" when no measure could be fitted
    statement : one line naming the best and the measures it is not told apart from
    """

    table: pd.DataFrame
    results: dict
    best: str
    statement: str


def carried_measures(df: pd.DataFrame) -> list[str]:
    """The domain's columns that are a registry's intensity measure (one that grows with
    the record's scale), in the domain's order."""
    wanted = set(fragility_measures())
    return [c for c in df.columns if isinstance(c, str) and measure_of(c) in wanted]


def check_carries_measures(df: pd.DataFrame) -> list[str]:
    """:func:`carried_measures`, or RbmError (one line) when there is none."""
    columns = carried_measures(df)
    if not columns:
        raise RbmError(
            "fragility: the domain carries no intensity measure of the records (pga_g,"
            " pgv_m_s, ...): nothing to compare"
        )
    return columns


def _unusable(df: pd.DataFrame, column: str) -> str:
    """Why a measure's column cannot be an intensity of this domain (one phrase), or ""."""
    ok = df[C.status].astype(str) != "failed" if C.status in df.columns else slice(None)
    values = pd.to_numeric(df[column], errors="coerce").to_numpy(float)[np.asarray(ok)]
    if values.size and np.all(np.isnan(values)):
        return "empty column (a rigid column has no first elastic period)" \
            if column.startswith("sa_t1") else "empty column"  # fmt: skip
    if not np.all(np.isfinite(values) & (values > 0.0)):
        return "not a number > 0 on every run"
    return ""


def compare_intensities(
    df: pd.DataFrame,
    *,
    n_resamples: int = 500,
    seed: int = 0,
    ci_percentiles: tuple[float, float] = (5.0, 95.0),
    ensemble_outcome: str = "members",
    n_members: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> IntensityComparison:
    """Fit the domain's runs on every intensity measure it carries and rank them by beta
    (module docstring). Options as :func:`rbm_cli.study.fragility.fragility`, the same
    for every measure; ``progress(done, total)`` over all the fits' bootstraps.

    Raises
    ------
    RbmError  One line: the domain carries no intensity measure (a domain of an older rbm,
        or of a user's table without them)
    """
    columns = check_carries_measures(df)
    rows, results = [], {}
    for k, column in enumerate(columns):
        part = None if progress is None else _part(progress, k, len(columns))
        why = _unusable(df, column)
        res = None
        if not why:
            try:
                res = fragility(df, n_resamples=n_resamples, seed=seed,
                                ci_percentiles=ci_percentiles, intensity_column=column,
                                ensemble_outcome=ensemble_outcome, n_members=n_members,
                                progress=part)  # fmt: skip
            except RbmError as exc:
                why = str(exc).removeprefix("fragility: ")
        if res is not None:
            results[column] = res
            why = why or ("no fit: " + res.note if res.fit is None else "")
        rows.append(_row(column, res, why))
    table = pd.DataFrame(rows, columns=[c for c in TABLE_COLUMNS if c != "rank"])
    # betas equal to TIE_DIGITS (a measure times a constant) keep the domain's order
    table["_key"] = table["beta"].round(TIE_DIGITS)
    table = table.sort_values("_key", kind="stable", na_position="last")
    table = table.drop(columns="_key").reset_index(drop=True)
    fitted = table["beta"].notna().to_numpy()
    table.insert(0, "rank", np.where(fitted, np.arange(1, len(table) + 1), np.nan))
    best = str(table["intensity_column"].iat[0]) if fitted.any() else ""
    return IntensityComparison(table, results, best, statement(table, results, best))


def _part(progress, k: int, parts: int):
    return lambda done, total: progress(k * total + done, parts * total)


def _row(column: str, res: FragilityResult | None, note: str) -> dict:
    measure = measure_of(column)
    fit = res.fit if res is not None else None
    nan2 = (math.nan, math.nan)
    beta_ci = res.beta_ci if res is not None and fit else nan2
    median_ci = res.median_ci_g if res is not None and fit else nan2
    return {
        "intensity_column": column,
        "quantity": (label(column) or column).rsplit(" [", 1)[0],
        "unit": measure.unit,
        "beta": fit.beta if fit else math.nan,
        "beta_ci_low": beta_ci[0],
        "beta_ci_high": beta_ci[1],
        "median": fit.median_g if fit else math.nan,
        "median_ci_low": median_ci[0],
        "median_ci_high": median_ci[1],
        "n_runs": res.n_runs if res is not None else 0,
        "note": note or (res.fit_warning if res is not None else ""),
    }


def statement(table: pd.DataFrame, results: dict, best: str) -> str:
    """One line: the measure of the lowest beta, and those whose beta interval overlaps
    its own (not told apart from it by this suite)."""
    if not best:
        return "no intensity measure of the domain could be fitted"
    row = table.iloc[0]
    res = results[best]
    lo, hi = res.ci_percentiles
    interval = ""
    if math.isfinite(row["beta_ci_low"]):
        interval = f" ({lo:g}-{hi:g} %: {row['beta_ci_low']:.3g}-{row['beta_ci_high']:.3g})"
    key = round(float(row["beta"]), TIE_DIGITS)
    same = [str(c) for c, b in zip(table["intensity_column"].iloc[1:], table["beta"].iloc[1:],
                                   strict=True) if round(float(b), TIE_DIGITS) == key]  # fmt: skip
    tied = f" (and {', '.join(same)}: the same beta, a constant times it here)" if same else ""
    text = f"lowest dispersion (most efficient): {best}{tied}, beta {row['beta']:.3g}{interval}"
    if not interval:
        return text + "; no bootstrap intervals to tell the measures apart"
    near = [
        str(r["intensity_column"])
        for _, r in table.iloc[1:].iterrows()
        if str(r["intensity_column"]) not in same
        and math.isfinite(r["beta"])
        and math.isfinite(r["beta_ci_low"])
        and r["beta_ci_low"] <= row["beta_ci_high"]
    ]
    if near:
        return text + f"; its interval overlaps those of {', '.join(near)}"
    return text + "; its interval overlaps no other measure's"


__all__ = [
    "TABLE_COLUMNS",
    "TIE_DIGITS",
    "IntensityComparison",
    "carried_measures",
    "check_carries_measures",
    "compare_intensities",
    "statement",
]
