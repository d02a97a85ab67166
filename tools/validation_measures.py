"""Measurements the validation report makes (tools/make_validation.py), as functions.

- :func:`zero_crossings` and :func:`period_from_crossings`: the rocking period of a
  recorded history (t, theta, theta'), from its zero crossings on the cubic Hermite
  interpolant, found by the integrator's own crossing search
  (:func:`rbm_cli.base.events.first_crossing`).
- :func:`linear_domain`: the closed-form (housner-linear) domain over a config's grid.
- :func:`differing_cells`: the cells where two domains disagree, and whether each is
  next to the boundary.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from rbm_cli.base.events import first_crossing
from rbm_cli.config.types import Config
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.models.block.closed_form import linear_run


def _hermite(y0: float, y1: float, d0: float, d1: float):
    """The cubic Hermite on s in [0, 1] with end values y0, y1 and end slopes d0, d1
    (per unit s), as a distance for first_crossing: s (m,) -> (values, slopes), (1, m)."""

    def dist(s):
        s = np.asarray(s, float)
        value = (
            (2 * s**3 - 3 * s**2 + 1) * y0
            + (s**3 - 2 * s**2 + s) * d0
            + (-2 * s**3 + 3 * s**2) * y1
            + (s**3 - s**2) * d1
        )
        slope = (
            (6 * s**2 - 6 * s) * y0
            + (3 * s**2 - 4 * s + 1) * d0
            + (-6 * s**2 + 6 * s) * y1
            + (3 * s**2 - 2 * s) * d1
        )
        return value[None, :], slope[None, :]

    return dist


def zero_crossings(t, theta, rate) -> np.ndarray:
    """Times where a sampled rotation changes sign, on its cubic Hermite interpolant.

    Parameters
    ----------
    t : (k,) array  Sample times [s], increasing
    theta : (k,) array  Rotation at the samples [rad]
    rate : (k,) array  Its rate at the samples [rad/s]

    Returns
    -------
    (c,) array  One time per sample interval where theta changes sign strictly [s]:
        the first zero of the interval's cubic Hermite, found by
        :func:`rbm_cli.base.events.first_crossing` (Brent's method, xtol 1e-15 of the
        interval).

    Notes
    -----
    On the interval [t_k, t_k+1] of length h, with s = (t - t_k) / h, the interpolant is
    H(s) = h00 theta_k + h10 h theta'_k + h01 theta_k+1 + h11 h theta'_k+1 (the standard
    cubic Hermite basis); it is searched with the sign that makes it start positive.
    Samples exactly at zero are not crossings.
    """
    t, theta, rate = (np.asarray(x, float) for x in (t, theta, rate))
    out = []
    for k in np.nonzero(np.sign(theta[:-1]) * np.sign(theta[1:]) < 0)[0]:
        h = t[k + 1] - t[k]
        sign = np.sign(theta[k])
        dist = _hermite(
            sign * theta[k], sign * theta[k + 1], sign * rate[k] * h, sign * rate[k + 1] * h
        )
        s, _ = first_crossing(dist, 0.0, 1.0, xtol=1e-15)
        out.append(t[k] + h * s)
    return np.array(out)


def period_from_crossings(times) -> float:
    """Rocking period [s] from successive zero crossings (or impacts) [s]: two half
    cycles per period, 2 (t_last - t_first) / (count - 1); NaN with fewer than two."""
    times = np.asarray(times, float)
    if len(times) < 2:
        return math.nan
    return 2.0 * (times[-1] - times[0]) / (len(times) - 1)


def linear_domain(config: Config, alpha: float, p: float, restitution: float) -> pd.DataFrame:
    """The housner-linear domain over the grid of a config, in closed form.

    Parameters
    ----------
    config : Config  Its grid, excitation and collapse ratio are used
    alpha : float  Slenderness of the linear model [rad]
    p : float  Its frequency parameter [rad/s]
    restitution : float  Angular-velocity ratio e at impacts [-]

    Returns
    -------
    DataFrame  One row per cell (frequency-major, as the grid): amplitude_g,
        frequency_hz, status, collapsed.
    """
    rows = []
    for f in config.grid.frequencies_hz:
        for a in config.grid.amplitudes_g:
            motion = make_ground_motion(config.excitation, a, f)
            out = linear_run(
                alpha, p, motion, restitution=restitution, collapse_ratio=config.collapse.ratio
            )
            rows.append(
                {
                    "amplitude_g": float(a),
                    "frequency_hz": float(f),
                    "status": out.status,
                    "collapsed": int(out.status == "collapsed"),
                }
            )
    return pd.DataFrame(rows)


def _flags(df: pd.DataFrame) -> dict:
    cols = (df.amplitude_g, df.frequency_hz, df.collapsed)
    return {(round(x, 9), round(f, 9)): int(c) for x, f, c in zip(*cols, strict=True)}


def differing_cells(a: pd.DataFrame, b: pd.DataFrame) -> list[dict]:
    """Cells of two domains whose collapsed flags differ.

    Returns
    -------
    list of dict  Sorted by frequency, then amplitude: amplitude_g, frequency_hz, a and
        b (the flags), near (True when an amplitude neighbour at the same frequency has
        the other flag in either domain: a cell next to the boundary). Cells are
        matched on amplitude and frequency rounded to 1e-9; neighbours are taken in
        the amplitudes of `a`.
    """
    ta, tb = _flags(a), _flags(b)
    amps = sorted({k[0] for k in ta})
    out = []
    for key in sorted(ta.keys() & tb.keys(), key=lambda k: (k[1], k[0])):
        if ta[key] == tb[key]:
            continue
        i = amps.index(key[0])
        neigh = [amps[j] for j in (i - 1, i + 1) if 0 <= j < len(amps)]
        near = any((n, key[1]) in t and t[(n, key[1])] != t[key] for t in (ta, tb) for n in neigh)
        out.append(
            {
                "amplitude_g": key[0],
                "frequency_hz": key[1],
                "a": ta[key],
                "b": tb[key],
                "near": near,
            }
        )
    return out
