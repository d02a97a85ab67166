"""Lognormal fragility by maximum likelihood on per-run outcomes (collapse or not).

    P(collapse | IM = x) = Phi( ln(x / theta) / beta )

Every run is a Bernoulli trial with that probability (Baker 2015, multiple-stripe
form); the likelihood is maximised over (ln theta, ln beta) with BFGS and its analytic
gradient. The per-record study, its bootstrap and its table are in
:mod:`rbm_cli.study.fragility`.

References
----------
.. [1] J. W. Baker (2015). Efficient analytical fragility function fitting using dynamic
   structural analysis. Earthquake Spectra 31(1), 579-599.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize
from scipy.special import log_ndtr, ndtr, ndtri

from rbm_cli.base.errors import RbmError


class NoFit(RbmError):
    """The outcomes allow no lognormal fit; ``reason`` says why, as a key of
    :data:`NO_FIT_REASONS` (the message says it in full, one line)."""

    def __init__(self, message: str, reason: str) -> None:
        super().__init__(message)
        self.reason = reason


#: Why outcomes allow no fit: the key a NoFit carries -> what the outcomes held, as a
#: phrase (a bootstrap counts its resamples with no fit by these).
NO_FIT_REASONS = {
    "no-runs": "no runs",
    "no-collapse": "no collapse",
    "all-collapse": "only collapses",
    "one-intensity": "runs at one intensity only",
    "separated": "outcomes separated by intensity (no finite dispersion)",
    "not-increasing": "outcomes that no increasing curve fits",
}


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


def fit_counts(log_x, n, k, start=None, unit: str = "g") -> LognormalFit:
    """MLE from counts per level: ln of each intensity [ln g], runs and collapses there
    (``start``: the (ln theta, ln beta) to start from; ``unit``: the intensity's, for the
    messages); :class:`NoFit` (an RbmError, one line, with its reason) when no finite,
    increasing fit exists (no collapse, only collapses, one intensity, separated or
    quasi-separated outcomes, collapse not rising with intensity)."""
    total_k, total_n = float(np.sum(k)), float(np.sum(n))
    if total_n == 0:
        raise NoFit("fragility: no runs to fit", "no-runs")
    if total_k == 0:
        raise NoFit(
            "fragility: no record collapsed at any intensity: the median lies above them",
            "no-collapse",
        )
    if total_k == total_n:
        raise NoFit(
            "fragility: every record collapsed at every intensity: the median lies below them",
            "all-collapse",
        )
    if np.unique(log_x[n > 0]).size < 2:
        x = math.exp(float(np.max(log_x[n > 0])))
        raise NoFit(
            f"fragility: all runs are at one intensity ({x:.6g} {unit}, {total_k:.6g} of "
            f"{total_n:.6g} collapsed): a lognormal curve needs runs at two intensities or more",
            "one-intensity",
        )
    survived, collapsed = n - k > 0, k > 0
    top_safe, low_unsafe = np.max(log_x[survived]), np.min(log_x[collapsed])
    if top_safe < low_unsafe:
        raise NoFit(
            f"fragility: outcomes are separated (all runs survive up to "
            f"{math.exp(top_safe):.6g} {unit} and collapse from "
            f"{math.exp(low_unsafe):.6g} {unit}): the dispersion has no finite estimate",
            "separated",
        )
    if top_safe == low_unsafe:  # one intensity with mixed outcomes, none mixed elsewhere
        j = int(np.flatnonzero(log_x == top_safe)[0])
        below, above = bool(np.any(log_x < top_safe)), bool(np.any(log_x > top_safe))
        sides = " and ".join(
            [*(["every run below it survives"] if below else []),
             *(["every run above it collapses"] if above else [])]
        )  # fmt: skip
        raise NoFit(
            f"fragility: outcomes are quasi-separated, mixed at one intensity only"
            f" ({math.exp(top_safe):.6g} {unit}: {k[j]:.6g} of {n[j]:.6g} collapsed; {sides}):"
            " the curve may rise there as steeply as it likes, so the dispersion has no"
            " finite estimate",
            "separated",
        )
    x0 = _start(log_x, n, k) if start is None else np.asarray(start, dtype=float)
    with np.errstate(all="ignore"):  # a trial step far out overflows; the result is checked
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
        raise NoFit(
            "fragility: no increasing lognormal curve fits these outcomes "
            "(collapse does not become more frequent with intensity)",
            "not-increasing",
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
        No collapse, only collapses, all runs at one intensity (a curve through one
        fraction has no dispersion), or outcomes separated by intensity (the likelihood
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
    return fit_counts(np.log(levels), n, k)
