"""A structure's copies of the engine's functions (numerics.binding, numerics.rk.steps_for):
each structure's steps call its own right-hand side, and the copies call each other."""

from __future__ import annotations

import numpy as np
import pytest

from rbm_cli.base.jit import ENABLED, jit, plain
from rbm_cli.models.rbm.step import stepper
from rbm_cli.models.rbm3d import kernel
from rbm_cli.numerics import rk
from rbm_cli.numerics.binding import bind
from rbm_cli.structures.column3d import beam_rates
from rbm_cli.structures.rates import rhs


def _globals(function):
    return getattr(function, "py_func", function).__globals__


def test_each_structure_steps_on_its_own_right_hand_side():
    assert _globals(stepper.attempt_step)["rhs"] is rhs
    assert _globals(kernel.attempt_step)["rhs"] is beam_rates
    # the copies call each other's copies, not the templates
    assert _globals(stepper.attempt_step)["rk_attempt"] is not rk.rk_attempt
    assert (
        _globals(stepper.attempt_step)["rk_attempt"]
        is _globals(stepper.dense_prepare)["rk_attempt"]
    )


def test_a_copy_runs_the_template_on_the_given_function():
    """An RK45 step of y' = -y from the copies bound to that right-hand side: the step's end
    is e^-h within the pair's error (a fifth-order step, h = 0.1)."""

    def decay(t, y, n, As, cs, es, gr, out):
        for i in range(y.size):
            out[i] = -y[i]

    initial_step, attempt_step, _ = (plain(f) for f in rk.steps_for("decay_test", decay))
    mc = rk.METHOD_CODES["RK45"]
    y, f = np.ones(1), -np.ones(1)
    K, ynew, tmp = np.zeros((rk.NS_MAX, 1)), np.zeros(1), np.zeros(1)
    none = np.zeros((1, 1))
    code, t_new, h, _, _ = attempt_step(
        mc, 0.0, y, f, 0.1, 1.0, K, ynew, tmp, 1, none, none[0], none[0], (0,), np.ones(1) * 1e-12,
        1e-10, np.zeros(1), -1.0 / (rk.TAB_EST[mc] + 1),
    )  # fmt: skip
    assert code == rk.STEP_TAKEN
    assert ynew[0] == pytest.approx(np.exp(-t_new), rel=1e-9)


def test_templates_come_from_one_module():
    with pytest.raises(TypeError, match="one module"):
        bind({"a": (rk.initial_step, {}), "b": (test_templates_come_from_one_module, {})},
             {}, "mixed")  # fmt: skip


@pytest.mark.skipif(not ENABLED, reason="compiled only: RBM_JIT=0 runs Python")
def test_the_steps_of_a_run_borrow_their_arrays():
    """The steps a run takes every step are compiled without reference counts (base.jit's
    borrow), the first step's size with them (it allocates); a borrowed function that
    allocates is refused when it compiles, and one cannot be both borrowed and inlined."""
    for steps in (stepper, kernel):
        assert steps.attempt_step.targetoptions.get("_nrt") is False
        assert steps.dense_prepare.targetoptions.get("_nrt") is False
        assert steps.initial_step.targetoptions.get("_nrt", True) is not False

    @jit(borrow=True)
    def allocates(n):
        return np.empty(n).size

    with pytest.raises(Exception, match="nopython mode"):  # numba refuses it as it types it
        allocates(3)
    with pytest.raises(TypeError, match="borrowed"):
        jit(inline=True, borrow=True)


@pytest.mark.skipif(not ENABLED, reason="compiled only: RBM_JIT=0 runs Python")
def test_the_exact_integrators_intervals_borrow_their_arrays():
    """The exact integrator's work on every interval (the certified search, the modes' and
    families' bounds, a point of the closed form, the peaks' bound) is compiled without
    reference counts; a new piece, which allocates its rows, is not."""
    from rbm_cli.models.rbm.exact import bounds, modal, peaks, piece, search

    borrowed = (search.next_point, bounds.mode_bounds, bounds.family_bounds, modal.advance,
                piece.eval_point, piece.eval_family, peaks.may_exceed)  # fmt: skip
    for function in borrowed:
        assert function.targetoptions.get("_nrt") is False, function
    assert piece.make_piece.targetoptions.get("_nrt", True) is not False
