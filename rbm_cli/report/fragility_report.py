"""Files and figures of a fragility analysis (:mod:`rbm_cli.study.fragility`).

:func:`write_fragility` writes ``fragility.csv`` (per intensity), ``fragility_curve.csv``
(the fitted curve and its band on a grid) and ``fragility.json`` (median, dispersion,
intervals, method, counts, seed). :func:`plot_fragility` and :func:`plot_ida` draw on a
given matplotlib axes, or on a new figure's (no pyplot state), and return the axes; saving
is the caller's business.
"""

from __future__ import annotations

import json
import math
import os
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd

from rbm_cli.base.errors import RbmError
from rbm_cli.report.fragility_store import FragilityFolder
from rbm_cli.study.fragility import METHOD, MIN_BAND_RECORDS, FragilityResult
from rbm_cli.study.outcomes import intensity_column as find_intensity_column
from rbm_cli.study.schema import C
from rbm_cli.study.schema import label as column_label

#: Float format of the CSV files (12 significant digits, as domain.csv).
FLOAT_FORMAT = "%.12g"


def _number(x: float) -> float | None:
    return None if x is None or not math.isfinite(x) else float(x)


def fragility_summary(result: FragilityResult) -> dict:
    """The contents of ``fragility.json``: strict JSON (no NaN; null where undefined)."""
    fit = result.fit
    return {
        "method": METHOD,
        "fitted": fit is not None,
        "note": result.note,
        "median_g": _number(fit.median_g) if fit else None,
        "beta": _number(fit.beta) if fit else None,
        "log_likelihood": _number(fit.log_likelihood) if fit else None,
        "median_ci_g": [_number(v) for v in result.median_ci_g],
        "beta_ci": [_number(v) for v in result.beta_ci],
        "ci_percentiles": list(result.ci_percentiles),
        "n_records": result.n_records,
        "n_runs": result.n_runs,
        "n_failed": result.n_failed,
        "n_levels": len(result.table),
        "n_resamples": result.n_resamples,
        "n_resamples_used": result.n_resamples_used,
        "seed": result.seed,
        "intensity_column": result.intensity_column,
        "intensity_unit": result.intensity_unit,
        "outcome": result.outcome,
        "ensemble_outcome": result.ensemble_outcome,
        "failed_by_intensity": [
            {"intensity": float(x), "n_failed": int(n)}
            for x, n in zip(result.table["intensity_g"], result.table["n_failed"], strict=True)
        ],
        "warning": result.warning,
        "fit_warning": result.fit_warning,
        "resamples_dropped": dict(result.resamples_dropped),
        "resamples_note": result.resamples_note,
        "dispersion": result.dispersion.summary() if result.dispersion is not None else None,
    }


def fragility_texts(result: FragilityResult, extra: dict | None = None) -> dict[str, str]:
    """The text of ``fragility.csv``, ``fragility_curve.csv`` and ``fragility.json``, by
    name; ``extra`` entries (JSON values, e.g. the domain's path) are added to the JSON."""
    summary = fragility_summary(result) | (extra or {})
    return {
        "fragility.csv": _csv(result.table),
        "fragility_curve.csv": _csv(result.curve),
        "fragility.json": json.dumps(summary, indent=2, allow_nan=False) + "\n",
    }


def _csv(frame: pd.DataFrame) -> str:
    return frame.to_csv(index=False, float_format=FLOAT_FORMAT, lineterminator="\n")


def write_fragility(result: FragilityResult, folder: str | os.PathLike) -> list[Path]:
    """Write ``fragility.csv``, ``fragility_curve.csv`` and ``fragility.json`` into ``folder``.

    Parameters
    ----------
    result : FragilityResult
        From :func:`rbm_cli.study.fragility.fragility`
    folder : str or os.PathLike
        Created if missing; locked against a fragility run into it, the three files are
        staged in full, then moved into place together
        (:class:`rbm_cli.report.fragility_store.FragilityFolder`)

    Returns
    -------
    list of pathlib.Path
        The three files

    Notes
    -----
    ``fragility.csv``: intensity_g, n_records, n_failed, n_collapsed, fraction, fitted
    (the fitted probability), band_lower, band_upper (the bootstrap band), one row per
    intensity. Undefined values (no fit, no runs at a level) are empty cells.
    """
    with FragilityFolder(folder) as store:
        return store.publish(fragility_texts(result))


# --------------------------------------------------------------------------- figures


def _new_axes():
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.figure import Figure

    return Figure(figsize=(7, 5)).subplots()


def plot_fragility(
    result: FragilityResult,
    ax=None,
    *,
    label: str | None = None,
    color: str | None = None,
    counts: bool = True,
    xlabel: str = "intensity: peak ground acceleration [g]",
):
    """Observed collapse fractions, the fitted lognormal curve and its bootstrap band.

    Parameters
    ----------
    result : FragilityResult
        From :func:`rbm_cli.study.fragility.fragility`
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure's when None)
    label : str, optional
        Prefix of the legend entries (e.g. the column's name, to overlay several results)
    color : str, optional
        Colour of all three marks
    counts : bool
        Write "collapsed/trials" beside each point (at most MAX_COUNT_LABELS points)
    xlabel : str
        Label of the intensity axis

    Returns
    -------
    matplotlib.axes.Axes
        The axes: points (marker "o", gid "observed"), fitted curve (gid "fitted"), band
        (a PolyCollection, gid "band"); the legend says which is which. Under the axes,
        notes: why there is no fit or no band (gid "note", "few-records"), an
        extrapolated fit (gid "fit-warning", in red) and the bootstrap resamples left out
        and why (gid "resamples-note")
    """
    ax = ax if ax is not None else _new_axes()
    prefix = f"{label}: " if label else ""
    color = _plot_observed(ax, result.table, prefix, color, counts)
    if result.fit is not None:
        _plot_fit(ax, result, prefix, color)
    if result.n_records < MIN_BAND_RECORDS:
        n = result.n_records
        _note(ax, f"{prefix}too few records: a fit from {n} record{'s' * (n != 1)}, below the "
                  f"{MIN_BAND_RECORDS} a bootstrap over records needs (no band, no intervals)",
              "few-records", "tab:red")  # fmt: skip
    if result.fit is None:
        _note(ax, f"{prefix}no fit: {result.note}", "note")
    elif result.note and result.n_records >= MIN_BAND_RECORDS:
        _note(ax, f"{prefix}{result.note}", "note")
    if result.fit_warning:
        _note(ax, f"{prefix}{result.fit_warning}", "fit-warning", "tab:red")
    if result.resamples_note:
        _note(ax, f"{prefix}{result.resamples_note}", "resamples-note")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("probability of collapse [-]")
    ax.set_ylim(-0.03, 1.03)
    ax.set_xlim(left=0.0)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    return ax


#: The gids of the notes under a fragility figure's axes.
NOTE_GIDS = ("note", "few-records", "fit-warning", "resamples-note")
#: Characters of a note's line under the axes (a longer note is wrapped).
NOTE_WIDTH = 120


def _note(ax, text: str, gid: str, color: str = "black") -> None:
    """A note under the axes (off the points and the legend), below the last one, wrapped
    at NOTE_WIDTH characters."""
    lines = sum(t.get_text().count("\n") + 1 for t in ax.texts if t.get_gid() in NOTE_GIDS)
    ax.text(0.0, -0.14 - 0.04 * lines, textwrap.fill(text, NOTE_WIDTH), transform=ax.transAxes,
            fontsize=7, va="top", color=color, gid=gid)  # fmt: skip


#: Most points labelled with their counts: beyond, the labels cover each other (a suite
#: scaled to each record's own intensity measure has one point per record and level).
MAX_COUNT_LABELS = 40


def _plot_observed(ax, table: pd.DataFrame, prefix: str, color, counts: bool):
    """The observed fractions (gid "observed"), with "collapsed/trials" beside each point
    when `counts` and there are at most MAX_COUNT_LABELS points (trials are the records, or
    every ensemble member of each record where members count as trials); returns the colour
    used."""
    trials = table["n_trials"] if "n_trials" in table.columns else table["n_records"]
    per_member = bool((trials != table["n_records"]).any())
    what = "collapsed/trials" if per_member else "collapsed/records"
    shown = counts and len(table) <= MAX_COUNT_LABELS
    (points,) = ax.plot(
        table["intensity_g"],
        table["fraction"],
        "o",
        color=color,
        label=f"{prefix}observed fraction collapsed" + (f" ({what})" if shown else ""),
    )
    points.set_gid("observed")
    color = points.get_color()
    if shown:
        for x, y, k, n in zip(
            table["intensity_g"], table["fraction"], table["n_collapsed"], trials, strict=True
        ):
            if n > 0:
                ax.annotate(
                    f"{k}/{n}",
                    (x, y),
                    textcoords="offset points",
                    xytext=(4, 4),
                    fontsize=7,
                    color=color,
                )
    return color


def _plot_fit(ax, result: FragilityResult, prefix: str, color) -> None:
    """The bootstrap band (gid "band", when resamples fitted) and the fitted curve (gid
    "fitted") of a result with a fit."""
    curve = result.curve
    lo, hi = result.ci_percentiles
    if result.n_resamples_used > 0:
        band = ax.fill_between(
            curve["intensity_g"],
            curve["lower"],
            curve["upper"],
            color=color,
            alpha=0.2,
            linewidth=0,
            label=f"{prefix}bootstrap {lo:g}-{hi:g} % band "
            f"({result.n_resamples_used} resamples of the records)",
        )
        band.set_gid("band")
    (fitted,) = ax.plot(
        curve["intensity_g"],
        curve["probability"],
        "-",
        color=color,
        label=f"{prefix}lognormal MLE: median {result.fit.median_g:.3g} {result.intensity_unit}, "
        f"beta {result.fit.beta:.2f}",
    )
    fitted.set_gid("fitted")


#: Colours of the records in ida.png (a record k gets colour k mod 20 and line style
#: k // 20 mod 4, so 80 records are told apart before a pair repeats).
IDA_COLOURS = "tab20"
IDA_STYLES = ("-", "--", "-.", ":")
#: Records per column of the IDA's legend (beside the axes: 25 names fit its height).
IDA_LEGEND_ROWS = 25


def ida_curve(x: np.ndarray, y: np.ndarray, collapsed: np.ndarray, right: float):
    """The IDA curve of one record in the field's convention (Vamvatsikos and Cornell
    2002): its runs sorted by intensity ``x``, peak response ``y``, up to its first
    collapse, then a flat line at that collapse intensity out to the response ``right``.

    Returns (response, intensity, first collapse index or None): the curve's points, the
    response on the horizontal axis. Runs above the first collapse are not on the curve.
    """
    hit = np.flatnonzero(collapsed)
    if hit.size == 0:
        return y.copy(), x.copy(), None
    k = int(hit[0])
    response = np.append(y[: k + 1], max(right, float(y[k])))
    intensity = np.append(x[: k + 1], x[k])
    return response, intensity, k


def ida_style(k: int) -> dict:
    """Colour and line style of the k-th record (by name) in ida.png."""
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib import colormaps

    colours = colormaps[IDA_COLOURS].colors
    return {"color": colours[k % len(colours)],
            "linestyle": IDA_STYLES[(k // len(colours)) % len(IDA_STYLES)]}  # fmt: skip


def plot_ida(df: pd.DataFrame, ax=None, *, intensity_column: str | None = None):
    """Incremental dynamic analysis: intensity against peak rotation ratio, a curve per
    record, flat from its first collapse on (the field's convention: intensity on the
    vertical axis, the response on the horizontal).

    Parameters
    ----------
    df : pandas.DataFrame
        Rows with ``record``, an intensity column [g] (``intensity_g``, ``amplitude_g`` or
        ``intensity``), ``max_rotation_ratio``, ``collapsed``; optional ``status``
        (failed rows are left out)
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure's when None)
    intensity_column : str, optional
        Name of the intensity column

    Returns
    -------
    matplotlib.axes.Axes
        One curve per record (gid ``record:<name>``, label the record's name): its runs
        sorted by intensity, response on x, intensity on y, up to the first collapse
        (marked "x", gid ``collapse:<name>``), then horizontal at that intensity to the
        right edge (:func:`ida_curve`); runs of a record that survive above its first
        collapse intensity are hollow circles off the curve (gid ``above:<name>``). The
        collapse limit (ratio 1) is a dashed vertical line (gid ``limit``). The legend,
        beside the axes, names every record (colour k mod 20, line style k // 20:
        :func:`ida_style`), in columns of :data:`IDA_LEGEND_ROWS`.
    """
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.lines import Line2D

    column = find_intensity_column(df, intensity_column)
    needed = [C.record, column or "intensity_g", C.max_rotation_ratio, C.collapsed]
    missing = [c for c in needed if c not in df.columns]
    if missing:
        raise RbmError(f"IDA plot: missing column {missing[0]!r}")
    rows = df if C.status not in df.columns else df[df[C.status].astype(str) != "failed"]
    ax = ax if ax is not None else _new_axes()
    ratios = rows[C.max_rotation_ratio].to_numpy(float)
    finite = ratios[np.isfinite(ratios)]
    right = 1.5 * max(1.0, float(finite.max()) if finite.size else 1.0)
    handles, above_any, collapse_any = [], False, False
    groups = sorted(rows.groupby(rows[C.record].astype(str)), key=lambda g: g[0])
    for k, (name, group) in enumerate(groups):
        group = group.sort_values(column)
        x = group[column].to_numpy(float)
        y = group[C.max_rotation_ratio].to_numpy(float)
        hit = group[C.collapsed].to_numpy(float) == 1.0
        response, intensity, first = ida_curve(x, y, hit, right)
        style = ida_style(k)
        (line,) = ax.plot(response, intensity, lw=1.0, alpha=0.85, label=name, **style)
        line.set_gid(f"record:{name}")
        handles.append(line)
        if first is None:
            continue
        collapse_any = True
        (mark,) = ax.plot([y[first]], [x[first]], "x", color=style["color"], ms=6)
        mark.set_gid(f"collapse:{name}")
        later = ~hit[first + 1 :]
        if later.any():
            above_any = True
            (up,) = ax.plot(y[first + 1 :][later], x[first + 1 :][later], "o", ms=4,
                            mfc="none", color=style["color"])  # fmt: skip
            up.set_gid(f"above:{name}")
    limit = ax.axvline(1.0, color="k", ls="--", lw=0.8, label="collapse limit (ratio 1)")
    limit.set_gid("limit")
    keys = [limit]
    if collapse_any:
        keys.append(Line2D([], [], color="0.3", marker="x", lw=1.0,
                           label="first collapse, then flat at its intensity"))  # fmt: skip
    if above_any:
        keys.append(Line2D([], [], color="0.3", marker="o", mfc="none", ls="none",
                           label="survived above its first collapse"))  # fmt: skip
    ax.set_ylabel("intensity: peak ground acceleration [g]")
    ax.set_xlabel(column_label(C.max_rotation_ratio))
    ax.set_xlim(0.0, right)
    ax.set_ylim(bottom=0.0)
    ax.grid(True, alpha=0.3)
    columns = max(1, math.ceil(len(handles) / IDA_LEGEND_ROWS))
    key = ax.legend(handles=keys, fontsize=7, loc="lower right")
    ax.add_artist(key)
    names = ax.legend(handles=handles, title=f"{len(handles)} records", fontsize=6,
                      title_fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0),
                      borderaxespad=0.0, ncols=columns)  # fmt: skip
    names.set_gid("records")
    key.set_gid("key")
    return ax
