"""First use without the wait: the kernel (or the rigid block's closed form) compiles in a
process of its own.

The compiled kernel takes 15-20 s to compile on a fresh installation (45-60 s on a loaded
machine), once; numba then keeps it in its on-disk cache. ``rbm run`` on an empty cache
does not wait for it: it starts this module as a detached process (its own session, so a
Ctrl-C in the terminal does not reach it, at low priority) that compiles the kernel into
the cache, and answers its own run with the Python integrator, the same method with the
same tolerances (tests/test_kernel.py holds the two to the same steps). A sweep started
while the compile runs waits for it instead of compiling a second time.

One compile at a time: the starting process takes an exclusive ``flock`` on a lock file
beside the kernel's cache and hands the open file to the child, which holds it until it
exits (the lock belongs to the open file, not to a process: the parent's copy closes, the
child's keeps it). A compile that dies releases the lock with its process; the next use
then compiles in the foreground. The child's output goes to ``rbm-compile.log`` beside the
lock.

The rigid block's compiled closed form (the default `auto` there) is started the same way
(``start("closed-form")``); its first run is answered by the Python step integrator
(DOP853, the same tolerances as the step kernel).

``RBM_BACKGROUND_COMPILE=0`` turns this off: the first run compiles in the foreground.
"""

from __future__ import annotations

import fcntl
import os
import subprocess
import sys
import time
from pathlib import Path

#: The lock file's name, in the kernel's cache folder.
LOCK_NAME = "rbm-compile.lock"
#: The compile's log, beside the lock.
LOG_NAME = "rbm-compile.log"
#: Environment variable: "0" compiles in the foreground.
ENV_SWITCH = "RBM_BACKGROUND_COMPILE"
#: Poll interval while waiting for a compile elsewhere [s].
POLL_S = 0.1


def cache_folder() -> Path | None:
    """The folder of numba's cache of the kernel (None if numba's private cache API is not
    the one read here, or caching is off)."""
    from rbm_cli.models.rbm.kernel_step import run_kernel

    try:
        return Path(run_kernel._cache._cache_path)
    except Exception:  # numba's private cache API changed: no background compile
        return None


def _open_lock() -> int | None:
    """An open file descriptor of the lock file (None if it cannot be made)."""
    folder = cache_folder()
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


def compiling_elsewhere() -> bool:
    """Whether another process holds the compile lock (a background compile runs)."""
    fd = _open_lock()
    if fd is None:
        return False
    try:
        return not _try_lock(fd)
    finally:
        os.close(fd)  # closing releases a lock taken here


#: What a background compile can compile: its warm_up's module.
TARGETS = {"kernel": "rbm_cli.models.rbm.kernel", "closed-form": "rbm_cli.models.rbm.closed_form"}


def start(target: str = "kernel") -> bool:
    """Start the background compile of target (TARGETS), unless a compile already runs.
    True when a compile runs in another process after the call; False when none could be
    started (switched off, no cache folder, not writable): the caller then compiles in the
    foreground."""
    if os.environ.get(ENV_SWITCH, "1").strip() == "0":
        return False
    fd = _open_lock()
    if fd is None:
        return False
    try:
        if not _try_lock(fd):
            return True  # another process compiles
        folder = cache_folder()
        with open(folder / LOG_NAME, "ab") as log:
            subprocess.Popen(
                [sys.executable, "-m", __name__, str(fd), target],
                pass_fds=(fd,),
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=log,
                start_new_session=True,
                close_fds=True,
            )
        return True
    except OSError:
        return False
    finally:
        os.close(fd)  # the child's copy of the open file keeps the lock


def wait(poll_s: float = POLL_S) -> float:
    """Wait until no other process compiles; the time waited [s]. Interruptible (Ctrl-C
    raises KeyboardInterrupt between polls)."""
    start_t = time.perf_counter()
    while compiling_elsewhere():
        time.sleep(poll_s)
    return time.perf_counter() - start_t


def _main(fd: int, target: str = "kernel") -> None:
    """The background process: compile (or load) the target (TARGETS) into the cache,
    holding the lock (fd) until it exits."""
    import importlib

    try:
        os.nice(10)  # leave the CPU to the run that started it
    except OSError:
        pass
    warm_up = importlib.import_module(TARGETS[target]).warm_up
    start_t = time.perf_counter()
    warm_up()
    print(f"rbm: {target} compiled in {time.perf_counter() - start_t:.1f} s (pid {os.getpid()})")
    os.close(fd)


if __name__ == "__main__":
    _main(int(sys.argv[1]), *sys.argv[2:3])
