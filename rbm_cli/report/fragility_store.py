"""The folder of a fragility set: one writer, leftovers of killed runs removed, the files
published together (`rbm fragility`, :func:`rbm_cli.report.fragility_report.write_fragility`).

A fragility run writes into its output folder, as the sweep publishes a domain
(rbm_cli.study.store):

- ``.fragility.lock``: held (``flock``) by the one run that writes the folder's fragility
  files, from before its bootstrap to the end of its publication. The kernel releases it
  when the run ends, however it ends; a second run into the folder is refused in one line.
- the set (:data:`FILES`) is written whole into a hidden staging folder
  ``.fragility.publish.<pid>.<random>/`` and flushed to the disk; only then are its files
  moved onto their names, fragility.json (which names the domain and its SHA-256) last,
  with SIGINT, SIGTERM and SIGHUP held back and by a process of its own
  (:func:`rbm_cli.base.folder.move_together`): a Ctrl-C waits until the set is whole, and
  a kill -9 of the run or of its process group cannot stop the moves half done. So the
  folder holds one whole set, the old one or the new one.
- what a killed run leaves (its staging folder, and the ``.<name>.<random>.tmp`` files
  that earlier versions staged beside the files) is removed by the next run into the
  folder, which holds the lock, so none of it can be in use. Nothing else is touched: no
  other file of the folder, and no staging folder of a sweep (``.publish.*``).
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

from rbm_cli.base.files import OutputError
from rbm_cli.base.folder import FolderLock, fsync_dir, fsync_file, move_together, signals_held

#: The files of a fragility set, in the order they are moved into place (the JSON last).
FILES = ("fragility.png", "ida.png", "fragility.csv", "fragility_curve.csv", "fragility.json")
LOCK = ".fragility.lock"
STAGING_PREFIX = ".fragility.publish."


class FragilityFolder:
    """The output folder of a fragility set, locked while the context is open (the
    folder is created on entry; see the module's docstring)."""

    def __init__(self, folder: str | os.PathLike):
        self.folder = Path(folder)
        self._lock = FolderLock(self.folder, LOCK, "rbm fragility")

    def __enter__(self) -> FragilityFolder:
        self._lock.__enter__()
        try:
            self.remove_leftovers()
        except BaseException:
            self._lock.__exit__(None, None, None)
            raise
        return self

    def __exit__(self, *exc) -> None:
        self._lock.__exit__(*exc)

    def remove_leftovers(self) -> list[str]:
        """Remove the staging folders and temporary files of fragility runs that were
        killed (with the lock held none is in use); returns their names."""
        removed = []
        for item in sorted(self.folder.iterdir()):
            name = item.name
            if name.startswith(STAGING_PREFIX) and item.is_dir() and not item.is_symlink():
                shutil.rmtree(item, ignore_errors=True)
            elif _stray_temporary(name) and item.is_file() and not item.is_symlink():
                item.unlink(missing_ok=True)
            else:
                continue
            removed.append(name)
        return removed

    def publish(self, contents: dict[str, str | bytes], retire: tuple[str, ...] = ()) -> list[Path]:
        """Write ``contents`` (file name: text or bytes, in :data:`FILES` order) into a
        staging folder, then move the files onto their names together (signals held,
        the last one last) and remove the files named in ``retire`` (files of the set
        being replaced that the new set does not have). Returns their paths.

        Raises
        ------
        OutputError
            One line: a file name taken by a folder, a write that failed (a full disk:
            the folder is then as it was), moves that failed.
        """
        for name in contents:
            if (self.folder / name).is_dir():
                raise OutputError(
                    f"{self.folder / name} is a folder: the fragility files need its name"
                )
        staging = Path(tempfile.mkdtemp(prefix=f"{STAGING_PREFIX}{os.getpid()}.", dir=self.folder))
        try:
            for name, data in contents.items():
                with open(staging / name, "wb") as fh:
                    fh.write(data.encode("utf-8") if isinstance(data, str) else data)
                fsync_file(staging / name)
            fsync_dir(staging)
            with signals_held():
                move_together([(staging / n, self.folder / n) for n in contents], self.folder)
                for name in retire:
                    (self.folder / name).unlink(missing_ok=True)
        except OSError as exc:
            raise OutputError(
                f"{self.folder}: cannot write the fragility files ({exc.strerror or exc})"
            ) from None
        finally:
            shutil.rmtree(staging, ignore_errors=True)
        return [self.folder / name for name in contents]


def _stray_temporary(name: str) -> bool:
    """A temporary file of an earlier version's publication: ``.<file>.<random>.tmp``."""
    return name.endswith(".tmp") and any(name.startswith(f".{f}.") for f in FILES)


__all__ = ["FILES", "LOCK", "STAGING_PREFIX", "FragilityFolder"]
