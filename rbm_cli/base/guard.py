"""Guards of the compiled kernel: a wall-clock budget and Ctrl-C.

A numba kernel does not return to Python until it ends, so neither a deadline nor a
KeyboardInterrupt can reach it from outside. The kernel calls :func:`poll` every
POLL_STEPS accepted steps instead: an object-mode block (about 1 us) that reads the
monotonic clock and a flag. Entering Python there also runs any pending signal handler;
:func:`interruptible` installs, for the length of one kernel call in the main thread, a
SIGINT handler that only sets that flag (an exception raised inside the object-mode
block would not cross the compiled frames cleanly), and raises KeyboardInterrupt once the
kernel has returned. The cost of the poll is discussed in docs/guide/solving.md.
"""

from __future__ import annotations

import _signal
import contextlib
import signal
import threading
import time
from collections.abc import Iterator

from numba import objmode

from rbm_cli.base.jit import jit

#: Accepted steps between two polls (a step costs ~1-100 us: a poll every few ms at most).
POLL_STEPS = 256
#: What poll returns.
GO_ON, PAST_DEADLINE, INTERRUPTED = 0, 1, 2

_interrupted = [False]


def _clock() -> float:
    """The monotonic clock [s], or -1 once Ctrl-C was pressed during a kernel call."""
    return -1.0 if _interrupted[0] else time.monotonic()


@jit
def poll(deadline):
    """GO_ON, PAST_DEADLINE (time.monotonic() beyond deadline [s]) or INTERRUPTED."""
    with objmode(now="float64"):
        now = _clock()
    if now < 0.0:
        return INTERRUPTED
    if now > deadline:
        return PAST_DEADLINE
    return GO_ON


def _flag(signum, frame) -> None:
    _interrupted[0] = True


def arm() -> bool:
    """Let Ctrl-C stop the kernel call that follows: SIGINT sets the flag that poll
    reads, until disarm(). Only in the main thread and when SIGINT has Python's default
    handler (a program that ignores or handles SIGINT itself keeps its handler); True if
    armed. (The _signal primitives: about 0.5 us for arm and disarm together.)"""
    if threading.current_thread() is not threading.main_thread():
        return False
    if _signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        return False
    _interrupted[0] = False
    _signal.signal(signal.SIGINT, _flag)
    return True


def disarm(armed: bool) -> None:
    """Restore Python's default SIGINT handler; raise KeyboardInterrupt if Ctrl-C was
    pressed while armed."""
    if not armed:
        return
    _signal.signal(signal.SIGINT, signal.default_int_handler)
    hit, _interrupted[0] = _interrupted[0], False
    if hit:
        raise KeyboardInterrupt


@contextlib.contextmanager
def interruptible() -> Iterator[None]:
    """arm() ... disarm() as a context manager (a few us more than the two calls)."""
    armed = arm()
    try:
        yield
    finally:
        disarm(armed)


__all__ = [
    "POLL_STEPS",
    "arm",
    "disarm",
    "poll",
    "interruptible",
    "GO_ON",
    "PAST_DEADLINE",
    "INTERRUPTED",
]
