"""Parsers of record files (PEER NGA ``.AT2``, CSV): strict, in blocks of lines, one-line errors.

Used by :func:`rbm_cli.inputs.records.read_record`, which documents the formats, and by the
config's ``excitation.file`` check (:mod:`rbm_cli.config.excitation`), which refuses a malformed
record when the config is loaded (so they live here, below the inputs). Each parser returns
plain arrays in the file's units; every malformed file raises an
:class:`~rbm_cli.base.errors.RbmError` whose one-line message names the file and the line.
Memory is bounded: about 2 x 8 bytes a sample plus one block of lines; files of more than
:data:`MAX_SAMPLES` samples or :data:`MAX_FILE_BYTES` bytes are refused before they are read.
"""

from __future__ import annotations

import os
import re
import stat
from collections.abc import Callable, Iterator
from itertools import chain
from pathlib import Path

import numpy as np

from rbm_cli.base.errors import RbmError
from rbm_cli.config.types import G  # gravity [m/s^2], the one definition

#: Most samples a record may have (a larger file is refused before it is parsed).
MAX_SAMPLES = 10_000_000

#: Largest record file accepted [bytes].
MAX_FILE_BYTES = 512 * 2**20

#: Lines parsed per numpy block.
_BLOCK_LINES = 8192


#: Units of a record's acceleration values -> their value in m/s^2.
UNITS = {"g": G, "m/s2": 1.0, "m/s^2": 1.0}


def read_file(
    path: Path, units: str = "g", fmt: str | None = None
) -> tuple[np.ndarray, np.ndarray, str]:
    """Times [s], accelerations [m/s^2] and title of an ``.AT2`` or CSV record, checked.

    The format is the suffix's (``.at2``/``.csv``, any case) unless ``fmt`` is given;
    ``units`` are those of a CSV's values (an ``.AT2`` is in g: ``m/s2`` is refused).
    Every problem raises an RbmError in one line naming the file (and the line).
    """
    if units not in UNITS:
        raise RbmError(f"{path}: units must be 'g' or 'm/s2', got {units!r}")
    check_file(path)
    kind = (fmt or path.suffix.lstrip(".")).lower()
    if kind not in ("at2", "csv"):
        raise RbmError(f"{path}: unknown record format {kind!r} (expected .AT2 or .csv)")
    if kind == "at2" and UNITS[units] != UNITS["g"]:
        raise RbmError(f"{path}: an .AT2 file is in g; units {units!r} do not apply")
    _check_text(path)
    if kind == "at2":
        t, values, title = read_at2(path)
        _check_peak(path, t, values, UNITS[units])
    else:
        (t, values), title = read_csv(path, units), ""
    return t, values * UNITS[units], title


#: Largest acceleration a record may hold [g] (the grid's largest amplitude): beyond it
#: the file is not a ground motion (wrong units?) and its arithmetic is not sound.
MAX_ACCELERATION_G = 1e3


def _check_peak(path, t: np.ndarray, values: np.ndarray, unit: float) -> None:
    """Refuse a record whose largest |acceleration| is above MAX_ACCELERATION_G (checked in
    the file's units, before the conversion could overflow)."""
    k = int(np.argmax(np.abs(values)))
    limit = MAX_ACCELERATION_G * G / unit
    if abs(values[k]) > limit:
        raise RbmError(
            f"{path}: the acceleration at t = {t[k]:.6g} s is {values[k]:.6g} (in the file's"
            f" units), more than {MAX_ACCELERATION_G:g} g: not a ground motion (check"
            " excitation.units)"
        )


#: How far a record's time steps may stray from their mean, relative to it, for the record
#: to count as evenly sampled (a CSV's times written in decimals differ from k dt by
#: round-off, some 1e-12 relative; an uneven record differs by far more).
EVEN_STEP_RTOL = 1e-6


def uniform_step(t: np.ndarray) -> float | None:
    """The time step [s] of samples at even steps (their mean step), or None when the
    steps are uneven (one strays from the mean by more than EVEN_STEP_RTOL of it)."""
    t = np.asarray(t, dtype=float)
    if t.size < 2:
        return None
    step = float(t[-1] - t[0]) / (t.size - 1)
    if not step > 0.0 or np.max(np.abs(np.diff(t) - step)) > EVEN_STEP_RTOL * step:
        return None
    return step


def check_samples(where: str, t: np.ndarray, values: np.ndarray, units: str,
                  at: Callable[[int], str]) -> None:  # fmt: skip
    """The rules every record's samples meet, whatever they came from (a CSV file, or
    arrays given in memory): finite times and values, the first time >= 0 [s], times
    strictly increasing (steps may be uneven, as a CSV's), the largest |value| at most
    MAX_ACCELERATION_G in ``units`` (a key of UNITS). ``where`` names the record, ``at(k)``
    the place of sample k in it (``line 12`` of a file, ``sample 3`` of arrays); the
    RbmError is one line, ``<where>: <at(k)>: <problem>``."""
    for series in (t, values):
        bad = ~np.isfinite(series)
        if bad.any():
            k = int(np.argmax(bad))
            raise RbmError(f"{where}: {at(k)}: non-finite value {float(series[k])!r}")
    if t[0] < 0.0:
        raise RbmError(f"{where}: {at(0)}: time must be >= 0 [s], got {float(t[0])!r}")
    steps = np.diff(t)
    if np.any(steps <= 0.0):
        k = int(np.argmax(steps <= 0.0)) + 1
        raise RbmError(
            f"{where}: {at(k)}: time must increase, got {float(t[k])!r} after {float(t[k - 1])!r}"
        )
    _check_peak(where, t, values, UNITS[units])


def check_file(path: Path) -> None:
    """Refuse a missing or unreadable file, a folder, anything but a regular file (a FIFO
    would block the read, a device such as /dev/zero never end it) and a file larger
    than MAX_FILE_BYTES; the file is not opened (its status is read, symbolic links
    followed)."""
    shown = str(path)
    if any(ord(c) < 32 or ord(c) == 127 for c in shown):
        raise RbmError(
            f"{shown!r}: a record file's name must not hold control characters (tab, new"
            " line, carriage return...): rename it"
        )
    try:
        info = os.stat(path)
    except FileNotFoundError:
        raise RbmError(f"{path}: no such file") from None
    except OSError as exc:
        raise RbmError(f"{path}: cannot read ({exc.strerror or exc})") from None
    if stat.S_ISDIR(info.st_mode):
        raise RbmError(f"{path}: is a folder, not a record file")
    if not stat.S_ISREG(info.st_mode):
        raise RbmError(f"{path}: not a regular file (a pipe, socket or device): not a record")
    if info.st_size > MAX_FILE_BYTES:
        raise RbmError(
            f"{path}: {info.st_size} bytes, more than the {MAX_FILE_BYTES} bytes a record may have"
        )


def _check_text(path: Path) -> None:
    """Refuse a file that is not UTF-8 text: NUL bytes (UTF-16, a binary file) in its
    first block."""
    with open(path, "rb") as fh:
        head = fh.read(4096)
    if head.startswith((b"\xff\xfe", b"\xfe\xff")) or b"\x00" in head:
        raise RbmError(
            f"{path}: not UTF-8 text (it holds NUL bytes: UTF-16 or a binary file); save it"
            " as UTF-8 text"
        )


def _numbered_lines(fh) -> Iterator[tuple[int, str]]:
    yield from enumerate(fh, start=1)


def _blocks(lines: Iterator[tuple[int, str]], skip_comments: bool):
    """Non-blank lines in blocks: (line numbers, texts)."""
    numbers: list[int] = []
    texts: list[str] = []
    for lineno, line in lines:
        s = line.strip()
        if not s or (skip_comments and s.startswith("#")):
            continue
        numbers.append(lineno)
        texts.append(s)
        if len(texts) >= _BLOCK_LINES:
            yield numbers, texts
            numbers, texts = [], []
    if texts:
        yield numbers, texts


def _to_float(token: str) -> float:
    try:
        return float(token)
    except ValueError:
        # Fortran double-precision exponent: 1.0D-02
        if re.fullmatch(r"[-+]?(\d+\.?\d*|\.\d+)[dD][-+]?\d+", token):
            return float(token.replace("D", "E").replace("d", "e"))
        raise


def _floats(tokens: list[str], where) -> np.ndarray:
    """Tokens to floats; on a bad token, ``where(index, token)`` raises the error."""
    try:
        return np.fromiter(map(float, tokens), dtype=float, count=len(tokens))
    except ValueError:
        out = np.empty(len(tokens))
        for k, tok in enumerate(tokens):
            try:
                out[k] = _to_float(tok)
            except ValueError:
                where(k, tok)
        return out


def read_at2(path: Path) -> tuple[np.ndarray, np.ndarray, str]:
    """Times [s], values [g] and title (header line 2) of an .AT2 file, checked."""
    with open(path, encoding="utf-8", errors="replace", newline=None) as fh:
        lines = _numbered_lines(fh)
        header = [line for _, (_, line) in zip(range(4), lines, strict=False)]
        if not any(h.strip() for h in header):
            if len(header) < 4:
                raise RbmError(f"{path}: empty file")
            raise RbmError(f"{path}: line 1: missing header (the first 4 lines are blank)")
        if len(header) < 4:
            raise RbmError(
                f"{path}: line {len(header) + 1}: missing header line "
                "(an .AT2 file has 4 header lines, then the values)"
            )
        _check_at2_kind(path, header[2])
        npts, dt = _at2_npts_dt(path, header[3])
        values = np.empty(npts)
        count = 0
        for numbers, texts in _blocks(lines, skip_comments=False):
            split = [s.split() for s in texts]
            tokens = list(chain.from_iterable(split))
            line_end = np.cumsum([len(s) for s in split])

            def where(k, tok, numbers=numbers, line_end=line_end):
                n = numbers[int(np.searchsorted(line_end, k, side="right"))]
                raise RbmError(f"{path}: line {n}: not a number: {tok[:40]!r}")

            vals = _floats(tokens, where)
            if count + vals.size > npts:
                k = npts - count  # index in this block of the first value too many
                n = numbers[int(np.searchsorted(line_end, k, side="right"))]
                raise RbmError(f"{path}: line {n}: more values than NPTS = {npts} (header, line 4)")
            bad = ~np.isfinite(vals)
            if bad.any():
                k = int(np.argmax(bad))
                n = numbers[int(np.searchsorted(line_end, k, side="right"))]
                raise RbmError(f"{path}: line {n}: non-finite value {tokens[k][:40]!r}")
            values[count : count + vals.size] = vals
            count += vals.size
    if count != npts:
        raise RbmError(f"{path}: line 4: NPTS = {npts} but the file has {count} values")
    title = header[1].strip()
    return np.arange(npts) * dt, values, title


def _check_at2_kind(path: Path, line3: str) -> None:
    """Refuse velocity/displacement series (.VT2/.DT2) and units other than g."""
    upper = line3.upper()
    for word in ("VELOCITY", "DISPLACEMENT"):
        if word in upper:
            raise RbmError(
                f"{path}: line 3: a {word.lower()} time series, not an acceleration in g"
            )
    m = re.search(r"UNITS\s+OF\s+(\S+)", upper)
    if m and m.group(1).rstrip(".,;") != "G":
        raise RbmError(f"{path}: line 3: values must be in units of G, got {m.group(1)!r}")


_NEW_NPTS = re.compile(r"\bNPTS\s*=\s*([^\s,]+)", re.IGNORECASE)
_NEW_DT = re.compile(r"\bDT\s*=\s*([^\s,]+)", re.IGNORECASE)
_OLD = re.compile(r"^\s*(\S+)\s+(\S+)\s+NPTS\s*,?\s*DT\b", re.IGNORECASE)


def _at2_npts_dt(path: Path, line4: str) -> tuple[int, float]:
    """NPTS and DT from the fourth header line (both styles)."""
    m_n, m_dt = _NEW_NPTS.search(line4), _NEW_DT.search(line4)
    m_old = _OLD.match(line4)
    if m_n and m_dt:
        n_text, dt_text = m_n.group(1), m_dt.group(1)
    elif m_old:
        n_text, dt_text = m_old.group(1), m_old.group(2)
    else:
        shown = line4.strip()[:60]
        raise RbmError(
            f"{path}: line 4: expected 'NPTS= n, DT= dt SEC' or 'n dt NPTS, DT', got {shown!r}"
        )
    try:
        npts = int(n_text)
    except ValueError:
        raise RbmError(f"{path}: line 4: NPTS must be an integer, got {n_text!r}") from None
    try:
        dt = _to_float(dt_text)
    except ValueError:
        raise RbmError(f"{path}: line 4: DT must be a number, got {dt_text!r}") from None
    if npts < 2:
        raise RbmError(f"{path}: line 4: NPTS must be >= 2, got {npts}")
    if npts > MAX_SAMPLES:
        raise RbmError(f"{path}: line 4: NPTS = {npts}, more than the {MAX_SAMPLES} allowed")
    if not (np.isfinite(dt) and dt > 0.0):
        raise RbmError(f"{path}: line 4: DT must be > 0 [s], got {dt_text!r}")
    return npts, dt


def read_csv(path: Path, units: str = "g") -> tuple[np.ndarray, np.ndarray]:
    """Times [s] and accelerations (in the file's ``units``) of a CSV record, checked
    (:func:`check_samples`)."""
    times: list[np.ndarray] = []
    accels: list[np.ndarray] = []
    linenos: list[np.ndarray] = []
    total = 0
    with open(path, encoding="utf-8-sig", errors="replace", newline=None) as fh:
        blocks = _blocks(_numbered_lines(fh), skip_comments=True)
        first = next(blocks, None)
        if first is None:
            raise RbmError(f"{path}: empty file")
        head_no, head = first[0][0], first[1][0]
        _check_csv_header(path, head_no, head)
        for numbers, texts in chain([(first[0][1:], first[1][1:])], blocks):
            if not texts:
                continue
            rows = [s.split(",") for s in texts]
            for n, row in zip(numbers, rows, strict=True):
                if len(row) < 2:
                    raise RbmError(
                        f"{path}: line {n}: expected at least 2 columns "
                        f"(time, acceleration), got {len(row)}"
                    )
            tokens = [f.strip() for row in rows for f in row[:2]]

            def where(k, tok, numbers=numbers):
                raise RbmError(f"{path}: line {numbers[k // 2]}: not a number: {tok[:40]!r}")

            vals = _floats(tokens, where).reshape(-1, 2)
            total += len(vals)
            if total > MAX_SAMPLES:
                raise RbmError(f"{path}: more than the {MAX_SAMPLES} samples allowed")
            times.append(vals[:, 0])
            accels.append(vals[:, 1])
            linenos.append(np.asarray(numbers, dtype=np.int64))
    if total < 2:
        raise RbmError(f"{path}: needs at least 2 data rows after the header, has {total}")
    t, a, lines = np.concatenate(times), np.concatenate(accels), np.concatenate(linenos)
    check_samples(str(path), t, a, units, lambda k: f"line {lines[k]}")
    return t, a


def _check_csv_header(path: Path, lineno: int, text: str) -> None:
    fields = [f.strip() for f in text.split(",")]
    if len(fields) < 2:
        raise RbmError(
            f"{path}: line {lineno}: expected at least 2 columns (time, acceleration), "
            f"got {len(fields)}"
        )
    numeric = 0
    for f in fields[:2]:
        try:
            _to_float(f)
            numeric += 1
        except ValueError:
            pass
    if numeric == 2:
        raise RbmError(
            f"{path}: line {lineno}: missing header row (column names such as "
            "'time_s,acceleration_g'), got numbers"
        )
