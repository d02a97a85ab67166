"""domain.png drawn by a process of its own, forked when a sweep starts (issue 18).

A sweep of cheap cells is mostly fixed cost: this process imports numba and loads the
compiled kernel (~0.5 s), and drawing domain.png needs matplotlib and pandas imported
(~0.4 s) and the figure drawn (~0.2 s). `rbm sweep` forks one child as it starts, before
either import: the child imports what the figure needs while this process runs the
cells, then draws the figure it is sent and exits. On two processors the two costs
overlap instead of adding up. The sweep sends the child its rows (dicts) and columns, and
the child builds the DataFrame (rbm_cli.study.domain.domain_frame): the sweep's process
never imports pandas. The figure is the same: the child runs
rbm_cli.report.domain_figure.domain_figure and savefig with the sweep's arguments.

The child ignores SIGINT (a Ctrl-C in the terminal reaches the whole process group;
only the sweep acts on it), reads its one request from a pipe, and exits when the pipe
closes (its sweep ended or was killed, even by kill -9). The sweep kills and reaps it
when it ends without a figure to draw, or is interrupted while the child draws (before
the staging folder the figure is written into is removed). No fork (another platform,
threads running, RBM_FIGURE_PROCESS=0, fork failing) or a child that died: the figure is
drawn in this process, as a library call of rbm_cli.api.run_sweep always does.
"""

from __future__ import annotations

import contextlib
import os
import pickle
import signal
import struct
import sys
import threading

#: Environment switch: "0" draws in the sweep's own process.
ENV = "RBM_FIGURE_PROCESS"
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
    from rbm_cli.report.domain_figure import domain_figure as draw

    return draw(df, config)


def _draw(request) -> None:
    """The work of the child (and of this process when no child can): domain.png of a
    DataFrame (``kind`` 'frame') or of (rows, fields) (``kind`` 'rows', the sweep's)."""
    kind, table, config, path, kwargs = request
    if kind == "rows":
        from rbm_cli.study.domain import domain_frame

        table = domain_frame(*table)
    domain_figure(table, config).savefig(path, **kwargs)


def _serve(requests: int, replies: int) -> None:
    """The child: import what a figure needs, then draw the one figure asked for."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    import matplotlib.backends.backend_agg  # noqa: F401  (savefig's canvas for png)
    import matplotlib.figure  # noqa: F401
    import pandas  # noqa: F401

    import rbm_cli.report.domain_figure  # noqa: F401

    request = _read(requests)
    if request is None:  # the sweep ended without a figure, or died
        return
    try:
        _draw(request)
        reply = None
    except Exception as exc:  # the sweep reports it (publish_result)
        try:
            reply = pickle.loads(pickle.dumps(exc))
        except Exception:
            reply = RuntimeError(f"{type(exc).__name__}: {exc}")
    with contextlib.suppress(OSError):
        _write(replies, ("done", reply))


class FigureProcess:
    """The child that draws a sweep's domain.png; :attr:`figure` is the sweep's ``figure``
    argument (rbm_cli.study.sweep.run_sweep) in place of :attr:`draws`, the function the
    child runs. Use as a context manager, or call close."""

    #: The function the child draws with (this module's lazy domain_figure).
    draws = staticmethod(domain_figure)

    def __init__(self, pid: int, requests: int, replies: int):
        self.pid, self._requests, self._replies = pid, requests, replies
        self._replied = False

    @classmethod
    def start(cls) -> FigureProcess | None:
        """Fork the child, or None where it cannot or should not be (see the module)."""
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
                _serve(req_r, rep_w)
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

    def _savefig(self, kind, table, config, path, kwargs) -> None:
        request = (kind, table, config, os.fspath(path), kwargs)
        if self.pid is None:
            return _draw(request)
        try:
            _write(self._requests, request)
            reply = _read(self._replies)
        except OSError:
            reply = None
        except BaseException:  # Ctrl-C while it draws: it stops before the folder goes
            self.close()
            raise
        self._replied = reply is not None
        self.close()
        if reply is None:  # the child is gone: draw here
            return _draw(request)
        error = reply[1]
        if error is not None:
            raise error

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
