"""Fragility curves from per-record outcomes: lognormal maximum likelihood and a bootstrap.

Input: one row per run, a record scaled to an intensity (its PGA [g], or a scale factor)
and whether the column collapsed. Output: per intensity level the number of records, of
collapses and the fraction; the lognormal fragility

    P(collapse | IM = x) = Phi( ln(x / theta) / beta )

fitted by maximum likelihood (Baker 2015, multiple-stripe form: every non-failed run is a
Bernoulli trial with that probability; :mod:`rbm_cli.study.fragility_fit`); and a bootstrap
over records for confidence intervals of theta and beta and a band of the curve. Files and
figures are in :mod:`rbm_cli.report.fragility_report`.

The bootstrap draws whole records with replacement (a record's runs at all intensities
stay together, so the correlation between its outcomes is kept), refits, and takes
percentiles of theta, beta and P(x) at each grid intensity (Efron and Tibshirani's
percentile interval). Resamples with no fit (e.g. no collapse drawn) are skipped and
counted by why (:data:`~rbm_cli.study.fragility_fit.NO_FIT_REASONS`), and a note says how
many and why: the draws left out are a suite's extremes (no collapse: a median above every
intensity), so the band of the others is narrower than the data's uncertainty. A suite of
one record has no bootstrap (every resample would be that record: a band of zero width, as
if the fit were certain): its fit has no band and no intervals, and its note says why. At
most :data:`MAX_RESAMPLES` resamples (each one a refit, about 1-3 ms). Percentile
intervals of a dispersion are somewhat narrow at small samples: on 80 simulated suites of
40 records (capacities lognormal, theta 0.4 g, beta 0.35, 20 levels) the 5-95 % intervals
covered theta in 89 % and beta in 83 % of the suites (nominal 90 %); the MLE of beta was
2 % low on average, as the sample standard deviation of 40 values is.

A fit that rests on extrapolation is flagged (``fit_warning``): a median outside the
intensities tested (the runs then hold one side of the curve only), or a curve whose rise
from 16 % to 84 % (theta e^-beta to theta e^beta, a factor e^(2 beta) in intensity) is
wider than the span of the intensities tested (its dispersion is then read from a part of
the curve the runs do not reach).

References
----------
.. [1] J. W. Baker (2015). Efficient analytical fragility function fitting using dynamic
   structural analysis. Earthquake Spectra 31(1), 579-599.
.. [2] B. Efron and R. J. Tibshirani (1993). An Introduction to the Bootstrap. Chapman &
   Hall (percentile intervals).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from rbm_cli.base.errors import RbmError
from rbm_cli.config.uncertain import SAMPLE
from rbm_cli.study.fragility_fit import (
    NO_FIT_REASONS,
    LognormalFit,
    NoFit,
    collapse_probability,
    fit_counts,
    fit_lognormal,
)
from rbm_cli.study.fragility_samples import DispersionSplit, dispersion_split
from rbm_cli.study.outcomes import (
    ENSEMBLE_OUTCOMES,
    intensity_unit,
    is_ensemble,
    level_table,
    prepare_outcomes,
    worst_angle,
)
from rbm_cli.study.schema import C

METHOD = (
    "lognormal fragility, maximum likelihood on per-record outcomes "
    "(Bernoulli per record and intensity; Baker 2015); percentile bootstrap over records"
)

#: Most bootstrap resamples (each is a refit: 100,000 take a few minutes).
MAX_RESAMPLES = 100_000
#: Largest seed of the bootstrap's generator (a 64-bit word).
MAX_SEED = 2**64 - 1
#: Fewest records a bootstrap over records can resample.
MIN_BAND_RECORDS = 2
#: Failed runs are said to concentrate at the high intensities when at least this share
#: of them (and 2 or more) is in the upper third of the intensity levels: left out, they
#: would most likely have been collapses, so the fitted median is biased upwards.
FAILED_HIGH_SHARE = 2.0 / 3.0


@dataclass(frozen=True)
class FragilityResult:
    """Fragility of one set of runs.

    table : per intensity: intensity_g, n_records, n_failed, n_collapsed, fraction,
        fitted, band_lower, band_upper
    curve : the fitted curve and its band on a grid: intensity_g, probability, lower, upper
    fit : the maximum-likelihood fit, or None when the data allow none (see ``note``)
    note : why there is no fit, or, with a fit, why it has no band (one record), one
        line; "" when there is nothing to say
    median_ci_g, beta_ci : bootstrap percentile intervals (nan without a band)
    intensity_column : the intensity's column; ``intensity_g`` in the tables and
        ``median_g`` are in its unit (:attr:`intensity_unit`)
    outcome : what a trial is, one line (each run; an ensemble's members or majority)
    ensemble_outcome : members, majority or member0 for an ensemble domain, else None
    warning : one line when failed runs concentrate at the high intensities, else ""
    fit_warning : one line when the fit is extrapolated (module docstring), else ""
    resamples_dropped : (what the resample held, count) of the bootstrap resamples with no
        fit, the most frequent first (empty when none was dropped)
    resamples_note : one line saying how many resamples were dropped and why, else ""
    """

    table: pd.DataFrame
    curve: pd.DataFrame
    fit: LognormalFit | None
    note: str
    median_ci_g: tuple[float, float]
    beta_ci: tuple[float, float]
    ci_percentiles: tuple[float, float]
    n_records: int
    n_runs: int
    n_failed: int
    n_resamples: int
    n_resamples_used: int
    seed: int
    intensity_column: str
    outcome: str = "each run a trial"
    ensemble_outcome: str | None = None
    warning: str = ""
    fit_warning: str = ""
    resamples_dropped: tuple[tuple[str, int], ...] = ()
    resamples_note: str = ""
    #: A domain over samples of uncertain keys: the records' and the keys' dispersion
    #: (rbm_cli.study.fragility_samples.DispersionSplit), else None
    dispersion: DispersionSplit | None = None

    @property
    def intensity_unit(self) -> str:
        """The unit of the intensity (of the median): g, m/s, m, s or - (dimensionless)."""
        return intensity_unit(self.intensity_column)

    @property
    def fitted(self) -> bool:
        return self.fit is not None


# --------------------------------------------------------------------------- bootstrap


def _record_matrices(rows: pd.DataFrame, levels: np.ndarray):
    """Per record and level: trials and collapses of the non-failed rows (0/1 each, or an
    ensemble cell's member counts)."""
    ok = rows[~rows["failed"]]
    records = np.unique(rows[C.record].to_numpy())
    r_index = pd.Index(records).get_indexer(ok[C.record])
    l_index = np.searchsorted(levels, ok["x"].to_numpy())
    runs = np.zeros((records.size, levels.size))
    hits = np.zeros((records.size, levels.size))
    np.add.at(runs, (r_index, l_index), ok["trials"].to_numpy())
    np.add.at(hits, (r_index, l_index), ok["hits"].to_numpy())
    return records, runs, hits


def _bootstrap(runs, hits, log_levels, start, n_resamples, seed, grid, progress=None):
    """Refit on records drawn with replacement; degenerate resamples are skipped and
    counted by their reason ({NO_FIT_REASONS key: count}, the fourth value returned).
    ``progress(done, total)`` is called after each resample."""
    rng = np.random.default_rng(seed)
    n_rec = runs.shape[0]
    thetas, betas = np.empty(n_resamples), np.empty(n_resamples)
    curves = np.empty((n_resamples, grid.size))  # filled in place: no list of arrays copied
    used_fits = 0
    dropped: dict[str, int] = {}
    for done in range(1, n_resamples + 1):
        weights = np.bincount(rng.integers(0, n_rec, n_rec), minlength=n_rec).astype(float)
        n = weights @ runs
        k = weights @ hits
        used = n > 0
        try:
            fit = fit_counts(log_levels[used], n[used], k[used], start=start)
        except NoFit as exc:
            fit = None
            dropped[exc.reason] = dropped.get(exc.reason, 0) + 1
        if fit is not None:
            thetas[used_fits], betas[used_fits] = fit.median_g, fit.beta
            curves[used_fits] = collapse_probability(grid, fit.median_g, fit.beta)
            used_fits += 1
        if progress is not None:
            progress(done, n_resamples)
    return thetas[:used_fits], betas[:used_fits], curves[:used_fits], dropped


def fragility(
    df: pd.DataFrame,
    *,
    n_resamples: int = 500,
    seed: int = 0,
    ci_percentiles: tuple[float, float] = (5.0, 95.0),
    grid_g=None,
    intensity_column: str | None = None,
    progress: Callable[[int, int], None] | None = None,
    ensemble_outcome: str = ENSEMBLE_OUTCOMES[0],
    n_members: int | None = None,
) -> FragilityResult:
    """Per-intensity counts, lognormal MLE and bootstrap band from per-record outcomes.

    The curve P(x) = Phi(ln(x / theta) / beta) is fitted as in :func:`fit_lognormal`; the
    intervals and the band are percentiles of a bootstrap over whole records (module
    docstring: method and measured coverage). Resamples with no fit are skipped and
    counted: ``n_resamples_used``.

    Parameters
    ----------
    df : pandas.DataFrame
        One row per run: ``record``, an intensity column [g] (``intensity_g``,
        ``amplitude_g`` or ``intensity``, or ``intensity_column``), ``collapsed`` (0/1),
        optional ``status`` (collapsed | survived | failed: failed rows are left out of
        the fit and counted); a suite over ``excitation.angle`` counts each record's worst
        angle at each intensity (rbm_cli.study.outcomes.worst_angle)
    n_resamples : int
        Bootstrap resamples of the records, 0 to :data:`MAX_RESAMPLES` (0: no bootstrap)
    seed : int
        Seed of the bootstrap's generator (numpy PCG64), 0 to :data:`MAX_SEED`
    ci_percentiles : (float, float)
        Percentiles of the bootstrap distribution that bound the intervals and the band,
        0 <= low < high <= 100
    grid_g : array_like, optional
        Intensities of the fitted curve and band [g]; default 201 points from 0 to 1.1 x
        the largest intensity
    intensity_column : str, optional  Name of the intensity column: the amplitude (by
        default) or a record's intensity measure (rbm_cli.study.intensities), in its unit
    progress : callable, optional
        ``progress(done, total)``, called after each bootstrap resample
    ensemble_outcome : str
        For an ensemble domain (a ``collapse_fraction`` column): ``members`` (every
        member a trial, the default), ``majority`` or ``member0`` (rbm_cli.study.outcomes)
    n_members : int, optional  The ensemble's members per cell (``members`` needs it)

    Returns
    -------
    FragilityResult
        With ``fit`` None and a one-line ``note`` when the data allow no fit (no collapse,
        only collapses, one intensity, separated outcomes): the per-intensity table is
        still there. From one record: the fit, no band and no intervals (``note`` says so).

    Raises
    ------
    RbmError
        Malformed input (missing column, intensity <= 0, collapsed not 0/1, unknown
        status, status and collapsed disagreeing, two runs of one record at one intensity,
        nothing but failed runs), or options out of range (:func:`check_options`).
    """
    lo_pct, hi_pct = check_options(n_resamples, seed, ci_percentiles)
    df = worst_angle(df) if isinstance(df, pd.DataFrame) else df
    rows, column = prepare_outcomes(df, intensity_column, ensemble_outcome, n_members)
    ensemble = is_ensemble(df)
    table = level_table(rows, trials=ensemble and ensemble_outcome == "members")
    levels = table["intensity_g"].to_numpy()
    grid = (
        np.linspace(0.0, 1.1 * levels.max(), 201) if grid_g is None else np.asarray(grid_g, float)
    )
    n_records = int(rows[C.record].nunique())
    fit, note, n_resamples = _fit_table(rows, levels, n_records, n_resamples,
                                        intensity_unit(column))  # fmt: skip
    band = _bootstrap_band(rows, levels, fit, n_resamples, seed, grid, [lo_pct, hi_pct], progress)
    curve = _curve(grid, fit, band)
    _add_fitted(table, grid, fit, band)
    dropped = tuple(sorted(((NO_FIT_REASONS[r], c) for r, c in band.dropped.items()),
                           key=lambda item: -item[1]))  # fmt: skip
    return FragilityResult(
        table=table,
        curve=curve,
        fit=fit,
        note=note,
        median_ci_g=band.median_ci_g,
        beta_ci=band.beta_ci,
        ci_percentiles=(float(lo_pct), float(hi_pct)),
        n_records=n_records,
        n_runs=int((~rows["failed"]).sum()),
        n_failed=int(rows["failed"].sum()),
        n_resamples=int(n_resamples) if fit is not None else 0,
        n_resamples_used=band.n_used,
        seed=int(seed),
        intensity_column=column,
        outcome=_outcome(ensemble, ensemble_outcome, n_members),
        ensemble_outcome=ensemble_outcome if ensemble else None,
        warning=failed_warning(table),
        fit_warning=fit_warning(fit, table, intensity_unit(column)),
        resamples_dropped=dropped,
        resamples_note=resamples_note(n_resamples if fit is not None else 0, dropped),
        dispersion=dispersion_split(df, intensity_column, ensemble_outcome, n_members)
        if SAMPLE in df.columns
        else None,
    )


def _outcome(ensemble: bool, how: str, n_members) -> str:
    """What a trial is, one line."""
    if not ensemble:
        return "each run a trial"
    return {
        "members": f"every ensemble member a trial ({n_members} per cell)"
        if n_members
        else "every ensemble member a trial (members per cell unknown: each cell weighs 1, "
        "its collapses the fraction of its members)",
        "majority": "each cell a trial, collapsed when most of its ensemble members did",
        "member0": "each cell a trial, its member 0's run",
    }[how]


def failed_warning(table: pd.DataFrame) -> str:
    """One line when the failed runs concentrate at the high intensities (at least
    FAILED_HIGH_SHARE of them, 2 or more, in the upper third of the levels), else ""."""
    failed = table["n_failed"].to_numpy()
    total = int(failed.sum())
    if total < 2:
        return ""
    top = int(failed[len(failed) - math.ceil(len(failed) / 3) :].sum())
    if top < FAILED_HIGH_SHARE * total:
        return ""
    low = table["intensity_g"].to_numpy()[len(failed) - math.ceil(len(failed) / 3)]
    return (
        f"{top} of the {total} failed runs are at the upper third of the intensities "
        f"(from {low:.4g}): left out of the fit, they may hide collapses, so the median may "
        "be too high"
    )


def fit_warning(fit: LognormalFit | None, table: pd.DataFrame, unit: str = "g") -> str:
    """One line when the fit rests on extrapolation (module docstring), else "": its median
    outside the intensities tested (those with runs that did not fail), or its rise from
    16 % to 84 % wider than their span (e^(2 beta) > highest / lowest)."""
    if fit is None:
        return ""
    trials = table["n_trials"] if "n_trials" in table.columns else table["n_records"]
    tested = table[trials.to_numpy() > 0]
    if tested.empty:
        return ""
    x = tested["intensity_g"].to_numpy(float)
    lo, hi = float(x.min()), float(x.max())
    median, beta = fit.median_g, fit.beta
    curve = f"median {median:.4g} {unit}, beta {beta:.3g}"

    def observed(at: float) -> str:
        row = tested.loc[tested["intensity_g"] == at].iloc[0]
        return f"{float(row['fraction']):.2g} collapsed there"

    if median > hi:
        return (
            f"extrapolated fit ({curve}): the median lies above the highest intensity tested"
            f" ({hi:.4g} {unit}, {observed(hi)}), so the runs hold only the curve's lower"
            " part; test higher intensities"
        )
    if median < lo:
        return (
            f"extrapolated fit ({curve}): the median lies below the lowest intensity tested"
            f" ({lo:.4g} {unit}, {observed(lo)}), so the runs hold only the curve's upper"
            " part; test lower intensities"
        )
    if 2.0 * beta > math.log(hi / lo):
        p16, p84 = median * math.exp(-beta), median * math.exp(beta)
        return (
            f"extrapolated dispersion ({curve}): the curve rises from 16 % to 84 % over a"
            f" factor e^(2 beta) = {math.exp(2.0 * beta):.3g} in intensity ({p16:.4g} to"
            f" {p84:.4g} {unit}), more than the intensities tested span (a factor"
            f" {hi / lo:.3g}: {lo:.4g} to {hi:.4g} {unit}), so beta is read from a part of"
            " the curve the runs do not reach"
        )
    return ""


def resamples_note(n_resamples: int, dropped) -> str:
    """One line: how many of the bootstrap's resamples had no fit and why (``dropped``:
    (what they held, count) pairs), and what that does to the band; "" when none."""
    total = sum(count for _, count in dropped)
    if n_resamples <= 0 or total == 0:
        return ""
    why = ", ".join(f"{count} drew {what}" for what, count in dropped)
    if total == n_resamples:
        return (
            f"all {n_resamples} bootstrap resamples of the records have no fit ({why}):"
            " no band and no intervals"
        )
    return (
        f"{total} of {n_resamples} bootstrap resamples of the records have no fit and are"
        f" left out ({why}): the band and intervals are the other {n_resamples - total}'s,"
        " and as the draws left out are the suite's extremes, they understate the"
        " uncertainty"
    )


def check_options(n_resamples, seed, ci_percentiles) -> tuple[float, float]:
    """The (low, high) percentiles [%] of :func:`fragility`, after checking its options:
    ``n_resamples`` a whole number from 0 to :data:`MAX_RESAMPLES`, ``seed`` one from 0
    to :data:`MAX_SEED`, ``ci_percentiles`` two numbers 0 <= low < high <= 100 (no bool,
    nan or text). RbmError, one line, naming the option otherwise."""
    for name, value, top in (("n_resamples", n_resamples, MAX_RESAMPLES),
                             ("seed", seed, MAX_SEED)):  # fmt: skip
        if not _whole(value) or not 0 <= value <= top:
            raise RbmError(
                f"fragility: {name} must be a whole number from 0 to {top:,}, got {_shown(value)}"
            )
    pair = ci_percentiles
    ok = isinstance(pair, tuple | list) and len(pair) == 2 and all(map(_real, pair))
    if not ok or not 0.0 <= pair[0] < pair[1] <= 100.0:
        raise RbmError(
            "fragility: ci_percentiles must be two numbers 0 <= low < high <= 100 [%], "
            f"got {_shown(pair)}"
        )
    return float(pair[0]), float(pair[1])


def _whole(value) -> bool:
    return isinstance(value, numbers.Integral) and not isinstance(value, bool | np.bool_)


def _real(value) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool | np.bool_)


def _shown(value) -> str:
    """A value as a message shows it: numpy scalars as plain numbers, at most 40 chars."""
    if isinstance(value, tuple | list):
        return "(" + ", ".join(_shown(v) for v in value[:3]) + (", ..." * (len(value) > 3)) + ")"
    text = repr(value.item() if isinstance(value, np.generic) else value)
    return text if len(text) <= 40 else text[:37] + "..."


def _fit_table(rows: pd.DataFrame, levels: np.ndarray, n_records: int, n_resamples: int,
               unit: str = "g"):  # fmt: skip
    """(fit, note, resamples to draw): the lognormal fit of the per-level trials and
    collapses, or None and why there is none (one line); with a fit from fewer than
    MIN_BAND_RECORDS records, no resamples (each would be the one record: a band of zero
    width, as if the fit were certain) and a note that says so."""
    ok = rows[~rows["failed"]]
    n = ok.groupby("x")["trials"].sum().reindex(levels, fill_value=0.0).to_numpy(float)
    k = ok.groupby("x")["hits"].sum().reindex(levels, fill_value=0.0).to_numpy(float)
    used = n > 0
    try:
        fit = fit_counts(np.log(levels[used]), n[used], k[used], unit=unit)
    except RbmError as exc:
        return None, str(exc).removeprefix("fragility: "), n_resamples
    if n_resamples > 0 and n_records < MIN_BAND_RECORDS:
        note = (
            f"a fit from {n_records} record: no bootstrap band or intervals (they resample "
            f"the records, so need {MIN_BAND_RECORDS} or more)"
        )
        return fit, note, 0
    return fit, "", n_resamples


@dataclass(frozen=True)
class _Band:
    """Bootstrap result: percentile band of the curve on the grid (lower, upper [-], nan
    without resamples), intervals of theta [g] and beta [-], resamples with a fit, and
    those without one by reason ({NO_FIT_REASONS key: count})."""

    lower: np.ndarray
    upper: np.ndarray
    median_ci_g: tuple[float, float]
    beta_ci: tuple[float, float]
    n_used: int
    dropped: dict = field(default_factory=dict)


def _bootstrap_band(rows, levels, fit, n_resamples, seed, grid, pct, progress=None) -> _Band:
    """The bootstrap over records around `fit` (none without a fit or resamples)."""
    thetas = betas = np.array([])
    curves = np.empty((0, grid.size))
    dropped: dict = {}
    if fit is not None and n_resamples > 0:
        _, runs, hits = _record_matrices(rows, levels)
        start = (math.log(fit.median_g), math.log(fit.beta))
        thetas, betas, curves, dropped = _bootstrap(
            runs, hits, np.log(levels), start, n_resamples, seed, grid, progress
        )
    if curves.shape[0] == 0:
        nan_pair = (math.nan, math.nan)
        lower, upper = np.full((2, grid.size), np.nan)
        return _Band(lower, upper, nan_pair, nan_pair, int(thetas.size), dropped)
    lower, upper = np.percentile(curves, pct, axis=0, overwrite_input=True)  # no sorted copy
    return _Band(
        lower,
        upper,
        tuple(np.percentile(thetas, pct)),
        tuple(np.percentile(betas, pct)),
        int(thetas.size),
        dropped,
    )


def _curve(grid: np.ndarray, fit: LognormalFit | None, band: _Band) -> pd.DataFrame:
    """The fitted curve at intensities `grid` [g] and its band (nan where there is none)."""
    probability = (
        collapse_probability(grid, fit.median_g, fit.beta) if fit else np.full(grid.size, np.nan)
    )
    return pd.DataFrame(
        {"intensity_g": grid, "probability": probability, "lower": band.lower, "upper": band.upper}
    )


def _add_fitted(table: pd.DataFrame, grid: np.ndarray, fit: LognormalFit | None, band: _Band):
    """Add to the per-level table the fitted probability and the band at each level."""
    levels = table["intensity_g"].to_numpy()
    table["fitted"] = collapse_probability(levels, fit.median_g, fit.beta) if fit else np.nan
    table["band_lower"] = np.interp(levels, grid, band.lower) if band.n_used else np.nan
    table["band_upper"] = np.interp(levels, grid, band.upper) if band.n_used else np.nan


__all__ = [
    "MAX_RESAMPLES",
    "MAX_SEED",
    "METHOD",
    "MIN_BAND_RECORDS",
    "ENSEMBLE_OUTCOMES",
    "FragilityResult",
    "LognormalFit",
    "check_options",
    "collapse_probability",
    "failed_warning",
    "fit_lognormal",
    "fit_warning",
    "resamples_note",
    "fragility",
]
