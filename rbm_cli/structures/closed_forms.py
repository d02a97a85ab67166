"""Closed-form results of the piecewise-linear rocking block (Spanos and Koh's linear block).

Pure functions for plots and tests: minimum overturning amplitudes of pulses,
the free rocking period, and the mapping of a rigid monolithic RBM column to
the linear model

    theta'' = p^2 (theta - alpha sgn(theta)) - p^2 a_g / g

Amplitude ratios are A / alpha, the pulse amplitude over the uplift level
(both in g). Frequencies are circular, omega [rad/s], except in
:func:`halfsine_threshold_curves`, which takes Hz and returns g.

References
----------
.. [1] G. W. Housner (1963). The behavior of inverted pendulum structures
   during earthquakes. Bulletin of the Seismological Society of America
   53(2), 403-417.
.. [2] P. D. Spanos and A.-S. Koh (1984). Rocking of rigid blocks due to
   harmonic shaking. Journal of Engineering Mechanics 110(11), 1627-1642.
.. [3] D. Baraldi, G. Milani and V. Sarhosis. A Rigid Beam Model for the
   seismic analysis of freestanding stone columns (the paper in
   ``paper/``), section 3.2.
"""

from __future__ import annotations

import math

import numpy as np

from rbm_cli.config.types import G
from rbm_cli.structures.column import Column


def _map_scalar(func, values):
    """Apply a scalar function elementwise; a scalar in gives a float out."""
    arr = np.asarray(values, dtype=float)
    out = np.array([func(float(v)) for v in arr.ravel()], dtype=float).reshape(arr.shape)
    return float(out) if out.ndim == 0 else out


def _check_nonnegative(name: str, values) -> np.ndarray:
    arr = np.asarray(values, dtype=float)
    if np.any(np.isnan(arr)) or np.any(arr < 0):
        raise ValueError(f"{name} must be >= 0")
    return arr


def housner_halfsine_threshold(omega_over_p):
    """Housner's approximate minimum overturning amplitude of a half-sine pulse.

    Parameters
    ----------
    omega_over_p : float or array_like
        Pulse circular frequency over the block's frequency parameter,
        omega / p [-], >= 0

    Returns
    -------
    float or numpy.ndarray
        A / alpha [-], the pulse amplitude over the uplift level

    Notes
    -----
    For a_g = A g sin(omega t), 0 <= t <= pi / omega, Housner's estimate is

    .. math:: A / \\alpha = \\sqrt{1 + (\\omega / p)^2}

    It drops the exponential term of the exact condition
    (:func:`linear_halfsine_threshold`): close for omega / p < 1, too high by
    up to a factor 2 for omega / p >> 1.

    References
    ----------
    Housner (1963), see the module references.
    """
    r = _check_nonnegative("omega_over_p", omega_over_p)
    out = np.sqrt(1.0 + r * r)
    return float(out) if out.ndim == 0 else out


def _halfsine_psi(ratio: float) -> float:
    """Root psi in (0, pi/2) of (w/p) sin(psi) - cos(psi) = exp(-(pi - psi) p / w)."""
    k = ratio

    def f(psi: float) -> float:
        return k * math.sin(psi) - math.cos(psi) - math.exp(-(math.pi - psi) / k)

    # f(0) = -1 - exp(-pi/k) < 0; f(pi/2) = k - exp(-pi/(2k)) > 0 for every
    # k > 0 (min over k of ln k + pi/(2k) is 1 + ln(pi/2) > 0). For small k the
    # root sits within ~k of pi/2 and for large k near 2/k: a tiny absolute
    # xtol keeps the relative accuracy at both ends.
    hi = 0.5 * math.pi
    if f(hi) <= 0.0:  # k so small that sin(pi/2 - k) rounds the sign away
        return hi
    # lazy: scipy.optimize loads only where needed (docs/architecture.md, Start-up)
    from scipy.optimize import brentq

    return brentq(f, 0.0, hi, xtol=1e-300, rtol=4 * np.finfo(float).eps, maxiter=500)


def linear_halfsine_threshold(omega_over_p):
    """Exact minimum overturning amplitude of a half-sine pulse, linear model.

    Parameters
    ----------
    omega_over_p : float or array_like
        Pulse circular frequency over the block's frequency parameter,
        omega / p [-], >= 0 (0 gives 1, inf gives inf)

    Returns
    -------
    float or numpy.ndarray
        A / alpha [-], the pulse amplitude over the uplift level

    Notes
    -----
    Pulse a_g = A g sin(omega t) for 0 <= t <= pi / omega, block at rest; it
    uplifts at t_0 = psi / omega with A sin(psi) = alpha. With
    q = (theta - alpha) + theta' / p, the linear equation on one side gives
    q' = p q + p A sin(omega t), q(t_0) = -alpha, and the block overturns in
    free motion iff q(pi / omega) >= 0 (no impact before the pulse ends).
    q(pi / omega) = 0 reduces to

    .. math:: (\\omega / p) \\sin\\psi - \\cos\\psi = e^{-(\\pi - \\psi) p / \\omega},
              \\qquad A / \\alpha = 1 / \\sin\\psi

    solved for psi in (0, pi/2) with brentq to machine precision. Small
    omega / p gives psi -> pi/2 - omega/p (Housner's value); large omega / p
    gives psi -> 2 p / omega, A / alpha -> omega / (2 p).

    References
    ----------
    Housner (1963); Spanos and Koh (1984), see the module references.
    """
    _check_nonnegative("omega_over_p", omega_over_p)

    def one(k: float) -> float:
        if k == 0.0:
            return 1.0
        if math.isinf(k):
            return math.inf
        return 1.0 / math.sin(_halfsine_psi(k))

    return _map_scalar(one, omega_over_p)


def rectangular_pulse_threshold(p, duration):
    """Minimum overturning amplitude of a rectangular pulse, linear model.

    Parameters
    ----------
    p : float or array_like
        Frequency parameter of the block [rad/s], > 0
    duration : float or array_like
        Pulse duration t_1 [s], >= 0 (0 gives inf)

    Returns
    -------
    float or numpy.ndarray
        A / alpha [-]

    Notes
    -----
    Constant a_g = A g for 0 <= t <= t_1, block at rest, A > alpha:

    .. math:: A / \\alpha = 1 / (1 - e^{-p t_1})

    References
    ----------
    Housner (1963), see the module references.
    """
    p = np.asarray(p, dtype=float)
    t1 = _check_nonnegative("duration", duration)
    if np.any(~(p > 0)):
        raise ValueError("p must be > 0 [rad/s]")
    with np.errstate(divide="ignore"):
        out = -1.0 / np.expm1(-p * t1)
    return float(out) if out.ndim == 0 else out


def free_rocking_period(p, theta0_over_alpha):
    """Period of free rocking of the linear model (no energy loss).

    Parameters
    ----------
    p : float or array_like
        Frequency parameter of the block [rad/s], > 0
    theta0_over_alpha : float or array_like
        Rocking amplitude over the slenderness, theta_0 / alpha [-], in [0, 1]
        (0 gives 0, 1 gives inf)

    Returns
    -------
    float or numpy.ndarray
        Period T [s]

    Notes
    -----
    From rest at theta_0, theta - alpha = (theta_0 - alpha) cosh(p t) reaches
    theta = 0 after a quarter period:

    .. math:: T = \\frac{4}{p} \\operatorname{arccosh}
              \\frac{1}{1 - \\theta_0 / \\alpha}

    References
    ----------
    Housner (1963), see the module references.
    """
    p = np.asarray(p, dtype=float)
    r = _check_nonnegative("theta0_over_alpha", theta0_over_alpha)
    if np.any(r > 1):
        raise ValueError("theta0_over_alpha must be in [0, 1]")
    if np.any(~(p > 0)):
        raise ValueError("p must be > 0 [rad/s]")
    with np.errstate(divide="ignore"):
        out = 4.0 / p * np.arccosh(1.0 / (1.0 - r))
    return float(out) if out.ndim == 0 else out


def linear_rocking_parameters(column: Column) -> tuple[float, float]:
    """Slenderness and frequency parameter of the linear model equal to a rigid RBM monolith.

    Parameters
    ----------
    column : rbm_cli.structures.column.Column
        A monolithic column (n = 1)

    Returns
    -------
    alpha : float
        alpha = theta_u,1 = B_1 / H [rad]
    p : float
        Frequency parameter [rad/s]

    Raises
    ------
    ValueError
        If the column has more than one drum.

    Notes
    -----
    The rigid RBM with n = 1, (I_G + m H^2 / 4) theta'' = -f(theta) - m (H/2) a_g,
    with f = M_u (1 - |theta| / theta_u) sgn(theta) and M_u = (B_1 / 2) m g,
    is the linear model with

    .. math:: \\alpha = B_1 / H, \\qquad p^2 = \\frac{m g (H/2)}{I_G + m H^2 / 4}

    With a top mass, m and I_G are those of the drum with the mass and H/2 is the height c
    of their common centre: p^2 = m g c / (I_G + m c^2) (and alpha = (B_1 / 2) / c).

    This is not Housner's p^2 = W R / I_O of the same block: the RBM puts the
    weight on the axis (lever arm H/2, no B/2 term in the inertia about the
    base), so for a rectangle p^2 = 6 g H / (4 H^2 + B^2) against
    3 g / (2 sqrt(H^2 + B^2)); they agree as B / H -> 0.

    References
    ----------
    Baraldi, Milani and Sarhosis, the Rigid Beam Model paper, section 3.2.
    """
    if column.n != 1:
        raise ValueError(
            f"linear_rocking_parameters needs a monolithic column (n = 1), got n = {column.n}"
        )
    m = float(column.masses[0])
    h = 2.0 * float(column.centres[0])  # twice the centre's height: H without a top mass
    i_g = float(column.inertias[0])
    alpha = float(column.rotation_capacity[0])
    p = math.sqrt(m * G * (h / 2.0) / (i_g + m * h * h / 4.0))
    return alpha, p


def halfsine_threshold_curves(column: Column, frequencies_hz) -> dict[str, np.ndarray]:
    """Half-sine overturning thresholds of a rigid RBM monolith, in g.

    Parameters
    ----------
    column : rbm_cli.structures.column.Column
        A monolithic column (n = 1)
    frequencies_hz : array_like
        Pulse frequencies f [Hz] (a_g = A g sin(2 pi f t), 0 <= t <= 1 / (2 f))

    Returns
    -------
    dict
        'housner': Housner's approximation [g]; 'linear': the exact value of
        the linear model [g]; arrays shaped like ``frequencies_hz``.

    Notes
    -----
    A = alpha * ratio(omega / p), omega = 2 pi f, with (alpha, p) from
    :func:`linear_rocking_parameters`.
    """
    alpha, p = linear_rocking_parameters(column)
    ratio = 2.0 * math.pi * np.asarray(frequencies_hz, dtype=float) / p
    return {
        "housner": alpha * np.asarray(housner_halfsine_threshold(ratio)),
        "linear": alpha * np.asarray(linear_halfsine_threshold(ratio)),
    }
