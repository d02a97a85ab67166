"""The uncompiled versions of detmath's compiled loops (rbm_cli.base.jit.plain), which
inverse and product run for small matrices and solver.implementation: python runs for
everything, give the compiled bits: the same IEEE operations in the same order, no FMA
contraction and no reordering in either."""

from __future__ import annotations

import numpy as np
import pytest

from rbm_cli.base import detmath
from rbm_cli.base.jit import plain


def bits(x) -> bytes:
    return np.asarray(x, dtype=float).tobytes()


@pytest.mark.parametrize("n", [1, 2, 3, 5, 8, 13])
def test_matmul_and_inverse_bodies_give_the_compiled_bits(n):
    rng = np.random.default_rng(n)
    for scale in (1.0, 1e-9, 1e9):
        a = rng.standard_normal((n, n)) * scale + np.eye(n) * rng.uniform(0.0, 2.0)
        b = rng.standard_normal((n, 3)) * rng.uniform(0.1, 10.0)
        assert bits(plain(detmath.matmul)(a, b)) == bits(detmath.matmul(a, b))
        assert bits(plain(detmath.matmul)(a, a)) == bits(detmath.matmul(a, a))
        inv_py, ok_py = plain(detmath._inverse)(a)
        inv_c, ok_c = detmath._inverse(a)
        assert ok_py == ok_c and bits(inv_py) == bits(inv_c)


def test_product_and_inverse_choose_by_size_with_the_same_bits(monkeypatch):
    """The same public results whichever body runs (all Python or all compiled)."""
    rng = np.random.default_rng(7)
    a, v = rng.standard_normal((6, 6)), rng.standard_normal(6)
    py = [detmath.product(a, a), detmath.product(a, v), detmath.product(v, v), detmath.inverse(a)]
    monkeypatch.setattr(detmath, "PYTHON_WORK", -1)  # compiled for every size
    compiled = [detmath.product(a, a), detmath.product(a, v), detmath.product(v, v),
                detmath.inverse(a)]  # fmt: skip
    assert [bits(x) for x in py] == [bits(x) for x in compiled]


def test_a_singular_matrix_is_refused_by_both():
    for work in (detmath.PYTHON_WORK, -1):
        detmath_work = work
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(detmath, "PYTHON_WORK", detmath_work)
            with pytest.raises(np.linalg.LinAlgError):
                detmath.inverse(np.array([[1.0, 2.0], [2.0, 4.0]]))


@pytest.mark.parametrize("y", [-0.125, 0.125, 0.2, -0.2, 1.0 / 3.0, 0.25, -0.25, 0.0, 1.7])
def test_pow_pos_body_gives_the_compiled_bits(y):
    rng = np.random.default_rng(11)
    xs = np.concatenate([10.0 ** rng.uniform(-15, 15, 400), [0.0, 1.0, 2.0, 0.5, 1e-300]])
    got = [plain(detmath.pow_pos)(float(x), y) for x in xs]
    want = [detmath.pow_pos(float(x), y) for x in xs]
    assert bits(got) == bits(want)
