"""A PyBullet physics client (no GUI), imported and connected quietly.

Bullet keeps its world in a C++ server; Python talks to it through a client.
A :class:`PhysicsClient` is one DIRECT client with a clear owner: whoever opens
it closes it (``with PhysicsClient() as client: ...``), and a caller that runs
many scenes may open one and hand it to each (``bullet_run(..., client=...)``).
Every scene resets the client's world (``resetSimulation``), so a run's result
does not depend on what ran in the client before (tests/test_bullet_library.py).

A run that is not handed a client uses the process's own,
:meth:`PhysicsClient.for_process`: opened on first use, shared by the runs of
that process (sweep workers are processes, each with its own) and closed when
the process exits. Connecting costs 4-20 ms here, against 0.5 ms for a reset,
and a short engine run takes about 0.1 s: a client per run made 20 short runs
25 % slower (measured), so the process keeps one.

PyBullet prints its build time to the C-level stderr on import; that line is
swallowed so that CLI output stays clean.
"""

from __future__ import annotations

import atexit
import ctypes
import os
import sys
from typing import ClassVar

from rbm_cli.base.errors import RbmError


class PhysicsClient:
    """One connected PyBullet DIRECT client; close it when done (or use ``with``).

    Attributes
    ----------
    module : the pybullet module (its functions take ``physicsClientId=id``)
    id : int  This client's id (None once closed)
    pid : int  The process that opened it

    Raises
    ------
    RbmError  PyBullet is not installed (``pip install pybullet``).
    """

    #: The process's own client (see :meth:`for_process`), None until first used.
    _process: ClassVar[PhysicsClient | None] = None

    def __init__(self) -> None:
        p = _quiet_import()
        self.module = p
        self.pid = os.getpid()
        self.id = _quiet(lambda: p.connect(p.DIRECT))

    @classmethod
    def for_process(cls) -> PhysicsClient:
        """The client this process's runs share when they are not handed one: opened
        on the first call (and again in a forked child, which cannot use its
        parent's), closed when the process exits. Its owner is the process: do not
        close it."""
        shared = cls._process
        if shared is None or shared.pid != os.getpid() or shared.id is None:
            shared = cls._process = cls()
            atexit.register(shared._close_at_exit)
        return shared

    def close(self) -> None:
        """Disconnect (the engine's world is freed); a second call does nothing."""
        if self.id is not None:
            self.module.disconnect(physicsClientId=self.id)
            self.id = None

    def _close_at_exit(self) -> None:
        if self.pid == os.getpid():  # not a forked child's inherited handler
            self.close()

    def __enter__(self) -> PhysicsClient:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _quiet_import():
    def load():
        # lazy: pybullet loads only where needed (docs/architecture.md, Start-up)
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
