"""exp, log, sin, cos and standard normals that give the same bits on every machine.

numpy's float64 ``exp``, ``log``, ``sin`` and ``cos`` dispatch on the CPU (SIMD kernels on
AVX-512 machines, the C library elsewhere) and may differ in the last bit; numpy's
``standard_normal`` calls the C library's ``exp`` and ``log`` in its ziggurat's tail. The
synthetic record suite (:mod:`rbm_cli.inputs.synthetic`) must be reproducible bit for bit from its
seed, so it uses these instead: each is built from IEEE 754 additions, multiplications and
divisions (correctly rounded everywhere, one numpy ufunc at a time, so no fused
multiply-add), exact scalings by powers of two (``ldexp``, ``frexp``, ``rint``) and the
uniform doubles of numpy's ``Generator.random`` (integer arithmetic). They are accurate to a
few units in the last place, not correctly rounded; that is enough, the point is that they
are the same everywhere.

References
----------
.. [1] W. J. Cody and W. Waite (1980). Software Manual for the Elementary Functions.
   Prentice-Hall (argument reduction by ln 2 split in two parts).
.. [2] G. Marsaglia and T. A. Bray (1964). A convenient method for generating normal
   variables. SIAM Review 6(3), 260-264 (the polar method).
"""

from __future__ import annotations

import math

import numpy as np

# ln 2 in two parts (fdlibm's): n * LN2_HI is exact for |n| < 2^11
_LN2_HI = 6.93147180369123816490e-01
_LN2_LO = 1.90821492927058770002e-10
_INV_LN2 = 1.44269504088896338700e00  # a literal, not libm: it decides n
_SQRT_HALF = math.sqrt(0.5)

# 1/k! for the Taylor polynomials (exact integer factorials, one correctly rounded division)
_INV_FACT = [1.0 / math.factorial(k) for k in range(30)]


def _horner(coeffs: list[float], x: np.ndarray) -> np.ndarray:
    """sum coeffs[k] x^k by Horner's rule, one ufunc at a time."""
    p = np.full_like(x, coeffs[-1])
    for c in reversed(coeffs[:-1]):
        p = p * x
        p = p + c
    return p


def exp(x) -> np.ndarray:
    """e^x, elementwise [-]: x = n ln 2 + r, |r| <= ln 2 / 2, Taylor degree 16 in r."""
    x = np.asarray(x, dtype=float)
    n = np.rint(np.clip(x, -1100.0, 1100.0) * _INV_LN2)
    r = (x - n * _LN2_HI) - n * _LN2_LO
    p = _horner(_INV_FACT[:17], r)
    out = np.ldexp(p, n.astype(np.int64))
    return np.where(x > 709.78, np.inf, np.where(x < -745.2, 0.0, out))


def log(x) -> np.ndarray:
    """ln x for x > 0, elementwise: x = m 2^e, m in [1/sqrt 2, sqrt 2), atanh series in m."""
    x = np.asarray(x, dtype=float)
    if np.any(~(x > 0.0)) or np.any(~np.isfinite(x)):
        raise ValueError("portable_math.log needs finite x > 0")
    m, e = np.frexp(x)
    low = m < _SQRT_HALF
    m = np.where(low, m * 2.0, m)
    e = (e - low).astype(float)
    z = (m - 1.0) / (m + 1.0)  # |z| <= 0.1716
    z2 = z * z
    series = _horner([1.0 / (2 * k + 1) for k in range(13)], z2)  # to z^25: < 1e-19
    ln_m = 2.0 * z * series
    return e * _LN2_HI + (e * _LN2_LO + ln_m)


def _check_small(x: np.ndarray) -> None:
    if np.any(np.abs(x) > 1.6):
        raise ValueError("portable_math.sin/cos take |x| <= 1.6 only")


def sin_small(x) -> np.ndarray:
    """sin x for |x| <= 1.6 (no argument reduction): Taylor to degree 23."""
    x = np.asarray(x, dtype=float)
    _check_small(x)
    coeffs = [(-1) ** k * _INV_FACT[2 * k + 1] for k in range(12)]
    return x * _horner(coeffs, x * x)


def cos_small(x) -> np.ndarray:
    """cos x for |x| <= 1.6 (no argument reduction): Taylor to degree 24."""
    x = np.asarray(x, dtype=float)
    _check_small(x)
    coeffs = [(-1) ** k * _INV_FACT[2 * k] for k in range(13)]
    return _horner(coeffs, x * x)


def standard_normal(rng: np.random.Generator, size: int) -> np.ndarray:
    """``size`` independent N(0, 1) draws by Marsaglia's polar method.

    Pairs (u, v) uniform on (-1, 1)^2 are drawn in batches from ``rng.random`` and kept
    when 0 < s = u^2 + v^2 < 1; each kept pair gives u c and v c with
    c = sqrt(-2 ln s / s). The stream consumed depends only on ``size`` and the
    generator's state, and every operation is exactly specified, so the draws are the same
    bits on every machine.
    """
    out = np.empty(2 * ((size + 1) // 2))
    filled = 0
    while filled < out.size:
        need = (out.size - filled) // 2
        pairs = 2.0 * rng.random((int(need / 0.78) + 8, 2)) - 1.0
        s = pairs[:, 0] * pairs[:, 0] + pairs[:, 1] * pairs[:, 1]
        keep = (s > 0.0) & (s < 1.0)
        u, v, s = pairs[keep, 0], pairs[keep, 1], s[keep]
        c = np.sqrt(-2.0 * log(s) / s)
        z = np.empty(2 * u.size)
        z[0::2] = u * c
        z[1::2] = v * c
        take = min(z.size, out.size - filled)
        out[filled : filled + take] = z[:take]
        filled += take
    return out[:size]
