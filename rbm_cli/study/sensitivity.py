"""Which uncertain key moves a domain's outcome most: rank correlations over its samples.

A domain over samples of uncertain keys (rbm_cli.config.uncertain: a row per cell and
sample, the value each key took in ``uncertain.<key>``) is a Latin hypercube design with
its outputs. For each key and each outcome (the peak rotation ratio ``max_rotation_ratio``
and ``collapsed``) this module gives, over the rows whose run did not fail:

- Spearman's rank correlation of the key's values with the outcome (scipy.stats.spearmanr)
  and its p-value;
- the partial rank correlation coefficient (PRCC): the Pearson correlation of the ranks of
  the key and of the outcome once both are cleared (least squares) of the ranks of every
  other input that varies: the other keys, the amplitude (the intensity), the frequency and
  the grid's axes over config keys (a record, or any axis of text, by an indicator per
  value). The cells of a domain span the intensity, which moves
  the outcome more than any key: Spearman's coefficient of a key is diluted by it, the
  PRCC is not. Its p-value is that of a Pearson correlation of n - 2 - k degrees of
  freedom with k inputs cleared (t = r sqrt((n - 2 - k) / (1 - r^2))).

A coefficient near +1 (-1): the outcome grows (falls) with the key; near 0: no monotone
effect. An outcome that does not vary (no collapse anywhere) gives no coefficient (NaN).
These are the measures that go with a Latin hypercube (Helton and Davis 2003; Marino et
al. 2008); variance-based indices (Sobol', as SALib computes them) need a design of their
own (Saltelli's, N (2k + 2) runs) that a sweep's samples are not.

References
----------
.. [1] J. C. Helton and F. J. Davis (2003). Latin hypercube sampling and the propagation of
   uncertainty in analyses of complex systems. Reliability Engineering and System Safety
   81(1), 23-69.
.. [2] S. Marino, I. B. Hogue, C. J. Ray and D. E. Kirschner (2008). A methodology for
   performing global uncertainty and sensitivity analysis in systems biology. Journal of
   Theoretical Biology 254(1), 178-196.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from rbm_cli.base.errors import RbmError
from rbm_cli.config.uncertain import PREFIX, config_path
from rbm_cli.study.domain import axis_columns
from rbm_cli.study.samples import has_samples
from rbm_cli.study.schema import C

#: The outcomes whose sensitivity is measured, in the table's order.
OUTCOMES = (C.max_rotation_ratio, C.collapsed)
#: The table's columns.
FIELDS = ("key", "outcome", "spearman", "spearman_p", "prcc", "prcc_p", "n_runs")


def _varies(values: np.ndarray) -> bool:
    finite = values[np.isfinite(values)]
    return finite.size > 1 and np.ptp(finite) > 0


def _numeric(df: pd.DataFrame, column: str) -> np.ndarray:
    return pd.to_numeric(df[column], errors="coerce").to_numpy(float)


def _ranks(values: np.ndarray) -> np.ndarray:
    # lazy: scipy.stats loads only where needed (docs/architecture.md, Start-up)
    from scipy.stats import rankdata

    return rankdata(values)


def _residual(y: np.ndarray, others: np.ndarray) -> np.ndarray:
    """y cleared of a least-squares fit on ``others`` (columns) and a constant."""
    design = np.column_stack([np.ones(y.size), others])
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    return y - design @ coef


def _correlation(a: np.ndarray, b: np.ndarray) -> float:
    sa, sb = np.std(a), np.std(b)
    if sa <= 1e-12 * max(1.0, np.abs(a).max()) or sb <= 1e-12 * max(1.0, np.abs(b).max()):
        return math.nan
    return float(np.clip(np.corrcoef(a, b)[0, 1], -1.0, 1.0))


def _p_value(r: float, dof: int) -> float:
    # lazy: scipy.stats loads only where needed (docs/architecture.md, Start-up)
    from scipy.stats import t as student

    if not math.isfinite(r) or dof < 1:
        return math.nan
    if abs(r) >= 1.0:
        return 0.0
    t = r * math.sqrt(dof / (1.0 - r * r))
    return float(2.0 * student.sf(abs(t), dof))


def _categories(df: pd.DataFrame, columns: list[str]) -> dict:
    """Indicator columns (0/1, the first value left out) of the columns that hold text (a
    record, a record file): cleared as the numeric inputs are, they take out each record's
    own level of the outcome."""
    out = {}
    for column in columns:
        if column not in df.columns or not np.isnan(_numeric(df, column)).all():
            continue
        values = df[column].astype(str).to_numpy()
        for value in list(dict.fromkeys(values))[1:]:
            out[f"{column}={value}"] = (values == value).astype(float)
    return out


def sensitivity(df: pd.DataFrame) -> pd.DataFrame:
    """The rank correlations of each uncertain key with each outcome (module docstring).

    Parameters
    ----------
    df : pandas.DataFrame  A domain over samples of uncertain keys (rbm_cli.study.domain
        read_domain of a domain.csv swept with an ``uncertain`` section)

    Returns
    -------
    pandas.DataFrame  A row per key and outcome (:data:`FIELDS`): the key's dotted path,
        the outcome's column, Spearman's coefficient and p-value, the PRCC and its
        p-value, the runs counted; the keys in the order of |PRCC| on the peak rotation
        ratio, largest first

    Raises
    ------
    RbmError  A domain without samples, or with fewer runs than inputs + 3
    """
    if not has_samples(df.columns):
        raise RbmError(
            "sensitivity: the domain has no samples of uncertain keys (no sample column):"
            " sweep a config with an uncertain section"
        )
    keys = [c for c in df.columns if str(c).startswith(PREFIX)]
    ok = df[df[C.status].astype(str) != "failed"] if C.status in df.columns else df
    controls = [C.amplitude_g, C.frequency_hz, *axis_columns(df.columns)]
    inputs = {c: _numeric(ok, c) for c in [*keys, *controls] if c in ok.columns}
    inputs = {c: v for c, v in inputs.items() if _varies(v)}
    inputs.update(_categories(ok, [C.record, *axis_columns(df.columns)]))
    rows = []
    for outcome in OUTCOMES:
        if outcome not in ok.columns:
            continue
        y = _numeric(ok, outcome)
        for key in keys:
            x = inputs.get(key)
            others = [c for c in inputs if c != key]
            use = np.isfinite(y) & np.all(
                [np.isfinite(inputs[c]) for c in [key, *others] if c in inputs], axis=0
            )
            n = int(use.sum())
            if x is None or n < len(others) + 3:
                rows.append((config_path(key), outcome, math.nan, math.nan, math.nan, math.nan, n))
                continue
            rx, ry = _ranks(x[use]), _ranks(y[use])
            rest = np.column_stack([_ranks(inputs[c][use]) for c in others]) if others else None
            spearman = _correlation(rx, ry)
            if rest is not None:
                prcc = _correlation(_residual(rx, rest), _residual(ry, rest))
            else:
                prcc = spearman
            rows.append((config_path(key), outcome, spearman, _p_value(spearman, n - 2), prcc,
                         _p_value(prcc, n - 2 - len(others)), n))  # fmt: skip
    if not rows:
        raise RbmError("sensitivity: the domain has none of the outcomes max_rotation_ratio,"
                       " collapsed")  # fmt: skip
    table = pd.DataFrame(rows, columns=list(FIELDS))
    first = table[table["outcome"] == table["outcome"].iloc[0]]
    order = first.assign(size=first["prcc"].abs().fillna(-1.0)).sort_values(
        "size", ascending=False, kind="stable"
    )["key"]
    rank = {k: i for i, k in enumerate(order)}
    out = table.assign(_r=table["key"].map(rank), _o=table["outcome"].map(OUTCOMES.index))
    return (
        out.sort_values(["_o", "_r"], kind="stable")
        .drop(columns=["_r", "_o"])
        .reset_index(drop=True)
    )


__all__ = ["FIELDS", "OUTCOMES", "sensitivity"]
