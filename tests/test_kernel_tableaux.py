"""The kernel's Runge-Kutta tableaux (written out in base/rk_tableaux.py so the
compiled path does not import scipy.integrate) are scipy's, bit for bit: the
kernel's step sequence is scipy's only if every coefficient is."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate._ivp import dop853_coefficients as dop
from scipy.integrate._ivp.rk import RK23, RK45

from rbm_cli.base import rk_tableaux as tb
from rbm_cli.numerics import rk


def padded(rows, shape) -> np.ndarray:
    """rows (trailing zeros dropped) back to an array of the given shape."""
    out = np.zeros(shape)
    if out.ndim == 1:
        out[: len(rows)] = rows
    else:
        for i, row in enumerate(rows):
            out[i, : len(row)] = row
    return out


def same_bits(a, b) -> bool:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and a.tobytes() == b.tobytes()


def test_dop853_is_scipys():
    assert tb.DOP853_N_STAGES == dop.N_STAGES
    assert tb.DOP853_N_STAGES_EXTENDED == dop.N_STAGES_EXTENDED
    for name in ("A", "C", "B", "E3", "E5", "D"):
        ref = getattr(dop, name)
        assert same_bits(padded(getattr(tb, f"DOP853_{name}"), ref.shape), ref), name


@pytest.mark.parametrize("cls", [RK23, RK45], ids=["RK23", "RK45"])
def test_rk_pairs_are_scipys(cls):
    name = cls.__name__
    assert getattr(tb, f"{name}_N_STAGES") == cls.n_stages
    assert getattr(tb, f"{name}_ERROR_ESTIMATOR_ORDER") == cls.error_estimator_order
    for part in ("A", "C", "B", "E", "P"):
        ref = getattr(cls, part)
        assert same_bits(padded(getattr(tb, f"{name}_{part}"), ref.shape), ref), part


def test_the_kernels_padded_tables_hold_scipys():
    """The kernel's tables (one padded shape for the three methods) hold scipy's arrays
    in their corners and zeros elsewhere."""
    m = {"RK23": 0, "RK45": 1, "DOP853": 2}
    assert rk.METHOD_CODES == m
    d = m["DOP853"]
    n = dop.N_STAGES_EXTENDED
    assert same_bits(rk.TAB_A[d], dop.A) and same_bits(rk.TAB_C[d], dop.C)
    assert same_bits(rk.TAB_B[d], padded(dop.B, n))
    assert same_bits(rk.TAB_E[d], padded(dop.E5, n))
    assert same_bits(rk.TAB_E3[d], padded(dop.E3, n))
    assert same_bits(rk.TAB_P[d][:, :4], dop.D.T) and not rk.TAB_P[d][:, 4:].any()
    assert (rk.TAB_NS[d], rk.TAB_EST[d]) == (dop.N_STAGES, 7)
    for cls in (RK23, RK45):
        k = m[cls.__name__]
        a = np.zeros((n, n))
        a[: cls.A.shape[0], : cls.A.shape[1]] = cls.A
        p = np.zeros((n, 8))
        p[: cls.P.shape[0], : cls.P.shape[1]] = cls.P
        assert same_bits(rk.TAB_A[k], a) and same_bits(rk.TAB_P[k], p)
        assert same_bits(rk.TAB_C[k], padded(cls.C, n))
        assert same_bits(rk.TAB_B[k], padded(cls.B, n))
        assert same_bits(rk.TAB_E[k], padded(cls.E, n))
        assert not rk.TAB_E3[k].any()
        assert rk.TAB_NS[k] == cls.n_stages
        assert rk.TAB_EST[k] == cls.error_estimator_order
