"""Closed forms of the linear rocking block against independent numerics.

The reference thresholds come from integrating the one-sided linear rocking
equation with scipy's solve_ivp and bisecting on the pulse amplitude; nothing
here re-evaluates the formulas under test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from rbm_cli.config.types import ColumnConfig, InterfaceConfig, StiffnessConfig
from rbm_cli.structures.closed_forms import (
    free_rocking_period,
    halfsine_threshold_curves,
    housner_halfsine_threshold,
    linear_halfsine_threshold,
    linear_rocking_parameters,
    rectangular_pulse_threshold,
)
from rbm_cli.structures.column import build_column

G = 9.81
ALPHA = 0.2  # slenderness of the test block [rad]
P = 1.7  # frequency parameter of the test block [rad/s]
RTOL_ODE = 1e-12
BISECT_RTOL = 1e-9


# --------------------------------------------------------------------------- numerics
def _overturns(forcing, t_start, t_pulse_end, alpha=ALPHA, p=P):
    """Does the block, at rest at theta = 0 at t_start, reach theta = alpha?

    Integrates theta'' = p^2 (theta - alpha) + p^2 forcing(t) (one side of the
    linear rocking equation; forcing in units of g, sign pushing theta up) until
    the pulse ends, then in free motion. A return to theta = 0 (an impact)
    ends the run as 'not overturned'.
    """

    def rhs_forced(t, y):
        return [y[1], p * p * (y[0] - alpha) + p * p * forcing(t)]

    def rhs_free(t, y):
        return [y[1], p * p * (y[0] - alpha)]

    def top(t, y):
        return y[0] - alpha

    def ground(t, y):  # offset: at uplift theta grows like (t - t_start)^3
        return y[0] + 1e-13 * alpha

    top.terminal = ground.terminal = True
    top.direction, ground.direction = 1, -1
    opts = dict(method="DOP853", rtol=RTOL_ODE, atol=1e-15 * alpha, events=[top, ground])

    sol = solve_ivp(rhs_forced, (t_start, t_pulse_end), [0.0, 0.0], **opts)
    assert sol.status >= 0, sol.message
    if sol.t_events[0].size:
        return True
    if sol.t_events[1].size:
        return False
    # free motion: near the threshold the block creeps along the separatrix,
    # ~ln(1/delta)/p to leave it; 60/p covers delta down to 1e-26
    sol = solve_ivp(rhs_free, (t_pulse_end, t_pulse_end + 60.0 / p), sol.y[:, -1], **opts)
    assert sol.status >= 0, sol.message
    if sol.t_events[0].size:
        return True
    if sol.t_events[1].size:
        return False
    raise AssertionError("neither overturned nor returned: widen the free-motion window")


def _bisect_amplitude(overturns_at, lo, rtol=BISECT_RTOL):
    """Smallest amplitude A > lo with overturns_at(A), by doubling then bisection."""
    hi = 2.0 * lo
    while not overturns_at(hi):
        lo, hi = hi, 2.0 * hi
    while hi - lo > rtol * hi:
        mid = 0.5 * (lo + hi)
        if overturns_at(mid):
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def numeric_halfsine_ratio(omega_over_p, alpha=ALPHA, p=P):
    """A / alpha that just overturns the block under A sin(w t), 0 <= t <= pi/w."""
    w = omega_over_p * p

    def overturns_at(a):
        t_up = math.asin(alpha / a) / w  # contact holds until A sin(w t) = alpha
        return _overturns(lambda t: a * math.sin(w * t), t_up, math.pi / w, alpha, p)

    return _bisect_amplitude(overturns_at, alpha) / alpha


def numeric_rectangular_ratio(p_t1, alpha=ALPHA, p=P):
    """A / alpha that just overturns the block under a constant A for t1 = p_t1 / p."""
    t1 = p_t1 / p
    return _bisect_amplitude(lambda a: _overturns(lambda t: a, 0.0, t1, alpha, p), alpha) / alpha


# --------------------------------------------------------------------------- half-sine
@pytest.mark.parametrize("omega_over_p", [0.3, 1.0, 3.0, 8.0])
def test_linear_halfsine_threshold_matches_bisection_of_the_ode(omega_over_p):
    numeric = numeric_halfsine_ratio(omega_over_p)
    exact = linear_halfsine_threshold(omega_over_p)
    assert exact == pytest.approx(numeric, rel=1e-7)


def test_housner_is_an_upper_estimate_close_at_low_frequency():
    k = np.array([0.01, 0.1, 0.3, 0.5, 1.0, 3.0, 8.0, 30.0])
    lin = linear_halfsine_threshold(k)
    hou = housner_halfsine_threshold(k)
    assert np.all(lin <= hou)
    ratio = hou / lin
    assert np.all(ratio[k < 0.5] < 1.002)  # close for w/p < 1
    assert 1.05 < ratio[k == 1.0][0] < 1.10
    assert 1.6 < ratio[k == 8.0][0] < 2.0  # 'up to ~2x too high'


def test_halfsine_limits():
    """w/p -> 0: the static level (A = alpha); w/p -> inf: Housner is 2x too high."""
    assert linear_halfsine_threshold(0.0) == 1.0
    assert linear_halfsine_threshold(1e-12) == pytest.approx(1.0, abs=1e-15)
    assert math.isinf(linear_halfsine_threshold(math.inf))
    big = 1e6
    assert housner_halfsine_threshold(big) / linear_halfsine_threshold(big) == pytest.approx(
        2.0, rel=1e-5
    )


def test_halfsine_threshold_shapes_and_errors():
    k = np.array([[0.3, 1.0], [3.0, 8.0]])
    out = linear_halfsine_threshold(k)
    assert out.shape == (2, 2)
    assert out[1, 0] == linear_halfsine_threshold(3.0)
    assert isinstance(linear_halfsine_threshold(1.0), float)
    assert isinstance(housner_halfsine_threshold(1.0), float)
    with pytest.raises(ValueError):
        linear_halfsine_threshold(-1.0)
    with pytest.raises(ValueError):
        housner_halfsine_threshold([1.0, math.nan])


@settings(max_examples=60, deadline=None)
@given(st.floats(1e-3, 1e3), st.floats(1.0001, 1.5))
def test_linear_threshold_increases_with_frequency(k, factor):
    assert linear_halfsine_threshold(k * factor) > linear_halfsine_threshold(k)
    assert linear_halfsine_threshold(k) <= housner_halfsine_threshold(k)


# --------------------------------------------------------------------------- rectangular
@pytest.mark.parametrize("p_t1", [0.1, 0.5, 1.0, 3.0])
def test_rectangular_pulse_threshold_matches_bisection_of_the_ode(p_t1):
    numeric = numeric_rectangular_ratio(p_t1)
    assert rectangular_pulse_threshold(P, p_t1 / P) == pytest.approx(numeric, rel=1e-7)


def test_rectangular_pulse_limits_and_arrays():
    assert math.isinf(rectangular_pulse_threshold(2.0, 0.0))
    assert rectangular_pulse_threshold(2.0, 100.0) == pytest.approx(1.0, abs=1e-15)
    out = rectangular_pulse_threshold(np.array([1.0, 2.0]), 0.5)
    assert out.shape == (2,) and out[0] > out[1]
    with pytest.raises(ValueError):
        rectangular_pulse_threshold(0.0, 1.0)
    with pytest.raises(ValueError):
        rectangular_pulse_threshold(1.0, -1.0)


# --------------------------------------------------------------------------- free rocking
@pytest.mark.parametrize("theta0_over_alpha", [1e-3, 0.1, 0.5, 0.9, 0.999])
def test_free_rocking_period_matches_quarter_period_integration(theta0_over_alpha):
    def rhs(t, y):
        return [y[1], P * P * (y[0] - ALPHA)]

    def ground(t, y):
        return y[0]

    ground.terminal, ground.direction = True, -1
    sol = solve_ivp(
        rhs,
        (0.0, 100.0 / P),
        [theta0_over_alpha * ALPHA, 0.0],
        method="DOP853",
        rtol=1e-13,
        atol=1e-16,
        events=ground,
    )
    quarter = sol.t_events[0][0]
    assert free_rocking_period(P, theta0_over_alpha) == pytest.approx(4 * quarter, rel=1e-8)


def test_free_rocking_period_limits():
    assert free_rocking_period(2.0, 0.0) == 0.0
    assert math.isinf(free_rocking_period(2.0, 1.0))
    # small amplitude: T ~ (4/p) sqrt(2 theta0/alpha)
    assert free_rocking_period(2.0, 1e-8) == pytest.approx(2.0 * math.sqrt(2e-8), rel=1e-6)
    with pytest.raises(ValueError):
        free_rocking_period(2.0, 1.5)


# --------------------------------------------------------------------------- RBM mapping
def _block(height, width, drums=1, stiffness=None):
    cfg = ColumnConfig(
        height=height,
        base_width=width,
        top_width=width,
        depth=1.0,
        density=2700.0,
        drum_heights=(height / drums,) * drums,
    )
    return build_column(cfg, InterfaceConfig(stiffness=stiffness or StiffnessConfig()))


def test_linear_rocking_parameters_rectangle():
    """4 m x 1 m x 1 m block: alpha = B/H; p from the rectangle's inertias.

    With I_G = m (H^2 + B^2)/12 the RBM denominator is I_G + m H^2/4 =
    m (4 H^2 + B^2)/12, so p^2 = 6 g H / (4 H^2 + B^2). Housner's
    p^2 = W R / I_O = 3 g / (4 R) (I_O = 4 m R^2 / 3, R the half-diagonal)
    is a different number: the RBM puts the weight on the axis.
    """
    height, width = 4.0, 1.0
    alpha, p = linear_rocking_parameters(_block(height, width))
    assert alpha == pytest.approx(0.25, rel=1e-14)
    assert p == pytest.approx(math.sqrt(6 * G * height / (4 * height**2 + width**2)), rel=1e-13)
    r = 0.5 * math.hypot(height, width)
    p_housner = math.sqrt(3 * G / (4 * r))
    assert p / p_housner == pytest.approx(1.0074, abs=1e-4)


def test_linear_rocking_parameters_tend_to_housner_for_slender_blocks():
    height, width = 4.0, 0.004
    alpha, p = linear_rocking_parameters(_block(height, width))
    r = 0.5 * math.hypot(height, width)
    assert alpha == pytest.approx(math.atan(width / height), rel=1e-6)
    assert p == pytest.approx(math.sqrt(3 * G / (4 * r)), rel=1e-6)


def test_linear_rocking_parameters_rejects_multidrum():
    col = _block(4.0, 1.0, drums=2, stiffness=StiffnessConfig("moment", (1e8,)))
    with pytest.raises(ValueError, match="n = 2"):
        linear_rocking_parameters(col)


def test_halfsine_threshold_curves_in_g():
    col = _block(4.0, 1.0)
    alpha, p = linear_rocking_parameters(col)
    f = np.array([p / (2 * math.pi), 3 * p / (2 * math.pi)])  # w/p = 1 and 3
    curves = halfsine_threshold_curves(col, f)
    assert set(curves) == {"housner", "linear"}
    np.testing.assert_allclose(curves["housner"], alpha * np.sqrt([2.0, 10.0]), rtol=1e-14)
    np.testing.assert_allclose(
        curves["linear"],
        alpha
        * np.array([numeric_halfsine_ratio(1.0, alpha, p), numeric_halfsine_ratio(3.0, alpha, p)]),
        rtol=1e-7,
    )
