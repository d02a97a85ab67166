"""A run's record: the arrays and numbers a structure's run shares with the run loop, held by
one reference.

A structure's functions, called by the run loop, read what they need from one record W:
compiled, W is a numba structure reference (numba.experimental.structref), and passing it
costs one reference count however many arrays it holds (a named tuple of arrays costs one
for each of its arrays, at every call). Uncompiled, W is a plain namespace. Its fields are
set one at a time after :func:`new_record`, every one of them before the loop runs.

A record's kind is declared once, in a module of its own (numba reads a structure type back
from its on-disk cache only if the type is not defined beside the cached functions), by
:func:`record_kind`: a list of (name, type) with the type written as numba spells it
(``"float64[:, ::1]"``, ``"int64"``, ``"bool"``, ``"Tuple((int64, float64))"``).
"""

from __future__ import annotations

from types import SimpleNamespace

from rbm_cli.base.jit import ENABLED

if ENABLED:
    # numba loads with the compiled modules that declare records (docs/architecture.md)
    from numba.core import types
    from numba.experimental import structref
    from numba.extending import overload

    @structref.register
    class RecordType(types.StructRef):
        """A run's record, as numba types it."""

        def preprocess_fields(self, fields):
            return tuple((name, types.unliteral(kind)) for name, kind in fields)

    #: The names a field's type may use.
    TYPE_NAMES = {"float64": types.float64, "int64": types.int64, "bool": types.boolean,
                  "Tuple": types.Tuple, "UniTuple": types.UniTuple}  # fmt: skip


def record_kind(fields: list[tuple[str, str]]):
    """The kind of a record with these fields ((name, type) pairs; see the module's notes):
    a numba structure type, or the field names when nothing is compiled."""
    names = [name for name, _ in fields]
    repeated = sorted({name for name in names if names.count(name) > 1})
    if repeated:
        raise TypeError(f"a record's fields repeat a name: {repeated}")
    if not ENABLED:
        return tuple(names)
    return RecordType([(name, eval(kind, {"__builtins__": {}}, TYPE_NAMES))  # noqa: S307
                       for name, kind in fields])  # fmt: skip


def record_fields(kind) -> tuple[str, ...]:
    """The field names of a record kind (record_kind)."""
    return tuple(kind) if not ENABLED else tuple(kind.field_dict)


def new_record(kind):
    """A new record of a kind (record_kind), its fields not yet set."""
    return SimpleNamespace()


if ENABLED:

    @overload(new_record)
    def _new_record(kind):
        def impl(kind):
            return structref.new(kind)

        return impl
