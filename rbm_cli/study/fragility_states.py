"""Damage states short of collapse: a fragility curve per threshold of the peak rotation
ratio, or of the residual slip.

A damage state is a threshold t of domain.csv's ``max_rotation_ratio`` (the peak of the
collapse quantity over its limit: theta_max / alpha for a rigid block), 0 < t <= 1; a run
exceeds it when its peak ratio reaches t or it collapsed (a collapsed run exceeds every
state; t = 1 is collapse). Each state is fitted on its own, by the single-state fit of
:func:`rbm_cli.study.fragility.fragility` on the domain with each run's outcome made "the
run exceeded t" (:func:`state_domain`): the same maximum likelihood, the same bootstrap
over records with the same seed, so each state's median, dispersion and intervals are
those ``rbm fragility`` gives a domain whose ``collapsed`` column says that.

Ordering. A run that exceeds a higher threshold exceeds every lower one, so the observed
fractions of the states are ordered at every intensity, and so, nearly always, are the
fitted medians. The fits are independent, though, so two curves with different
dispersions cross once, at ln x* = (beta_j ln theta_i - beta_i ln theta_j) / (beta_j -
beta_i): on one side of x* the higher state's curve lies above the lower one's. No fit is
adjusted; :func:`crossings` reports, one line each, every pair of states whose medians are
out of order, or whose curves cross within the intensities tested (a crossing outside
them is a property of the extrapolated tails only and is not reported).

An ensemble domain holds the peak rotation of each cell's member 0 only: its states
count member 0's run of each cell, one trial per cell (as ``--ensemble-outcome member0``),
and :attr:`DamageStates.note` says so.

Residual states are the same, of another column (:data:`RESIDUAL`): a threshold t > 0 [m]
of ``residual_slip_m``, the largest slip of a joint where a run of the contact engine
(model bullet) ended; a run exceeds it when its residual slip reaches t or it collapsed
(a collapsed column has no residual slip: it is down, beyond every state). There is no
upper bound, and no threshold is collapse.

Damage short of collapse, at thresholds of theta_max / alpha from 0.01 to 1, and the
choice of the intensity measure, are those of the probabilistic rocking literature
(D'Angela et al.; Kazantzi, Lachanas and Vamvatsikos 2021).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from rbm_cli.base.errors import RbmError
from rbm_cli.study.fragility import FragilityResult, fragility
from rbm_cli.study.outcomes import is_ensemble
from rbm_cli.study.schema import C

#: The column a damage state is a threshold of.
STATE_COLUMN = C.max_rotation_ratio


@dataclass(frozen=True)
class StateMeasure:
    """What a set of states is thresholds of.

    column : str  domain.csv's column
    name : str  The states' name in messages and figures ("damage states")
    option : str  How a user asks for them, named in a refusal ("--damage-states")
    what : str  The column's quantity, in words
    upper : float or None  The largest threshold, which is collapse (None: no bound)
    unit : str  The thresholds' unit ("-": dimensionless)
    """

    column: str
    name: str
    option: str
    what: str
    upper: float | None
    unit: str


#: Damage states: thresholds of the peak rotation ratio, 0 < t <= 1 (1: collapse).
PEAK = StateMeasure(STATE_COLUMN, "damage states", "--damage-states / damage_states",
                    "the peak rotation ratio", 1.0, "-")  # fmt: skip
#: Residual states: thresholds of the contact engine's residual slip [m], t > 0.
RESIDUAL = StateMeasure(C.residual_slip_m, "residual states",
                        "--residual-states / residual_states",
                        "the residual slip of the contact engine, model bullet", None,
                        "m")  # fmt: skip


@dataclass(frozen=True)
class DamageStates:
    """The fragility of each damage state of one domain.

    thresholds : the states' thresholds of ``measure.column`` (``max_rotation_ratio`` [-]
        by default), increasing
    results : one :class:`~rbm_cli.study.fragility.FragilityResult` per threshold: the
        fragility of "the run reached the threshold or collapsed"
    crossings : one line per pair of states whose fits are out of order (module
        docstring), () when none
    note : one line when the domain is an ensemble's (member 0's runs counted), else ""
    measure : the column they are thresholds of (:data:`PEAK` or :data:`RESIDUAL`)
    """

    thresholds: tuple[float, ...]
    results: tuple[FragilityResult, ...]
    crossings: tuple[str, ...] = ()
    note: str = ""
    measure: StateMeasure = PEAK

    @property
    def intensity_column(self) -> str:
        return self.results[0].intensity_column

    @property
    def intensity_unit(self) -> str:
        return self.results[0].intensity_unit

    def table(self) -> pd.DataFrame:
        """One row per state: threshold (of ``state_column``), median [the intensity's
        unit] and its interval, beta and its interval, the counts, and the fit's notes
        (nan/"" where undefined)."""
        rows = []
        for t, res in zip(self.thresholds, self.results, strict=True):
            fit = res.fit
            rows.append({
                "damage_state": t,
                "state_column": self.measure.column,
                "intensity_column": res.intensity_column,
                "intensity_unit": res.intensity_unit,
                "median": fit.median_g if fit else math.nan,
                "median_ci_low": res.median_ci_g[0],
                "median_ci_high": res.median_ci_g[1],
                "beta": fit.beta if fit else math.nan,
                "beta_ci_low": res.beta_ci[0],
                "beta_ci_high": res.beta_ci[1],
                "n_records": res.n_records,
                "n_runs": res.n_runs,
                "n_failed": res.n_failed,
                "n_exceeding": float(res.table["n_collapsed"].sum()),
                "n_resamples_used": res.n_resamples_used,
                "note": res.note,
                "fit_warning": res.fit_warning,
            })  # fmt: skip
        return pd.DataFrame(rows)


def check_damage_states(
    values, where: str = "fragility: damage_states", measure: StateMeasure = PEAK
) -> tuple[float, ...]:
    """The thresholds of ``measure``'s column, checked: one or more real numbers, each
    finite, > 0 and, for the peak rotation ratio, <= 1 (1: collapse), strictly increasing.
    RbmError, one line naming ``where``, otherwise."""
    column = measure.column
    if isinstance(values, str | bytes) or not isinstance(values, Sequence | np.ndarray):
        raise RbmError(
            f"{where} must be a list of thresholds of {column}, got {type(values).__name__}"
        )
    values = list(values)
    if not values:
        raise RbmError(f"{where} must hold at least one threshold of {column}")
    upper = measure.upper
    for v in values:
        if not isinstance(v, numbers.Real) or isinstance(v, bool | np.bool_):
            raise RbmError(f"{where}: each threshold must be a number, got {v!r}")
        if not math.isfinite(v) or not 0.0 < v <= (math.inf if upper is None else upper):
            bound = f" and <= {upper:g} ({upper:g}: collapse)" if upper is not None else ""
            unit = f" [{measure.unit}]" if measure.unit != "-" else ""
            raise RbmError(
                f"{where}: each threshold of {column} must be finite, > 0{bound}{unit}, got"
                f" {float(v):g}"
            )
    for a, b in zip(values, values[1:], strict=False):
        if not b > a:
            raise RbmError(
                f"{where}: thresholds must be strictly increasing, got {float(b):g} after"
                f" {float(a):g}"
            )
    return tuple(float(v) for v in values)


def state_domain(df: pd.DataFrame, threshold: float, measure: StateMeasure = PEAK) -> pd.DataFrame:
    """The domain with each run's outcome made "exceeded ``threshold``": a run that did not
    fail is marked collapsed (``collapsed`` 1, ``status`` collapsed) when its value of
    ``measure.column`` (max_rotation_ratio by default) >= threshold or it collapsed,
    survived otherwise; failed runs stay failed. An ensemble's collapse_fraction (of
    collapse, over its members) is dropped: each row counts its own run, member 0's.

    Raises
    ------
    RbmError  One line: no such column (naming the option that asked for it), or a run
        neither failed nor collapsed without a number there
    """
    column = measure.column
    if column not in df.columns:
        raise RbmError(
            f"fragility: {measure.name} ({measure.option}) need the column {column!r}"
            f" ({measure.what}), which the domain lacks"
        )
    status = df[C.status].astype(str).to_numpy() if C.status in df.columns else None
    failed = status == "failed" if status is not None else np.zeros(len(df), bool)
    collapsed = pd.to_numeric(df[C.collapsed], errors="coerce").to_numpy(float) == 1.0
    ratio = pd.to_numeric(df[column], errors="coerce").to_numpy(float)
    bad = ~failed & ~collapsed & ~np.isfinite(ratio)
    if bad.any():
        i = int(np.argmax(bad))
        raise RbmError(
            f"fragility: row {i + 1} (record {str(df[C.record].iat[i])!r}): "
            f"{column} must be a number for {measure.name}, got {df[column].iat[i]!r}"
        )
    with np.errstate(invalid="ignore"):
        exceeded = ~failed & (collapsed | (ratio >= threshold))
    out = df.drop(columns=[C.collapse_fraction], errors="ignore").copy()
    out[C.collapsed] = exceeded.astype(int)
    if status is not None:
        out[C.status] = np.where(failed, "failed", np.where(exceeded, "collapsed", "survived"))
    return out


def damage_states(
    df: pd.DataFrame,
    thresholds,
    *,
    n_resamples: int = 500,
    seed: int = 0,
    ci_percentiles: tuple[float, float] = (5.0, 95.0),
    intensity_column: str | None = None,
    progress: Callable[[int, int], None] | None = None,
    measure: StateMeasure = PEAK,
) -> DamageStates:
    """The fragility of each damage state (module docstring).

    Parameters
    ----------
    df : pandas.DataFrame
        A record-suite domain (as :func:`rbm_cli.study.fragility.fragility` takes it) with
        the column of ``measure`` (``max_rotation_ratio`` by default)
    thresholds : sequence of float
        Thresholds of that column, strictly increasing (:func:`check_damage_states`):
        of max_rotation_ratio [-], 0 < t <= 1; of residual_slip_m (:data:`RESIDUAL`) [m],
        t > 0
    n_resamples, seed, ci_percentiles, intensity_column
        As :func:`rbm_cli.study.fragility.fragility`, the same for every state
    progress : callable, optional
        ``progress(done, total)`` over the bootstraps of all the states
    measure : StateMeasure
        The column the states are thresholds of: :data:`PEAK` (damage states, the
        default) or :data:`RESIDUAL` (residual states)

    Returns
    -------
    DamageStates
    """
    thresholds = check_damage_states(thresholds, f"fragility: {measure.option}", measure)
    results = []
    parts = len(thresholds)
    for k, t in enumerate(thresholds):
        part = None if progress is None else _part(progress, k, parts)
        results.append(
            fragility(
                state_domain(df, t, measure),
                n_resamples=n_resamples,
                seed=seed,
                ci_percentiles=ci_percentiles,
                intensity_column=intensity_column,
                progress=part,
                ensemble_outcome="member0",
            )  # fmt: skip
        )
    note = (
        f"an ensemble domain: each of the {measure.name} counts each cell's member 0's run"
        f" (the domain holds {measure.what} of member 0 only)"
        if is_ensemble(df)
        else ""
    )
    lines = crossings(thresholds, results, measure.name)
    return DamageStates(thresholds, tuple(results), lines, note, measure)


def _part(progress, k: int, parts: int):
    return lambda done, total: progress(k * total + done, parts * total)


def crossing_intensity(median_a: float, beta_a: float, median_b: float, beta_b: float):
    """The intensity where two lognormal curves are equal (nan for equal dispersions):
    ln x* = (beta_b ln theta_a - beta_a ln theta_b) / (beta_b - beta_a)."""
    if beta_a == beta_b:
        return math.nan
    return math.exp((beta_b * math.log(median_a) - beta_a * math.log(median_b)) / (beta_b - beta_a))


def crossings(thresholds, results, name: str = "damage states") -> tuple[str, ...]:
    """One line per pair of fitted states (lower threshold a, higher b) whose medians are
    out of order (theta_b < theta_a), or whose curves cross within the intensities tested
    (the higher state's curve above the lower's from there on); ``name``: the states'."""
    lines = []
    for i in range(len(results)):
        for j in range(i + 1, len(results)):
            a, b = results[i].fit, results[j].fit
            if a is None or b is None:
                continue
            ta, tb, unit = thresholds[i], thresholds[j], results[i].intensity_unit
            if b.median_g < a.median_g:
                lines.append(
                    f"{name} {ta:g} and {tb:g}: medians out of order ({b.median_g:.4g}"
                    f" {unit} for {tb:g} below {a.median_g:.4g} {unit} for {ta:g})"
                )
                continue
            x = crossing_intensity(a.median_g, a.beta, b.median_g, b.beta)
            levels = _tested(results[i]) + _tested(results[j])
            if math.isfinite(x) and levels and min(levels) <= x <= max(levels):
                lines.append(
                    f"{name} {ta:g} and {tb:g}: the fitted curves cross at"
                    f" {x:.4g} {unit}, within the intensities tested (beta {a.beta:.3g} and"
                    f" {b.beta:.3g}): on one side of it state {tb:g}'s curve lies above"
                    f" {ta:g}'s"
                )
    return tuple(lines)


def _tested(result: FragilityResult) -> list[float]:
    table = result.table
    trials = table["n_trials"] if "n_trials" in table.columns else table["n_records"]
    return [float(x) for x in table["intensity_g"][trials.to_numpy() > 0]]


__all__ = [
    "PEAK",
    "RESIDUAL",
    "STATE_COLUMN",
    "DamageStates",
    "StateMeasure",
    "check_damage_states",
    "crossing_intensity",
    "crossings",
    "damage_states",
    "state_domain",
]
