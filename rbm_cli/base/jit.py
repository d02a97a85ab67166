"""One source for every compiled algorithm: numba compiles it, or Python runs it as written.

The integrators are written once, in the subset of Python that numba compiles (loops over
arrays, scalars, tuples; no objects), and decorated with :func:`jit`. Two switches choose
who runs them:

- ``RBM_JIT=0`` in the environment, read when rbm is imported: :func:`jit` leaves every
  function as it is, and the whole program runs uncompiled (for a debugger, a profiler,
  coverage, or a machine without a working numba);
- :func:`plain`, at run time: the uncompiled version of one compiled function, in a process
  that compiles. It is the function's own code (``py_func``) with every compiled function it
  calls replaced by its uncompiled version, and so on down. ``solver.implementation:
  python`` runs an integrator this way.

Both run the same statements as the compiled code. Numba compiles without ``fastmath``:
LLVM neither contracts ``a * b + c`` into a fused multiply-add nor reorders a sum, and the
transcendental functions come from :mod:`rbm_cli.base.detmath`, so the uncompiled run gives
the same bits (tests/test_jit.py checks it on whole runs). It is slower, 30-100x.

Compiled functions are cached on disk (``cache=True``), keyed on every compiled source
(:mod:`rbm_cli.base.compile_cache`).
"""

from __future__ import annotations

import functools
import os
import types
from collections.abc import Callable

from rbm_cli.base.compile_cache import key_numba_cache

#: The environment variable that turns compilation off ("0") for the whole process.
ENV_SWITCH = "RBM_JIT"
#: Whether :func:`jit` compiles (read once, at import).
ENABLED = os.environ.get(ENV_SWITCH, "1").strip() != "0"

if ENABLED:
    key_numba_cache()  # before the first decorator: the cache is keyed on every source


def jit(function: Callable | None = None, *, inline: bool = False, borrow: bool = False):
    """Compile ``function`` with numba (``njit(cache=True)``), or leave it as it is when
    ``RBM_JIT=0``. ``inline=True`` inlines it into its compiled callers (a small helper
    called in a hot loop; the arithmetic is the same). ``borrow=True`` compiles it without
    reference counts (numba's ``_nrt=False``): for a function called every step that only
    reads and writes the arrays and numbers it is given and returns numbers (numba refuses
    to compile one that allocates an array or reads a record's field). Compiled with them,
    a function counts a reference to each array it takes, an atomic add at its start and a
    subtract at its end, that numba's pruning of counts removes only in straight code (a
    function with loops and branches, or a helper inlined into one, keeps them); a borrowed
    function counts none, and whatever it inlines is borrowed too. The arithmetic is the
    same.

    Use as ``@jit``, ``@jit(inline=True)`` or ``@jit(borrow=True)``.

    A compiled caller's call is typed with its arguments' plain types, never their
    literal ones (:func:`_typed_plainly`).
    """
    if inline and borrow:
        raise TypeError("a borrowed function is called, not inlined")

    def decorate(f: Callable) -> Callable:
        if not ENABLED:
            return f
        # lazy: numba loads only where needed (docs/architecture.md, Start-up)
        from numba import njit

        if borrow:
            return _typed_plainly(njit(cache=True, _nrt=False)(f))
        return _typed_plainly(njit(cache=True, inline="always" if inline else "never")(f))

    return decorate if function is None else decorate(function)


def _typed_plainly(dispatcher):
    """The dispatcher, compiled for the plain types of a compiled caller's arguments.

    numba types a constant argument (``0``, ``-1``, ``True``, a tuple holding one) as a
    literal first and compiles the callee for it, then, once the caller's types are
    unified, compiles it again for the plain type: two compiles of the callee and of
    everything it calls that is not cached yet. The run loop and five more functions were
    compiled twice this way (about 6 s of a first use of 60 s). Here the call is typed with
    the plain types only; the literal converts to its plain type as any argument does, and
    the code and its arithmetic are the same."""
    from numba.core import types  # lazy: as numba above

    typed = dispatcher.get_call_template

    def get_call_template(args, kws):
        plain_args = tuple(types.unliteral(a) for a in args)
        return typed(plain_args, {k: types.unliteral(v) for k, v in kws.items()})

    dispatcher.get_call_template = get_call_template
    return dispatcher


def is_compiled(function: Callable) -> bool:
    """Whether ``function`` is a numba dispatcher (compiled, or compiled on its first call)."""
    return hasattr(function, "py_func") and hasattr(function, "signatures")


@functools.cache
def plain(function: Callable) -> Callable:
    """The uncompiled version of a compiled function: its Python code, calling the
    uncompiled versions of the compiled functions it calls (found in the globals of its
    module, at any depth). A function that is not compiled comes back as it is.

    The copies share one copy of each module's globals, taken at the first call (made once
    per function and kept), so functions of one module that call each other stay together;
    the module itself is not changed.
    """
    if not is_compiled(function):
        return function
    return _plain(function, {}, {})


def _plain(dispatcher, functions: dict, namespaces: dict) -> Callable:
    source = dispatcher.py_func
    if id(source) in functions:
        return functions[id(source)]
    key = id(source.__globals__)
    namespace = namespaces.get(key)
    fresh = namespace is None
    if fresh:
        namespace = namespaces[key] = dict(source.__globals__)
    copy = types.FunctionType(
        source.__code__, namespace, source.__name__, source.__defaults__, source.__closure__
    )
    copy.__doc__, copy.__qualname__ = source.__doc__, source.__qualname__
    functions[id(source)] = copy
    if fresh:  # every compiled name the module can call, replaced once
        for name, value in list(namespace.items()):
            if is_compiled(value):
                namespace[name] = _plain(value, functions, namespaces)
    return copy


__all__ = ["ENABLED", "ENV_SWITCH", "is_compiled", "jit", "plain"]
