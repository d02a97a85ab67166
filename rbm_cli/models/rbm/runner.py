"""The Rigid Beam Model's runner: the column's equations assembled once, run by the step
kernel (compiled, or its source uncompiled with `solver.implementation: python`). With
`solver.method: exact` the linear pieces are integrated in closed form instead
(rbm_cli.models.rbm.exact; tests/test_exact.py holds it to the step kernel). A rigid
monolith runs in the block's closed form (rbm_cli.models.block.closed_form) under
`closed-form`, and under `auto` (the default) where that applies
(rbm_cli.models.methods.resolve_method; tests/test_closed_form_jit.py)."""

from __future__ import annotations

import dataclasses
from functools import partial

import numpy as np

from rbm_cli.base.errors import RbmError
from rbm_cli.config.types import CLOSED_FORM_KINDS, STEP_DEFAULT, Config, SolverConfig
from rbm_cli.models.contract import DEFAULT_OUTPUT_DT
from rbm_cli.models.methods import resolve_method
from rbm_cli.models.outcome import Outcome
from rbm_cli.models.result import history_from_samples
from rbm_cli.physics.assembly import SHAPE_CHANGE, model_from_config, shape_change
from rbm_cli.physics.equations import Model
from rbm_cli.physics.excitation import GroundMotion

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
        self.n_interfaces = self.model.n
        init = config.excitation.initial
        n = self.model.n
        self.theta0 = np.zeros(n) if not init.rotations else np.asarray(init.rotations, float)
        self.rate0 = np.zeros(n) if not init.velocities else np.asarray(init.velocities, float)
        self._integrators: dict = {}  # (method, implementation) -> integrator, on first use
        excitation = config.excitation
        if config.solver.method == "exact":
            from rbm_cli.models.rbm.exact.motion import check_exact

            check_exact(self.model, excitation.type, excitation.vertical is not None)
        if config.solver.method == "closed-form":
            _check_closed_form(self.model, config)

    def method(self, solver: SolverConfig) -> str:
        """The method a run with this solver uses: solver.method, or what `auto` resolves
        to (closed-form or DOP853, rbm_cli.models.methods.resolve_method)."""
        method = resolve_method(self.config, solver)
        if method == "closed-form" and solver.method == "auto":
            from rbm_cli.models.block.closed_form import why_not

            if why_not(self.model) is not None:  # a model given in place of the config's
                return STEP_DEFAULT
        return method

    def _integrator(self, method: str, implementation: str):
        """The integrator of a method and implementation, imported only when a run needs
        it; the compiled one with this column's kernel inputs, prepared once."""
        if method == "closed-form":
            from rbm_cli.models.block.closed_form import integrate_closed_form, rbm_block

            return partial(integrate_closed_form, block=rbm_block(self.model))
        if method == "exact":
            from rbm_cli.models.rbm.exact.integrate import integrate_exact, prepare_exact

            return partial(integrate_exact, prepared=prepare_exact(self.model))
        from rbm_cli.models.rbm.step import integrate, prepare_kernel

        return partial(integrate, prepared=prepare_kernel(self.model))

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
        method = self.method(solver)
        if method != solver.method:  # auto: the step integrators read the method it stands for
            solver = dataclasses.replace(solver, method=method)
        key = (method if method in ("exact", "closed-form") else "step", solver.implementation)
        integrator = self._integrators.get(key)
        if integrator is None:
            integrator = self._integrators[key] = self._integrator(method, solver.implementation)
        n = self.model.n
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
            )
            out.lifted_off(t_lift)
            if t_shape is not None and out.status == "survived":
                out.stop("failed", SHAPE_CHANGE, t_shape)
        except NUMERICAL_FAILURES as exc:
            out = Outcome(status="failed", message=f"numerical failure: {exc}")
            out.max_ratio = np.full(n, np.nan)
            out.friction = np.full(n, np.nan)
        if record:
            out.history = history_from_samples(self.model.node_map, motion, out.samples)
        out.method = method
        return out


def _check_closed_form(model: Model, config: Config) -> None:
    """RbmError (one line) unless `closed-form` takes this model and excitation."""
    from rbm_cli.models.block.closed_form import rbm_block

    rbm_block(model)
    excitation = config.excitation
    if excitation.type not in CLOSED_FORM_KINDS or excitation.vertical is not None:
        what = "a vertical record" if excitation.vertical is not None else excitation.type
        raise RbmError(
            f"solver.method closed-form does not take {what} (no closed form): use DOP853 (or auto)"
        )
