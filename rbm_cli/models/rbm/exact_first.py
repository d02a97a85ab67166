"""`solver.method: exact-first`, on an RBM column whose joints are all elastic: the exact
integrator while every joint stays on its elastic branch, the step kernel (DOP853) for the
whole run once one leaves it.

While every joint is closed the column is linear: the exact integrator moves its modes in
closed form and takes no steps for their vibration, where the step kernel's steps follow
the highest elastic mode (some 20 steps a cycle at the default tolerance). Once a joint
opens, the exact integrator costs more than the step kernel (its certified search at every
event). Measured on the 40 record runs of the stored 8-drum suite's CI band
(`python tools/profile_methods.py`): the exact integrator takes 0.16 of the step kernel's
time on the run where no joint opens, 1.1-2.3 times it on the 39 where one does.

So a run starts with the exact integrator asked to stop at the first event of a joint
(rbm_cli.models.rbm.exact.integrate, until_open; its search is certified, so no opening is
missed). A run that ends without one is the exact integrator's outcome; the others are run
again from the start by the step kernel, bit for bit the run DOP853 gives alone. The time
spent before the opening is lost on those: on that band, 0.14 s of 13.4 s. Where it applies
(rbm_cli.models.methods): where the exact integrator does, on a column whose joints are all
elastic. `auto` does not pick it (rbm_cli.models.methods says why).
"""

from __future__ import annotations

import dataclasses
import time

from rbm_cli.config.types import STEP_DEFAULT
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.models.outcome import Outcome
from rbm_cli.models.rbm.exact.integrate import integrate_exact, prepare_exact
from rbm_cli.models.rbm.step import integrate as integrate_steps
from rbm_cli.models.rbm.step import prepare_kernel
from rbm_cli.structures.equations import Model


def prepare(model: Model):
    """The integrator of one column (rbm_cli.models.methods.Integrator): the exact
    integrator's modes and the step kernel's inputs, prepared once for every run."""
    exact, steps = prepare_exact(model), prepare_kernel(model)

    def integrate(model: Model, motion: GroundMotion, theta0, rate0, solver, **options) -> Outcome:
        """One run; options: the Integrator's (record, output_dt, early_stop,
        friction_limit), passed on to both integrators."""
        start = time.monotonic()
        out = integrate_exact(model, motion, theta0, rate0, solver, prepared=exact,
                              until_open=True, **options)  # fmt: skip
        if out is not None:
            out.method = "exact"
            return out
        left = max(0.0, float(solver.max_wall_time) - (time.monotonic() - start))
        solver = dataclasses.replace(solver, method=STEP_DEFAULT, max_wall_time=left)
        out = integrate_steps(model, motion, theta0, rate0, solver, prepared=steps, **options)
        out.method = STEP_DEFAULT
        return out

    return integrate


__all__ = ["prepare"]
