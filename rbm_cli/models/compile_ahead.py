"""First use: the compiled code is compiled before the first run, one compile at a time.

Compiling takes time, once per installation: the kernel about 45 s on two shared cores
(less on a fast idle machine, more on a busy one), the integrator in two directions about
45 s, the exact integrator about 80 s, the rigid block's closed form 6-10 s; numba then
keeps them in its on-disk cache. The first `rbm run` or `rbm sweep` that needs one of them
compiles it in its own process before its first cell (:func:`compile_once`) and answers
with it: the code every later run loads from the cache, so the same answer the first time
as every time after (a cell in chaotic motion is not answered the same by two integrators,
whose round-off differs). The command says on stderr what it waits for and roughly how
long (the ``notify`` of :func:`compile_once`).

One compile at a time: a process that finds the code missing from the cache takes an
exclusive ``flock`` on a lock file beside the cache (:data:`LOCK_NAME`) and holds it while
it compiles. Another process that needs the code meanwhile (a sweep started beside a first
run) finds the lock taken, says that it waits, and once the lock is free loads what the
first one compiled instead of compiling it a second time. A compile that dies releases the
lock with its process; the process that waited then compiles it itself. Without a lock
file (numba's private cache API is not the one read here, or the cache folder is not
writable) each process compiles its own.
"""

from __future__ import annotations

import fcntl
import importlib
import os
import time
from collections.abc import Callable
from pathlib import Path

#: The lock file's name, in the folder of numba's cache of the compiled code.
LOCK_NAME = "rbm-compile.lock"
#: Poll interval while waiting for a compile elsewhere [s].
POLL_S = 0.1

#: What can be compiled (rbm_cli.models.methods.compiled_codes): the module of its
#: needs_compile and warm_up, and its compiled function whose cache folder holds the lock.
TARGETS = {
    "kernel": ("rbm_cli.models.rbm.step", "run_kernel"),
    "closed-form": ("rbm_cli.models.block.closed_form", "run_block"),
    "exact": ("rbm_cli.models.rbm.exact.integrate", "run_exact"),
    "rbm3d": ("rbm_cli.models.rbm3d.runner", "run3d"),
}
#: What each is called in a note.
NAMES = {
    "kernel": "the integrator",
    "closed-form": "the rigid block's closed form",
    "exact": "the exact integrator",
    "rbm3d": "the integrator in two directions",
}
#: About how long a first compile takes [s]: measured on two shared cores at a load of 1-2
#: (the first `rbm run` with an empty cache: kernel 42 s, in two directions 45 s, on
#: 2026-11-30 at a load of 0.7-0.9; exact integrator 76 s, closed form 6-10 s).
ABOUT_S = {"kernel": 45, "closed-form": 10, "exact": 80, "rbm3d": 45}


def _module(target: str):
    return importlib.import_module(TARGETS[target][0])


def needs_compile(target: str) -> bool | None:
    """Whether target (TARGETS) has no usable on-disk cache: True, False, or None when it
    cannot be told (base.compile_cache.cache_empty)."""
    return _module(target).needs_compile()


def cache_folder(target: str = "kernel") -> Path | None:
    """The folder of numba's cache of target (TARGETS); None if numba's private cache API is
    not the one read here, or caching is off. The kernel's, the closed form's and the exact
    integrator's modules share one folder, so one lock."""
    module_name, function = TARGETS[target]
    try:
        return Path(getattr(importlib.import_module(module_name), function)._cache._cache_path)
    except Exception:  # numba's private cache API changed: no lock
        return None


def _open_lock(target: str) -> int | None:
    """An open file descriptor of the lock file (None if it cannot be made)."""
    folder = cache_folder(target)
    if folder is None:
        return None
    try:
        folder.mkdir(parents=True, exist_ok=True)
        return os.open(folder / LOCK_NAME, os.O_RDWR | os.O_CREAT, 0o644)
    except OSError:
        return None


def _try_lock(fd: int) -> bool:
    """Take the exclusive lock without waiting; False if another process holds it."""
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    return True


def compile_once(
    target: str, notify: Callable[[str], None] | None = None, poll_s: float = POLL_S
) -> tuple[float, str]:
    """Compile target into numba's cache, or load it from there, in this process, one
    compile at a time (see the module). Interruptible: Ctrl-C raises KeyboardInterrupt, and
    the lock is released.

    Parameters
    ----------
    target : str  'kernel', 'closed-form' or 'exact' (TARGETS)
    notify : callable(str), optional  Called with one line before a wait: "compiling
        <what> (first use only, about N s)", or "waiting for <what> to compile in another
        rbm process (first use only, about N s)"; not called when the code is in the cache.
    poll_s : float  Interval between two looks at the lock while another process holds
        it [s]

    Returns
    -------
    (seconds, what)  The time it took [s] and what it was spent on: "compiling <what>",
        "waiting for <what> to compile" or "loading <what>".
    """
    module, name = _module(target), NAMES[target]
    say = notify or (lambda text: None)
    about = f"(first use only, about {ABOUT_S[target]} s on an idle machine)"
    start = time.perf_counter()
    needs = module.needs_compile()
    waited = False
    fd = _open_lock(target) if needs is not False else None
    try:
        if fd is not None and not _try_lock(fd):
            say(f"waiting for {name} to compile in another rbm process {about}")
            while not _try_lock(fd):
                time.sleep(poll_s)
            waited = True
            needs = module.needs_compile()  # False: that process compiled it
        if needs:  # (after a wait too: that compile died)
            say(f"compiling {name} {about}")
        module.warm_up()
    finally:
        if fd is not None:
            os.close(fd)  # releases the lock
    if needs:
        what = f"compiling {name}"
    else:
        what = f"waiting for {name} to compile" if waited else f"loading {name}"
    return time.perf_counter() - start, what
