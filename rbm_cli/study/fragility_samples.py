"""The fragility of a record-suite domain over samples of uncertain keys: the dispersion
split between the records and the keys, and curves per tercile of a key.

A suite swept with an ``uncertain`` section (rbm_cli.config.uncertain) has a run per
record, intensity and sample. rbm_cli.study.fragility fits one lognormal curve to all of
them (every run a trial): its dispersion beta is the total one, records and keys together.
:func:`dispersion_split` separates the two as Vamvatsikos and Fragiadakis (2010) do for a
Latin hypercube of model parameters: each sample's runs (its column under every record)
are fitted alone, giving its median theta_i and its record-to-record dispersion beta_i;

- beta_RTR = sqrt(mean(beta_i^2)), the records' dispersion about a sample's median;
- beta_U = the standard deviation of ln theta_i (n - 1 in the denominator), the spread of
  the median capacity that the uncertain keys cause;
- beta_total = sqrt(beta_RTR^2 + beta_U^2), the square-root-of-sum-of-squares rule with
  which FEMA P-695 (2009, section 7.3) combines the record-to-record and the modelling
  dispersions; the fit over every run (``beta_pooled``) estimates the same total
  directly, and the two agree where the capacities are lognormal.

A sample whose runs allow no fit (no collapse among them, or collapse at every run) is
left out of the split and counted (``n_fitted`` of ``n_samples``); beta_U needs two fitted
samples, beta_RTR one.

:func:`by_tercile` fits the runs of the samples whose value of a key lies in each third of
the key's values (the lower, middle and upper tercile of the samples, by rank): how the
curve moves with that key.

References
----------
.. [1] D. Vamvatsikos and M. Fragiadakis (2010). Incremental dynamic analysis for estimating
   seismic performance sensitivity and uncertainty. Earthquake Engineering and Structural
   Dynamics 39(2), 141-163.
.. [2] FEMA P-695 (2009). Quantification of Building Seismic Performance Factors. Federal
   Emergency Management Agency, Washington DC.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from rbm_cli.base.errors import RbmError
from rbm_cli.config.uncertain import SAMPLE, column_name
from rbm_cli.study.fragility_fit import NoFit, fit_counts
from rbm_cli.study.outcomes import prepare_outcomes

#: The terciles' names, lowest values first.
TERCILES = ("lower third", "middle third", "upper third")


@dataclass(frozen=True)
class DispersionSplit:
    """The record-to-record and the keys' dispersion of a suite over samples (module
    docstring). Medians in the intensity's unit; dispersions [-] (NaN where undefined).

    beta_rtr, beta_u, beta_total : float  The split and its square-root sum of squares
    median_pooled, beta_pooled : float  The fit over every run (NaN with none)
    n_samples, n_fitted : int  Samples, and those whose runs were fitted
    per_sample : DataFrame  sample, median, beta, note (why a sample has no fit)
    """

    beta_rtr: float
    beta_u: float
    beta_total: float
    median_pooled: float
    beta_pooled: float
    n_samples: int
    n_fitted: int
    per_sample: pd.DataFrame

    def summary(self) -> dict:
        """As fragility.json holds it (null where undefined)."""

        def num(x):
            return float(x) if x is not None and math.isfinite(x) else None

        return {
            "method": "Vamvatsikos and Fragiadakis (2010): a fit per sample; beta_rtr the"
            " root mean square of their betas, beta_u the standard deviation of ln of their"
            " medians, beta_total = sqrt(beta_rtr^2 + beta_u^2) (FEMA P-695)",
            "beta_rtr": num(self.beta_rtr),
            "beta_u": num(self.beta_u),
            "beta_total": num(self.beta_total),
            "median_pooled": num(self.median_pooled),
            "beta_pooled": num(self.beta_pooled),
            "n_samples": self.n_samples,
            "n_fitted": self.n_fitted,
            "per_sample": [
                {
                    SAMPLE: int(r[SAMPLE]),
                    "median": num(r["median"]),
                    "beta": num(r["beta"]),
                    "note": r["note"],
                }  # fmt: skip
                for _, r in self.per_sample.iterrows()
            ],
        }


def _fit(rows: pd.DataFrame):
    """The MLE of some prepared runs (rbm_cli.study.outcomes.prepare_outcomes), or the
    one-line reason there is none."""
    ok = rows[~rows["failed"]]
    levels, inverse = np.unique(ok["x"].to_numpy(), return_inverse=True)
    n = np.bincount(inverse, weights=ok["trials"].to_numpy(), minlength=levels.size)
    k = np.bincount(inverse, weights=ok["hits"].to_numpy(), minlength=levels.size)
    try:
        return fit_counts(np.log(levels), n, k), ""
    except NoFit as exc:
        return None, str(exc).removeprefix("fragility: ")


def _prepared(df: pd.DataFrame, intensity_column: str | None, ensemble_outcome, n_members):
    if SAMPLE not in df.columns:
        raise RbmError("fragility: the domain has no samples of uncertain keys (no sample column)")
    rows, _ = prepare_outcomes(df, intensity_column, ensemble_outcome, n_members)
    return rows


def dispersion_split(
    df: pd.DataFrame,
    intensity_column: str | None = None,
    ensemble_outcome: str = "members",
    n_members: int | None = None,
) -> DispersionSplit:
    """The dispersion split of a suite over samples (module docstring); ``df`` the domain's
    rows, checked as rbm_cli.study.fragility.fragility checks them."""
    rows = _prepared(df, intensity_column, ensemble_outcome, n_members)
    pooled, _ = _fit(rows)
    per = []
    for sample, runs in rows.groupby(SAMPLE, sort=True):
        fit, note = _fit(runs)
        per.append((sample, fit.median_g if fit else math.nan, fit.beta if fit else math.nan,
                    note))  # fmt: skip
    table = pd.DataFrame(per, columns=[SAMPLE, "median", "beta", "note"])
    fitted = table.dropna(subset=["median", "beta"])
    beta_rtr = math.sqrt(float(np.mean(fitted["beta"] ** 2))) if len(fitted) else math.nan
    beta_u = float(np.std(np.log(fitted["median"]), ddof=1)) if len(fitted) > 1 else math.nan
    return DispersionSplit(
        beta_rtr=beta_rtr,
        beta_u=beta_u,
        beta_total=math.hypot(beta_rtr, beta_u),
        median_pooled=pooled.median_g if pooled else math.nan,
        beta_pooled=pooled.beta if pooled else math.nan,
        n_samples=len(table),
        n_fitted=len(fitted),
        per_sample=table,
    )


def by_tercile(
    df: pd.DataFrame,
    key: str,
    intensity_column: str | None = None,
    ensemble_outcome: str = "members",
    n_members: int | None = None,
) -> pd.DataFrame:
    """A fit per tercile of an uncertain key's sampled values (module docstring): a row
    per tercile with its name, the key's least and largest value in it, its samples, runs,
    median and beta (NaN and the reason in ``note`` where its runs allow no fit).
    ``key``: the key's dotted path (``interface.restitution``) or its column."""
    column = key if key.startswith("uncertain.") else column_name(key)
    if column not in df.columns:
        keys = [c.removeprefix("uncertain.") for c in df.columns if c.startswith("uncertain.")]
        raise RbmError(
            f"fragility --by: {key} is not an uncertain key of the domain"
            f" (its keys: {', '.join(keys) or 'none'})"
        )
    rows = _prepared(df, intensity_column, ensemble_outcome, n_members)
    values = pd.to_numeric(df[column], errors="coerce").to_numpy(float)
    rows["value"] = values
    per_sample = rows.groupby(SAMPLE, sort=True)["value"].first()
    if len(per_sample) < 3:
        raise RbmError(
            f"fragility --by: terciles need 3 samples or more, the domain has {len(per_sample)}"
        )
    order = per_sample.rank(method="first").to_numpy() - 1.0
    third = np.minimum((order * 3 // len(per_sample)).astype(int), 2)
    which = dict(zip(per_sample.index, third, strict=True))
    out = []
    for t, name in enumerate(TERCILES):
        samples = [s for s, k in which.items() if k == t]
        runs = rows[rows[SAMPLE].isin(samples)]
        fit, note = _fit(runs)
        vals = per_sample.loc[samples]
        out.append((name, float(vals.min()), float(vals.max()), len(samples),
                    int((~runs["failed"]).sum()), fit.median_g if fit else math.nan,
                    fit.beta if fit else math.nan, note))  # fmt: skip
    return pd.DataFrame(
        out, columns=["tercile", "lowest", "highest", "n_samples", "n_runs", "median", "beta",
                      "note"],
    )  # fmt: skip


__all__ = ["TERCILES", "DispersionSplit", "by_tercile", "dispersion_split"]
