"""Near-fault pulses of the rocking literature: ground acceleration as pure functions of time.

Every pulse starts at t = 0, lasts its ``*_duration`` [s] and is 0 outside; SI units: the
acceleration amplitude in [m/s^2], the frequency in [Hz] (the period is T_p = 1 / f_p).
Positive acceleration is ground acceleration in +x (as the records, :mod:`rbm_cli.inputs.records`).

- one-sine (Zhang and Makris's cycloidal type A): A sin(w t), 0 <= t <= T_p; peak A at T_p/4
- cycloidal type B (one-cosine): A cos(w t), 0 <= t <= T_p; peak |A| at 0, T_p/2 and T_p
- Ricker (symmetric): A (1 - 2 u^2) exp(-u^2), u = pi f_p (t - t0); peak A at t0
- Mavroeidis-Papageorgiou: the derivative of MP's velocity pulse, scaled to peak |A|

with w = 2 pi f_p. Each returns a float for a scalar t and an array otherwise.

References
----------
.. [1] J. Zhang and N. Makris (2001). Rocking response of free-standing blocks under
   cycloidal pulses. Journal of Engineering Mechanics 127(5), 473-483.
.. [2] N. Makris and Y. S. Roussos (2000). Rocking response of rigid blocks under
   near-source ground motions. Geotechnique 50(3), 243-262.
.. [3] N. H. Ricker (1943). Further developments in the wavelet theory of seismogram
   structure. Bulletin of the Seismological Society of America 33(3), 197-228.
.. [4] M. F. Vassiliou and N. Makris (2011). Estimating time scales and length scales in
   pulselike earthquake acceleration records with wavelet analysis. Bulletin of the
   Seismological Society of America 101(2), 596-618.
.. [5] G. P. Mavroeidis and A. S. Papageorgiou (2003). A mathematical representation of
   near-fault ground motions. Bulletin of the Seismological Society of America 93(3),
   1099-1131.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from rbm_cli.base.errors import RbmError

#: Default time shift of the Ricker wavelet, in periods 1/f_p: its value at t = 0 is then
#: (1 - 2 u^2) exp(-u^2) with u = 1.5 pi, i.e. -1e-8 of the peak.
RICKER_SHIFT_PERIODS = 1.5


def _check(name: str, value: float, low: float | None = None, strict: bool = True) -> float:
    value = float(value)
    if not math.isfinite(value):
        raise RbmError(f"pulse parameter {name} must be finite, got {value!r}")
    if low is not None and (value <= low if strict else value < low):
        raise RbmError(f"pulse parameter {name} must be > {low:g}, got {value!r}")
    return value


def _on_support(t, duration: float, values_of):
    """values_of(t) on 0 <= t <= duration, 0 elsewhere; a float for a scalar t."""
    tt = np.asarray(t, dtype=float)
    inside = (tt >= 0.0) & (tt <= duration)
    out = np.where(inside, values_of(np.where(inside, tt, 0.0)), 0.0)
    return float(out) if out.ndim == 0 else out


# --------------------------------------------------------------------------- sine pulses


def one_sine_duration(frequency_hz: float) -> float:
    """Duration of the one-sine and cycloidal pulses, T_p = 1 / f_p [s]."""
    return 1.0 / _check("frequency_hz", frequency_hz, 0.0)


def one_sine_pulse(t, amplitude: float, frequency_hz: float):
    """One-sine (full-cycle sine) acceleration pulse, Zhang and Makris's cycloidal type A.

    Parameters
    ----------
    t : float or array_like
        Time [s]
    amplitude : float
        Peak acceleration A [m/s^2]
    frequency_hz : float
        Pulse frequency f_p [Hz], > 0; the pulse lasts T_p = 1 / f_p

    Returns
    -------
    float or numpy.ndarray
        Ground acceleration [m/s^2]

    Notes
    -----
    .. math:: a_g(t) = A \\sin(\\omega_p t), \\quad 0 \\le t \\le T_p, \\quad
              \\omega_p = 2 \\pi f_p

    The ground velocity (A / w_p)(1 - cos w_p t) >= 0 returns to 0 at T_p and the ground
    ends displaced by A T_p / w_p: a forward (fling) pulse. Zhang and Makris's type-A
    cycloidal pulse, written with their velocity amplitude v_p, is this pulse with
    A = w_p v_p / 2.

    References
    ----------
    Zhang and Makris (2001); Makris and Roussos (2000); see the module references.

    Examples
    --------
    >>> one_sine_pulse(0.25, amplitude=2.0, frequency_hz=1.0)
    2.0
    """
    amp = _check("amplitude", amplitude)
    w = 2.0 * math.pi * _check("frequency_hz", frequency_hz, 0.0)
    return _on_support(t, 2.0 * math.pi / w, lambda s: amp * np.sin(w * s))


def cycloidal_pulse(t, amplitude: float, frequency_hz: float, kind: str = "B"):
    """Cycloidal pulse of Zhang and Makris (2001), type A or B, by its peak acceleration.

    Parameters
    ----------
    t : float or array_like
        Time [s]
    amplitude : float
        Peak acceleration A [m/s^2]
    frequency_hz : float
        Pulse frequency f_p [Hz], > 0; the pulse lasts T_p = 1 / f_p
    kind : str
        ``"A"`` (forward pulse: the one-sine acceleration pulse) or ``"B"`` (default,
        forward-and-back pulse: a one-cosine acceleration pulse)

    Returns
    -------
    float or numpy.ndarray
        Ground acceleration [m/s^2]

    Notes
    -----
    Zhang and Makris give the ground velocity with amplitude v_p; the accelerations are

    .. math:: \\text{A:}\\; a_g = A \\sin(\\omega_p t), \\qquad
              \\text{B:}\\; a_g = A \\cos(\\omega_p t), \\qquad 0 \\le t \\le T_p

    with A = w_p v_p / 2 (type A) and A = w_p v_p (type B). Type B's velocity
    (A / w_p) sin(w_p t) and displacement (A / w_p^2)(1 - cos w_p t) both return to 0 at
    T_p; its acceleration jumps from 0 to A at t = 0 and from A to 0 at T_p.

    References
    ----------
    Zhang and Makris (2001); see the module references.

    Examples
    --------
    >>> cycloidal_pulse(0.5, amplitude=2.0, frequency_hz=1.0)
    -2.0
    """
    if kind == "A":
        return one_sine_pulse(t, amplitude, frequency_hz)
    if kind != "B":
        raise RbmError(f"pulse parameter kind must be 'A' or 'B', got {kind!r}")
    amp = _check("amplitude", amplitude)
    w = 2.0 * math.pi * _check("frequency_hz", frequency_hz, 0.0)
    return _on_support(t, 2.0 * math.pi / w, lambda s: amp * np.cos(w * s))


# --------------------------------------------------------------------------- Ricker


def _ricker_shift(frequency_hz: float, shift_s: float | None) -> float:
    f = _check("frequency_hz", frequency_hz, 0.0)
    if shift_s is None:
        return RICKER_SHIFT_PERIODS / f
    return _check("shift_s", shift_s, 0.0)


def ricker_duration(frequency_hz: float, shift_s: float | None = None) -> float:
    """Duration 2 t0 of the Ricker wavelet [s] (default t0 = 1.5 / f_p)."""
    return 2.0 * _ricker_shift(frequency_hz, shift_s)


def ricker_wavelet(t, amplitude: float, frequency_hz: float, shift_s: float | None = None):
    """Symmetric Ricker wavelet ("Mexican hat") of peak acceleration A at t0.

    Parameters
    ----------
    t : float or array_like
        Time [s]
    amplitude : float
        Peak acceleration A [m/s^2], reached at t = t0
    frequency_hz : float
        Peak frequency f_p [Hz] of the wavelet's Fourier amplitude spectrum, > 0
    shift_s : float, optional
        Time t0 of the peak [s], > 0; default 1.5 / f_p. The wavelet is cut to
        0 <= t <= 2 t0 (with the default, the cut ends are 1e-8 A).

    Returns
    -------
    float or numpy.ndarray
        Ground acceleration [m/s^2]

    Notes
    -----
    .. math:: a_g(t) = A (1 - 2 u^2) e^{-u^2}, \\quad u = \\pi f_p (t - t_0),
              \\quad 0 \\le t \\le 2 t_0

    It is the second derivative of a Gaussian: its Fourier amplitude is proportional to
    (f / f_p)^2 exp(-(f / f_p)^2), largest at f = f_p; its zero crossings are at
    t0 +- 1 / (sqrt(2) pi f_p); the ground velocity A (t - t0) e^{-u^2} and displacement
    return to 0 at the end (up to the cut). Vassiliou and Makris (2011) use this symmetric
    wavelet with T_p = 1 / f_p.

    References
    ----------
    Ricker (1943); Vassiliou and Makris (2011); see the module references.

    Examples
    --------
    >>> ricker_wavelet(1.5, amplitude=3.0, frequency_hz=1.0)
    3.0
    """
    amp = _check("amplitude", amplitude)
    f = _check("frequency_hz", frequency_hz, 0.0)
    t0 = _ricker_shift(f, shift_s)

    def values(s):
        u2 = (math.pi * f * (s - t0)) ** 2
        return amp * (1.0 - 2.0 * u2) * np.exp(-u2)

    return _on_support(t, 2.0 * t0, values)


# --------------------------------------------------------------------------- MP pulse


def _mp_check(frequency_hz: float, gamma: float, nu: float) -> tuple[float, float, float]:
    f = _check("frequency_hz", frequency_hz, 0.0)
    g = _check("gamma", gamma, 1.0)
    return f, g, _check("nu", nu)


def mavroeidis_papageorgiou_duration(frequency_hz: float, gamma: float) -> float:
    """Duration gamma / f_p of the Mavroeidis-Papageorgiou pulse [s]."""
    f, g, _ = _mp_check(frequency_hz, gamma, 0.0)
    return g / f


def mp_shape(s, gamma: float, nu: float):
    """MP acceleration over f_p for a unit velocity amplitude, s = f_p (t - t0) [cycles]."""
    x = 2.0 * np.pi * s
    return -(np.pi / gamma) * (
        np.sin(x / gamma) * np.cos(x + nu) + gamma * np.sin(x + nu) * (1.0 + np.cos(x / gamma))
    )


@lru_cache(maxsize=256)
def _mp_peak(gamma: float, nu: float) -> float:
    """max |mp_shape| over the pulse: dense sampling, then Brent on the best bracket."""
    half = gamma / 2.0
    s = np.linspace(-half, half, int(256 * gamma) + 1)
    values = np.abs(mp_shape(s, gamma, nu))
    k = int(np.argmax(values))
    lo, hi = s[max(k - 1, 0)], s[min(k + 1, s.size - 1)]
    # lazy: scipy.optimize loads only where needed (docs/architecture.md, Start-up)
    from scipy.optimize import minimize_scalar  # here: no scipy at import (a shorter start-up)

    best = minimize_scalar(
        lambda x: -abs(float(mp_shape(x, gamma, nu))),
        bounds=(lo, hi),
        method="bounded",
        options={"xatol": 1e-12 * max(1.0, gamma)},
    )
    return max(float(values[k]), -float(best.fun))


def mp_peak(gamma: float, nu: float) -> float:
    """max |a| of the Mavroeidis-Papageorgiou shape for a unit velocity amplitude, over
    f_p [-]: the pulse of peak A has V = A / (f_p mp_peak) (checked gamma > 1)."""
    _, g, nu = _mp_check(1.0, gamma, nu)
    return _mp_peak(g, nu)


def mavroeidis_papageorgiou(t, amplitude: float, frequency_hz: float, gamma: float, nu: float):
    """Mavroeidis-Papageorgiou (2003) near-fault pulse, scaled to peak acceleration A.

    Parameters
    ----------
    t : float or array_like
        Time [s]
    amplitude : float
        Peak acceleration A [m/s^2]: the pulse is scaled so that max |a_g| = |A|
    frequency_hz : float
        Prevailing frequency f_p [Hz], > 0
    gamma : float
        Oscillatory character (number of half cycles of the envelope), > 1 [-]
    nu : float
        Phase of the harmonic [rad]

    Returns
    -------
    float or numpy.ndarray
        Ground acceleration [m/s^2]

    Notes
    -----
    Mavroeidis and Papageorgiou give the ground velocity, with t0 the centre of the pulse,

    .. math:: v(t) = \\frac{V}{2} \\Big[1 + \\cos\\Big(\\frac{2 \\pi f_p}{\\gamma}
              (t - t_0)\\Big)\\Big] \\cos\\big(2 \\pi f_p (t - t_0) + \\nu\\big),
              \\quad |t - t_0| \\le \\frac{\\gamma}{2 f_p}

    and 0 outside. The acceleration is its derivative,

    .. math:: a(t) = -\\frac{V \\pi f_p}{\\gamma} \\Big[\\sin\\Big(\\frac{2 \\pi f_p}{\\gamma}
              (t - t_0)\\Big) \\cos\\big(2 \\pi f_p (t - t_0) + \\nu\\big)
              + \\gamma \\sin\\big(2 \\pi f_p (t - t_0) + \\nu\\big)
              \\Big[1 + \\cos\\Big(\\frac{2 \\pi f_p}{\\gamma} (t - t_0)\\Big)\\Big]\\Big]

    Here t0 = gamma / (2 f_p), so the pulse starts at t = 0 (with a = v = 0) and ends at
    gamma / f_p (with v = 0; the displacement need not return to 0). Instead of the
    velocity amplitude V the pulse is given by its peak acceleration: V is chosen so that
    max |a| = |A| (the maximum found by dense sampling and Brent's method, to ~1e-12).
    The sign pattern is MP's: A > 0 keeps it, A < 0 flips it. As gamma grows the pulse
    tends to a harmonic under a slow cosine-bell envelope,
    a / (2 pi f_p V) -> -sin(2 pi f_p (t - t0) + nu) (1 + cos(2 pi f_p (t - t0) / gamma)) / 2.

    References
    ----------
    Mavroeidis and Papageorgiou (2003), eqs. for the velocity pulse and its derivative;
    see the module references.

    Examples
    --------
    >>> t = np.linspace(0.0, 2.0, 2001)
    >>> a = mavroeidis_papageorgiou(t, amplitude=3.0, frequency_hz=1.0, gamma=2.0, nu=0.0)
    >>> round(float(np.max(np.abs(a))), 4)
    3.0
    """
    amp = _check("amplitude", amplitude)
    f, g, nu = _mp_check(frequency_hz, gamma, nu)
    t0 = g / (2.0 * f)
    scale = amp / _mp_peak(g, nu)
    return _on_support(t, 2.0 * t0, lambda s: scale * mp_shape(f * (s - t0), g, nu))


#: Pulse name -> (acceleration function, duration function), for a later config axis.
PULSES = {
    "one-sine": (one_sine_pulse, one_sine_duration),
    "cycloidal": (cycloidal_pulse, one_sine_duration),
    "ricker": (ricker_wavelet, ricker_duration),
    "mavroeidis-papageorgiou": (mavroeidis_papageorgiou, mavroeidis_papageorgiou_duration),
}
