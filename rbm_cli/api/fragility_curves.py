"""Fragility of a record-suite domain: ``rbm.fragility`` (the fit and its band as data) and
``rbm fragility`` (its files and figures: rbm_cli.report.fragility_run.run_fragility). The
fit is imported when one is made, not with the package: ``run_fragility`` and
``MAX_RESAMPLES`` are read from their modules on first use."""

from __future__ import annotations

import numbers
import os
from pathlib import Path
from typing import TYPE_CHECKING

from rbm_cli.base.errors import RbmError
from rbm_cli.study.intensities import fragility_measures, measure_of
from rbm_cli.study.schema import DEFAULT_INTENSITIES

if TYPE_CHECKING:
    import pandas as pd

    from rbm_cli.study.fragility import FragilityResult
    from rbm_cli.study.fragility_states import DamageStates

__all__ = [
    "MAX_RESAMPLES",  # noqa: F822 (read on first use)
    "check_intensity",
    "check_members",
    "damage_states_of",
    "fragility",
    "intensity_help",
    "intensity_names",
    "residual_states_of",
    "run_fragility",  # noqa: F822 (read on first use)
]


def intensity_names() -> tuple[str, ...]:
    """The columns a fragility may be fitted on: the amplitude's
    (rbm_cli.study.schema.DEFAULT_INTENSITIES, the first present by default), then a
    record's measures that grow with its scale (the registry of
    rbm_cli.study.intensities, in its order; a measure per period as its pattern,
    ``sa_<T>s_g``)."""
    return DEFAULT_INTENSITIES + tuple(m.column for m in fragility_measures())


def intensity_help() -> str:
    """The help of ``rbm fragility --intensity``: the measures it takes (the registry's,
    read when the help is shown) and its default."""
    measures = intensity_names()[len(DEFAULT_INTENSITIES) :]
    defaults = DEFAULT_INTENSITIES
    return (
        f"The intensity measure to fit on, a column of the domain: a record's"
        f" {', '.join(measures[:-1])} or {measures[-1]}  [default: the amplitude,"
        f" {', '.join(defaults[:-1])} or {defaults[-1]}, the first present]"
    )


def check_intensity(name, where: str = "intensity") -> str | None:
    """``name`` (None: the default), checked to be an intensity measure's column
    (:func:`intensity_names`; ``sa_0p5s_g`` for the pattern ``sa_<T>s_g``): a count, a
    time or another result is not one.

    Raises
    ------
    RbmError  One line naming ``where`` and the measures there are
    """
    if name is None:
        return None
    ok = isinstance(name, str) and (
        name in DEFAULT_INTENSITIES or _grows_with_scale(measure_of(name))
    )
    if not ok:
        shown = repr(name) if isinstance(name, str) else type(name).__name__
        raise RbmError(
            f"{where} must be an intensity measure, got {shown} (one of"
            f" {', '.join(intensity_names())})"
        )
    return name


def _grows_with_scale(measure) -> bool:
    """Whether a registry entry (None: not a measure's column) is a fragility's intensity."""
    return measure is not None and measure in fragility_measures()


def check_members(n_members) -> int | None:
    """n_members: None (unknown) or a whole number >= 1 (not a boolean, a string or nan).

    Raises
    ------
    RbmError  One line naming it
    """
    if n_members is None:
        return None
    if isinstance(n_members, bool) or not isinstance(n_members, numbers.Integral) \
            or n_members < 1:  # fmt: skip
        raise RbmError(
            "fragility: n_members must be a whole number >= 1 (the members per cell of an"
            f" ensemble domain) or None, got {n_members!r}"
        )
    return int(n_members)


def damage_states_of(text, where: str = "--damage-states") -> tuple[float, ...] | None:
    """The thresholds of max_rotation_ratio written as ``text`` ("0.1,0.3,1.0"; None:
    none), checked (rbm_cli.study.fragility_states.check_damage_states).

    Raises
    ------
    RbmError  One line naming ``where``: a part that is not a number, a threshold not
        finite, not > 0 or above 1, thresholds not strictly increasing
    """
    return _thresholds_of(text, where, residual=False)


def residual_states_of(text, where: str = "--residual-states") -> tuple[float, ...] | None:
    """The thresholds of residual_slip_m [m] written as ``text`` ("0.005,0.02,0.05"; None:
    none), checked (rbm_cli.study.fragility_states.check_damage_states of RESIDUAL).

    Raises
    ------
    RbmError  One line naming ``where``: a part that is not a number, a threshold not
        finite or not > 0, thresholds not strictly increasing
    """
    return _thresholds_of(text, where, residual=True)


def _thresholds_of(text, where: str, residual: bool) -> tuple[float, ...] | None:
    if text is None:
        return None
    # lazy: loads pandas only where needed (docs/architecture.md, Start-up)
    from rbm_cli.study.fragility_states import PEAK, RESIDUAL, check_damage_states

    measure = RESIDUAL if residual else PEAK
    example = "0.005,0.02,0.05" if residual else "0.1,0.3,1.0"
    column = measure.column + (f" [{measure.unit}]" if measure.unit != "-" else "")
    values = []
    for part in str(text).split(","):
        try:
            values.append(float(part))
        except ValueError:
            raise RbmError(
                f"{where} must be thresholds of {column} separated by commas (such"
                f" as {example}), got {part.strip()[:40]!r} in {str(text)[:60]!r}"
            ) from None
    return check_damage_states(values, where, measure)


def __getattr__(name: str):
    if name == "run_fragility":
        # lazy: loads matplotlib and pandas only where needed (docs/architecture.md, Start-up)
        from rbm_cli.report.fragility_run import run_fragility

        return run_fragility
    if name == "MAX_RESAMPLES":
        # lazy: loads pandas only where needed (docs/architecture.md, Start-up)
        from rbm_cli.study.fragility import MAX_RESAMPLES

        return MAX_RESAMPLES
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def fragility(
    domain: pd.DataFrame | str | os.PathLike,
    *,
    n_resamples: int = 500,
    seed: int = 0,
    ci_percentiles: tuple[float, float] = (5.0, 95.0),
    intensity_column: str | None = None,
    intensity: str | None = None,
    ensemble_outcome: str = "members",
    n_members: int | None = None,
    damage_states=None,
    residual_states=None,
) -> FragilityResult | DamageStates:
    """The lognormal fragility of a record-suite domain, as data (what ``rbm fragility``
    computes and writes to fragility.csv, fragility_curve.csv and fragility.json; no file
    is written here).

    Parameters
    ----------
    domain : pandas.DataFrame or path  A domain over records x intensities: the rows of
        ``rbm.sweep(cfg, motions=[...])``, of a suite config's sweep, or its domain.csv
        (columns ``record``, an intensity [g] such as ``amplitude_g``, ``status``,
        ``collapsed``)
    n_resamples : int  Bootstrap resamples of the records (0: no band, no intervals)
    seed : int  Seed of the bootstrap (numpy PCG64), 0 to 2**64 - 1
    ci_percentiles : (float, float)  Percentiles bounding the intervals and the band [%]
    intensity : str, optional  The intensity measure fitted on: a column of the domain,
        the amplitude by default (intensity_g, amplitude_g or intensity, the first
        present), or a record's measure (pga_g, pgv_m_s, pgd_m, arias_m_s, cav_m_s,
        sa_t1_g, sa_<T>s_g, pga_over_g_tan_alpha, pgv_p_over_g_tan_alpha); the median and
        the tables' intensity_g are then in its unit (``result.intensity_unit``)
    intensity_column : str, optional  The same as ``intensity`` (its older name)
    ensemble_outcome : str  For an ensemble domain (a ``collapse_fraction`` column):
        ``members`` (every member a trial, the default: all the runs the sweep made),
        ``majority`` (a cell collapses when most members did) or ``member0`` (the row's
        own run); ``result.outcome`` says which
    n_members : int, optional  Members per cell of an ensemble domain given as a
        DataFrame, a whole number >= 1 (a domain.csv's meta.json says it for a path)
    damage_states : sequence of float, optional  Thresholds of max_rotation_ratio [-],
        each finite, 0 < t <= 1 (1: collapse), strictly increasing: a fragility curve
        per damage state (a run exceeds a state when its peak rotation ratio reaches the
        threshold or it collapsed; an ensemble domain's member 0 runs), returned as a
        ``DamageStates`` (rbm_cli.study.fragility_states: ``thresholds``, ``results``, one
        FragilityResult per state, ``crossings``, ``table()``) instead of one result
    residual_states : sequence of float, optional  Thresholds of residual_slip_m [m], each
        finite, > 0, strictly increasing: a fragility curve per residual state of a domain
        of the contact engine (model bullet: a run exceeds a state when its residual slip
        reaches the threshold or it collapsed), returned as a ``DamageStates`` as
        ``damage_states`` are (``measure`` says of which column); give one of the two

    Returns
    -------
    FragilityResult  ``fit`` (``median_g`` [g], ``beta`` [-], ``log_likelihood``; None
        when the runs allow no fit, ``note`` says why), ``median_ci_g`` [g] and
        ``beta_ci`` (the bootstrap intervals), ``curve`` (a DataFrame: intensity_g [g],
        probability, lower, upper: the fitted curve and its band), ``table`` (per
        intensity: intensity_g [g], n_records, n_failed, n_collapsed, fraction, fitted,
        band_lower, band_upper), n_records, n_runs, n_failed

    Raises
    ------
    RbmError  One line: not a suite domain (no ``record`` column), bad rows or options
        (an intensity that is not a measure, such as ``n_rhs``; n_members not a whole
        number >= 1)

    Examples
    --------
    >>> import pandas as pd, rbm
    >>> rows = [{"record": r, "amplitude_g": a, "collapsed": int(a >= c)}
    ...         for r, c in (("r1", 0.3), ("r2", 0.5), ("r3", 0.7)) for a in (0.2, 0.4, 0.6, 0.8)]
    >>> res = rbm.fragility(pd.DataFrame(rows), n_resamples=0)
    >>> round(res.fit.median_g, 2), list(res.curve.columns)  # capacities' geometric mean: 0.47
    (0.48, ['intensity_g', 'probability', 'lower', 'upper'])
    """  # noqa: E501
    # lazy: pandas loads only where needed (docs/architecture.md, Start-up)
    import pandas as pd

    # lazy: loads pandas only where needed (docs/architecture.md, Start-up)
    from rbm_cli.report.fragility_run import n_members as members_of

    # lazy: loads pandas only where needed (docs/architecture.md, Start-up)
    from rbm_cli.study.fragility import check_options

    # lazy: loads pandas only where needed (docs/architecture.md, Start-up)
    from rbm_cli.study.fragility import fragility as fit

    # lazy: loads pandas only where needed (docs/architecture.md, Start-up)
    from rbm_cli.study.outcomes import prepare_outcomes, read_suite_domain

    check_options(n_resamples, seed, ci_percentiles)
    n_members = check_members(n_members)
    check_intensity(intensity, "fragility: intensity")
    check_intensity(intensity_column, "fragility: intensity_column")
    if damage_states is not None and residual_states is not None:
        raise RbmError("fragility: damage_states and residual_states are two sets of curves:"
                       " give one per call")  # fmt: skip
    # lazy: loads pandas only where needed (docs/architecture.md, Start-up)
    from rbm_cli.study.fragility_states import PEAK, RESIDUAL, check_damage_states

    measure = PEAK
    if damage_states is not None:
        damage_states = check_damage_states(damage_states)
    elif residual_states is not None:
        measure = RESIDUAL
        damage_states = check_damage_states(residual_states, "fragility: residual_states",
                                            RESIDUAL)  # fmt: skip
    if intensity is not None and intensity_column is not None and intensity != intensity_column:
        raise RbmError(f"fragility: intensity {intensity!r} and intensity_column "
                       f"{intensity_column!r} name two columns: give one")  # fmt: skip
    column = intensity if intensity is not None else intensity_column
    if isinstance(domain, str | os.PathLike):
        path = domain
        domain = read_suite_domain(path)
        if n_members is None:
            n_members = members_of(Path(path), domain)
    elif isinstance(domain, pd.DataFrame):
        domain = domain.copy()
    # checked (one line) before the fit
    prepare_outcomes(domain, column, ensemble_outcome, n_members)
    if damage_states is not None:
        # lazy: loads pandas only where needed (docs/architecture.md, Start-up)
        from rbm_cli.study.fragility_states import damage_states as fit_states

        return fit_states(domain, damage_states, n_resamples=n_resamples, seed=seed,
                          ci_percentiles=ci_percentiles, intensity_column=column,
                          measure=measure)  # fmt: skip
    return fit(domain, n_resamples=n_resamples, seed=seed, ci_percentiles=ci_percentiles,
               intensity_column=column, ensemble_outcome=ensemble_outcome,
               n_members=n_members)  # fmt: skip
