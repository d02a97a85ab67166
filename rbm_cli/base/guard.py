"""Guards of the compiled kernel: a wall-clock budget and Ctrl-C.

A numba kernel does not return to Python until it ends, so neither a deadline nor a
KeyboardInterrupt can reach it from outside. The kernel calls :func:`poll` every
POLL_STEPS accepted steps instead: an object-mode block (about 1 us) that reads the
monotonic clock and a flag. Entering Python there also runs any pending signal handler;
:func:`interruptible` installs, for the length of one kernel call in the main thread, a
SIGINT handler that only sets that flag (an exception raised inside the object-mode
block would not cross the compiled frames cleanly), and, once the kernel has returned, puts
back the handler it replaced and calls it: Python's own raises KeyboardInterrupt, and so
does the ``rbm`` command's (rbm_cli.cli.main), which also ignores the Ctrl-C that follow.
The cost of the poll is discussed in docs/guide/solving.md.
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


#: The SIGINT handler arm() replaced, put back by disarm().
_replaced: list = [None]


def raises_keyboard_interrupt(handler) -> bool:
    """Whether a SIGINT handler is one arm() may take over for a kernel call: Python's
    default, or a handler that says it raises KeyboardInterrupt as that one does (its
    attribute ``raises_keyboard_interrupt`` is True: the ``rbm`` command's)."""
    return handler is signal.default_int_handler or (
        getattr(handler, "raises_keyboard_interrupt", False) is True
    )


def arm() -> bool:
    """Let Ctrl-C stop the kernel call that follows: SIGINT sets the flag that poll
    reads, until disarm(). Only in the main thread and when SIGINT's handler raises
    KeyboardInterrupt (raises_keyboard_interrupt: a program that ignores or handles SIGINT
    otherwise keeps its handler); True if armed. (The _signal primitives: about 0.5 us for
    arm and disarm together.)"""
    if threading.current_thread() is not threading.main_thread():
        return False
    handler = _signal.getsignal(signal.SIGINT)
    if not raises_keyboard_interrupt(handler):
        return False
    _interrupted[0] = False
    _replaced[0] = handler
    _signal.signal(signal.SIGINT, _flag)
    return True


def disarm(armed: bool) -> None:
    """Put back the SIGINT handler arm() replaced; if Ctrl-C was pressed while armed,
    call it (it raises KeyboardInterrupt)."""
    if not armed:
        return
    handler, _replaced[0] = _replaced[0], None
    _signal.signal(signal.SIGINT, handler)
    hit, _interrupted[0] = _interrupted[0], False
    if hit:
        handler(signal.SIGINT, None)


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
    "raises_keyboard_interrupt",
    "GO_ON",
    "PAST_DEADLINE",
    "INTERRUPTED",
]
