"""Command line of rbm: thin click commands over the library.

Each command loads a config, calls one library function and writes or prints
the result. Errors a user can cause (:class:`rbm_cli.api.errors.RbmError`, bad
options) end in one line ``Error: ...`` on stderr and exit status 2.

The group and its shared helpers are in :mod:`rbm_cli.cli.common`; each command
module registers its commands on it when imported (:func:`commands`; ``cli`` here is
that group with its commands).

Ctrl-C. :func:`main` installs its SIGINT handler before anything else is imported (the
imports take seconds on a loaded machine): the first Ctrl-C raises KeyboardInterrupt
wherever the command is, imports included, and the command stops, keeps what it can and
says so in one line, exit status 130; the Ctrl-C that follow are ignored, so that the
stop ends and says its line (how many cells a sweep kept, how to resume it); none
changes the exit status once it is known. A compiled loop takes the handler over while it
runs (rbm_cli.base.guard) and calls it when it returns. After a Ctrl-C, the errors of
finalizers of objects it left half-built are not reported, and one a finalizer swallowed
is sent again; an error a Ctrl-C caused (Python turns one inside a class's __set_name__
into a RuntimeError) is said as the Ctrl-C. CPython remembers a KeyboardInterrupt that
ended an exec or eval of a string (numba, dataclasses and namedtuple build code so) even
when it was caught, and ``python -m rbm_cli`` then ended by SIGINT instead of its exit
status: main() clears that before it ends. Only a Ctrl-C during Python's own start,
before main() runs, ends the process otherwise.
"""

from __future__ import annotations

import gc
import os
import signal
import sys

if "matplotlib" in sys.modules:  # (main() called from a program that drew already)
    sys.modules["matplotlib"].use("Agg")
else:  # the CLI saves figures to files; only the CLI picks a backend; matplotlib is
    os.environ["MPLBACKEND"] = "Agg"  # imported by the commands that draw, not here

__all__ = ["cli", "commands", "main"]  # noqa: F822  (cli: the module's __getattr__)

#: Exit status after Ctrl-C: 128 + SIGINT, as a shell reports it (rbm_cli.cli.common's
#: EXIT_INTERRUPTED, which a Ctrl-C during the imports cannot wait for).
EXIT_CTRL_C = 128 + signal.SIGINT

#: True once main() knows its exit status: a Ctrl-C from then on changes nothing.
_ending = [False]
#: True once a Ctrl-C raised KeyboardInterrupt.
_stopped = [False]


def _ctrl_c(signum, frame) -> None:
    """The rbm command's SIGINT handler: the first Ctrl-C raises KeyboardInterrupt, the
    ones that follow are ignored (SIGINT's disposition becomes SIG_IGN), none raises once
    the exit status is known."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if not _ending[0]:
        _stopped[0] = True
        raise KeyboardInterrupt


_ctrl_c.raises_keyboard_interrupt = True  # a compiled loop may take it over (base/guard.py)


def _unraisable(info) -> None:
    """The command's sys.unraisablehook: as Python's until a Ctrl-C; after it, what a
    finalizer raised is not reported (a KeyboardInterrupt in a constructor leaves objects
    half-built whose finalizers fail: numba's llvmlite objects), and a KeyboardInterrupt
    that a finalizer swallowed is sent again, so that the command still stops: from
    another thread, 10 ms later, once the finalizer has returned (sent from here, it
    would be raised here, in the hook, and swallowed again)."""
    if not _stopped[0]:
        sys.__unraisablehook__(info)
    elif isinstance(info.exc_value, KeyboardInterrupt) and not _ending[0]:
        # lazy: after the Ctrl-C handler is in place (module docstring)
        import threading

        try:
            signal.signal(signal.SIGINT, _ctrl_c)  # (a finalizer of the main thread)
        except ValueError:
            return
        again = threading.Timer(0.01, os.kill, (os.getpid(), signal.SIGINT))
        again.daemon = True
        again.start()


def _forget_caught_keyboard_interrupts() -> None:
    """CPython keeps a flag for a KeyboardInterrupt that ended an exec or eval of a
    string even when it was caught later, and when the process runs as ``python -m``,
    ends it by SIGINT instead of its exit status (Py_RunMain). Every exec of a string
    starts by clearing that flag."""
    exec("")


def commands():
    """The `rbm` click group with every command registered (imports the command modules)."""
    # lazy: after the Ctrl-C handler is in place (module docstring)
    from rbm_cli.cli import bench, domain, fragility, run, sensitivity, sweep  # noqa: F401
    from rbm_cli.cli.common import cli as group

    return group


def __getattr__(name: str):
    if name == "cli":  # imported when asked for, not with this module (see main)
        return commands()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def main(argv: list[str] | None = None) -> None:
    """Console-script entry point (``rbm``); ends with SystemExit and the exit status.

    Ctrl-C: see the module. The process ends with it, so what it holds is frozen out of
    the garbage collector first, and the exit does not traverse it (a sweep's ~200,000
    objects: ~0.2-0.4 s of its wall time). The collector is off while the command imports
    and loads (collections of the young objects of module imports, which all live to the
    end: ~10 % of the start-up's CPU) and on again, with what was loaded frozen, once its
    work starts (rbm_cli.cli.common.work_starts)."""
    try:
        signal.signal(signal.SIGINT, _ctrl_c)  # before the imports: they take seconds
        sys.unraisablehook = _unraisable
        gc.disable()  # until the command's work starts (common.work_starts)
        status = _run(commands(), argv)
    except KeyboardInterrupt:  # in the imports, or in click's own parsing or exit
        status = _interrupted()
    except Exception as exc:
        if not _from_ctrl_c(exc):
            raise
        status = _interrupted()
    finally:
        _ending[0] = True
        gc.freeze()
    _forget_caught_keyboard_interrupts()
    raise SystemExit(status)


def _run(group, argv: list[str] | None):
    """The command's exit status; click's errors said as click says them."""
    # lazy: after the Ctrl-C handler is in place (module docstring)
    import click

    try:
        returned = group.main(args=argv, prog_name="rbm", standalone_mode=False)
    except SystemExit as end:  # a command's sys.exit
        return end.code
    except click.Abort:  # click's word for a KeyboardInterrupt it caught itself
        return _interrupted()
    except click.ClickException as exc:  # one line (Interrupted: after a Ctrl-C)
        exc.show()
        return exc.exit_code
    # the commands return None; an int is click's Exit (--help, --version): its status
    return returned if isinstance(returned, int) else 0


def _from_ctrl_c(exc: BaseException) -> bool:
    """Whether an error stands for a Ctrl-C: a KeyboardInterrupt is in its chain of causes.
    Python 3.11 turns one raised inside a class's __set_name__ (a dataclass's fields,
    built while the command imports) into a RuntimeError caused by it."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


def _interrupted() -> int:
    """Say a Ctrl-C that no command said (one in the imports, or in click's own parsing);
    its exit status."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    sys.stderr.write("Error: interrupted (Ctrl-C)\n")
    sys.stderr.flush()
    return EXIT_CTRL_C


if __name__ == "__main__":  # pragma: no cover
    main()
