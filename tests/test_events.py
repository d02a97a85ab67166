"""Unit tests of the event search of a solver step (rbm_cli.base.events).

The functions are given distances whose crossings are known in closed form, so
the expected times come from the formulas, not from the code.
"""

from __future__ import annotations

import numpy as np
import pytest

from rbm_cli.base.events import first_crossing, hermite_dip
from rbm_cli.models.rbm.step.events import within_reach


def _dist(rows):
    """rows: list of (value(t), rate(t)) pairs -> dist(ts) of first_crossing."""

    def dist(ts):
        ts = np.asarray(ts, dtype=float)
        return (
            np.array([f(ts) for f, _ in rows]),
            np.array([g(ts) for _, g in rows]),
        )

    return dist


def test_first_crossing_takes_a_dip_before_a_later_crossing():
    """Guards a past bug (found by the property suite): row 0 dips below zero on (0.2, 0.3) and
    comes back; row 1 ends below zero, crossing at t = 0.9. Root finding on the
    minimum over rows may converge on 0.9; the first event is at 0.2."""
    rows = [
        (lambda t: (t - 0.2) * (t - 0.3), lambda t: 2 * t - 0.5),
        (lambda t: 0.9 - t, lambda t: -np.ones_like(t)),
    ]
    t, row = first_crossing(_dist(rows), 0.0, 1.0)
    assert row == 0
    assert t == pytest.approx(0.2, abs=1e-12)


def test_first_crossing_earliest_of_two_rows_ending_below_zero():
    rows = [
        (lambda t: 0.7 - t, lambda t: -np.ones_like(t)),
        (lambda t: 0.45 - t, lambda t: -np.ones_like(t)),
    ]
    t, row = first_crossing(_dist(rows), 0.0, 1.0)
    assert (row, t) == (1, pytest.approx(0.45, abs=1e-12))


def test_first_crossing_finds_a_dip_inside_one_subinterval():
    """A narrow dip (width 0.02) inside one of the 8 sub-intervals and between two
    check points: found by the Hermite check on the dense values."""
    rows = [(lambda t: (t - 0.40) * (t - 0.42), lambda t: 2 * t - 0.82)]
    t, row = first_crossing(_dist(rows), 0.0, 1.0)
    assert (row, t) == (0, pytest.approx(0.40, abs=1e-12))


def test_first_crossing_none_when_every_row_stays_positive():
    rows = [(lambda t: (t - 0.5) ** 2 + 1e-6, lambda t: 2 * (t - 0.5))]
    assert first_crossing(_dist(rows), 0.0, 1.0) is None


def test_first_crossing_at_the_start():
    rows = [(lambda t: 1.0 + 0 * t, lambda t: 0 * t), (lambda t: t - 0.1, lambda t: 1 + 0 * t)]
    assert first_crossing(_dist(rows), 0.0, 1.0) == (0.0, 1)


def test_end_of_step_cubic_misses_a_dip_that_first_crossing_finds():
    """Why the dense output is checked inside the step: d(t) = 0.05 - sin(w t) over a
    step of 0.9 periods goes below zero at t = asin(0.05)/w and back, but seen from the
    step's ends (d > 0 at both, falling at both) the cubic Hermite shows no dip;
    within_reach flags the step and first_crossing finds the crossing."""
    w, h, delta = 2 * np.pi, 0.9, 0.05

    def d(t):
        return delta - np.sin(w * t)

    def r(t):
        return -w * np.cos(w * t)

    def a(t):
        return w * w * np.sin(w * t)

    d0, d1, r0, r1, a0, a1 = (np.array([v]) for v in (d(0), d(h), r(0), r(h), a(0), a(h)))
    assert d0[0] > 0 and d1[0] > 0 and hermite_dip(d0, d1, r0, r1, h) is None
    mask = np.zeros(1, dtype=np.bool_)
    assert within_reach(d0, d1, r0, r1, a0, a1, h, mask) and mask[0]
    t, row = first_crossing(_dist([(d, r)]), 0.0, h)
    assert row == 0
    assert t == pytest.approx(np.arcsin(delta) / w, abs=1e-12)


def test_within_reach_false_far_from_every_surface():
    one = np.array([1.0])
    mask = np.ones(1, dtype=np.bool_)
    assert not within_reach(one, one, 0.1 * one, -0.1 * one, one, one, 0.01, mask)
    assert not mask[0]
