"""The process's PyBullet physics client (no GUI), imported and connected quietly.

Bullet keeps its world in a C++ server; a process talks to it through one
client. rbm opens one DIRECT client per process, on first use, and every run
resets it (``resetSimulation``): this is the one piece of module state in
rbm, and it holds no result. Sweep workers are processes, each with its own.
PyBullet prints its build time to the C-level stderr on import; that line is
swallowed so that CLI output stays clean.
"""

from __future__ import annotations

import ctypes
import os
import sys

from rbm_cli.base.errors import RbmError

_CLIENT: dict = {}


def engine():
    """(pybullet module, client id) of this process, connected on first call.

    Raises
    ------
    RbmError  PyBullet is not installed (``pip install pybullet``).
    """
    pid = os.getpid()
    if _CLIENT.get("pid") != pid:  # first use, or a forked child
        p = _quiet_import()
        _CLIENT.update(pid=pid, module=p, client=_quiet(lambda: p.connect(p.DIRECT)))
    return _CLIENT["module"], _CLIENT["client"]


def _quiet_import():
    def load():
        import pybullet

        return pybullet

    try:
        return _quiet(load)
    except ImportError:
        raise RbmError(
            "model bullet needs PyBullet: pip install pybullet (it is a dependency of rbm)"
        ) from None


def _flush_c_stdout() -> None:
    """fflush(NULL): push what C code buffered while stdout pointed at /dev/null."""
    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):  # no C library to ask: nothing buffered we can reach
        pass


def _quiet(fn):
    """Call fn with the C-level stdout and stderr sent to /dev/null (PyBullet
    prints its build time to stderr on import)."""
    for stream in (sys.stdout, sys.stderr):
        stream.flush()
    fds = []
    for stream, default in ((sys.stdout, 1), (sys.stderr, 2)):
        try:
            fds.append(stream.fileno())
        except (AttributeError, OSError, ValueError):  # captured (tests): the process's own
            fds.append(default)
    saved = [os.dup(fd) for fd in fds]
    try:
        with open(os.devnull, "wb") as null:
            for fd in fds:
                os.dup2(null.fileno(), fd)
            try:
                return fn()
            finally:
                _flush_c_stdout()
                for fd, keep in zip(fds, saved, strict=True):
                    os.dup2(keep, fd)
    finally:
        for keep in saved:
            os.close(keep)
