"""The sweep's store: one writer per folder, a validated journal, an atomic publication.

A sweep of config <name> writes OUTPUT/<name>/:

- ``.sweep.lock``: held (``flock``) by the one sweep that writes the folder. The kernel
  releases it when that process ends, however it ends, so a killed sweep leaves no stale
  lock; a second sweep into the folder is refused in one line.
- ``domain.partial.jsonl``, the journal: a header line (the config's hash and its
  solver.method as written, which a resume keeps: rbm_cli.study.sweep), then one
  JSON row per finished cell, each carrying the hash too, appended and fsync'ed chunk by
  chunk. Every row read back is validated (types, ranges, status values, status and
  collapsed agreeing, the cell in the grid, the hash); a row that fails is not trusted but
  run again, and a line cut by a kill is expected.
- ``domain.partial.json``, the state file: the hash and the resume command. Its loss is
  recovered from the journal (every row holds the hash).
- the result (``domain.csv``, ``boundary.csv``, ``domain.png``, ``meta.json``) is written
  whole into a hidden staging folder ``.publish.<pid>.<random>/``, fsync'ed, and only then
  moved into place, with SIGINT, SIGTERM and SIGHUP held back, meta.json last; the journal
  is removed after. So a folder whose journal exists is unfinished, whatever else it holds,
  and a folder with meta.json and no journal is finished. A staging folder left by a
  killed sweep is removed by the next sweep of the folder (which holds the lock).

Nothing here deletes a finished cell: a journal or a finished result that a new sweep
may not continue is refused, or, with ``force``, moved to ``superseded/<time>/``.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from rbm_cli.base.errors import RbmError
from rbm_cli.base.files import current_umask
from rbm_cli.base.folder import FolderBusy, FolderLock, fsync_dir, fsync_file, signals_held
from rbm_cli.study.domain import row_key
from rbm_cli.study.journal_rows import validate_row

JOURNAL = "domain.partial.jsonl"
STATE = "domain.partial.json"
LOCK = ".sweep.lock"
FINALS = ("domain.png", "boundary.csv", "domain.csv", "meta.json")  # publication order
STAGING_PREFIX = ".publish."
SUPERSEDED = "superseded"
JOURNAL_FORMAT = 1


@dataclass
class JournalRead:
    """What a journal holds: the valid rows by cell, and what was not trusted."""

    rows: dict[tuple[str, ...], dict] = field(default_factory=dict)
    hashes: set[str] = field(default_factory=set)  # config hashes seen (header and rows)
    rejected: int = 0  # lines that failed validation (run again)
    first_problem: str = ""
    cut: bool = False  # the last line was cut (no newline: a kill while writing)
    solver_method: str | None = None  # the header's solver.method (None: not recorded)
    records: list | None = None  # the header's record files [key, file, SHA-256] (None: none)


class SweepStore:
    """The folder of one sweep, locked for as long as the store is open (a context
    manager). See the module's docstring for the layout."""

    def __init__(self, folder: str | os.PathLike):
        self.folder = Path(folder)
        self.journal = self.folder / JOURNAL
        self.state = self.folder / STATE
        self._lock: FolderLock | None = None
        self._fh = None

    # ---------------------------------------------------------------- lock
    def __enter__(self) -> SweepStore:
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise RbmError(
                f"cannot write to output folder {self.folder}: {exc.strerror or exc}"
            ) from None
        self._lock = FolderLock(self.folder, LOCK, "sweep").__enter__()
        self._remove_stale_staging()
        return self

    def __exit__(self, *exc) -> None:
        self.close_journal()
        if self._lock is not None:
            self._lock.__exit__(*exc)
            self._lock = None

    def _remove_stale_staging(self) -> None:
        """Staging folders of publications that did not finish, and temporary copies of the
        journal's header or the state file that a kill left before their rename: with the
        lock held, none can be in use."""
        for item in self.folder.glob(STAGING_PREFIX + "*"):
            if item.is_dir() and not item.is_symlink():
                shutil.rmtree(item, ignore_errors=True)
        for name in (JOURNAL, STATE):
            for item in self.folder.glob(f".{name}.*.tmp"):
                if item.is_file() and not item.is_symlink():
                    with contextlib.suppress(OSError):
                        item.unlink()

    # ---------------------------------------------------------------- what the folder holds
    def finished_hash(self) -> str | None:
        """The config hash of the finished result here ('' if meta.json is unreadable),
        or None if there is no finished result (no meta.json, or a journal: unfinished)."""
        meta = self.folder / "meta.json"
        if self.journal.exists() or not meta.is_file():
            return None
        try:
            value = json.loads(meta.read_text(encoding="utf-8")).get("config_hash", "")
            return value if isinstance(value, str) else ""
        except (OSError, ValueError, AttributeError):
            return ""

    def state_hash(self) -> str | None:
        """The hash in the state file, or None if it is missing or unreadable."""
        try:
            value = json.loads(self.state.read_text(encoding="utf-8")).get("config_hash")
        except (OSError, ValueError, AttributeError):
            return None
        return value if isinstance(value, str) else None

    def read_journal(
        self,
        digest: str,
        grid: set[tuple[str, ...]],
        n_interfaces: int,
        ensemble: int,
        paths: tuple[str, ...] = (),
    ) -> JournalRead:
        """Every line of the journal, validated (see validate_row). A line cut by a kill
        (the last one, without its newline) is expected and not counted as rejected."""
        out = JournalRead()
        try:
            data = self.journal.read_bytes()
        except FileNotFoundError:
            return out
        except OSError as exc:
            raise RbmError(f"cannot read {self.journal}: {exc.strerror or exc}") from None
        lines = data.split(b"\n")
        if lines and lines[-1] == b"":
            lines.pop()
        elif lines:
            out.cut = True
        legacy = self.state_hash() == digest  # rows of a journal without hashes
        for number, raw in enumerate(lines, start=1):
            last_cut = out.cut and number == len(lines)
            try:
                row = json.loads(raw.decode("utf-8"))
            except (UnicodeDecodeError, ValueError):
                if not last_cut:
                    out.rejected += 1
                    out.first_problem = out.first_problem or f"line {number}: not JSON text"
                continue
            if isinstance(row, dict) and "rbm_journal" in row:  # the header
                if isinstance(row.get("records"), list):
                    out.records = row["records"]
                if isinstance(row.get("config_hash"), str):
                    out.hashes.add(row["config_hash"])
                    legacy = legacy or row["config_hash"] == digest
                    if row["config_hash"] == digest and isinstance(row.get("solver_method"), str):
                        out.solver_method = row["solver_method"]
                continue
            if isinstance(row, dict) and isinstance(row.get("config_hash"), str):
                out.hashes.add(row["config_hash"])
            problem = validate_row(row, digest, grid, n_interfaces, ensemble, paths)
            if not problem and "config_hash" not in row and not legacy:
                problem = "no config hash, and no state file of this config to vouch for it"
            if problem:
                if not last_cut:
                    out.rejected += 1
                    out.first_problem = out.first_problem or f"line {number}: {problem}"
                continue
            out.rows.setdefault(row_key(row, paths), row)
        return out

    # ---------------------------------------------------------------- writing
    def set_aside(self, names: Iterable[str]) -> Path:
        """Move these files of the folder to superseded/<UTC time>/ (never delete them)."""
        stamp = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())
        target = self.folder / SUPERSEDED / stamp
        k = 1
        while target.exists():
            k += 1
            target = self.folder / SUPERSEDED / f"{stamp}-{k}"
        target.mkdir(parents=True)
        for name in names:
            if (self.folder / name).exists():
                os.replace(self.folder / name, target / name)
        fsync_dir(self.folder)
        return target

    def start_journal(
        self,
        digest: str,
        n_cells: int,
        resume_command: str,
        solver_method: str | None = None,
        records: Sequence | None = None,
    ) -> None:
        """A new journal (header line) and state file, replacing none: the caller has
        made sure no journal is here (or set it aside). solver_method: the config's
        solver.method as written (auto, DOP853, ...), kept for the resume; records: the
        record files the config names (key path, file, SHA-256), kept so that a resume
        over a changed record can name it.

        Raises
        ------
        RbmError  The journal cannot be written (a full disk, a read-only folder): one
            line; no journal or state file is left
        """
        header = {
            "rbm_journal": JOURNAL_FORMAT,
            "config_hash": digest,
            "n_cells": n_cells,
            "started_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        }
        if solver_method is not None:
            header["solver_method"] = solver_method
        if records:
            header["records"] = [list(r) for r in records]
        try:
            self._write_small(self.journal, json.dumps(header) + "\n")
            self.write_state(digest, n_cells, resume_command)
        except OSError as exc:
            for path in (self.journal, self.state):
                with contextlib.suppress(OSError):
                    path.unlink()
            raise RbmError(
                f"cannot start the sweep's journal in {self.folder}:"
                f" {exc.strerror or exc}; nothing was run"
            ) from None

    def write_state(self, digest: str, n_cells: int, resume_command: str) -> None:
        state = {"config_hash": digest, "n_cells": n_cells, "resume": resume_command}
        self._write_small(self.state, json.dumps(state) + "\n")

    def _write_small(self, path: Path, text: str) -> None:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=self.folder)
        try:
            os.fchmod(fd, 0o666 & ~current_umask())  # mkstemp makes 0o600 files
            with os.fdopen(fd, "w", encoding="utf-8") as fh:
                fh.write(text)
                fh.flush()
                os.fsync(fh.fileno())
            os.replace(tmp, path)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            raise
        fsync_dir(self.folder)

    def open_journal(self) -> None:
        """Open the journal for appending; a line cut by a kill gets its newline first,
        so the next row is not glued to it."""
        self._fh = self.journal.open("ab")
        if self._fh.tell() > 0:
            with self.journal.open("rb") as fh:
                fh.seek(-1, os.SEEK_END)
                if fh.read(1) != b"\n":
                    self._fh.write(b"\n")

    def append(self, rows: Sequence[dict], digest: str) -> None:
        """Rows of finished cells, each with the config hash; flushed and fsync'ed."""
        text = "".join(json.dumps({**row, "config_hash": digest}) + "\n" for row in rows)
        self._fh.write(text.encode("utf-8"))
        self._fh.flush()
        os.fsync(self._fh.fileno())

    def close_journal(self) -> None:
        if self._fh is not None:
            with contextlib.suppress(OSError):
                self._fh.close()
            self._fh = None

    def publish(self, writers: Sequence[tuple[str, Callable[[Path], None]]]) -> None:
        """Write every final file into a staging folder, then move them into place in
        one step (signals held, meta.json last) and remove the journal and state file.

        ``writers``: (file name, function writing that file at the given path), in
        FINALS order. A failure while writing (a full disk, a plot error) leaves the
        folder as it was: the journal and any older result untouched."""
        self.close_journal()
        staging = Path(tempfile.mkdtemp(prefix=f"{STAGING_PREFIX}{os.getpid()}.", dir=self.folder))
        try:
            for name, write in writers:
                write(staging / name)
                fsync_file(staging / name)
            fsync_dir(staging)
            with signals_held():
                for name, _ in writers:
                    os.replace(staging / name, self.folder / name)
                fsync_dir(self.folder)
                self.journal.unlink(missing_ok=True)
                self.state.unlink(missing_ok=True)
                fsync_dir(self.folder)
        finally:
            shutil.rmtree(staging, ignore_errors=True)


__all__ = [
    "FINALS",
    "JOURNAL",
    "LOCK",
    "STATE",
    "FolderBusy",
    "JournalRead",
    "SweepStore",
    "signals_held",
    "validate_row",
]
