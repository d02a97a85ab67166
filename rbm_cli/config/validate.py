"""Helpers of the config parser: value checkers and grid axes.

Each checker returns a clean value or raises ConfigError whose one-line message
names the YAML key path (dots and list indices, ``column.drums[2]``) and the
allowed range or values. No file I/O here: :mod:`rbm_cli.config.load` reads the file,
:mod:`rbm_cli.config.yaml_reader` parses it.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from rbm_cli.base.errors import ConfigError

RANGE_KEYS = ("start", "stop", "step", "num", "spacing")
SPACINGS = ("linear", "log")
MAX_GRID_VALUES = 10_000  # per axis
GRID_STOP_TOL = 1e-9  # in units of step: stop is included when within it
GRID_DIGITS = 12  # significant digits of generated grid values


def join(path: str, key: str | int) -> str:
    """Key path of ``key`` under ``path``: ``join('column', 'drums')`` -> ``column.drums``.

    Integers are list indices: ``join('column.drums', 2)`` -> ``column.drums[2]``.
    """
    if isinstance(key, int):
        return f"{path}[{key}]"
    return f"{path}.{key}" if path else str(key)


def fmt(x: float) -> str:
    """A number as a message shows it: 12 significant digits, no trailing zeros."""
    if isinstance(x, int):
        if x.bit_length() <= 64:
            return str(x)
        return f"{x:.6e}" if x.bit_length() < 1000 else "a huge integer"
    return f"{x:.12g}"


def describe(value: Any) -> str:
    """What the user wrote, for the ``got ...`` part of a message."""
    if value is None:
        return "nothing (null; delete the key to use its default)"
    if isinstance(value, bool):
        return f"{str(value).lower()} (a boolean)"
    if isinstance(value, int | float):
        return fmt(value)
    if isinstance(value, str):
        text = value if len(value) <= 40 else value[:37] + "..."
        if _YAML11_NUMBER.match(value):
            return (
                f"{text!r} (YAML 1.1 base-60, octal, hex or binary notation is not read as a"
                " number: write it in decimal)"
            )
        try:
            float(value)
        except ValueError:
            return repr(text)
        if _YAML11_STRING.match(value):
            dotted = re.sub(r"([0-9])([eE])", r"\1.0\2", value, count=1)
            return (
                f"{text!r} (a quoted string, or a number a YAML 1.1 reader such as"
                f" yaml.safe_load left as a string: write it unquoted with a dot, {dotted},"
                " or read the file with rbm.load_config)"
            )
        return f"{text!r} (a quoted string; write numbers without quotes)"
    if isinstance(value, Mapping):
        return "a mapping"
    if isinstance(value, list | tuple):
        return "a list"
    return f"a value of type {type(value).__name__}"


def range_text(
    lo: float | None = None,
    hi: float | None = None,
    *,
    lo_open: bool = True,
    hi_open: bool = False,
) -> str:
    """``> 0``, ``>= 0``, ``<= 10000`` or ``in (0, 1]``: the allowed range of a number."""
    if lo is not None and hi is not None:
        return f"in {'(' if lo_open else '['}{fmt(lo)}, {fmt(hi)}{')' if hi_open else ']'}"
    if lo is not None:
        return f"{'>' if lo_open else '>='} {fmt(lo)}"
    if hi is not None:
        return f"{'<' if hi_open else '<='} {fmt(hi)}"
    return ""


def _units(unit: str) -> str:
    return f" [{unit}]" if unit else ""


def is_number(value: Any) -> bool:
    """True for int and float, false for booleans (which Python counts as ints)."""
    return isinstance(value, int | float) and not isinstance(value, bool)


def number(
    value: Any,
    path: str,
    unit: str = "",
    lo: float | None = None,
    hi: float | None = None,
    *,
    lo_open: bool = True,
    hi_open: bool = False,
    hint: str = "",
    inf_hint: str = "",
) -> float:
    """A finite float within the given range.

    Parameters
    ----------
    value : any  What the YAML holds
    path : str  Key path, for the message
    unit : str  Unit shown in brackets, e.g. ``m``; empty for dimensionless
    lo, hi : float or None  Bounds; None for none
    lo_open, hi_open : bool  Whether the bound itself is excluded
    hint : str  Advice appended to a range error
    inf_hint : str  Advice appended to an infinite or NaN value's error
    """
    rng = range_text(lo, hi, lo_open=lo_open, hi_open=hi_open)
    wanted = f"a number {rng}".rstrip() + _units(unit)
    extra = f" ({hint})" if hint else ""
    if not is_number(value):
        raise ConfigError(f"{path} must be {wanted}, got {describe(value)}")
    try:
        x = float(value)
    except OverflowError:  # an integer too large for a float
        x = math.inf
    if not math.isfinite(x):
        wanted = f"a finite number {rng}".rstrip() + _units(unit)
        extra = f" ({inf_hint})" if inf_hint else ""
        raise ConfigError(f"{path} must be {wanted}, got {describe(value)}{extra}")
    bad_lo = lo is not None and (x <= lo if lo_open else x < lo)
    bad_hi = hi is not None and (x >= hi if hi_open else x > hi)
    if bad_lo or bad_hi:
        raise ConfigError(f"{path} must be {wanted}, got {describe(value)}{extra}")
    return x


#: Why a bound is there, as range messages say it.
FINITE_WHY = "masses, inertias and moments stay finite"
SOUND_WHY = "the arithmetic is sound"


def in_bounds(
    x: float, path: str, unit: str, bounds: tuple[float, float], why: str = FINITE_WHY
) -> float:
    """x within the closed interval ``bounds`` [assumption: the range where ``why``]."""
    if not bounds[0] <= x <= bounds[1]:
        raise ConfigError(
            f"{path} must be in [{fmt(bounds[0])}, {fmt(bounds[1])}] [{unit}] (the range where"
            f" {why}), got {fmt(x)}"
        )
    return x


def integer(value: Any, path: str, lo: int, hi: int | None = None, what: str = "") -> int:
    """An integer in [lo, hi]; a float with an integral value (``2e6``) is accepted."""
    rng = f">= {lo}" if hi is None else f"in {lo}..{hi}"
    wanted = f"an integer {rng}{what}"
    if isinstance(value, float) and math.isfinite(value) and value.is_integer():
        value = int(value)
    if not isinstance(value, int) or isinstance(value, bool):
        raise ConfigError(f"{path} must be {wanted}, got {describe(value)}")
    if value < lo or (hi is not None and value > hi):
        raise ConfigError(f"{path} must be {wanted}, got {value}")
    return value


def choice(value: Any, path: str, allowed: Iterable[str]) -> str:
    """One of the allowed strings."""
    allowed = tuple(allowed)
    if not isinstance(value, str) or value not in allowed:
        raise ConfigError(f"{path} must be one of {', '.join(allowed)}, got {describe(value)}")
    return value


def mapping(value: Any, path: str, allowed: Iterable[str], required: Iterable[str] = ()) -> dict:
    """A mapping whose keys are all allowed and include the required ones.

    ``None`` (a section whose contents are all commented out) reads as empty.
    """
    allowed = tuple(allowed)
    where = path or "top level"
    if value is None:
        value = {}
    if not isinstance(value, Mapping):
        raise ConfigError(
            f"{where} must be a mapping of keys ({', '.join(allowed)}), got {describe(value)}"
        )
    for key in value:
        if key not in allowed:
            at = f"in {path}" if path else "at top level"
            raise ConfigError(f"unknown key {str(key)!r} {at} (allowed: {', '.join(allowed)})")
    for key in required:
        if key not in value:
            raise ConfigError(f"{join(path, key)} is required")
    return dict(value)


def number_list(
    value: Any,
    path: str,
    unit: str = "",
    lo: float | None = None,
    *,
    lo_open: bool = True,
    length: int | None = None,
    length_text: str = "",
) -> tuple[float, ...]:
    """A non-empty list of finite numbers, each above ``lo``; of ``length`` items if given."""
    if not isinstance(value, list | tuple):
        raise ConfigError(f"{path} must be a list of numbers{_units(unit)}, got {describe(value)}")
    if length is not None and len(value) != length:
        wanted = length_text or f"{length} values"
        raise ConfigError(f"{path} must have {wanted}, got {len(value)} values")
    if not value:
        raise ConfigError(f"{path} must not be empty")
    return tuple(number(v, join(path, i), unit, lo, lo_open=lo_open) for i, v in enumerate(value))


# --------------------------------------------------------------------------- text

#: Strings YAML 1.1 would have read as numbers: base 60, octal with a leading zero, hex, binary.
_YAML11_NUMBER = re.compile(
    r"^[-+]?(?:[0-9][0-9_]*(?::[0-5]?[0-9])+(?:\.[0-9_]*)?|0[0-9_]+|0x[0-9a-fA-F_]+|0b[01_]+)$"
)

#: Floats YAML 1.1 (PyYAML's yaml.safe_load) reads as strings: an exponent with no dot.
_YAML11_STRING = re.compile(r"^[-+]?[0-9][0-9_]*[eE][-+]?[0-9]+$")


def one_line(text: str) -> str:
    """``text`` with every run of whitespace (newlines too) made one space."""
    return " ".join(str(text).split())


# --------------------------------------------------------------------------- grid


def grid_axis(
    value: Any,
    path: str,
    unit: str,
    *,
    lo_open: bool,
    bounds: tuple[float, float] | None = None,
) -> tuple[float, ...]:
    """One grid axis: a number, a list, or {start, stop, step} / {start, stop, num} (with
    ``spacing: log``, num values evenly spaced in log, start > 0); every value > 0
    (lo_open) or >= 0, and within ``bounds`` if given."""
    values = _grid_values(value, path, unit, lo_open=lo_open)
    if bounds is not None:
        for i, x in enumerate(values):
            if not bounds[0] <= x <= bounds[1]:
                where = path if len(values) == 1 else join(path, i)
                raise ConfigError(
                    f"{where} must be in [{fmt(bounds[0])}, {fmt(bounds[1])}] [{unit}]"
                    f" (the range the tool accepts), got {fmt(x)}"
                )
    return values


def _grid_values(value: Any, path: str, unit: str, *, lo_open: bool) -> tuple[float, ...]:
    if is_number(value):
        return (number(value, path, unit, 0.0, lo_open=lo_open),)
    if isinstance(value, Mapping):
        return _generated(value, path, unit, lo_open=lo_open)
    if not isinstance(value, list | tuple):
        raise ConfigError(
            f"{path} must be a number, a list of numbers, {{start, stop, step}} or"
            f" {{start, stop, num}} [{unit}], got {describe(value)}"
        )
    if not value:
        raise ConfigError(f"{path} must not be an empty list (delete the key for no grid)")
    if len(value) > MAX_GRID_VALUES:
        raise ConfigError(f"{path} must have at most {MAX_GRID_VALUES} values, got {len(value)}")
    values = number_list(value, path, unit, 0.0, lo_open=lo_open)
    seen: set[float] = set()
    for i, x in enumerate(values):
        if x in seen:
            raise ConfigError(f"{join(path, i)} repeats {fmt(x)}: list each value once")
        seen.add(x)
    return values


def _generated(
    value: Mapping[str, Any], path: str, unit: str, *, lo_open: bool
) -> tuple[float, ...]:
    m = mapping(value, path, RANGE_KEYS)
    for key in ("start", "stop"):
        if key not in m:
            raise ConfigError(f"{join(path, key)} is required (with step or num)")
    if ("step" in m) == ("num" in m):
        given = "both" if "step" in m else "neither"
        raise ConfigError(f"{path} needs exactly one of step and num, got {given}")
    spacing = choice(m.get("spacing", "linear"), join(path, "spacing"), SPACINGS)
    if spacing == "log" and "num" not in m:
        raise ConfigError(f"{join(path, 'spacing')}: log needs num (not step)")
    log = spacing == "log"
    start = number(m["start"], join(path, "start"), unit, 0.0, lo_open=lo_open or log)
    stop = number(m["stop"], join(path, "stop"), unit, 0.0, lo_open=lo_open or log)
    if stop < start:
        raise ConfigError(
            f"{join(path, 'stop')} must be >= {join(path, 'start')} ({fmt(start)}), got {fmt(stop)}"
        )
    if "step" in m:
        step = number(m["step"], join(path, "step"), unit, 0.0)
        count = math.floor((stop - start) / step + GRID_STOP_TOL) + 1
        if count > MAX_GRID_VALUES:
            raise ConfigError(
                f"{join(path, 'step')} gives {count} values (at most"
                f" {MAX_GRID_VALUES}): use a larger step"
            )
        raw = np.minimum(start + step * np.arange(count), stop)  # no overshoot of stop
    else:
        count = integer(m["num"], join(path, "num"), 1, MAX_GRID_VALUES)
        if count == 1 and stop != start:
            raise ConfigError(
                f"{join(path, 'num')} is 1 but stop ({fmt(stop)}) differs from start"
                f" ({fmt(start)}): use num >= 2, or stop equal to start"
            )
        raw = np.geomspace(start, stop, count) if log else np.linspace(start, stop, count)
    values = tuple(float(f"{x:.{GRID_DIGITS}g}") for x in raw)
    if len(set(values)) != len(values):
        key = join(path, "step" if "step" in m else "num")
        raise ConfigError(
            f"{key} makes the values too close: they repeat at {GRID_DIGITS} significant digits"
        )
    return values
