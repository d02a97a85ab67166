"""The stochastic ground-motion model of Rezaeian and Der Kiureghian (2008, 2010).

A modulated, filtered white noise with a time-varying filter: each white-noise impulse
w_i at t_i excites a damped oscillator whose frequency and damping are those of the
filter *at t_i*; the sum is normalised to unit variance (:func:`unit_process`) and
multiplied by a gamma-shaped modulating function (:func:`modulating_function`); a
critically damped high-pass oscillator (:func:`highpass`) then makes the residual
velocity and displacement vanish. The seeded record suite built on it is
:mod:`rbm_cli.inputs.synthetic`.

Bit for bit: the arithmetic is IEEE additions, multiplications, divisions and square roots
applied elementwise (no matrix products, no BLAS, no reductions whose order a CPU could
change), recurrences run in a fixed order, and exp, log, sin, cos come from
:mod:`rbm_cli.base.portable_math`, not from the CPU-dispatched numpy/libm ones. The two
scalars found by root finding (the modulating function's alpha_2, alpha_3) are rounded to 6
significant digits, so a last-bit difference in scipy's gamma functions cannot reach them.

References
----------
.. [1] S. Rezaeian and A. Der Kiureghian (2008). A stochastic ground motion model with
   separable temporal and spectral nonstationarities. Earthquake Engineering and
   Structural Dynamics 37(13), 1565-1584.
.. [2] S. Rezaeian and A. Der Kiureghian (2010). Simulation of synthetic ground motions for
   specified earthquake and site characteristics. Earthquake Engineering and Structural
   Dynamics 39(10), 1155-1180.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np
from scipy.optimize import brentq
from scipy.special import gammaincinv

from rbm_cli.base import portable_math as pm
from rbm_cli.base.errors import RbmError

#: Corner frequency of the high-pass oscillator [Hz] (RDK 2010: 0.2 Hz).
HIGHPASS_HZ = 0.2

#: Lowest filter frequency [Hz]: the linear trend of omega_f is cut here (our choice).
FLOOR_HZ = 0.3

#: Impulses whose responses are built together (memory: block x samples x 8 bytes).
_BLOCK = 256


@dataclass(frozen=True)
class RDKParameters:
    """Parameters of one record of the RDK model.

    Parameters
    ----------
    duration_5_95_s : float
        Significant duration D_5-95 [s]: time between 5 % and 95 % of the Arias intensity
    t_mid_s : float
        Time at which 45 % of the Arias intensity is reached [s]
    frequency_mid_hz : float
        Filter frequency at t_mid, omega_mid / 2 pi [Hz]
    frequency_slope_hz_per_s : float
        Rate of change of the filter frequency, omega' / 2 pi [Hz/s]
    damping : float
        Filter damping ratio zeta_f, 0 < zeta_f < 1 [-]
    pga_g : float
        Peak ground acceleration the record is scaled to [g]
    """

    duration_5_95_s: float
    t_mid_s: float
    frequency_mid_hz: float
    frequency_slope_hz_per_s: float
    damping: float
    pga_g: float

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if not math.isfinite(value):
                raise RbmError(f"synthetic parameter {f.name} must be finite, got {value!r}")
        for name in ("duration_5_95_s", "t_mid_s", "frequency_mid_hz", "pga_g"):
            if getattr(self, name) <= 0.0:
                raise RbmError(f"synthetic parameter {name} must be > 0, got {getattr(self, name)}")
        if not 0.0 < self.damping < 1.0:
            raise RbmError(f"synthetic parameter damping must be in (0, 1), got {self.damping}")


# --------------------------------------------------------------------------- modulation


def _gamma_quantiles(k: float) -> tuple[float, float, float]:
    return tuple(float(gammaincinv(k, p)) for p in (0.05, 0.45, 0.95))


def modulating_parameters(duration_5_95_s: float, t_mid_s: float) -> tuple[float, float]:
    """alpha_2 [-] and alpha_3 [1/s] of q(t) = t^(alpha_2 - 1) exp(-alpha_3 t) from D_5-95, t_mid.

    Notes
    -----
    The Arias intensity accumulated by time t is proportional to the integral of q^2, a
    gamma distribution of shape k = 2 alpha_2 - 1 and rate 2 alpha_3. With Q_p the
    p-quantile of the unit-rate gamma of shape k, t_mid = Q_0.45 / (2 alpha_3) and
    D_5-95 = (Q_0.95 - Q_0.05) / (2 alpha_3): the ratio t_mid / D fixes k (root finding),
    then t_mid fixes alpha_3 (RDK 2010 map (D_5-95, t_mid) to alpha this way). Both are
    rounded to 6 significant digits. Needs t_mid / D_5-95 > 0.204 (k > 1).
    """

    def ratio(k: float) -> float:
        q05, q45, q95 = _gamma_quantiles(k)
        return q45 / (q95 - q05)

    target = t_mid_s / duration_5_95_s
    lo, hi = 1.0 + 1e-9, 2000.0
    if not ratio(lo) < target < ratio(hi):
        raise RbmError(
            f"synthetic parameters: t_mid_s / duration_5_95_s must be in "
            f"({ratio(lo):.3f}, {ratio(hi):.1f}), got {target:.3f}"
        )
    k = brentq(lambda x: ratio(x) - target, lo, hi, xtol=1e-12, rtol=1e-13)
    alpha_3 = _gamma_quantiles(k)[1] / (2.0 * t_mid_s)
    return float(f"{(k + 1.0) / 2.0:.6g}"), float(f"{alpha_3:.6g}")


def modulating_function(t: np.ndarray, alpha_2: float, alpha_3: float) -> np.ndarray:
    """q(t) = t^(alpha_2 - 1) exp(-alpha_3 t), scaled to a peak of 1 at (alpha_2 - 1)/alpha_3.

    The RDK factor alpha_1 is left out: each record is scaled to its PGA afterwards.
    """
    t = np.asarray(t, dtype=float)
    t_peak = (alpha_2 - 1.0) / alpha_3
    positive = t > 0.0
    safe = np.where(positive, t, 1.0)
    expo = (alpha_2 - 1.0) * (pm.log(safe) - pm.log(np.float64(t_peak))) - alpha_3 * (safe - t_peak)
    return np.where(positive, pm.exp(expo), 0.0)


# --------------------------------------------------------------------------- filter


def filter_frequency_hz(t: np.ndarray, params: RDKParameters) -> np.ndarray:
    """omega_f(t) / 2 pi = f_mid + f' (t - t_mid), not below :data:`FLOOR_HZ` [Hz]."""
    f = params.frequency_mid_hz + params.frequency_slope_hz_per_s * (np.asarray(t) - params.t_mid_s)
    return np.maximum(f, FLOOR_HZ)


def impulse_responses(omega: np.ndarray, damping: float, dt: float, n_lags: int) -> np.ndarray:
    """h(k dt) for k = 0 .. n_lags - 1 of oscillators of frequencies ``omega`` [rad/s].

    Returns an (n_lags, len(omega)) array of

    .. math:: h(\\tau) = \\frac{\\omega}{\\sqrt{1 - \\zeta^2}} e^{-\\zeta \\omega \\tau}
              \\sin(\\omega \\sqrt{1 - \\zeta^2} \\tau)

    (RDK's filter: the pseudo-acceleration impulse response of a damped oscillator), by
    the exact two-term recurrence h_{k+1} = 2 e^{-zeta omega dt} cos(omega_d dt) h_k
    - e^{-2 zeta omega dt} h_{k-1}, h_0 = 0.
    """
    omega = np.asarray(omega, dtype=float)
    root = math.sqrt(1.0 - damping * damping)
    wd_dt = omega * root * dt
    if np.any(wd_dt > 1.6):
        raise RbmError(
            f"synthetic: filter frequency {float(np.max(omega)) / (2 * math.pi):.3g} Hz is too "
            f"high for dt = {dt} s (need f dt <= 0.25)"
        )
    decay = pm.exp(-damping * omega * dt)
    c1 = 2.0 * decay * pm.cos_small(wd_dt)
    c2 = decay * decay
    h = np.zeros((n_lags, omega.size))
    if n_lags > 1:
        h[1] = (omega / root) * decay * pm.sin_small(wd_dt)
    for k in range(1, n_lags - 1):
        h[k + 1] = c1 * h[k] - c2 * h[k - 1]
    return h


def unit_process(params: RDKParameters, n: int, dt: float, noise: np.ndarray) -> np.ndarray:
    """RDK's filtered white noise normalised to unit variance, before modulation.

    Parameters
    ----------
    params : RDKParameters
        Filter parameters (frequency_mid_hz, frequency_slope_hz_per_s, t_mid_s, damping)
    n : int
        Samples, at t_k = k dt
    dt : float
        Time step [s]
    noise : numpy.ndarray
        Standard normal impulses w_i at t_i = i dt, shape (n,) or (m, n) for m
        realisations at once (each row gives the same bits as alone)

    Returns
    -------
    numpy.ndarray
        z(t_k) = sum_{i <= k} h_i(t_k - t_i) w_i / sigma_h(t_k), same shape as ``noise``;
        0 where sigma_h = 0 (t = 0)

    Notes
    -----
    .. math:: z(t) = \\frac{1}{\\sigma_h(t)} \\sum_{i: t_i \\le t}
              h[t - t_i, \\lambda(t_i)] w_i, \\qquad
              \\sigma_h^2(t) = \\sum_{i: t_i \\le t} h^2[t - t_i, \\lambda(t_i)]

    with lambda(t_i) = (omega_f(t_i), zeta_f): each impulse's response keeps the filter of
    its own time (RDK 2008, eq. 8). The sums are accumulated impulse by impulse in a
    fixed order.
    """
    noise = np.asarray(noise, dtype=float)
    if noise.shape[-1] != n:
        raise RbmError(f"synthetic: noise has {noise.shape[-1]} samples, expected {n}")
    t = np.arange(n) * dt
    omega = 2.0 * math.pi * filter_frequency_hz(t, params)
    total = np.zeros(noise.shape)
    var = np.zeros(n)
    for start in range(0, n, _BLOCK):
        stop = min(start + _BLOCK, n)
        h = impulse_responses(omega[start:stop], params.damping, dt, n - start)
        for j, i in enumerate(range(start, stop)):
            column = h[: n - i, j]
            total[..., i:] += noise[..., i : i + 1] * column
            var[i:] += column * column
    sigma = np.sqrt(var)
    return np.where(sigma > 0.0, total / np.where(sigma > 0.0, sigma, 1.0), 0.0)


def highpass(acceleration: np.ndarray, dt: float, corner_hz: float = HIGHPASS_HZ) -> np.ndarray:
    """RDK's high-pass: the acceleration of a critically damped oscillator driven by the input.

    Notes
    -----
    .. math:: \\ddot u + 2 \\omega_c \\dot u + \\omega_c^2 u = \\ddot x(t), \\qquad
              \\text{output } \\ddot u, \\quad \\omega_c = 2 \\pi f_c

    integrated with Newmark's average acceleration (trapezoidal) rule from rest, so the
    trapezoidal integrals of the output are exactly the oscillator's velocity and
    displacement, which decay to 0 once the input has: no residual velocity or
    displacement (RDK 2010, f_c = 0.2 Hz).
    """
    x = np.asarray(acceleration, dtype=float).tolist()
    wc = 2.0 * math.pi * corner_hz
    denom = 1.0 + wc * dt + wc * wc * dt * dt / 4.0
    out = [0.0] * len(x)
    u = v = 0.0
    y = x[0]
    out[0] = y
    for k in range(1, len(x)):
        v_pred = v + dt / 2.0 * y
        u_pred = u + dt * v + dt * dt / 4.0 * y
        y_new = (x[k] - 2.0 * wc * v_pred - wc * wc * u_pred) / denom
        v = v_pred + dt / 2.0 * y_new
        u = u_pred + dt * dt / 4.0 * y_new
        y = y_new
        out[k] = y
    return np.array(out)
