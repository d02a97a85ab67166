"""What a row of a sweep's journal must be to be trusted (rbm_cli.study.store reads them).

A row is a finished cell of one config: the config's hash, a cell of the grid, a status
of STATUSES with collapsed agreeing, and every other domain.csv field of its type and
range. A hand-made or damaged row fails here and its cell is run again.
"""

from __future__ import annotations

import math

from rbm_cli.study.domain import row_key
from rbm_cli.study.result import STATUSES
from rbm_cli.study.robustness import SENSITIVE_TO
from rbm_cli.study.schema import C

COUNT_FIELDS = (C.n_uplifts, C.n_impacts, C.n_steps, C.n_rhs)


def _is_number(x) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool)


def _nan_or_none(x) -> bool:
    return x is None or (isinstance(x, float) and math.isnan(x))


def validate_row(
    row,
    digest: str,
    grid: set[tuple[str, ...]],
    n_interfaces: int,
    ensemble: int,
    paths: tuple[str, ...] = (),
) -> str:
    """'' if a journal row is a finished cell of this config, else what is wrong.

    The row must be a mapping with the config's hash (rows of journals made before the
    hash was written carry none: the caller allows that only with a matching state
    file), a cell of the grid, a status of STATUSES, collapsed 0/1 agreeing with it, and
    every other domain.csv field of the right type and range (a failed run may leave
    them out or NaN). ``paths``: the grid's axes over config keys, whose values the row
    carries in columns of those names (rbm_cli.study.cells); n_interfaces: the most
    interfaces of any point's column."""
    if not isinstance(row, dict):
        return "not a JSON object"
    if "config_hash" in row and row["config_hash"] != digest:
        return f"made by another config (hash {str(row['config_hash'])[:24]!r})"
    a, f = row.get(C.amplitude_g), row.get(C.frequency_hz)
    if not (_is_number(a) and math.isfinite(a) and a >= 0):
        return f"amplitude_g must be a finite number >= 0, got {a!r}"
    if not (f is None or (_is_number(f) and math.isfinite(f) and f > 0)):
        return f"frequency_hz must be a finite number > 0 (or empty), got {f!r}"
    if row_key(row, paths) not in grid:
        point = "".join(f", {p} {row.get(p)!r}" for p in paths)
        return f"the cell ({a} g, {f} Hz{point}) is not in the config's grid"
    status = row.get(C.status)
    if status not in STATUSES:
        return f"status must be one of {', '.join(STATUSES)}, got {str(status)[:40]!r}"
    collapsed = row.get(C.collapsed)
    if collapsed not in (0, 1) or isinstance(collapsed, bool):
        return f"collapsed must be 0 or 1, got {collapsed!r}"
    if collapsed != (status == "collapsed"):
        return f"status {status!r} but collapsed {collapsed}: they disagree"
    if not isinstance(row.get(C.message), str):
        return "message must be a string"
    failed = status == "failed"
    problem = _check_numbers(row, failed, status == "collapsed", n_interfaces)
    if problem:
        return problem
    if ensemble > 1:
        cf = row.get(C.collapse_fraction)
        if not (_is_number(cf) and (math.isnan(cf) or 0.0 <= cf <= 1.0)):
            return f"collapse_fraction must be in [0, 1] or NaN, got {cf!r}"
        robust = row.get(C.robust)
        if robust not in (0, 1) or isinstance(robust, bool):
            return f"robust must be 0 or 1, got {robust!r}"
        if robust == 1 and cf not in (0.0, 1.0):
            return f"robust 1 but collapse_fraction {cf!r}: they disagree"
        why = row.get(C.sensitive_to)
        if why not in SENSITIVE_TO:
            return f"sensitive_to must be one of {', '.join(SENSITIVE_TO)}, got {why!r}"
        if (robust == 1) != (why == "none"):
            return f"robust {robust} but sensitive_to {why!r}: they disagree"
    return ""


def _check_numbers(row: dict, failed: bool, collapsed: bool, n_interfaces: int) -> str:
    for key in COUNT_FIELDS:
        v = row.get(key)
        if v is None and failed:
            continue
        if not (isinstance(v, int) and not isinstance(v, bool) and v >= 0):
            return f"{key} must be an integer >= 0, got {v!r}"
    for key in (C.max_rotation_ratio, C.max_top_displacement_m):
        v = row.get(key)
        if failed and (v is None or _nan_or_none(v)):
            continue
        if not (_is_number(v) and math.isfinite(v) and v >= 0):
            return f"{key} must be a finite number >= 0, got {v!r}"
    t, where = row.get(C.t_collapse_s), row.get(C.collapse_interface)
    if collapsed:
        if not (_is_number(t) and math.isfinite(t) and t >= 0):
            return f"t_collapse_s of a collapsed cell must be a finite time >= 0, got {t!r}"
        ok = isinstance(where, int) and not isinstance(where, bool)
        if not (ok and 1 <= where <= n_interfaces):
            return f"collapse_interface must be in 1..{n_interfaces}, got {where!r}"
    elif not (_nan_or_none(t) and where is None):
        return "t_collapse_s and collapse_interface must be empty unless collapsed"
    return ""
