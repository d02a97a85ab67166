"""Run a sweep's chunks on workers and yield each chunk's rows as it finishes.

Backends: ``loky`` (worker processes, the default), ``threading``, ``sequential`` and
``dask`` (a Dask distributed cluster).

A pool costs a fixed time before it saves any (its workers start, import and load the
kernel; POOL_COST_S), so ``loky`` starts one only when it pays: the chunks
run in this process, one at a time, and once PROBE_S of them has been timed, the time
those left would take here is estimated from the time per cell so far; as soon as a
pool of J workers (J = --jobs, at most one per processor) would save more than it costs,
(1 - 1/J) x that time > POOL_COST_S, the rest goes to the pool. A cheap sweep thus never
starts one, whatever --jobs says, and a costly one runs a few cells here first (the
first chunk is cut small: rbm_cli.study.sweep); the rows do not depend on where a chunk
ran. A pool is stopped once its chunks are done (its
workers are killed, not waited for: nothing of theirs is left to read).

Interruption is part of the contract:

- loky workers ignore SIGINT (a Ctrl-C in the terminal reaches the whole process group:
  only the sweep itself handles it; they start with it blocked) and watch their parent:
  a worker whose sweep died, even by kill -9, exits within WATCH_INTERVAL_S. On Ctrl-C,
  or any error, the sweep cancels what is queued and stops its workers before it reports.
- a Dask scheduler address is probed first with a bounded handshake, so an address that
  is not a Dask scheduler (an HTTP port) is refused in one line instead of blocking.
"""

from __future__ import annotations

import asyncio
import contextlib
import importlib.util
import os
import queue
import signal
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, wait
from multiprocessing import resource_tracker

from rbm_cli.base.errors import RbmError

#: Seconds between two checks of a worker that its sweep is still alive.
WATCH_INTERVAL_S = 1.0
#: Bound of the Dask handshake probe [s]; distributed's own timeout covers only the
#: TCP connection, and a server that accepts it but never answers blocked forever.
DASK_PROBE_TIMEOUT_S = 10.0
#: Chunks queued per worker at a time (a shutdown with many queued chunks tripped a
#: race in loky's manager thread: KeyError, InvalidStateError).
IN_FLIGHT = 2
#: Idle loky workers exit after this long [s] (a pool is stopped after its sweep; this
#: bounds the life of one whose sweep could not stop it).
IDLE_TIMEOUT_S = 60
#: The fixed cost of a pool [s]: its workers' start, imports and kernel load, and their
#: stop (measured for `rbm sweep` on 2 cores at low load: ~0.6-1 s).
POOL_COST_S = 1.0
#: Work timed in this process [s] before its time per cell is trusted: one cell's time
#: (a first call's lazy set-up in it, or a cell below uplift) says little of the rest.
PROBE_S = 0.2
#: Longest wait [s] of the sweep's thread on the pool's starter in one piece: a Ctrl-C
#: that another thread received is acted on between two (it does not end a join).
WAIT_SLICE_S = 0.05


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
    fn: Callable,
    args: Sequence[tuple],
    jobs: int,
    backend: str,
    scheduler: str | None,
    sizes: Sequence[int] | None = None,
    placed: dict | None = None,
) -> Iterator:
    """fn(*a) for every a in args, on up to `jobs` workers; yields each result as it
    finishes (in no set order), and None now and then while nothing finishes (loky).
    Stops every worker before an exception leaves (KeyboardInterrupt included).

    sizes : the cells of each item (default 1 each), for loky's estimate of the time
        left (the module's docstring: a pool only when it pays; jobs=1 never).
    placed : filled with "workers": the processes or threads the items ran on, 0 if
        all ran in this process (loky, sequential), None if not known (dask)."""
    placed = {} if placed is None else placed
    placed["workers"] = {"loky": 0, "sequential": 0, "threading": jobs}.get(backend)
    if not args:
        return
    if backend == "sequential":
        for a in args:
            yield fn(*a)
        return
    if backend == "loky":
        yield from _here_then_pool(fn, args, jobs, sizes or [1] * len(args), placed)
        return
    # lazy: joblib loads only where needed (docs/architecture.md, Start-up)
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


def pool_pays(time_left_s: float, jobs: int) -> bool:
    """Whether a pool of `jobs` workers (at most one per processor) would save more than
    it costs on work that would take time_left_s [s] in this process."""
    workers = min(jobs, os.cpu_count() or 1)
    return time_left_s * (1 - 1 / workers) > POOL_COST_S


def _here_then_pool(fn: Callable, args: Sequence[tuple], jobs: int, sizes, placed) -> Iterator:
    """Items in this process until the estimate says a pool pays, the rest on loky."""
    left, done, spent = sum(sizes), 0, 0.0
    for i, a in enumerate(args):
        if done and spent >= PROBE_S and pool_pays(spent / done * left, jobs):
            yield from _loky(fn, args[i:], jobs, placed)
            return
        start = time.perf_counter()
        result = fn(*a)
        spent += time.perf_counter() - start
        done, left = done + sizes[i], left - sizes[i]
        yield result


def _loky(fn: Callable, args: Iterable[tuple], jobs: int, placed: dict | None = None) -> Iterator:
    """fn(*a) for every a in args on a loky pool of `jobs` workers, started here and
    stopped at the end (placed["workers"] = jobs once it started)."""
    # lazy: joblib loads only where needed (docs/architecture.md, Start-up)
    from joblib.externals.loky import get_reusable_executor

    queue = iter(args)
    pending: set = set()
    executor = starter = None

    def refill() -> None:  # at most IN_FLIGHT chunks a worker queued, as joblib does
        while len(pending) < IN_FLIGHT * jobs:
            a = next(queue, None)
            if a is None:
                return
            pending.add(executor.submit(fn, *a))

    try:
        executor = get_reusable_executor(
            max_workers=jobs,
            timeout=IDLE_TIMEOUT_S,
            initializer=_worker_init,
            initargs=(os.getpid(),),
        )
        # multiprocessing's resource tracker, started on first use, unblocks SIGINT in
        # the thread that starts it: started here, not in the starter below
        resource_tracker.ensure_running()
        starter = _Starter(refill)  # the workers start in the first submits
        starter.start()
        starter.wait()
        if placed is not None:
            placed["workers"] = jobs
        while pending:
            done, pending = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
            if not done:
                yield None  # a heartbeat: the caller may report progress
            for future in done:
                yield future.result()
            refill()
        _stop(executor)  # every result is read
    except BaseException:
        # the queued futures are failed by the shutdown itself (cancelling them first
        # made loky's manager thread raise InvalidStateError and the process hang)
        if starter is not None:
            starter.finish()  # every worker started is in loky's table before the stop
        if executor is not None:
            _stop(executor)
        raise


class _Starter:
    """The first submits, in which loky starts the workers, in a thread of their own
    created with SIGINT blocked. The workers inherit that thread's mask (exec
    keeps it), so a Ctrl-C to the group while they import stays pending in them until
    _worker_init ignores it (before, it printed a worker's traceback). The sweep's own
    thread keeps its SIGINT handler and its mask (blocked only while the starter is
    created): a Ctrl-C raises KeyboardInterrupt there, in start() or wait(), as anywhere
    else, while a start that has begun, which a KeyboardInterrupt inside loky's Popen
    left half done (a worker missing from the pool's table, never stopped: the sweep
    hung at exit), goes on to its end in the starter; finish() waits for that before the
    pool is stopped. The starter begins only once go is set: whether it will start
    workers is then known from that flag alone."""

    def __init__(self, submit: Callable[[], None]):
        self.go, self.cancel, self.done = threading.Event(), threading.Event(), threading.Event()
        self.error: list[BaseException] = []
        self.thread = threading.Thread(target=self._run, args=(submit,), daemon=True)

    def _run(self, submit: Callable[[], None]) -> None:
        try:
            while not self.go.wait(WAIT_SLICE_S):
                if self.cancel.is_set():
                    return
            submit()
        except BaseException as exc:  # raised in the sweep's thread by wait()
            self.error.append(exc)
        finally:
            self.done.set()

    def start(self) -> None:
        mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        try:
            self.thread.start()  # a thread starts with its creator's mask
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, mask)  # a Ctrl-C meanwhile: now
        self.go.set()

    def wait(self) -> None:
        """Until the submits are done (a Ctrl-C raises meanwhile: short waits, for one
        that another thread received is acted on between two); their error, if any."""
        while not self.done.wait(WAIT_SLICE_S):
            pass
        if self.error:
            raise self.error[0]

    def finish(self) -> None:
        """Cancel a start not begun; else wait for its end, whatever Ctrl-C says (the
        one being handled is enough)."""
        if not self.go.is_set():
            self.cancel.set()
            return
        while not self.done.is_set():
            with contextlib.suppress(KeyboardInterrupt):
                self.done.wait(WAIT_SLICE_S)


def _stop(executor) -> None:
    """Kill the pool's workers and reap them: a worker that ends by itself finalizes its
    interpreter first (~1 s at exit), and loky leaves killed ones unreaped (zombies in
    the group). A later sweep that pays for a pool starts another."""
    workers = list(getattr(executor, "_processes", {}).values())  # loky's own table
    # the ids of submitted chunks not yet sent to a worker: on shutdown(kill_workers),
    # loky's manager thread fails every pending chunk, then looks these up again and
    # dies on a KeyError (a traceback on stderr) when one was submitted since its last
    # pass (a Ctrl-C just after a submit). Their futures fail all the same.
    with contextlib.suppress(AttributeError, queue.Empty):
        while True:
            executor._work_ids.get_nowait()
    executor.shutdown(wait=True, kill_workers=True)
    for worker in workers:
        worker.join(timeout=WATCH_INTERVAL_S)


#: What a missing dask says (the check before a sweep starts, and the imports).
NO_DASK = "--backend dask needs dask's distributed scheduler: pip install 'rbm[dask]'"


def check_dask_installed() -> None:
    """Refuse the dask backend where dask.distributed is not installed (one line), before
    a sweep writes anything: a journal whose resume command repeats a backend that cannot
    run would be of no use."""
    try:
        found = all(importlib.util.find_spec(name) for name in ("dask", "distributed"))
    except (ImportError, ValueError):
        found = False
    if not found:
        raise RbmError(NO_DASK)


def _dask_client(scheduler: str | None):
    try:
        # lazy: dask is optional (an extra) (docs/architecture.md, Start-up)
        from dask.distributed import Client
    except ImportError:
        raise RbmError(NO_DASK) from None
    if not scheduler:
        return Client(processes=False)
    probe_dask(scheduler)
    try:
        return Client(scheduler, timeout=DASK_PROBE_TIMEOUT_S)
    except (OSError, TimeoutError, ValueError) as exc:
        raise RbmError(f"cannot reach the Dask scheduler {scheduler}: {exc}") from None


def probe_dask(address: str) -> None:
    """Connect and complete distributed's handshake within DASK_PROBE_TIMEOUT_S."""
    try:
        # lazy: dask is optional (an extra) (docs/architecture.md, Start-up)
        from distributed.comm import connect
    except ImportError:
        raise RbmError(NO_DASK) from None

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
