"""Run a sweep's chunks on workers and yield each chunk's rows as it finishes.

Backends: ``loky`` (worker processes, the default), ``threading``, ``sequential`` and
``dask`` (a Dask distributed cluster). Interruption is part of the contract (issue 14):

- loky workers ignore SIGINT (a Ctrl-C in the terminal reaches the whole process group:
  only the sweep itself handles it) and watch their parent: a worker whose sweep died,
  even by kill -9, exits within WATCH_INTERVAL_S. On Ctrl-C, or any error, the sweep
  cancels what is queued and stops its workers before it reports.
- a Dask scheduler address is probed first with a bounded handshake, so an address that
  is not a Dask scheduler (an HTTP port) is refused in one line instead of blocking.
"""

from __future__ import annotations

import os
import signal
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Sequence

from rbm_cli.base.errors import RbmError

#: Seconds between two checks of a worker that its sweep is still alive.
WATCH_INTERVAL_S = 1.0
#: Bound of the Dask handshake probe [s]; distributed's own timeout covers only the
#: TCP connection, and a server that accepts it but never answers blocked forever.
DASK_PROBE_TIMEOUT_S = 10.0
#: Chunks queued per worker at a time (a shutdown with many queued chunks tripped a
#: race in loky's manager thread: KeyError, InvalidStateError).
IN_FLIGHT = 2
#: Idle loky workers exit after this long [s] (they are reused by the next sweep).
IDLE_TIMEOUT_S = 60


def _watch_parent(parent: int) -> None:
    while True:
        time.sleep(WATCH_INTERVAL_S)
        if os.getppid() != parent:
            os._exit(3)  # the sweep is gone: nothing will read this worker's rows


def _worker_init(parent: int) -> None:
    """In each loky worker: ignore SIGINT (the sweep handles Ctrl-C and stops the
    workers) and exit when the sweep that started the worker dies."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_watch_parent, args=(parent,), daemon=True).start()


def run_chunks(
    fn: Callable, args: Sequence[tuple], jobs: int, backend: str, scheduler: str | None
) -> Iterator:
    """fn(*a) for every a in args, on `jobs` workers; yields each result as it finishes
    (in no set order), and None now and then while nothing finishes (loky). Stops every
    worker before an exception leaves (KeyboardInterrupt included)."""
    if not args:
        return
    if jobs == 1 and backend in ("loky", "sequential"):
        for a in args:
            yield fn(*a)
        return
    if backend == "loky":
        yield from _loky(fn, args, jobs)
        return
    import joblib

    if backend == "dask":
        client = _dask_client(scheduler)
        try:
            with joblib.parallel_config(backend="dask"):
                par = joblib.Parallel(n_jobs=jobs, return_as="generator_unordered")
                yield from par(joblib.delayed(fn)(*a) for a in args)
        finally:
            client.close()
        return
    par = joblib.Parallel(n_jobs=jobs, backend=backend, return_as="generator_unordered")
    yield from par(joblib.delayed(fn)(*a) for a in args)


def _loky(fn: Callable, args: Iterable[tuple], jobs: int) -> Iterator:
    from concurrent.futures import FIRST_COMPLETED, wait

    from joblib.externals.loky import get_reusable_executor

    executor = get_reusable_executor(
        max_workers=jobs,
        timeout=IDLE_TIMEOUT_S,
        initializer=_worker_init,
        initargs=(os.getpid(),),
    )
    queue = iter(args)
    pending: set = set()

    def refill() -> None:  # at most IN_FLIGHT chunks a worker queued, as joblib does
        while len(pending) < IN_FLIGHT * jobs:
            a = next(queue, None)
            if a is None:
                return
            pending.add(executor.submit(fn, *a))

    try:
        refill()
        while pending:
            done, pending = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
            if not done:
                yield None  # a heartbeat: the caller may report progress
            for future in done:
                yield future.result()
            refill()
    except BaseException:
        # the queued futures are failed by the shutdown itself (cancelling them first
        # made loky's manager thread raise InvalidStateError and the process hang)
        executor.shutdown(wait=True, kill_workers=True)
        raise


def _dask_client(scheduler: str | None):
    try:
        from dask.distributed import Client
    except ImportError:
        raise RbmError(
            "--backend dask needs dask's distributed scheduler: pip install 'rbm[dask]'"
        ) from None
    if not scheduler:
        return Client(processes=False)
    probe_dask(scheduler)
    try:
        return Client(scheduler, timeout=DASK_PROBE_TIMEOUT_S)
    except (OSError, TimeoutError, ValueError) as exc:
        raise RbmError(f"cannot reach the Dask scheduler {scheduler}: {exc}") from None


def probe_dask(address: str) -> None:
    """Connect and complete distributed's handshake within DASK_PROBE_TIMEOUT_S."""
    import asyncio

    try:
        from distributed.comm import connect
    except ImportError:
        raise RbmError(
            "--backend dask needs dask's distributed scheduler: pip install 'rbm[dask]'"
        ) from None

    async def probe() -> None:
        comm = await connect(address, timeout=DASK_PROBE_TIMEOUT_S / 2)
        await comm.close()

    try:
        asyncio.run(asyncio.wait_for(probe(), DASK_PROBE_TIMEOUT_S))
    except TimeoutError:
        raise RbmError(
            f"cannot reach the Dask scheduler {address}: no Dask handshake within"
            f" {DASK_PROBE_TIMEOUT_S:g} s (is it a Dask scheduler's address?)"
        ) from None
    except (OSError, ValueError, TypeError) as exc:
        reason = " ".join(str(exc).split())
        raise RbmError(f"cannot reach the Dask scheduler {address}: {reason}") from None
