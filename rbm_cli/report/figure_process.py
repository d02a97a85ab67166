"""Figures drawn by a process of their own, forked as `rbm sweep` or `rbm run` starts
(a shorter wall time: the figures' imports overlap the run).

A sweep of cheap cells, or one run, is mostly fixed cost: this process imports numba and
loads the compiled kernel or closed form (~0.5 s), and the figures need matplotlib (and
for a domain pandas) imported (~0.4 s) and drawn (~0.2-0.6 s). The command forks one
child as it starts, before either import: the child imports what its figures need
(:data:`DOMAIN_IMPORTS`, :data:`RUN_IMPORTS`) while this process runs the cells, then
runs the one call it is sent and exits. On two processors the two costs overlap instead
of adding up.

One protocol for both commands: the request is a module-level function (pickled by
reference) and its arguments; the reply is its return value or its exception, raised
here. The sweep sends rbm_cli.report.domain_figure's figure of its rows (dicts) and
columns, which the child turns into a DataFrame (rbm_cli.study.domain.domain_frame) and
saves to the path it is given: the sweep's process never imports pandas. A run sends
the two calls of rbm_cli.report.run_figures.run_png_calls and gets back the bytes of
history.png and shapes.png (the child writes no file; the run folder writes them, see
rbm_cli.report.run_folder.write_run): the run's process imports neither matplotlib nor
pandas. Several calls sent together (:meth:`FigureProcess.submit_all`) run side by side:
the first in the child, each other one in a grandchild the child forks once its imports
are done (a cheap fork), which sends its value back to the child through a pipe of its own
and is reaped by it. A grandchild ignores SIGINT too, and on Linux dies with the child
(elsewhere it ends once its call is done, its reply finding the pipe closed).

The child ignores SIGINT (a Ctrl-C in the terminal reaches the whole process group;
only the command acts on it), reads its one request from a pipe, and exits when the pipe
closes (its command ended or was killed, even by kill -9). The command kills and reaps it
when it ends without a figure to draw, or is interrupted while the child draws (before
the staging folder the figure is written into is removed). No fork (another platform,
threads running, RBM_FIGURE_PROCESS=0, fork failing) or a child that died: the call runs
in this process, as a library call of rbm_cli.api.run_sweep always does.
"""

from __future__ import annotations

import contextlib
import importlib
import os
import pickle
import signal
import struct
import sys
import threading

#: Environment switch: "0" draws in the command's own process.
ENV = "RBM_FIGURE_PROCESS"
#: What the child of `rbm sweep` imports before its request: domain.png's modules.
DOMAIN_IMPORTS = (
    "matplotlib.backends.backend_agg",  # savefig's canvas for png
    "matplotlib.figure",
    "pandas",
    "rbm_cli.report.domain_figure",
)
#: What the child of `rbm run` imports: history.png's and shapes.png's (no pandas).
RUN_IMPORTS = ("matplotlib.backends.backend_agg", "matplotlib.figure", "rbm_cli.report.run_figures")
_LEN = struct.Struct("<Q")


def _write(fd: int, obj) -> None:
    data = pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL)
    view = memoryview(_LEN.pack(len(data)) + data)
    while view:
        view = view[os.write(fd, view) :]


def _read_exact(fd: int, n: int) -> bytes | None:
    parts, left = [], n
    while left:
        chunk = os.read(fd, min(left, 1 << 20))
        if not chunk:
            return None  # the other end closed
        parts.append(chunk)
        left -= len(chunk)
    return b"".join(parts)


def _read(fd: int):
    """One object from the pipe, or None when the other end closed first."""
    head = _read_exact(fd, _LEN.size)
    if head is None:
        return None
    data = _read_exact(fd, _LEN.unpack(head)[0])
    return None if data is None else pickle.loads(data)


def domain_figure(df, config):
    """rbm_cli.report.domain_figure.domain_figure(df, config), imported when a figure is
    drawn (matplotlib and pandas with it): the function the child draws with."""
    # lazy: loads pandas only where needed (docs/architecture.md, Start-up)
    from rbm_cli.report.domain_figure import domain_figure as draw

    return draw(df, config)


def _draw(kind, table, config, path, kwargs) -> None:
    """domain.png of a DataFrame (``kind`` 'frame') or of (rows, fields) (``kind`` 'rows',
    the sweep's), saved to ``path``: what the sweep's child (or this process) runs."""
    if kind == "rows":
        # lazy: loads pandas only where needed (docs/architecture.md, Start-up)
        from rbm_cli.study.domain import domain_frame

        table = domain_frame(*table)
    domain_figure(table, config).savefig(path, **kwargs)


def _call(call):
    function, args, kwargs = call
    return function(*args, **kwargs)


def _outcome(run) -> tuple:
    """(run(), None), or (None, its exception) where the exception can be pickled (else a
    RuntimeError naming it): a reply."""
    try:
        return (run(), None)
    except Exception as exc:  # the command raises it (the sweep: publish_result)
        try:
            error = pickle.loads(pickle.dumps(exc))
        except Exception:
            error = RuntimeError(f"{type(exc).__name__}: {exc}")
        return (None, error)


def _die_with_parent(parent: int) -> None:
    """Have the kernel kill this process when its parent dies (Linux's PR_SET_PDEATHSIG),
    so a grandchild never outlives the child the command killed; elsewhere it ends once its
    call is done, its reply finding the pipe closed."""
    if not sys.platform.startswith("linux"):
        return
    with contextlib.suppress(Exception):
        # lazy: Linux only (docs/architecture.md, Start-up)
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # 1: PR_SET_PDEATHSIG
    if os.getppid() != parent:  # the child died before that was set
        os._exit(1)


def _fork_call(call, inherited: tuple[int, ...]):
    """Run ``call`` in a grandchild forked now (this child's imports are done, so the fork
    is cheap) and return a function that waits for its value: one figure drawn beside
    another on two processors. No fork: the function runs the call here."""
    read, write = os.pipe()
    parent = os.getpid()
    try:
        pid = os.fork()
    except OSError:
        os.close(read)
        os.close(write)
        return lambda: _call(call)
    if pid == 0:  # pragma: no cover - the grandchild (ends by os._exit, whatever happens)
        code = 0
        try:
            _die_with_parent(parent)
            for fd in (read, *inherited):  # the command's pipes are the child's alone
                os.close(fd)
            _write(write, _outcome(lambda: _call(call)))
        except BaseException:  # its child died (the pipe): nothing to send it
            code = 1
        finally:
            os._exit(code)
    os.close(write)

    def value():
        try:
            reply = _read(read)
        finally:
            os.close(read)
            os.waitpid(pid, 0)
        if reply is None:
            raise RuntimeError(f"the process drawing {call[0].__name__} died")
        if reply[1] is not None:
            raise reply[1]
        return reply[0]

    return value


def _run_calls(calls: list, inherited: tuple[int, ...]) -> list:
    """The values of ``calls`` run in the child: the first here, each other one at the same
    time in a grandchild of its own (which closes ``inherited``, the child's pipes to the
    command); every grandchild waited for before any error is raised."""
    pending = [_fork_call(call, inherited) for call in calls[1:]]
    try:
        values = [_call(calls[0])]
    finally:
        outcomes = [_outcome(value) for value in pending]  # (each grandchild reaped)
    for value, error in outcomes:
        if error is not None:
            raise error
        values.append(value)
    return values


def _serve(requests: int, replies: int, imports: tuple[str, ...]) -> None:
    """The child: import ``imports``, then run the calls asked for and send their values."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    for name in imports:
        importlib.import_module(name)
    calls = _read(requests)
    if calls is None:  # the command ended without a figure, or died
        return
    reply = _outcome(lambda: _run_calls(calls, (requests, replies)))
    with contextlib.suppress(OSError):
        _write(replies, reply)


class FigureProcess:
    """The child that draws a command's figures: :meth:`submit` a call, then take its
    :meth:`result` (or :meth:`call`, both at once); for a sweep, :attr:`figure` is the
    ``figure`` argument of rbm_cli.study.sweep.run_sweep in place of :attr:`draws`, the
    function the child runs. One call per child. Use as a context manager, or call close."""

    #: The function the child draws with (this module's lazy domain_figure).
    draws = staticmethod(domain_figure)

    def __init__(self, pid: int, requests: int, replies: int):
        self.pid, self._requests, self._replies = pid, requests, replies
        self._replied = False
        self._calls: list | None = None
        self._many = False

    @classmethod
    def start(cls, imports: tuple[str, ...] = DOMAIN_IMPORTS) -> FigureProcess | None:
        """Fork the child, which imports the modules ``imports`` (names) as it starts, or
        None where it cannot or should not be (see the module)."""
        if os.environ.get(ENV) == "0" or not hasattr(os, "fork"):
            return None
        if threading.active_count() > 1:  # fork copies one thread: not with others running
            return None
        req_r, req_w = os.pipe()
        rep_r, rep_w = os.pipe()
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                stream.flush()
        try:
            pid = os.fork()
        except OSError:
            for fd in (req_r, req_w, rep_r, rep_w):
                os.close(fd)
            return None
        if pid == 0:  # pragma: no cover - the child (ends by os._exit, whatever happens)
            code = 0
            try:
                os.close(req_w)
                os.close(rep_r)
                _serve(req_r, rep_w, imports)
            except BaseException:
                code = 1
            finally:
                os._exit(code)
        os.close(req_r)
        os.close(rep_w)
        return cls(pid, req_w, rep_r)

    @property
    def figure(self) -> _Painter:
        """What the sweep calls for domain.png: ``figure(df, config)`` or (the sweep's)
        ``figure.from_rows(rows, fields, config)``, an object whose savefig has the child
        draw domain_figure of that domain and save it."""
        return _Painter(self)

    def submit(self, function, *args, **kwargs) -> None:
        """Send the child ``function(*args, **kwargs)`` (a module-level function, pickled by
        reference) and return at once; :meth:`result` waits for its value."""
        self._send([(function, args, kwargs)], many=False)

    def submit_all(self, calls: list[tuple]) -> None:
        """Send the child ``calls``, (function, args) pairs, and return at once: the child
        runs the first and forks a grandchild for each other one, all at the same time
        (figures drawn on as many processors); :meth:`result` waits for the list of their
        values."""
        self._send([(function, tuple(args), {}) for function, args in calls], many=True)

    def _send(self, calls: list[tuple], many: bool) -> None:
        """The request; it blocks only while the child, still importing, has not read a
        request larger than the pipe holds."""
        self._calls, self._many = calls, many
        if self.pid is None:
            return
        try:
            _write(self._requests, calls)
        except OSError:  # the child is gone: result() runs them here
            self.close()
        except BaseException:  # Ctrl-C
            self.close()
            raise

    def result(self):
        """The value of the call submitted (the list of values for submit_all), its
        exception raised here, once the child has sent it; the child is then reaped. Run
        here, one after the other, if there is no child or it died."""
        calls, self._calls = self._calls, None
        if calls is None:
            raise RuntimeError("FigureProcess.result without a call submitted")
        reply = None
        if self.pid is not None:
            try:
                reply = _read(self._replies)
            except OSError:
                reply = None
            except BaseException:  # Ctrl-C while it draws: stopped before the folder goes
                self.close()
                raise
            self._replied = reply is not None
            self.close()
        if reply is None:  # no child, or it is gone: run here
            values = [_call(call) for call in calls]
        else:
            values, error = reply
            if error is not None:
                raise error
        return values if self._many else values[0]

    def call(self, function, *args, **kwargs):
        """``function(*args, **kwargs)`` run by the child (see :meth:`submit`)."""
        self.submit(function, *args, **kwargs)
        return self.result()

    def _savefig(self, kind, table, config, path, kwargs) -> None:
        self.call(_draw, kind, table, config, os.fspath(path), kwargs)

    def close(self) -> None:
        """Stop the child (killed unless it has replied and is exiting) and reap it."""
        if self.pid is None:
            return
        for fd in (self._requests, self._replies):
            with contextlib.suppress(OSError):
                os.close(fd)
        with contextlib.suppress(OSError):
            if not self._replied:  # still importing or waiting: nothing of it is needed
                os.kill(self.pid, signal.SIGKILL)
            os.waitpid(self.pid, 0)  # (one that replied is exiting)
        self.pid = None

    def __enter__(self) -> FigureProcess:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class _Painter:
    """FigureProcess.figure: a domain (a DataFrame, or rows and their fields) to a figure
    the child draws."""

    def __init__(self, owner: FigureProcess):
        self._owner = owner

    def __call__(self, df, config) -> _Remote:
        return _Remote(self._owner, "frame", df, config)

    def from_rows(self, rows: list[dict], fields: tuple[str, ...], config) -> _Remote:
        """The figure of a sweep's rows (dicts with the columns ``fields``): the child builds
        the DataFrame (rbm_cli.study.domain.domain_frame), not this process."""
        return _Remote(self._owner, "rows", (rows, tuple(fields)), config)


class _Remote:
    """A figure to be drawn by the child: the one method the sweep calls is savefig."""

    def __init__(self, owner: FigureProcess, kind: str, table, config):
        self._owner, self._kind, self._table, self._config = owner, kind, table, config

    def savefig(self, path, **kwargs) -> None:
        self._owner._savefig(self._kind, self._table, self._config, path, kwargs)


__all__ = ["ENV", "FigureProcess"]
