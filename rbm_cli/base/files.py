"""Files written atomically, and output folders checked before anything is made.

Every file is written to a temporary name in its destination folder and moved into place
with :func:`os.replace`, so a reader never sees half a file and an interrupted process
leaves no partial output. Used by the sweep's store, the run folder and the benchmark.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import math
import os
import shutil
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from rbm_cli.base.errors import RbmError

if TYPE_CHECKING:
    import pandas as pd

#: Significant digits of every float written to CSV.
FLOAT_FORMAT = "%.12g"


class OutputError(RbmError):
    """An output folder or file cannot be created or written."""


def current_umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


# --------------------------------------------------------------------------- atomic writers


@contextlib.contextmanager
def _atomic_target(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; move it onto ``path`` on success.

    On any exception the temporary file is removed and the exception re-raised.
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        os.chmod(tmp_path, 0o666 & ~current_umask())  # mkstemp makes 0o600 files
        yield tmp_path
        os.replace(tmp_path, path)
    except BaseException:
        with contextlib.suppress(OSError):
            tmp_path.unlink()
        raise


def write_csv_atomic(
    path: str | os.PathLike, frame: pd.DataFrame, float_format: str = FLOAT_FORMAT
) -> Path:
    """Write a table as CSV (no index, floats with 12 significant digits), atomically."""
    with _atomic_target(path) as tmp:
        frame.to_csv(tmp, index=False, float_format=float_format, lineterminator="\n")
    return Path(path)


def json_ready(obj: Any) -> Any:
    """Convert numpy scalars/arrays, tuples and dataclasses to JSON types.

    Non-finite floats (nan, inf) become ``None`` so the file is strict JSON.
    """
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return json_ready(dataclasses.asdict(obj))
    if isinstance(obj, dict):
        return {str(k): json_ready(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [json_ready(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return [json_ready(v) for v in obj.tolist()]
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, float | np.floating):
        value = float(obj)
        return value if math.isfinite(value) else None
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    return obj


def write_text_atomic(path: str | os.PathLike, text: str) -> Path:
    """Write text (UTF-8), atomically."""
    with _atomic_target(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)


def write_chunks_atomic(path: str | os.PathLike, chunks: Iterable[str | bytes]) -> Path:
    """Write text (UTF-8) or bytes given in pieces (a long CSV, a PNG), atomically."""
    with _atomic_target(path) as tmp, open(tmp, "wb") as fh:
        for chunk in chunks:
            fh.write(chunk.encode("utf-8") if isinstance(chunk, str) else chunk)
    return Path(path)


def write_json_atomic(path: str | os.PathLike, obj: Any) -> Path:
    """Write ``obj`` as indented, strict JSON (nan/inf as null), atomically."""
    return write_text_atomic(path, json.dumps(json_ready(obj), indent=2, allow_nan=False) + "\n")


def save_figure_atomic(fig, path: str | os.PathLike, dpi: int = 150) -> Path:
    """Save a matplotlib figure (format from the suffix of ``path``), atomically."""
    path = Path(path)
    fmt = path.suffix.lstrip(".") or "png"
    with _atomic_target(path) as tmp:
        fig.savefig(tmp, format=fmt, dpi=dpi, bbox_inches="tight")
    return path


def check_writable_dir(path: str | os.PathLike) -> Path:
    """Check, without creating anything, that ``path`` is or can become a writable folder.

    Raises
    ------
    OutputError
        If ``path`` or one of its existing ancestors is not a folder, or the
        nearest existing ancestor is not writable.
    """
    path = Path(path)
    probe = path
    while not probe.exists():
        if probe.is_symlink():  # dangling link
            raise OutputError(f"output folder {path}: {probe} is a broken link")
        parent = probe.parent
        if parent == probe:
            break
        probe = parent
    if probe.exists() and not probe.is_dir():
        raise OutputError(f"cannot create output folder {path}: {probe} is not a folder")
    if probe.exists() and not os.access(probe, os.W_OK | os.X_OK):
        raise OutputError(f"cannot write output folder {path}: {probe} is not writable")
    return path


def make_dirs(path: Path) -> None:
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        reason = exc.strerror or str(exc)
        raise OutputError(f"cannot create output folder {path}: {reason}") from None


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # exists, owned by someone else
        return True
    return True


def remove_stale_staging(parent: Path, folder: str) -> int:
    """Remove the staging folders ``.<folder>.<pid>.*`` that a killed ``rbm run`` left
    behind (their process is gone); a live run's staging is left alone. Returns how
    many were removed."""
    removed = 0
    for item in parent.glob(f".{folder}.*"):
        parts = item.name[len(folder) + 2 :].split(".", 1)
        if not (item.is_dir() and not item.is_symlink() and parts[0].isdigit()):
            continue
        if int(parts[0]) != os.getpid() and not _alive(int(parts[0])):
            shutil.rmtree(item, ignore_errors=True)
            removed += 1
    return removed
