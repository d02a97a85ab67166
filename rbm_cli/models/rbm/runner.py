"""The Rigid Beam Model's runner: the column's equations assembled once, run by the step
kernel (compiled, or its source uncompiled with `solver.implementation: python`). With
`solver.method: exact` the linear pieces are integrated in closed form instead
(rbm_cli.models.rbm.exact; tests/test_exact.py holds it to the step kernel). A rigid
monolith runs in the block's closed form (rbm_cli.models.block.closed_form) under
`closed-form`, and under `auto` (the default) where that applies
(rbm_cli.models.methods.resolve; tests/test_closed_form_jit.py)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from rbm_cli.config.types import Config, SolverConfig
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.models.contract import DEFAULT_OUTPUT_DT
from rbm_cli.models.history import history_from_samples
from rbm_cli.models.methods import resolve
from rbm_cli.models.outcome import Outcome
from rbm_cli.structures.assembly import SHAPE_CHANGE, model_from_config, shape_change
from rbm_cli.structures.equations import Model

#: What a numerical failure of the integrator raises; the run ends `failed`, with the reason.
NUMERICAL_FAILURES = (FloatingPointError, np.linalg.LinAlgError, ValueError, ZeroDivisionError)


class RbmRunner:
    """The Rigid Beam Model of a config's column (rbm_cli.models.contract.Runner).

    Parameters
    ----------
    config : Config  Validated configuration
    model : Model  Pre-assembled equations (tests that alter a column); default: the config's
    """

    def __init__(self, config: Config, model: Model | None = None) -> None:
        self.config = config
        self.model = model if model is not None else model_from_config(config)
        self.n_interfaces = self.model.joints
        init = config.excitation.initial
        n = self.model.n
        self.theta0 = np.zeros(n) if not init.rotations else np.asarray(init.rotations, float)
        self.rate0 = np.zeros(n) if not init.velocities else np.asarray(init.velocities, float)
        limit = config.interface.friction_limit  # interface.friction: checked against
        self.friction_limit = math.inf if limit is None else float(limit)
        self._integrators: dict = {}  # (method, implementation) -> integrator, on first use
        resolve(config, model=self.model)  # an explicit method that does not apply: refused

    def integrator_of(self, method):
        """The integrator a method prepares for this runner's column (made once per method
        and implementation)."""
        return method.integrator(self.model)

    def run(
        self,
        motion: GroundMotion,
        solver: SolverConfig,
        *,
        record: bool = False,
        output_dt: float = DEFAULT_OUTPUT_DT,
        early_stop: bool = True,
    ) -> Outcome:
        """One run (rbm_cli.models.contract.Runner.run)."""
        method = resolve(self.config, solver, self.model)
        if method.name != solver.method:  # auto: the step integrators read its pair
            solver = dataclasses.replace(solver, method=method.name)
        key = (method.prepare, solver.implementation)
        integrator = self._integrators.get(key)
        if integrator is None:
            integrator = self._integrators[key] = self.integrator_of(method)
        n, mf = self.model.joints, self.model.friction_joints
        t_lift = motion.lift_off  # a vertical record dropping faster than gravity
        t_shape = shape_change(self.model, motion)  # or changing the order of a law's pieces
        if t_shape is not None and t_lift is not None:  # the earlier one ends the run
            t_lift, t_shape = (None, t_shape) if t_shape < t_lift else (t_lift, None)
        t_stop = t_lift if t_lift is not None else t_shape
        if t_stop is not None:
            motion = motion.until(t_stop)
        try:
            out = integrator(
                self.model,
                motion,
                self.theta0,
                self.rate0,
                solver,
                record=record,
                output_dt=output_dt,
                early_stop=early_stop,
                friction_limit=self.friction_limit,
            )
            out.lifted_off(t_lift)
            if t_shape is not None and out.status == "survived":
                out.stop("failed", SHAPE_CHANGE, t_shape)
        except NUMERICAL_FAILURES as exc:
            out = Outcome(status="failed", message=f"numerical failure: {exc}")
            out.max_ratio = np.full(n, np.nan)
            out.friction = np.full(mf, np.nan)
            out.friction_peak = np.full(mf, np.nan)
        if record:
            out.history = history_from_samples(self.model.node_map, motion, out.samples)
        out.method = out.method or method.name  # exact-first says which of its two ran
        return out
