"""A structure's own copies of the engine's functions.

The engine's run loop (numerics.loop.run_motion) and its Runge-Kutta steps (numerics.rk)
call a structure's functions by name: the loop its event and figure functions, a step its
right-hand side. numba compiles a function with the functions its globals name frozen in,
and reads a function passed as an argument or closed over back from its on-disk cache
poorly; so each structure gets copies of these functions whose globals name its own, each
compiled on its own (:func:`bind`). A copy runs the template's statements; compiled or
not (base.jit) as every function of the package.
"""

from __future__ import annotations

import types
from collections.abc import Callable

from rbm_cli.base.jit import jit


def bind(
    templates: dict[str, tuple[Callable, dict]],
    given: dict[str, Callable],
    suffix: str,
) -> dict[str, Callable]:
    """Copies of the template functions (name -> (uncompiled function, how base.jit.jit
    compiles it: ``{}``, ``{"inline": True}`` or ``{"borrow": True}``)),
    written in one module, whose globals are that module's with the names of ``given``
    bound to its functions and the templates' names to each other's copies. Each copy is
    named ``<name>_<suffix>`` (numba's on-disk cache keeps one entry per name) and compiled
    with base.jit.jit as the template says."""
    modules = {f.__module__ for f, _ in templates.values()}
    if len(modules) != 1:
        raise TypeError(f"templates come from one module, not {sorted(modules)}")
    first = next(iter(templates.values()))[0]
    namespace = dict(first.__globals__)
    namespace.update(given)
    copies = {}
    for name, (template, how) in templates.items():
        code = template.__code__
        copy = types.FunctionType(code, namespace, f"{name}_{suffix}", template.__defaults__)
        copy.__qualname__ = f"{name}_{suffix}"
        copy.__doc__, copy.__module__ = template.__doc__, template.__module__
        copies[name] = jit(copy, **how)
    namespace.update(copies)  # before any compile: the copies call each other
    return copies
