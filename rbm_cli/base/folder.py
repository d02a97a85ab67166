"""One writer per folder, and files that belong together moved into place together.

:class:`FolderLock` is an exclusive lock on a file in a folder, held by the one process
that writes the files it guards; :func:`move_together` moves staged files onto their names
so that a kill of the process (kill -9 included) between two moves cannot leave them half
done. :func:`signals_held` holds SIGINT, SIGTERM and SIGHUP back while files are moved. Used by
the sweep's store (rbm_cli.study.store) and `rbm fragility` (rbm_cli.report.fragility_store).
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
import signal
import threading
from collections.abc import Iterator
from pathlib import Path

from rbm_cli.base.files import OutputError, make_dirs


def fsync_file(path: str | os.PathLike) -> None:
    """Flush a file's data to the disk."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def fsync_dir(folder: str | os.PathLike) -> None:
    """Flush a folder's entries (renames, new files) to the disk, where the system allows."""
    with contextlib.suppress(OSError):
        fsync_file(folder)


@contextlib.contextmanager
def signals_held() -> Iterator[None]:
    """SIGINT, SIGTERM and SIGHUP held back (delivered after the block), so a Ctrl-C
    cannot land between two renames of a publication. SIGKILL cannot be held."""
    held = {signal.SIGINT, signal.SIGTERM, signal.SIGHUP}
    try:
        old = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    except (AttributeError, OSError, ValueError):  # not POSIX, or not allowed here
        yield
        return
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


class FolderBusy(OutputError):
    """Another process holds a folder's lock."""


class FolderLock:
    """An exclusive lock (``flock``) on the file ``name`` in ``folder``, held from
    ``__enter__`` (which creates the folder) to ``__exit__`` (which removes the file).

    The kernel releases the lock when its holder ends, however it ends (kill -9
    included), so a killed writer leaves no stale lock, only the file, which the next
    holder removes. A process forked while it is held holds it too, until it ends.
    A second holder is refused in one line (:class:`FolderBusy`) naming ``what`` holds
    it and its process id.
    """

    def __init__(self, folder: str | os.PathLike, name: str, what: str):
        self.folder = Path(folder)
        self.path = self.folder / name
        self.what = what
        self._fd: int | None = None

    def __enter__(self) -> FolderLock:
        make_dirs(self.folder)
        for _ in range(100):  # the file may be removed by its holder as it ends
            fd = self._lock_once()
            if fd is not None:
                break
        else:  # pragma: no cover - a hundred holders in a row
            raise FolderBusy(f"{self.folder} is being written by another {self.what}")
        self._fd = fd
        with contextlib.suppress(OSError):
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        return self

    def _lock_once(self) -> int | None:
        """The locked file's descriptor; None if the file was replaced meanwhile."""
        try:
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise OutputError(
                f"cannot write to output folder {self.folder}: {exc.strerror or exc}"
            ) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            os.close(fd)
            if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                raise FolderBusy(
                    f"{self.folder} is being written by another {self.what}{self._holder()}: "
                    "wait for it to end, or use another -o folder"
                ) from None
            raise OutputError(f"cannot lock {self.path}: {exc.strerror or exc}") from None
        try:
            same = os.stat(self.path).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            same = False
        if not same:  # its holder removed it after we opened it: lock the new one
            os.close(fd)
            return None
        return fd

    def _holder(self) -> str:
        with contextlib.suppress(OSError, ValueError, IndexError):
            return f" (pid {int(self.path.read_text().split()[0])})"
        return ""

    def __exit__(self, *exc) -> None:
        if self._fd is not None:
            with contextlib.suppress(OSError):
                self.path.unlink()  # still held: a waiter re-checks the inode
            os.close(self._fd)  # releases the flock
            self._fd = None


def move_together(moves: list[tuple[Path, Path]], folder: str | os.PathLike) -> None:
    """Move files onto their names (one :func:`os.replace` each, in order), then flush
    ``folder``, in a process of its own when one can be forked.

    That process is forked in a session of its own, so a kill of this process or of its
    process group (Ctrl-C in a terminal, kill -9) between two moves cannot leave them half
    done: it finishes them, and holds what this process held (a :class:`FolderLock`)
    until it has. The caller holds SIGINT, SIGTERM and SIGHUP back around the call
    (:func:`signals_held`), so that they too wait for the end; the child
    inherits that. Without a fork (another platform, Python threads running, the fork
    refused) the moves are made here: a kill -9 between two of them is then not covered.

    Raises
    ------
    OutputError
        One line: a move failed (the moves before it are done, so the folder holds old
        and new files), or the process moving them was killed.
    """
    pid, reply = _fork_mover(moves, folder)
    if pid is None:
        try:
            _move(moves, folder)
        except OSError as exc:
            raise OutputError(
                f"{folder}: cannot move the files into place: {_reason(exc)}"
            ) from None
        return
    chunks = []
    while chunk := os.read(reply, 4096):
        chunks.append(chunk)
    os.close(reply)
    with contextlib.suppress(ChildProcessError):  # reaped already (SIGCHLD ignored)
        os.waitpid(pid, 0)
    answer = b"".join(chunks).decode("utf-8", "replace")
    if answer != "ok":
        raise OutputError(
            f"{folder}: cannot move the files into place: {answer or 'the mover was killed'}"
        )


def _fork_mover(moves, folder) -> tuple[int | None, int]:
    """(pid, read end of its reply pipe) of a forked child making the moves; (None, -1)
    when there is none (no fork, Python threads running, fork refused)."""
    if not hasattr(os, "fork") or not hasattr(os, "setsid") or threading.active_count() > 1:
        return None, -1  # fork copies one thread: not with others running
    reply, write_end = os.pipe()
    try:
        pid = os.fork()
    except OSError:  # no memory, no process slot
        os.close(reply)
        os.close(write_end)
        return None, -1
    if pid == 0:  # the child: moves, says how it went, and ends (never returns)
        answer = b"the mover failed"
        try:
            os.close(reply)
            with contextlib.suppress(OSError):
                os.setsid()  # out of the process group a kill -9 or a Ctrl-C reaches
            _move(moves, folder)
            answer = b"ok"
        except OSError as exc:
            answer = _reason(exc).encode("utf-8", "replace")
        finally:
            with contextlib.suppress(BaseException):
                os.write(write_end, answer)
            os._exit(0)
    os.close(write_end)
    return pid, reply


def _move(moves, folder) -> None:
    for source, target in moves:
        os.replace(source, target)
    fsync_dir(folder)


def _reason(exc: OSError) -> str:
    name = f" ({exc.filename})" if exc.filename else ""
    return f"{exc.strerror or exc}{name}"
