"""Which method runs a config: `solver.method: auto` (the default) resolved.

- model `rbm`: the rigid block's compiled closed form (`closed-form`,
  rbm_cli.models.block.closed_form) where it applies -- a rigid monolithic column (one drum,
  interface.stiffness rigid, xi 1, formulation relative or geometric), an excitation with a
  closed form (harmonic, free, the sine pulses, records exact per sample interval), no
  vertical record, `solver.implementation: compiled` -- else DOP853 (the step kernel, or
  kernel's source uncompiled with `implementation: python`);
- `housner-linear`: `closed-form` whatever the method says (compiled, or its source run
  uncompiled with `implementation: python`; under a vertical record too, gam taken per
  piece);
- `housner`: DOP853; `bullet`: its engine (the method does not apply).

An explicit method is kept: `DOP853` on a rigid monolith runs the step kernel.
"""

from __future__ import annotations

from rbm_cli.config.types import CLOSED_FORM_KINDS, STEP_DEFAULT, Config, SolverConfig


def closed_form_applies(config: Config, solver: SolverConfig | None = None) -> bool:
    """Whether `auto` runs the RBM of this config in closed form (solver: the one a run
    is given, default the config's)."""
    solver = config.solver if solver is None else solver
    interface, excitation = config.interface, config.excitation
    return (
        config.model == "rbm"
        and solver.implementation == "compiled"
        and config.column.n_drums == 1
        and interface.stiffness.kind == "rigid"
        and interface.xi == 1.0
        and interface.formulation in ("relative", "geometric")
        and excitation.type in CLOSED_FORM_KINDS
        and excitation.vertical is None
    )


def resolve_method(config: Config, solver: SolverConfig | None = None) -> str:
    """The method that runs this config's cells: solver.method, or what `auto` stands for
    (see the module); 'engine' for `bullet`."""
    solver = config.solver if solver is None else solver
    if config.model == "bullet":
        return "engine"
    if config.model == "housner-linear":
        return "closed-form"
    if solver.method != "auto":
        return solver.method
    if closed_form_applies(config, solver):
        return "closed-form"
    return STEP_DEFAULT


def step_method(solver: SolverConfig) -> str:
    """The Runge-Kutta pair of a step integrator: solver.method, DOP853 for `auto`."""
    return STEP_DEFAULT if solver.method == "auto" else solver.method


def compiled_code(config: Config) -> str | None:
    """Which compiled code the cells of this config run: 'kernel' (the step kernel),
    'exact' (the compiled exact integrator), 'closed-form' (the block's closed form), or
    None (Python, or a model without compiled code): a target of
    rbm_cli.models.rbm.compile_ahead."""
    method = resolve_method(config)
    compiled = config.solver.implementation == "compiled"
    if config.model == "housner-linear":
        return "closed-form" if compiled else None
    if config.model != "rbm" or not compiled:
        return None
    if method in ("closed-form", "exact"):
        return method
    return "kernel"
