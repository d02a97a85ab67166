"""The converged-cell rule of the comparisons with the step kernel (tests of the closed form,
the exact integrator, and the exact integrator on frames).

A cell counts where the step kernel has converged: DOP853 at rtol 1e-11 and 1e-12 give the
same outcome and event counts, and peak rotation ratio, top displacement and collapse time
within 1e-9. There another method must give rtol 1e-12's outcome and events (not compared
on runs stopped early after a pulse: where free motion stops is decided at step ends), and
those three figures within 1e-8.
"""

from __future__ import annotations

import math

COMPARED = ("max_rotation_ratio", "max_top_displacement_m", "t_collapse_s")


def close(x: float, y: float, rel: float) -> bool:
    """x within rel of y (both NaN: equal)."""
    return (math.isnan(x) and math.isnan(y)) or abs(x - y) <= rel * abs(y)


def converged(k11, k12) -> bool:
    """Whether the step kernel's runs at rtol 1e-11 and 1e-12 agree (the module's rule)."""
    return (
        k11.status == k12.status
        and (k11.n_uplifts, k11.n_impacts) == (k12.n_uplifts, k12.n_impacts)
        and all(close(getattr(k11, a), getattr(k12, a), 1e-9) for a in COMPARED)
    )


def assert_agrees(step, other, cell) -> None:
    """other gives the converged step kernel's (rtol 1e-12) outcome, events and figures."""
    assert other.status == step.status, cell
    if "stopped early" not in (step.message + other.message):
        assert (other.n_uplifts, other.n_impacts) == (step.n_uplifts, step.n_impacts), cell
    for name in COMPARED:
        x, y = getattr(other, name), getattr(step, name)
        assert close(x, y, 1e-8), (cell, name, x, y)
