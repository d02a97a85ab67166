"""The methods that run a config's cells, in one table (:data:`METHODS`).

Each row says which models a method runs and, per model, the compiled code it needs (a
target of rbm_cli.models.compile_ahead, None where it runs no compiled code), where it does
not apply (a one-line reason), and, for the Rigid Beam Model, the integrator it prepares
once per column (an :class:`Integrator`). `solver.method: auto` (the default) is resolved
here and nowhere else (:func:`resolve`):

- model `rbm`: the rigid block's closed form (`closed-form`, rbm_cli.models.block) where it
  applies -- a rigid monolithic column (one drum, interface.stiffness rigid, xi 1,
  formulation relative or geometric), an excitation with a closed form (harmonic, free, the
  sine pulses, records exact per sample interval), no vertical record, `solver.implementation:
  compiled` -- else DOP853 (the step integrator, rbm_cli.models.rbm.step). Not `exact-first`
  (rbm_cli.models.rbm.exact_first), though it picks the faster method per cell on an
  elastic column: its first use compiles a second integrator, every process loads both,
  and on the stored studies it gained 3 % (the 8-drum harmonic domain) or lost 3 % (the
  200-run record suite; docs/performance.md);
- `housner-linear`: `closed-form`, whatever the method says;
- `housner` and `housner-3d`: DOP853 (scipy's pairs); `rbm-3d`: DOP853 (the step kernel's
  pairs, in its own compiled run); `bullet`: its engine (the method does not apply).

An explicit method is kept where it applies (`DOP853` on a rigid monolith runs the step
integrator) and refused in one line where it does not. Every compiled method also runs its
own source uncompiled with `solver.implementation: python` (rbm_cli.base.jit.plain).

Adding a method is one row here (and its name in rbm_cli.config.types.METHODS).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from rbm_cli.base.errors import RbmError
from rbm_cli.config.types import CLOSED_FORM_KINDS, STEP_DEFAULT, Config, SolverConfig
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.models.outcome import Outcome
from rbm_cli.models.rbm.exact.motion import exact_why_not
from rbm_cli.structures.equations import Model


class Integrator(Protocol):
    """What a method prepares for one RBM column: one run from an initial state [rad,
    rad/s] under a motion, with a run's solver settings, to an Outcome (with
    friction_limit [-], inf for none: where the friction demand first exceeded it,
    Outcome.slip; friction_duration [s]: the duration the demand is held for,
    Outcome.friction, 0 for its peak)."""

    def __call__(
        self,
        model: Model,
        motion: GroundMotion,
        theta0: np.ndarray,
        rate0: np.ndarray,
        solver: SolverConfig,
        *,
        record: bool,
        output_dt: float,
        early_stop: bool,
        friction_limit: float = ...,
        friction_duration: float = ...,
    ) -> Outcome: ...


def column_why_not(one_rigid_drum: bool, one_piece: bool, formulation: str) -> str | None:
    """Why the block's closed form does not take an RBM column: one rigid drum or not, one
    law piece a side (xi 1) or not, and the formulation; None if it takes it."""
    if not one_rigid_drum:
        return "it takes a rigid monolithic column only (one drum, interface.stiffness rigid)"
    if not one_piece:
        return "it takes one law piece a side only (interface.xi 1)"
    if formulation == "absolute":
        return "it takes interface.formulation relative or geometric"
    return None


def model_why_not(model: Model) -> str | None:
    """Why the block's closed form does not take this RBM model (:func:`column_why_not` of
    its column), or None if it does."""
    law = model.laws[0]
    return column_why_not(model.n == 1 and law.rigid, len(law.edges) == 0, model.formulation)


def _closed_form_why_not(config: Config, model: Model | None) -> str | None:
    if config.model == "housner-linear":
        return None
    if model is not None:  # the runner's model, which may stand in for the config's
        reason = model_why_not(model)
    else:
        interface = config.interface
        reason = column_why_not(
            config.column.n_drums == 1 and interface.stiffness.kind == "rigid",
            interface.xi == 1.0,
            interface.formulation,
        )
    if reason is not None:
        return f"solver.method closed-form: {reason}; use DOP853 (or auto)"
    excitation = config.excitation
    if excitation.type not in CLOSED_FORM_KINDS or excitation.vertical is not None:
        what = "a vertical record" if excitation.vertical is not None else excitation.type
        return (
            f"solver.method closed-form does not take {what} (no closed form): use DOP853 (or auto)"
        )
    return None


def _exact_why_not(config: Config, model: Model | None, method: str = "exact") -> str | None:
    excitation = config.excitation
    return exact_why_not(
        config.interface.formulation,
        excitation.type,
        excitation.vertical is not None,
        config.interface.damping if model is None else model.damping,
        method,
    )


def _exact_first_why_not(config: Config, model: Model | None) -> str | None:
    reason = _exact_why_not(config, model, "exact-first")
    if reason is not None:
        return reason
    rigid = (any(law.rigid for law in model.laws) if model is not None
             else config.interface.stiffness.kind == "rigid")  # fmt: skip
    if not rigid:
        return None
    return (
        "solver.method exact-first takes columns whose joints are all elastic"
        " (interface.stiffness not rigid): use DOP853 (or auto)"
    )


@dataclass(frozen=True)
class Method:
    """One row of the table.

    Attributes
    ----------
    name : str  As written in solver.method
    runs : dict  Model name -> the compiled code a run of that model needs with
        `solver.implementation: compiled` (compile_ahead targets; () for none)
    prepare : str  "module:function" making the :class:`Integrator` of an RBM Model, or ""
        (the model's runner integrates itself)
    why_not : callable  (config, model or None) -> one-line reason it does not apply, or None
    """

    name: str
    runs: dict[str, tuple[str, ...]]
    prepare: str = ""
    why_not: Callable[[Config, Model | None], str | None] = field(
        default=lambda config, model: None
    )

    def integrator(self, model: Model) -> Integrator:
        """This method's integrator for one RBM column, imported only when asked for."""
        module, _, function = self.prepare.partition(":")
        return getattr(importlib.import_module(module), function)(model)

    def compiled_codes(self, config: Config) -> tuple[str, ...]:
        """The compiled code the cells of config run with this method (none: ())."""
        if config.solver.implementation != "compiled":
            return ()
        return self.runs.get(config.model, ())


_STEP = "rbm_cli.models.rbm.step:prepare"
#: The models of the step pairs but `rbm`: their compiled code (none: scipy's pairs, stepped
#: by the model's runner).
_PAIRS = {"housner": (), "housner-3d": (), "rbm-3d": ("rbm3d",)}

#: The methods, by name: where each applies, what it prepares, what it compiles.
METHODS: dict[str, Method] = {
    m.name: m
    for m in (
        Method(
            "closed-form",
            {"rbm": ("closed-form",), "housner-linear": ("closed-form",)},
            "rbm_cli.models.block.closed_form:prepare",
            _closed_form_why_not,
        ),
        Method(
            "exact",
            {"rbm": ("exact",)},
            "rbm_cli.models.rbm.exact.integrate:prepare",
            _exact_why_not,
        ),
        Method(
            "exact-first",
            {"rbm": ("exact", "kernel")},
            "rbm_cli.models.rbm.exact_first:prepare",
            _exact_first_why_not,
        ),
        Method("DOP853", {"rbm": ("kernel",), **_PAIRS}, _STEP),
        Method("RK45", {"rbm": ("kernel",), **_PAIRS}, _STEP),
        Method("RK23", {"rbm": ("kernel",), **_PAIRS}, _STEP),
        Method("engine", {"bullet": ()}),
    )
}


def resolve(
    config: Config, solver: SolverConfig | None = None, model: Model | None = None
) -> Method:
    """The method that runs this config's cells: solver.method, or what `auto` stands for
    (see the module). solver: the one a run is given (default the config's); model: the
    column's equations when a runner has them (a model given in place of the config's).
    RbmError in one line where the method does not apply."""
    solver = config.solver if solver is None else solver
    if config.model == "bullet":
        return METHODS["engine"]
    if config.model == "housner-linear":
        return METHODS["closed-form"]
    if solver.method == "auto":
        closed = METHODS["closed-form"]
        if (
            config.model == "rbm"
            and solver.implementation == "compiled"
            and closed.why_not(config, model) is None
        ):
            return closed
        return METHODS[STEP_DEFAULT]
    method = METHODS[solver.method]
    if config.model not in method.runs:
        steps = ", ".join(name for name, m in METHODS.items() if config.model in m.runs)
        raise RbmError(
            f"solver.method {solver.method} is for model rbm (its piecewise-linear equations);"
            f" model {config.model} takes auto, {steps}"
        )
    reason = method.why_not(config, model)
    if reason is not None:
        raise RbmError(reason)
    return method


def resolve_method(config: Config, solver: SolverConfig | None = None) -> str:
    """The name of the method that runs this config's cells (:func:`resolve`)."""
    return resolve(config, solver).name


def step_method(solver: SolverConfig) -> str:
    """The Runge-Kutta pair of a step integrator called with a solver as written:
    solver.method, DOP853 (the table's default step method) for `auto`."""
    return STEP_DEFAULT if solver.method == "auto" else solver.method


def compiled_codes(config: Config) -> tuple[str, ...]:
    """Which compiled code the cells of this config run: 'kernel' (the step integrator),
    'exact', both (exact-first), 'closed-form', or none (Python, or a model without compiled
    code): targets of rbm_cli.models.compile_ahead."""
    return resolve(config).compiled_codes(config)
