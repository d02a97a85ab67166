"""The ``grid`` section: amplitudes x frequencies x any other config key.

A grid is the product of its axes. ``amplitudes`` [g] and ``frequencies`` [Hz] are the
excitation's; every other key is an **axis over a config key** named by its dotted path
(``column.height``, ``interface.stiffness.normal``, ``excitation.file`` ...),
with the same value syntax (a value, a list, or ``{start, stop, num | step, spacing}``).
Axes that vary together are **linked**: ``linked`` is a list of mappings, each of two or
more paths to lists of one length, one axis whose k-th point sets every path to its k-th
value. Two virtual paths describe a column by shape and size instead of its keys:

- ``column.size`` [m]: the height of a geometrically similar column: every length of the
  column (height, widths, depth, listed drum heights) is scaled by size / height;
- ``column.slenderness`` [-]: H / B_1: the base width becomes height / slenderness and
  the top width and depth scale with it (the taper is kept).

Each point of the axes is a config of its own, validated as a config is (rbm_cli.config
.points): a bad value is refused in one line naming the axis, the value and the problem.
"""

from __future__ import annotations

import glob
import os
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from rbm_cli.base.errors import ConfigError
from rbm_cli.config.motions import Motion, unique_names
from rbm_cli.config.types import Axis, GridConfig
from rbm_cli.config.validate import (
    MAX_GRID_VALUES,
    describe,
    fmt,
    grid_axis,
    is_number,
    join,
    mapping,
)

#: Grid and command-line excitation ranges [assumption]: g and Hz at the edges.
AMPLITUDE_RANGE_G = (0.0, 1e3)
FREQUENCY_RANGE_HZ = (1e-3, 1e3)
#: Keys of the excitation's own axes, and the key of linked axes.
EXCITATION_AXES = ("amplitudes", "frequencies")
LINKED = "linked"
#: Paths that are not config keys but describe the column by similarity (module docstring).
VIRTUAL_PATHS = {"column.size": "m", "column.slenderness": ""}
#: Keys that cannot vary over a grid: the folder name, the grid itself.
FIXED_KEYS = ("name", "grid")
#: Top-level keys of one value, which cannot be an axis either (a domain holds one model).
TOP_SCALARS = ("model",)
#: Sections, which vary by the keys inside them (one named as an example).
SECTIONS = {
    "column": "column.height",
    "interface": "interface.restitution",
    "excitation": "excitation.file",
    "collapse": "collapse.ratio",
    "solver": "solver.rtol",
}
#: Largest number of points of the non-excitation axes together (each is one config).
MAX_POINTS = 10_000
#: Most cells a grid may have, with or without ``--force`` (a sweep keeps a row per cell in
#: memory, about 2 kB each; 10^6 cells are days of runs at 0.1-1 s a cell).
MAX_CELLS = 1_000_000
PATH_RE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*")


def parse_grid(raw: Any) -> GridConfig:
    """The validated ``grid`` section (module docstring); an empty grid when absent."""
    if raw is not None and not isinstance(raw, Mapping):
        raise ConfigError(
            "grid must be a mapping (amplitudes, frequencies, linked, or config key paths),"
            f" got {describe(raw)}"
        )
    g = dict(raw or {})
    amplitudes, frequencies = (
        grid_axis(g[key], join("grid", key), unit, lo_open=lo_open, bounds=bounds)
        if key in g
        else ()
        for key, unit, lo_open, bounds in (
            ("amplitudes", "g", False, AMPLITUDE_RANGE_G),
            ("frequencies", "Hz", True, FREQUENCY_RANGE_HZ),
        )
    )
    grid = GridConfig(amplitudes_g=amplitudes, frequencies_hz=frequencies, axes=parse_axes(g))
    if grid.n_cells > MAX_CELLS:  # counted before any point is built
        sizes = [len(amplitudes), len(frequencies)] + [len(a.points) for a in grid.axes]
        shown = " x ".join(f"{n:,}" for n in sizes if n)
        raise ConfigError(
            f"grid: {shown} = {grid.n_cells:,} cells, more than the {MAX_CELLS:,} a sweep"
            " can hold: split it into several configs"
        )
    return grid


def parse_axes(raw: Mapping[str, Any]) -> tuple[Axis, ...]:
    """The axes over config keys of a grid mapping (every key but amplitudes and
    frequencies), in the order written."""
    axes = []
    for key, value in raw.items():
        if key in EXCITATION_AXES:
            continue
        if key == LINKED:
            axes.extend(_linked(value))
            continue
        path = _path(key, f"grid.{key}")
        axes.append(Axis((path,), tuple((v,) for v in _values(value, f"grid.{key}", path))))
    paths = [p for axis in axes for p in axis.paths]
    for p in set(paths):
        if paths.count(p) > 1:
            raise ConfigError(f"grid: the axis {p} is given twice (once per grid)")
    if "column.size" in paths and "column.height" in paths:
        raise ConfigError("grid: column.size and column.height both set the height: use one")
    if "column.slenderness" in paths and "column.base_width" in paths:
        raise ConfigError(
            "grid: column.slenderness and column.base_width both set the base width: use one"
        )
    n_points = 1
    for axis in axes:
        n_points *= len(axis.points)
    if n_points > MAX_POINTS:
        raise ConfigError(
            f"grid: the axes over config keys make {n_points:,} points (at most {MAX_POINTS:,})"
        )
    return tuple(axes)


def _path(key: Any, where: str) -> str:
    if not isinstance(key, str) or not PATH_RE.fullmatch(key):
        raise ConfigError(
            f"{where}: a grid key is amplitudes, frequencies, {LINKED}, or a config key by its"
            f" dotted path (column.height, interface.restitution, ...), got {describe(key)}"
        )
    if key.split(".")[0] in FIXED_KEYS:
        raise ConfigError(f"{where}: {key} cannot vary over a grid")
    if key in TOP_SCALARS:
        raise ConfigError(
            f"{where}: {key} cannot vary over a grid (a domain holds one model): sweep one"
            " config per model and draw them together with rbm plot-domain A.csv --compare"
            " B.csv"
        )
    if "." not in key:
        if key in SECTIONS:
            raise ConfigError(
                f"{where}: the whole {key} section cannot vary over a grid: give a key inside"
                f" it by its dotted path, such as {SECTIONS[key]}"
            )
        raise ConfigError(
            f"unknown key {key!r} in grid (allowed: amplitudes, frequencies, {LINKED},"
            " or a config key by its dotted path such as column.height)"
        )
    return key


def _values(value: Any, where: str, path: str, unique: bool = True) -> tuple[Any, ...]:
    """The values of one axis: numbers through grid_axis (lists and ranges), or a list
    of strings (restitution "housner", excitation.file ...); for excitation.file also
    motions given as arrays (rbm_cli.config.motions), each name once."""
    unit = VIRTUAL_PATHS.get(path, "")
    if isinstance(value, Mapping):
        return grid_axis(value, where, unit, lo_open=False, bounds=None)
    if is_number(value) or isinstance(value, str | bool):
        return (value,)
    if path == "excitation.file" and isinstance(value, Motion):
        return (value,)
    if path == "excitation.file" and isinstance(value, list | tuple):
        if any(isinstance(v, Motion) for v in value):  # motions given as arrays
            return unique_names(value, where)
    if not isinstance(value, list | tuple) or not value:
        raise ConfigError(
            f"{where} must be a value, a non-empty list, or {{start, stop, step | num}},"
            f" got {describe(value)}"
        )
    if len(value) > MAX_GRID_VALUES:
        raise ConfigError(f"{where} must have at most {MAX_GRID_VALUES} values, got {len(value)}")
    out = []
    for i, v in enumerate(value):
        if not (is_number(v) or isinstance(v, str | bool)):
            raise ConfigError(f"{join(where, i)} must be a number or a string, got {describe(v)}")
        if unique and any(v == w and type(v) is type(w) for w in out):
            raise ConfigError(f"{join(where, i)} repeats {_text(v)}: list each value once")
        out.append(v)
    return tuple(out)


def _linked(value: Any) -> list[Axis]:
    where = f"grid.{LINKED}"
    if not isinstance(value, list | tuple) or not value:
        raise ConfigError(
            f"{where} must be a list of mappings, each of two or more config key paths to"
            f" lists of one length, got {describe(value)}"
        )
    axes = []
    for i, group in enumerate(value):
        at = join(where, i)
        if not isinstance(group, Mapping) or len(group) < 2:
            raise ConfigError(f"{at} must map two or more config key paths to lists of values")
        paths = tuple(_path(k, join(at, str(k))) for k in group)
        columns = [
            _values(group[k], join(at, str(k)), p, False)
            for k, p in zip(group, paths, strict=False)
        ]
        lengths = {len(c) for c in columns}
        if len(lengths) != 1:
            sizes = ", ".join(f"{p}: {len(c)}" for p, c in zip(paths, columns, strict=False))
            raise ConfigError(f"{at}: linked axes must have as many values each, got {sizes}")
        points = tuple(zip(*columns, strict=False))
        if len(set(points)) != len(points):
            raise ConfigError(f"{at}: a point repeats (each set of linked values once)")
        axes.append(Axis(paths, points))
    return axes


def _text(value: Any) -> str:
    return fmt(value) if is_number(value) else repr(value)


def point_label(paths: tuple[str, ...], point: tuple[Any, ...]) -> str:
    """``column.height = 2, column.base_width = 0.5``: a point, for messages and legends."""
    return ", ".join(f"{p} = {_text(v)}" for p, v in zip(paths, point, strict=False))


__all__ = [
    "AMPLITUDE_RANGE_G",
    "FREQUENCY_RANGE_HZ",
    "LINKED",
    "MAX_CELLS",
    "MAX_POINTS",
    "VIRTUAL_PATHS",
    "parse_axes",
    "hoist_suite",
    "parse_grid",
    "point_label",
]


#: File names a folder of records is read for (``excitation.file: <folder>``).
RECORD_SUFFIXES = (".at2", ".csv")
GLOB_CHARS = "*?["


#: Grid paths whose values are record files: each value may be a file, a folder or a glob.
RECORD_PATHS = ("excitation.file", "excitation.vertical", "excitation.file_y")


def hoist_suite(top: Mapping[str, Any], base_dir: str | os.PathLike | None) -> dict:
    """A config mapping with its suites of records spelt out as grid axes.

    ``excitation.file`` naming several records (a list, a folder or a glob) becomes a grid
    axis ``excitation.file`` over each file (sorted for a folder or a glob; relative to
    ``base_dir`` as written), the excitation keeping the first so that it validates as one
    record. A folder or a glob given as a value of a grid axis over ``excitation.file`` or
    ``excitation.vertical`` is replaced by its files in the same way, in the order written.
    A suite of pairs (``excitation.file_y`` a list, folder or glob parallel to
    ``excitation.file``'s, or ``excitation.file`` a list of ``{x: FILE, y: FILE}``) becomes
    a linked axis over ``excitation.file`` and ``excitation.file_y`` (:func:`_suite_pairs`).
    Any other mapping comes back as it is."""
    top = dict(top)
    base = Path(base_dir or ".")
    grid = top.get("grid")
    if isinstance(grid, Mapping):
        grid = dict(grid)
        for path in RECORD_PATHS:
            if path in grid:
                grid[path] = _axis_files(grid[path], f"grid.{path}", base)
        _refuse_linked_suites(grid.get(LINKED), base)
        top["grid"] = grid
    excitation = top.get("excitation")
    if not isinstance(excitation, Mapping) or "file" not in excitation:
        return top
    pairs = _suite_pairs(excitation, base)
    if pairs is not None:
        return _hoist_pairs(top, excitation, grid, pairs)
    files = _suite_files(excitation["file"], base)
    if files is None:
        return top
    grid = dict(grid) if isinstance(grid, Mapping) else {}
    if "excitation.file" in grid:
        raise ConfigError(
            "excitation.file names several records and grid.excitation.file is given too: use one"
        )
    grid["excitation.file"] = files
    return {**top, "excitation": {**excitation, "file": files[0]}, "grid": grid}


#: Keys of a pair of records written as one item of ``excitation.file``.
PAIR_KEYS = ("x", "y")
PAIR_PATHS = ("excitation.file", "excitation.file_y")


def _suite_pairs(excitation: Mapping[str, Any], base: Path) -> tuple[list, list] | None:
    """The (x files, y files) of a suite of pairs, in pair order, or None when the
    excitation names no such suite (one file, a suite of single records, or a value left to
    the excitation's own checks).

    Two forms: ``excitation.file`` a list of ``{x: FILE, y: FILE}`` (``file_y`` absent),
    or ``excitation.file_y`` beside ``excitation.file`` with either a list, a folder or a
    glob: both expand (:func:`_suite_files`; one file counts as one) to as many files,
    paired in the order each expands to (a list's as written, a folder's or a glob's
    sorted)."""
    value = excitation["file"]
    if isinstance(value, Mapping):
        raise ConfigError(
            "excitation.file: a pair {x: FILE, y: FILE} goes in a list (a suite of pairs);"
            " one record's two components are excitation.file and excitation.file_y"
        )
    if isinstance(value, list | tuple) and any(isinstance(v, Mapping) for v in value):
        return _written_pairs(value, excitation, base)
    y_value = excitation.get("file_y")
    if y_value is None or not isinstance(value, str | list | tuple):
        return None
    if not isinstance(y_value, str | list | tuple):
        raise ConfigError(
            "excitation.file_y must be a record file, a list of them, a folder or a glob"
            f" (paired with excitation.file's), got {describe(y_value)}"
        )
    xs = _suite_files(value, base)
    ys = _suite_files(y_value, base, "excitation.file_y")
    if xs is None and ys is None:
        return None  # one pair: the excitation's own file and file_y
    xs, ys = xs or [value], ys or [y_value]
    if len(xs) != len(ys):
        raise ConfigError(
            f"excitation.file names {_count(xs)} and excitation.file_y {_count(ys)}: a"
            " suite of pairs takes one y record per x record, paired in order (a list's as"
            " written, a folder's or a glob's sorted)"
        )
    _check_pairs(xs, ys, [(join("excitation.file", i), join("excitation.file_y", i))
                          for i in range(len(xs))])  # fmt: skip
    return xs, ys


def _count(files: list) -> str:
    return "1 record" if len(files) == 1 else f"{len(files)} records"


def _written_pairs(value: list | tuple, excitation: Mapping[str, Any], base: Path) -> tuple:
    """The (x files, y files) of ``excitation.file`` written as a list of {x, y}."""
    if "file_y" in excitation:
        raise ConfigError(
            "excitation.file lists pairs {x, y} and excitation.file_y is given too: give the"
            " y records in the pairs or in excitation.file_y, not both"
        )
    xs, ys, wheres = [], [], []
    for i, item in enumerate(value):
        at = join("excitation.file", i)
        if not isinstance(item, Mapping):
            raise ConfigError(
                f"{at} must be a pair {{x: FILE, y: FILE}} as the list's other items are, got"
                f" {describe(item)}"
            )
        pair = mapping(item, at, PAIR_KEYS, required=PAIR_KEYS)
        for key in PAIR_KEYS:
            where, file = join(at, key), pair[key]
            if not isinstance(file, str) or not file.strip():
                raise ConfigError(f"{where} must be a record file's path, got {describe(file)}")
            if _suite_files(file, base, where) is not None:
                raise ConfigError(
                    f"{where}: {file!r} is a folder or a pattern: a pair names one file for"
                    " each component (parallel folders or patterns go in excitation.file and"
                    " excitation.file_y)"
                )
        xs.append(pair["x"])
        ys.append(pair["y"])
        wheres.append((join(at, "x"), join(at, "y")))
    _check_pairs(xs, ys, wheres)
    return xs, ys


def _check_pairs(xs: list, ys: list, wheres: list[tuple[str, str]]) -> None:
    """Each file once in a suite of pairs, never paired with itself (``wheres``: where
    each pair's x and y are written)."""
    seen: dict[str, str] = {}
    for x, y, (at_x, at_y) in zip(xs, ys, wheres, strict=True):
        if x == y:
            raise ConfigError(
                f"{at_y}: {y!r} is the pair's x record too: a pair is a record's two"
                " horizontal components"
            )
        for file, at in ((x, at_x), (y, at_y)):
            if file in seen:
                raise ConfigError(
                    f"{at}: {file!r} is named twice (at {seen[file]} too): each record file"
                    " once in a suite of pairs"
                )
            seen[file] = at


def _hoist_pairs(top: dict, excitation: Mapping[str, Any], grid: Any, pairs: tuple) -> dict:
    """The config with its suite of pairs as a linked axis over excitation.file and
    excitation.file_y (after the grid's other linked axes), the excitation keeping the first
    pair: the config a linked axis written by hand makes, to its hash."""
    xs, ys = pairs
    grid = dict(grid) if isinstance(grid, Mapping) else {}
    linked = grid.get(LINKED)
    if linked is not None and (not isinstance(linked, list | tuple) or not linked):
        _linked(linked)  # refuses it, in its own words
    for path in PAIR_PATHS:
        named = path in grid or any(
            isinstance(group, Mapping) and path in group for group in linked or ()
        )
        if named:
            raise ConfigError(
                f"excitation.file names a suite of pairs and the grid has an axis over {path}"
                " too: use one"
            )
    grid[LINKED] = [*(linked or ()), {"excitation.file": xs, "excitation.file_y": ys}]
    return {**top, "excitation": {**excitation, "file": xs[0], "file_y": ys[0]}, "grid": grid}


def _axis_files(value: Any, where: str, base: Path) -> Any:
    """An axis's record values with each folder or glob replaced by its files (a value
    that is neither a string nor a list is left to the axis's own checks)."""
    single = isinstance(value, str)
    if not single and not isinstance(value, list | tuple):
        return value
    out: list = []
    named: dict[str, Any] = {}
    for i, item in enumerate([value] if single else value):
        at = where if single else join(where, i)
        files = _suite_files(item, base, at) if isinstance(item, str) else None
        for f in [item] if files is None else files:
            if isinstance(f, str) and f in named:
                raise ConfigError(
                    f"{at}: {f!r} is named twice (by {named[f]!r} and {item!r}): list each"
                    " record once"
                )
            named[f] = item
            out.append(f)
    return out[0] if single and len(out) == 1 else out


def _refuse_linked_suites(linked: Any, base: Path) -> None:
    """A folder or glob in a linked axis of records is refused: its length would not be
    known where the other linked lists are written."""
    if not isinstance(linked, list | tuple):
        return
    for i, group in enumerate(linked):
        if not isinstance(group, Mapping):
            continue
        for path in RECORD_PATHS:
            values = group.get(path)
            items = values if isinstance(values, list | tuple) else [values]
            for item in items:
                if isinstance(item, str) and _suite_files(item, base, path) is not None:
                    raise ConfigError(
                        f"{join(join(f'grid.{LINKED}', i), path)}: {item!r} is a folder or a"
                        " pattern: a linked axis lists each record file by name"
                    )


def _suite_files(value: Any, base: Path, where: str = "excitation.file") -> list[str] | None:
    """The files of a suite, or None for one file (left to the excitation's own checks)."""
    if isinstance(value, list | tuple):
        if not value:
            raise ConfigError(f"{where} must not be an empty list")
        for i, v in enumerate(value):
            if not isinstance(v, str) or not v.strip():
                raise ConfigError(f"{join(where, i)} must be a file path, got {describe(v)}")
        return list(value)
    if not isinstance(value, str) or not value.strip():
        return None
    if any(c in value for c in GLOB_CHARS):
        try:
            matches = glob.glob(os.path.join(base, value))
        except (OSError, ValueError) as exc:
            raise ConfigError(f"{where}: the pattern {value!r} cannot be read: {exc}") from None
        found = sorted(Path(p) for p in matches if _is_record(Path(p)))
        if not found:
            raise ConfigError(f"{where}: the pattern {value!r} matches no file (in {base})")
        return [_relative(p, base) for p in found]
    folder = base / os.path.expanduser(value)
    try:
        if not folder.is_dir():
            return None
        found = sorted(p for p in folder.iterdir() if _is_record(p))
    except OSError as exc:
        raise ConfigError(f"{where}: {value!r}: cannot read ({exc.strerror or exc})") from None
    if not found:
        raise ConfigError(f"{where}: the folder {value!r} holds no .AT2 or .csv record file")
    return [_relative(p, base) for p in found]


def _is_record(path: Path) -> bool:
    """A file of a folder or a glob that is read as a record: a regular file (a folder
    named x.AT2 is not) with the suffix .AT2 or .csv (any case)."""
    try:
        return path.suffix.lower() in RECORD_SUFFIXES and path.is_file()
    except OSError:
        return False


def _relative(path: Path, base: Path) -> str:
    try:
        return path.relative_to(base).as_posix()
    except ValueError:
        return path.as_posix()
