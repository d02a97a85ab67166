"""scipy's Runge-Kutta steppers with steps that end at given times (knots).

A record's acceleration is linear between its samples, with a kink at each: a step across
a kink loses the order of the method (its error control then shrinks the step until the
kink is resolved, at a cost of many rejected steps). The steppers here end every step at
the next knot (a sample time) instead, as the compiled kernel does
(rbm_cli.inputs.ground.next_uplift and its record pieces): inside a step the forcing is
one straight line. With no knots (every other excitation) they are scipy's steppers, step for step.
"""

from __future__ import annotations

import numpy as np


def next_knot(knots: np.ndarray, x: float, bound: float) -> float:
    """The first knot > x [s] if it is before bound, else bound."""
    k = int(np.searchsorted(knots, x, side="right"))
    if k < knots.size and knots[k] < bound:
        return float(knots[k])
    return bound


def clip_at_knots(method):
    """A subclass of a scipy RungeKutta stepper whose steps end at the knots set on it
    (``stepper.knots``, an increasing array [s]; None: no clipping). The knot taken is the
    first beyond t + the smallest step scipy allows (10 ulp of t), so no step is shorter."""

    class Clipped(method):
        knots: np.ndarray | None = None

        def _step_impl(self):
            if self.knots is None:
                return super()._step_impl()
            t, bound = self.t, self.t_bound
            min_step = 10 * np.abs(np.nextafter(t, self.direction * np.inf) - t)
            self.t_bound = next_knot(self.knots, t + min_step, bound)
            try:
                return super()._step_impl()
            finally:
                self.t_bound = bound

    Clipped.__name__ = method.__name__
    Clipped.__qualname__ = method.__qualname__
    return Clipped
