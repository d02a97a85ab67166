"""Fragility curves from per-record outcomes: lognormal maximum likelihood and a bootstrap.

Input: one row per run, a record scaled to an intensity (its PGA [g], or a scale factor)
and whether the column collapsed. Output: per intensity level the number of records, of
collapses and the fraction; the lognormal fragility

    P(collapse | IM = x) = Phi( ln(x / theta) / beta )

fitted by maximum likelihood (Baker 2015, multiple-stripe form: every non-failed run is a
Bernoulli trial with that probability); and a bootstrap over records for confidence
intervals of theta and beta and a band of the curve. Files and figures are in
:mod:`rbm_cli.report.fragility_report`.

References
----------
.. [1] J. W. Baker (2015). Efficient analytical fragility function fitting using dynamic
   structural analysis. Earthquake Spectra 31(1), 579-599.
.. [2] B. Efron and R. J. Tibshirani (1993). An Introduction to the Bootstrap. Chapman &
   Hall (percentile intervals).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.optimize import minimize
from scipy.special import log_ndtr, ndtr, ndtri

from rbm_cli.base.errors import RbmError
from rbm_cli.study.outcomes import level_table, prepare_outcomes

METHOD = (
    "lognormal fragility, maximum likelihood on per-record outcomes "
    "(Bernoulli per record and intensity; Baker 2015); percentile bootstrap over records"
)


@dataclass(frozen=True)
class LognormalFit:
    """A fitted lognormal fragility.

    median_g : float  Median theta [g] (intensity of 50 % collapse probability)
    beta : float  Dispersion, the standard deviation of ln(capacity) [-]
    log_likelihood : float  Maximised log-likelihood [-]
    """

    median_g: float
    beta: float
    log_likelihood: float


@dataclass(frozen=True)
class FragilityResult:
    """Fragility of one set of runs.

    table : per intensity: intensity_g, n_records, n_failed, n_collapsed, fraction,
        fitted, band_lower, band_upper
    curve : the fitted curve and its band on a grid: intensity_g, probability, lower, upper
    fit : the maximum-likelihood fit, or None when the data allow none (see ``note``)
    note : why there is no fit (one line), or ""
    median_ci_g, beta_ci : bootstrap percentile intervals (nan without a fit)
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

    @property
    def fitted(self) -> bool:
        return self.fit is not None


def collapse_probability(intensity_g, median_g: float, beta: float):
    """Lognormal fragility Phi(ln(x / theta) / beta) [-] at intensities x [g] (0 at x <= 0)."""
    x = np.asarray(intensity_g, dtype=float)
    with np.errstate(divide="ignore"):
        z = (np.log(np.maximum(x, 0.0)) - math.log(median_g)) / beta
    out = ndtr(z)
    return float(out) if out.ndim == 0 else out


# --------------------------------------------------------------------------- the fit


def _neg_log_likelihood(params, log_x, n, k):
    """-ln L and its gradient in (ln theta, ln beta), binomial counts per level."""
    log_theta, log_beta = params
    beta = math.exp(log_beta)
    z = (log_x - log_theta) / beta
    lp, lq = log_ndtr(z), log_ndtr(-z)
    value = -float(np.sum(k * lp + (n - k) * lq))
    log_pdf = -0.5 * z * z - 0.5 * math.log(2.0 * math.pi)
    dz = k * np.exp(log_pdf - lp) - (n - k) * np.exp(log_pdf - lq)  # d lnL / dz
    grad = np.array([np.sum(dz) / beta, np.sum(dz * z)])
    return value, grad


def _start(log_x, n, k) -> np.ndarray:
    """Starting (ln theta, ln beta): least squares of probit(fraction) on ln x."""
    p = np.clip((k + 0.5) / (n + 1.0), 0.02, 0.98)
    z = ndtri(p)
    w = n / np.sum(n)
    mx, mz = np.sum(w * log_x), np.sum(w * z)
    sxx = np.sum(w * (log_x - mx) ** 2)
    slope = np.sum(w * (log_x - mx) * (z - mz)) / sxx if sxx > 0 else 0.0
    if slope <= 0.05:
        return np.array([mx, math.log(0.5)])
    return np.array([mx - mz / slope, -math.log(slope)])


def _fit_counts(log_x, n, k, start=None) -> LognormalFit:
    """MLE from counts per level; RbmError when no finite, increasing fit exists."""
    total_k, total_n = float(np.sum(k)), float(np.sum(n))
    if total_n == 0:
        raise RbmError("fragility: no runs to fit")
    if total_k == 0:
        raise RbmError(
            "fragility: no record collapsed at any intensity: the median lies above them"
        )
    if total_k == total_n:
        raise RbmError(
            "fragility: every record collapsed at every intensity: the median lies below them"
        )
    survived, collapsed = n - k > 0, k > 0
    if np.max(log_x[survived]) <= np.min(log_x[collapsed]):
        raise RbmError(
            f"fragility: outcomes are separated (all runs survive up to "
            f"{math.exp(np.max(log_x[survived])):.6g} g and collapse from "
            f"{math.exp(np.min(log_x[collapsed])):.6g} g): the dispersion has no finite estimate"
        )
    x0 = _start(log_x, n, k) if start is None else np.asarray(start, dtype=float)
    res = minimize(
        _neg_log_likelihood,
        x0,
        args=(log_x, n, k),
        jac=True,
        method="BFGS",
        options={"gtol": 1e-9, "maxiter": 500},
    )
    log_theta, log_beta = res.x
    spread = np.max(log_x) - np.min(log_x)
    if (
        not np.all(np.isfinite(res.x))
        or abs(log_theta - np.mean(log_x)) > 10.0 * max(spread, 1.0)
        or log_beta > math.log(50.0)
        or np.max(np.abs(res.jac)) > 1e-4 * max(total_n, 1.0)
    ):
        raise RbmError(
            "fragility: no increasing lognormal curve fits these outcomes "
            "(collapse does not become more frequent with intensity)"
        )
    return LognormalFit(math.exp(log_theta), math.exp(log_beta), -float(res.fun))


def fit_lognormal(intensity_g, collapsed) -> LognormalFit:
    """Maximum-likelihood lognormal fragility from individual outcomes.

    Parameters
    ----------
    intensity_g : array_like
        Intensity of each run [g], > 0
    collapsed : array_like
        1 (or True) where the run collapsed, 0 where it survived

    Returns
    -------
    LognormalFit
        Median theta [g], dispersion beta [-], log-likelihood

    Raises
    ------
    RbmError
        No collapse, only collapses, or outcomes separated by intensity (the likelihood
        then has no maximum: beta -> 0 or theta -> 0 or infinity), or collapse not
        increasing with intensity.

    Notes
    -----
    Each run is a Bernoulli trial with probability p(x) = Phi(ln(x / theta) / beta); the
    likelihood is, with n_j runs and k_j collapses at intensity x_j (Baker 2015),

    .. math:: L(\\theta, \\beta) = \\prod_j \\binom{n_j}{k_j} p(x_j)^{k_j}
              (1 - p(x_j))^{n_j - k_j}

    maximised over (ln theta, ln beta) with BFGS and the analytic gradient, from a probit
    least-squares start.

    Examples
    --------
    Two levels, 1 of 4 and 3 of 4 collapsed: the curve passes through both fractions, so
    theta = sqrt(0.2 x 0.4) and beta = ln 2 / (2 Phi^-1(0.75)):

    >>> fit = fit_lognormal([0.2] * 4 + [0.4] * 4, [1, 0, 0, 0, 1, 1, 1, 0])
    >>> round(fit.median_g, 4), round(fit.beta, 4)
    (0.2828, 0.5138)
    """
    x = np.asarray(intensity_g, dtype=float).ravel()
    c = np.asarray(collapsed, dtype=float).ravel()
    if x.size != c.size:
        raise RbmError(f"fragility: {x.size} intensities but {c.size} outcomes")
    if np.any(~np.isfinite(x)) or np.any(x <= 0.0):
        raise RbmError("fragility: intensities must be finite and > 0 [g]")
    if np.any((c != 0.0) & (c != 1.0)):
        raise RbmError("fragility: collapsed must be 0 or 1")
    levels, inverse = np.unique(x, return_inverse=True)
    n = np.bincount(inverse, minlength=levels.size).astype(float)
    k = np.bincount(inverse, weights=c, minlength=levels.size)
    return _fit_counts(np.log(levels), n, k)


# --------------------------------------------------------------------------- bootstrap


def _record_matrices(rows: pd.DataFrame, levels: np.ndarray):
    """Per record and level: runs (0/1) and collapses (0/1) of the non-failed rows."""
    ok = rows[~rows["failed"]]
    records = np.unique(rows["record"].to_numpy())
    r_index = pd.Index(records).get_indexer(ok["record"])
    l_index = np.searchsorted(levels, ok["x"].to_numpy())
    runs = np.zeros((records.size, levels.size))
    hits = np.zeros((records.size, levels.size))
    np.add.at(runs, (r_index, l_index), 1.0)
    np.add.at(hits, (r_index, l_index), ok["collapsed"].to_numpy())
    return records, runs, hits


def _bootstrap(runs, hits, log_levels, start, n_resamples, seed, grid):
    """Refit on records drawn with replacement; degenerate resamples are skipped."""
    rng = np.random.default_rng(seed)
    n_rec = runs.shape[0]
    thetas, betas, curves = [], [], []
    for _ in range(n_resamples):
        weights = np.bincount(rng.integers(0, n_rec, n_rec), minlength=n_rec).astype(float)
        n = weights @ runs
        k = weights @ hits
        used = n > 0
        try:
            fit = _fit_counts(log_levels[used], n[used], k[used], start=start)
        except RbmError:
            continue
        thetas.append(fit.median_g)
        betas.append(fit.beta)
        curves.append(collapse_probability(grid, fit.median_g, fit.beta))
    return np.array(thetas), np.array(betas), np.array(curves).reshape(len(curves), grid.size)


def fragility(
    df: pd.DataFrame,
    *,
    n_resamples: int = 500,
    seed: int = 0,
    ci_percentiles: tuple[float, float] = (5.0, 95.0),
    grid_g=None,
    intensity_column: str | None = None,
) -> FragilityResult:
    """Per-intensity counts, lognormal MLE and bootstrap band from per-record outcomes.

    Parameters
    ----------
    df : pandas.DataFrame
        One row per run: ``record``, an intensity column [g] (``intensity_g``,
        ``amplitude_g`` or ``intensity``, or ``intensity_column``), ``collapsed`` (0/1),
        optional ``status`` (collapsed | survived | failed: failed rows are left out of
        the fit and counted)
    n_resamples : int
        Bootstrap resamples of the records (0: no bootstrap)
    seed : int
        Seed of the bootstrap's generator (numpy PCG64)
    ci_percentiles : (float, float)
        Percentiles of the bootstrap distribution that bound the intervals and the band
    grid_g : array_like, optional
        Intensities of the fitted curve and band [g]; default 201 points from 0 to 1.1 x
        the largest intensity
    intensity_column : str, optional
        Name of the intensity column

    Returns
    -------
    FragilityResult
        With ``fit`` None and a one-line ``note`` when the data allow no fit (no collapse,
        only collapses, separated outcomes): the per-intensity table is still there.

    Raises
    ------
    RbmError
        Malformed input (missing column, intensity <= 0, collapsed not 0/1, unknown
        status, two runs of one record at one intensity, nothing but failed runs).

    Notes
    -----
    The curve P(x) = Phi(ln(x / theta) / beta) is fitted as in :func:`fit_lognormal`. The
    bootstrap draws whole records with replacement (a record's runs at all intensities
    stay together, so the correlation between its outcomes is kept), refits, and takes
    percentiles of theta, beta and P(x) at each grid intensity (Efron and Tibshirani's
    percentile interval). Resamples with no fit (e.g. no collapse drawn) are skipped and
    counted: ``n_resamples_used``. Percentile intervals of a dispersion are somewhat
    narrow at small samples: on 80 simulated suites of 40 records (capacities lognormal,
    theta 0.4 g, beta 0.35, 20 levels) the 5-95 % intervals covered theta in 89 % and beta
    in 83 % of the suites (nominal 90 %); the MLE of beta was 2 % low on average, as the
    sample standard deviation of 40 values is.

    Examples
    --------
    >>> res = fragility(pd.read_csv("domain.csv"), n_resamples=500, seed=1)  # doctest: +SKIP
    >>> res.fit.median_g, res.median_ci_g  # doctest: +SKIP
    """
    if n_resamples < 0:
        raise RbmError(f"fragility: n_resamples must be >= 0, got {n_resamples}")
    lo_pct, hi_pct = ci_percentiles
    if not 0.0 <= lo_pct < hi_pct <= 100.0:
        raise RbmError(
            f"fragility: ci_percentiles must be 0 <= low < high <= 100, got {ci_percentiles}"
        )
    rows, column = prepare_outcomes(df, intensity_column)
    table = level_table(rows)
    levels = table["intensity_g"].to_numpy()
    grid = (
        np.linspace(0.0, 1.1 * levels.max(), 201) if grid_g is None else np.asarray(grid_g, float)
    )
    nan_pair = (math.nan, math.nan)
    used = table["n_records"].to_numpy() > 0
    fit, note = None, ""
    try:
        fit = _fit_counts(
            np.log(levels[used]),
            table["n_records"].to_numpy(float)[used],
            table["n_collapsed"].to_numpy(float)[used],
        )
    except RbmError as exc:
        note = str(exc).removeprefix("fragility: ")
    thetas = betas = np.array([])
    curves = np.empty((0, grid.size))
    if fit is not None and n_resamples > 0:
        _, runs, hits = _record_matrices(rows, levels)
        start = (math.log(fit.median_g), math.log(fit.beta))
        thetas, betas, curves = _bootstrap(
            runs, hits, np.log(levels), start, n_resamples, seed, grid
        )
    pct = [lo_pct, hi_pct]
    have_band = curves.shape[0] > 0
    probability = (
        collapse_probability(grid, fit.median_g, fit.beta) if fit else np.full(grid.size, np.nan)
    )
    lower, upper = (
        np.percentile(curves, pct, axis=0) if have_band else np.full((2, grid.size), np.nan)
    )
    curve = pd.DataFrame(
        {"intensity_g": grid, "probability": probability, "lower": lower, "upper": upper}
    )
    table["fitted"] = collapse_probability(levels, fit.median_g, fit.beta) if fit else np.nan
    table["band_lower"] = np.interp(levels, grid, lower) if have_band else np.nan
    table["band_upper"] = np.interp(levels, grid, upper) if have_band else np.nan
    return FragilityResult(
        table=table,
        curve=curve,
        fit=fit,
        note=note,
        median_ci_g=tuple(np.percentile(thetas, pct)) if have_band else nan_pair,
        beta_ci=tuple(np.percentile(betas, pct)) if have_band else nan_pair,
        ci_percentiles=(float(lo_pct), float(hi_pct)),
        n_records=int(rows["record"].nunique()),
        n_runs=int((~rows["failed"]).sum()),
        n_failed=int(rows["failed"].sum()),
        n_resamples=int(n_resamples) if fit is not None else 0,
        n_resamples_used=int(thetas.size),
        seed=int(seed),
        intensity_column=column,
    )
