"""Arithmetic that gives the same bits on every x86-64 machine (numba).

Two things in the path from a config to a domain used to round differently from
one machine to another (measured in docs/reproducibility.md):

- BLAS and LAPACK. OpenBLAS picks its kernels for the CPU at run time
  (Haswell, SkylakeX, Sandybridge, ...): a kernel with FMA or with wider
  vectors sums the same products in another order. numpy's ``@`` and
  ``np.linalg.inv`` in the model's assembly, and numba's ``@`` in the compiled
  kernel, went through it.
- The C library's sin, asin and pow. glibc picks an FMA or a plain variant of
  its libm per CPU; the two differ in the last bit on some arguments.

This module replaces both by plain loops and by fdlibm's algorithms (sin, asin,
log, exp, and pow from them; as fdlibm and musl write them, freely licensed),
compiled by numba. Numba compiles without fastmath:
LLVM then neither contracts ``a * b + c`` into an FMA nor reorders a sum, so a
loop gives the same bits whatever the CPU and numba's target
(``NUMBA_CPU_NAME=generic`` included; tests/test_reproducibility.py checks it
in subprocesses). The matrices are tiny (n <= 200 drums), so the loops cost
nothing measurable.
"""

from __future__ import annotations

import math

import numpy as np

from rbm_cli.base.jit import jit, plain


# ---------------------------------------------------------------- linear algebra
@jit
def dot(x, y):
    """sum_i x_i y_i, summed in index order."""
    s = 0.0
    for i in range(x.size):
        s += x[i] * y[i]
    return s


@jit
def matvec(a, x, out):
    """out = a @ x (summed in index order), in place; returns out."""
    for i in range(a.shape[0]):
        s = 0.0
        for j in range(a.shape[1]):
            s += a[i, j] * x[j]
        out[i] = s
    return out


@jit
def matmul(a, b):
    """a @ b (each entry summed in index order), a new array."""
    n, k = a.shape
    m = b.shape[1]
    out = np.empty((n, m))
    for i in range(n):
        for j in range(m):
            s = 0.0
            for q in range(k):
                s += a[i, q] * b[q, j]
            out[i, j] = s
    return out


@jit
def _inverse(a):
    """Gauss-Jordan elimination with partial pivoting; (inverse, ok)."""
    n = a.shape[0]
    w = a.copy()
    inv = np.eye(n)
    for c in range(n):
        p = c
        big = abs(w[c, c])
        for r in range(c + 1, n):
            if abs(w[r, c]) > big:
                big, p = abs(w[r, c]), r
        if big == 0.0:  # singular; a non-finite matrix gives NaN/inf, as LAPACK's does
            return inv, False
        if p != c:
            for j in range(n):
                w[c, j], w[p, j] = w[p, j], w[c, j]
                inv[c, j], inv[p, j] = inv[p, j], inv[c, j]
        d = w[c, c]
        for j in range(n):
            w[c, j] /= d
            inv[c, j] /= d
        for r in range(n):
            if r != c:
                f = w[r, c]
                if f != 0.0:
                    for j in range(n):
                        w[r, j] -= f * w[c, j]
                        inv[r, j] -= f * inv[c, j]
    return inv, True


#: Multiply-adds up to which inverse and product run their loop uncompiled
#: (``rbm_cli.base.jit.plain``): the same IEEE operations in the same order (no FMA, no
#: reordering in either), so the same bits, without loading numba's compiled code for the
#: small matrices of a column's assembly. ~5 ms of Python.
PYTHON_WORK = 20_000


def inverse(a: np.ndarray) -> np.ndarray:
    """Inverse of a square matrix, the same bits on every machine.

    Raises numpy.linalg.LinAlgError if the matrix is singular (a zero pivot); a
    matrix with infinite or NaN entries gives a non-finite inverse, as LAPACK's does.
    """
    a2 = np.ascontiguousarray(a, dtype=float)
    inv, ok = (plain(_inverse) if a2.shape[0] ** 3 <= PYTHON_WORK else _inverse)(a2)
    if not ok:
        raise np.linalg.LinAlgError("singular matrix")
    return inv


def product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a @ b for 1-D or 2-D float arrays, the same bits on every machine."""
    a2 = np.ascontiguousarray(a, dtype=float)
    b2 = np.ascontiguousarray(b, dtype=float)
    va, vb = a2.ndim == 1, b2.ndim == 1
    x, y = a2.reshape(1, -1) if va else a2, b2.reshape(-1, 1) if vb else b2
    work = x.shape[0] * x.shape[1] * y.shape[1]
    out = (plain(matmul) if work <= PYTHON_WORK else matmul)(x, y)
    if va and vb:
        return out[0, 0]
    if va:
        return out[0]
    if vb:
        return out[:, 0]
    return out


# ---------------------------------------------------------------- sin (fdlibm)
_S1 = -1.66666666666666324348e-01
_S2 = 8.33333333332248946124e-03
_S3 = -1.98412698298579493134e-04
_S4 = 2.75573137070700676789e-06
_S5 = -2.50507602534068634195e-08
_S6 = 1.58969099521155010221e-10
_C1 = 4.16666666666666019037e-02
_C2 = -1.38888888888741095749e-03
_C3 = 2.48015872894767294178e-05
_C4 = -2.75573143513906633035e-07
_C5 = 2.08757232129817482790e-09
_C6 = -1.13596475577881948265e-11
_TOINT = 1.5 / 2.220446049250313e-16
_PIO4 = 0.7853981633974483
_INVPIO2 = 6.36619772367581382433e-01
_PIO2_1 = 1.57079632673412561417e00
_PIO2_1T = 6.07710050650619224932e-11
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_2T = 2.02226624879595063154e-21
_PIO2_3 = 2.02226624871116645580e-21
_PIO2_3T = 8.47842766036889956997e-32
#: |x| up to which sin needs no reduction: high word 0x3fe921fb (fdlibm's test)
_NO_REDUCTION = 0.7853984832763671
_TINY = 1.4901161193847656e-08  # 2^-26


@jit(inline=True)
def sin(x):
    """sin(x) by fdlibm's algorithm: within 1 ulp, the same bits everywhere.

    Exact reduction up to |x| ~ 1.6e6 (a 10 Hz motion for 25,000 s); beyond, the
    absolute error grows as x's own ulp, the error x already carries. NaN from
    |x| >= 1e15 (and for an infinite or NaN argument).

    One body, no calls, and inlined by numba into its caller (inline="always"):
    a call that LLVM does not inline makes numba take and release a reference
    to every array the caller holds (atomic NRT operations, ~50 ns a call), which
    tripled the cost of the kernel's right-hand side."""
    ax = abs(x)
    if ax <= _NO_REDUCTION:  # fdlibm's __sin(x, 0, 0)
        if ax < _TINY:
            return x
        z = x * x
        w = z * z
        r = _S2 + z * (_S3 + z * _S4) + z * w * (_S5 + z * _S6)
        return x + z * x * (_S1 + z * r)
    if not ax < 1e15:
        return math.nan
    # fdlibm's __rem_pio2, medium case: x = n pi/2 + y0 + y1, three Cody-Waite
    # steps (good to 151 bits up to |x| = 2^20 pi/2 ~ 1.6e6; beyond, n pi/2 is
    # rounded, so the absolute error grows as x's own ulp does). fdlibm skips the
    # 2nd and 3rd steps when the 1st cancelled few bits; they are always taken
    # here (the test needs frexp, which costs more in the kernel than the flops).
    fn = x * _INVPIO2 + _TOINT - _TOINT
    r = x - fn * _PIO2_1
    w = fn * _PIO2_1T
    if r - w < -_PIO4:
        fn -= 1.0
        r = x - fn * _PIO2_1
        w = fn * _PIO2_1T
    elif r - w > _PIO4:
        fn += 1.0
        r = x - fn * _PIO2_1
        w = fn * _PIO2_1T
    t = r
    w = fn * _PIO2_2
    r = t - w
    w = fn * _PIO2_2T - ((t - r) - w)
    t = r
    w = fn * _PIO2_3
    r = t - w
    w = fn * _PIO2_3T - ((t - r) - w)
    y0 = r - w
    y1 = (r - y0) - w
    q = int(fn) & 3
    z = y0 * y0
    w = z * z
    if q & 1:  # fdlibm's __cos(y0, y1)
        r = z * (_C1 + z * (_C2 + z * _C3)) + w * w * (_C4 + z * (_C5 + z * _C6))
        hz = 0.5 * z
        w = 1.0 - hz
        v = w + (((1.0 - w) - hz) + (z * r - y0 * y1))
    else:  # fdlibm's __sin(y0, y1, 1)
        r = _S2 + z * (_S3 + z * _S4) + z * w * (_S5 + z * _S6)
        v = z * y0
        v = y0 - ((z * (0.5 * y1 - v * r) - y1) - v * _S1)
    return -v if q & 2 else v


# ---------------------------------------------------------------- asin (fdlibm)
_PIO2_HI = 1.57079632679489655800e00
_PIO2_LO = 6.12323399573676603587e-17
_PS0 = 1.66666666666666657415e-01
_PS1 = -3.25565818622400915405e-01
_PS2 = 2.01212532134862925881e-01
_PS3 = -4.00555345006794114027e-02
_PS4 = 7.91534994289814532176e-04
_PS5 = 3.47933107596021167570e-05
_QS1 = -2.40339491173441421878e00
_QS2 = 2.02094576023350569471e00
_QS3 = -6.88283971605453293030e-01
_QS4 = 7.70381505559019352791e-02
_NEAR_ONE = 0.9749999046325684  # high word 0x3fef3333


@jit
def _r(z):
    p = z * (_PS0 + z * (_PS1 + z * (_PS2 + z * (_PS3 + z * (_PS4 + z * _PS5)))))
    q = 1.0 + z * (_QS1 + z * (_QS2 + z * (_QS3 + z * _QS4)))
    return p / q


@jit
def asin(x):
    """asin(x) by fdlibm's algorithm: within 1 ulp, the same bits everywhere."""
    ax = abs(x)
    if ax >= 1.0:
        if ax == 1.0:
            return x * _PIO2_HI
        return math.nan
    if ax < 0.5:
        if ax < _TINY:
            return x
        return x + x * _r(x * x)
    z = (1.0 - ax) * 0.5
    s = math.sqrt(z)  # IEEE square root: correctly rounded on every machine
    r = _r(z)
    if ax >= _NEAR_ONE:
        v = _PIO2_HI - (2.0 * (s + s * r) - _PIO2_LO)
    else:
        m, e = math.frexp(s)  # f: s with the low 32 bits of its pattern cleared
        f = math.ldexp(math.floor(m * 2097152.0) / 2097152.0, e)
        c = (z - f * f) / (s + f)
        v = 0.5 * _PIO2_HI - (2.0 * s * r - (_PIO2_LO - 2.0 * c) - (0.5 * _PIO2_HI - 2.0 * f))
    return -v if x < 0.0 else v


# ---------------------------------------------------------------- log, exp, pow (fdlibm)
_LN2_HI = 6.93147180369123816490e-01
_LN2_LO = 1.90821492927058770002e-10
_INVLN2 = 1.44269504088896338700e00
_LG1 = 6.666666666666735130e-01
_LG2 = 3.999999999940941908e-01
_LG3 = 2.857142874366239149e-01
_LG4 = 2.222219843214978396e-01
_LG5 = 1.818357216161805012e-01
_LG6 = 1.531383769920937332e-01
_LG7 = 1.479819860511658591e-01
_P1 = 1.66666666666666019037e-01
_P2 = -2.77777777770155933842e-03
_P3 = 6.61375632143793436117e-05
_P4 = -1.65339022054652515390e-06
_P5 = 4.13813679705723846039e-08
_SQRT_HALF = 0.7071067811865476


@jit
def log(x):
    """Natural logarithm by fdlibm's algorithm (x reduced to [sqrt(2)/2, sqrt(2))
    by frexp, which is exact): within 1 ulp, the same bits everywhere."""
    if not x > 0.0:
        if x == 0.0:
            return -math.inf
        return math.nan
    if x == math.inf:
        return x
    m, k = math.frexp(x)  # x = m 2^k, m in [0.5, 1)
    if m < _SQRT_HALF:
        m *= 2.0
        k -= 1
    f = m - 1.0
    if f == 0.0 and k == 0:
        return 0.0
    hfsq = 0.5 * f * f
    s = f / (2.0 + f)
    z = s * s
    w = z * z
    t1 = w * (_LG2 + w * (_LG4 + w * _LG6))
    t2 = z * (_LG1 + w * (_LG3 + w * (_LG5 + w * _LG7)))
    r = t2 + t1
    dk = float(k)
    return s * (hfsq + r) + dk * _LN2_LO - hfsq + f + dk * _LN2_HI


@jit
def exp(x):
    """e^x by fdlibm's algorithm: within 1 ulp, the same bits everywhere."""
    if x != x:
        return x
    if x > 709.782712893383973096:
        return math.inf
    if x < -745.13321910194110842:
        return 0.0
    ax = abs(x)
    if ax > 0.5 * _LN2_HI:
        if ax >= 1.5 * _LN2_HI:
            k = int(_INVLN2 * x + (0.5 if x >= 0.0 else -0.5))
        else:
            k = 1 if x >= 0.0 else -1
        hi = x - k * _LN2_HI
        lo = k * _LN2_LO
        x = hi - lo
    elif ax > 3.725290298461914e-09:  # 2^-28
        k, hi, lo = 0, x, 0.0
    else:
        return 1.0 + x
    xx = x * x
    c = x - xx * (_P1 + xx * (_P2 + xx * (_P3 + xx * (_P4 + xx * _P5))))
    y = 1.0 + (x * c / (2.0 - c) - lo + hi)
    if k == 0:
        return y
    if k > 1020:  # scale in two exact steps (no overflow in between)
        return math.ldexp(math.ldexp(y, k - 1000), 1000)
    return math.ldexp(y, k)


@jit
def pow_pos(x, y):
    """x^y for x >= 0 as exp(y log x), the same bits everywhere: the error of log
    is scaled by |y log x|, so within ~16 ulp where that is below ~40 (the step-size
    control's err^(-1/8) over err in 1e-15..1e15). 0^y: 0 for y > 0, inf for y < 0."""
    if x == 0.0:
        return 0.0 if y > 0.0 else (1.0 if y == 0.0 else math.inf)
    if y == -0.125:  # DOP853's step control: three IEEE square roots, no frexp
        return 1.0 / math.sqrt(math.sqrt(math.sqrt(x)))
    if y == 0.125:
        return math.sqrt(math.sqrt(math.sqrt(x)))
    return exp(y * log(x))
