"""The polar picture of a domain over the ground motion's azimuth (an ``excitation.angle``
axis: models housner-3d and rbm-3d): per angle [deg], the critical amplitude [g] as the
radius.

What is drawn. Per angle, the boundary of the domain at that angle
(:func:`rbm_cli.study.domain.boundary`, the one rule of boundary.csv): the lowest grid
amplitude at which the column collapsed and the highest amplitude below it at which it
survived. The level at which the column starts to rock (its static multiplier) is a dashed
grey circle. The collapse radius is a solid line, the survival radius a dashed line in the
same colour, and the band between them is shaded: the boundary lies in it. One curve per
point of the remaining axes (the frequency and any other axis), with a legend. An angle
where nothing collapsed up to the grid's largest amplitude is *open*: its collapse radius
is drawn on a dotted ring beyond that amplitude, marked by an open triangle, the line to it
dotted. Where the column collapsed at the grid's lowest amplitude, the survival radius is 0.
Failed runs count neither as collapse nor as survival (grey squares at their cells; the
legend says how many were left out). In an ensemble domain the outcome of a cell is the
majority's, as in boundary.csv.

Angles. The azimuth is measured from x, counter-clockwise, as ``excitation.angle`` is.
Angles that go round the whole turn (no gap wider than 1.5 times the even spacing of the
turn) close the curves; otherwise the axes show only the sector the angles span (rounded
out to 15 degrees). Between two grid angles the radii are joined linearly in the angle, so
a constant radius is an arc.

Every artist carries a gid: 'band-<k>', 'collapsed-<k>' (the solid line and its marks),
'to-open-<k>' (dotted, to an open angle), 'survived-<k>', 'open-<k>' (the open triangles)
of the k-th curve; 'open-ring', 'static', 'failed'.
"""

from __future__ import annotations

import math
import numbers

import numpy as np
import pandas as pd

from rbm_cli.base.errors import RbmError
from rbm_cli.config.types import Config
from rbm_cli.report.domain_view import point_key, value_text
from rbm_cli.report.plot_axes import STATIC, point_colours, uplift_level
from rbm_cli.study.boundary_lines import MAJORITY, line_ident, line_order, majority_status
from rbm_cli.study.domain import axis_columns, boundary
from rbm_cli.study.outcomes import ANGLE_AXIS
from rbm_cli.study.schema import C

__all__ = [
    "ANGLE_AXIS",
    "POLAR_FIELDS",
    "curve_columns",
    "curve_label",
    "draw_polar",
    "has_angle_axis",
    "is_closed_turn",
    "polar_boundary",
    "static_level",
]

#: polar_boundary's columns after the curve's: the angle [deg], the highest survived and
#: the lowest collapsed amplitude [g] (NaN where there is none) and the failed runs left out.
POLAR_FIELDS = ("angle_deg", "survived_g", "collapsed_g", "n_failed")
#: The ring of the open angles and the edge of the axes, as multiples of the grid's
#: largest amplitude.
OPEN_RING, EDGE = 1.1, 1.2
#: Largest step [deg] of the lines joining two grid angles (a constant radius is an arc).
STEP_DEG = 2.0
#: A sector's edges are rounded out to this [deg].
SECTOR_ROUND = 15.0
#: Opacity of the band between the two radii.
BAND_ALPHA = 0.2
#: Legend labels of the styles (the curves' own entries name their point).
COLLAPSED_LABEL = "solid, filled marks: lowest amplitude that collapsed"
SURVIVED_LABEL = "dashed: highest amplitude below it that survived"
BAND_LABEL = "shaded: between the two (the boundary lies there)"
FAILED_LABEL = "failed run, left out (neither collapse nor survival)"
#: What the radius and the angle are (beside the axes, under the legend).
AXES_NOTE = ("radius: amplitude [g]\nangle: azimuth of the ground motion [deg],\n"
             "    from x, counter-clockwise")  # fmt: skip


def has_angle_axis(df: pd.DataFrame) -> bool:
    """The domain has an ``excitation.angle`` axis: it is drawn in polar axes."""
    return ANGLE_AXIS in axis_columns(df.columns)


def curve_columns(df: pd.DataFrame) -> list[str]:
    """The columns whose values make one curve: the axes other than the angle, then
    frequency_hz."""
    return [c for c in axis_columns(df.columns) if c != ANGLE_AXIS] + [C.frequency_hz]


def _angles(df: pd.DataFrame, where: str) -> np.ndarray:
    """The angle of every row [deg], as floats; an RbmError (one line) for a value that is
    not a finite number."""
    raw = df[ANGLE_AXIS]
    x = pd.to_numeric(raw, errors="coerce").to_numpy(float)
    bad = ~np.isfinite(x)
    if bad.any():
        i = int(np.argmax(bad))
        value = "an empty field" if pd.isna(raw.iloc[i]) else repr(str(raw.iloc[i]))
        raise RbmError(
            f"{where}: line {i + 2}: {ANGLE_AXIS} must be a finite number [deg], got {value}"
        )
    return x


def _outcomes(df: pd.DataFrame) -> pd.Series:
    """Each cell's outcome as the boundary counts it: the status, or for an ensemble the
    majority's ('failed' where every member failed)."""
    if C.collapse_fraction in df.columns:
        return df[C.collapse_fraction].map(majority_status)
    return df[C.status].astype(str)


def polar_boundary(df: pd.DataFrame, where: str = "the domain") -> pd.DataFrame:
    """Per curve and angle: the highest survived and the lowest collapsed amplitude [g].

    Parameters
    ----------
    df : DataFrame  A domain with an ``excitation.angle`` column (domain.csv's rows)
    where : str  How messages name the domain (its file)

    Returns
    -------
    DataFrame  One row per curve (the values of :func:`curve_columns`) and angle:
        those columns, then angle_deg [deg] as in the grid, survived_g (the highest
        amplitude below collapsed_g that survived; NaN if none), collapsed_g (the lowest
        amplitude that collapsed; NaN if none: an open angle), n_failed (failed runs there,
        counted as neither) [g]; curves in boundary.csv's order, angles ascending. An
        ensemble's outcome is its majority's (rbm_cli.study.boundary_lines).

    Raises
    ------
    RbmError  No ``excitation.angle`` column, or an angle that is not a finite number
    """
    if not has_angle_axis(df):
        raise RbmError(f"{where} has no {ANGLE_AXIS} column: it has no polar picture")
    df = df.assign(**{ANGLE_AXIS: _angles(df, where)})
    by = [*axis_columns(df.columns), C.frequency_hz]
    bnd = boundary(df)
    failed = df.loc[(_outcomes(df) == "failed").to_numpy(), by]
    counts: dict = {}
    for values in failed.itertuples(index=False):
        key = point_key(values)
        counts[key] = counts.get(key, 0) + 1
    n_failed = [counts.get(point_key(v), 0) for v in bnd[by].itertuples(index=False)]
    curve = curve_columns(df)
    out = bnd[curve].copy()
    out["angle_deg"] = bnd[ANGLE_AXIS].to_numpy(float)
    out["survived_g"] = bnd["highest_safe_g"].to_numpy(float)
    out["collapsed_g"] = bnd["lowest_unsafe_g"].to_numpy(float)
    out["n_failed"] = np.asarray(n_failed, int)
    idents = [line_ident(tuple(v)) for v in out[curve].itertuples(index=False)]
    key = line_order(idents)
    order = sorted(range(len(out)), key=lambda i: (key(idents[i]), out["angle_deg"].iloc[i]))
    return out.iloc[order].reset_index(drop=True)


def curve_label(columns: list[str], values) -> str:
    """A curve's legend label: its axes' values, then its frequency ('1 Hz'; none for a
    record)."""
    parts = []
    for column, value in zip(columns, values, strict=True):
        if column == C.frequency_hz:
            if value is not None and not pd.isna(value):
                parts.append(f"{float(value):g} Hz")
        else:
            parts.append(f"{column} = {value_text(value, column)}")
    return ", ".join(parts) or "critical amplitude"


def is_closed_turn(angles_deg) -> tuple[bool, float, float]:
    """(closed, start, end) of a set of angles [deg]: closed when they go round the whole
    turn (three or more directions, no gap wider than 1.5 times 360 / their count); else
    the sector they span, from ``start`` counter-clockwise to ``end`` (start in
    [-180, 180), end - start < 360)."""
    a = np.unique(np.round(np.mod(np.asarray(angles_deg, float), 360.0), 9) % 360.0)
    if a.size == 0:
        return False, 0.0, 0.0
    gaps = np.append(np.diff(a), a[0] + 360.0 - a[-1])
    k = int(np.argmax(gaps))
    if a.size >= 3 and gaps[k] <= 1.5 * 360.0 / a.size:
        return True, 0.0, 360.0
    start = float(a[(k + 1) % a.size])
    start = (start + 180.0) % 360.0 - 180.0
    return False, start, start + 360.0 - float(gaps[k])


def _unwrap(angles_deg: np.ndarray, start: float) -> np.ndarray:
    """The angles [deg] as start + their counter-clockwise distance from it, in [0, 360)."""
    return start + np.mod(np.round(angles_deg - start, 9), 360.0)


def _dense(theta_deg: np.ndarray, r: np.ndarray, keep: np.ndarray) -> tuple:
    """(theta [rad], r) joined linearly in the angle between consecutive points, in steps
    of at most STEP_DEG; the segments where ``keep`` is False are NaN (a gap), and so is a
    point of no kept segment."""
    n_points = len(theta_deg)
    ts, rs = [], []
    for i in range(n_points):
        ends = [keep[j] for j in (i - 1, i) if 0 <= j < n_points - 1]
        ts.append([theta_deg[i]])
        rs.append([r[i] if any(ends) else np.nan])
        if i == n_points - 1:
            break
        t0, t1 = theta_deg[i], theta_deg[i + 1]
        n = max(2, math.ceil((t1 - t0) / STEP_DEG))  # a gap keeps a point inside it
        s = np.linspace(0.0, 1.0, n + 1)[1:-1]
        ts.append(t0 + s * (t1 - t0))
        rs.append(r[i] + s * (r[i + 1] - r[i]) if keep[i] else np.full(s.shape, np.nan))
    return np.radians(np.concatenate(ts)), np.concatenate(rs)


def _numeric(groups: list) -> bool:
    """One numeric quantity varies over the curves (ordered colours)."""
    columns = list(zip(*(values for values, _ in groups), strict=True))
    varying = [c for c in columns if len({str(v) for v in c}) > 1]
    return len(varying) == 1 and all(
        isinstance(v, numbers.Real) and not isinstance(v, bool) for v in varying[0]
    )


def _draw_curve(ax, rows: pd.DataFrame, k: int, colour, label: str, closed: bool,
                start: float, ring: float) -> bool:  # fmt: skip
    """One curve (module docstring); returns whether it has an open angle."""
    theta = _unwrap(rows["angle_deg"].to_numpy(float), start)
    order = np.argsort(theta, kind="stable")
    theta = theta[order]
    survived = rows["survived_g"].to_numpy(float)[order]
    collapsed = rows["collapsed_g"].to_numpy(float)[order]
    known = np.isfinite(survived) | np.isfinite(collapsed)  # not every run failed
    is_open = known & ~np.isfinite(collapsed)
    low = np.where(known & ~np.isfinite(survived), 0.0, survived)  # collapsed at the lowest
    high = np.where(is_open, ring, collapsed)
    if closed:
        theta, low, high = (
            np.append(v, w) for v, w in ((theta, theta[0] + 360.0), (low, low[0]), (high, high[0]))
        )
        known, is_open = np.append(known, known[0]), np.append(is_open, is_open[0])
    both = known[:-1] & known[1:]
    to_open = both & (is_open[:-1] | is_open[1:])
    t, lo = _dense(theta, low, both)
    _, hi = _dense(theta, high, both)
    finite = np.isfinite(lo) & np.isfinite(hi)
    ax.fill_between(t, np.nan_to_num(lo), np.nan_to_num(hi), where=finite, color=colour,
                    alpha=BAND_ALPHA, linewidth=0, gid=f"band-{k}")  # fmt: skip
    if len(theta) == 1 and known[0]:  # one direction: the band is a bar along its ray
        ax.plot(np.radians([theta[0]] * 2), [low[0], high[0]], color=colour, linewidth=6,
                alpha=BAND_ALPHA, solid_capstyle="butt", gid=f"band-{k}")  # fmt: skip
    _, solid = _dense(theta, high, both & ~to_open)
    ax.plot(t, solid, color=colour, linewidth=1.8, label=label, gid=f"collapsed-{k}")
    n = len(rows)  # the marks: each grid angle once (not the closing point)
    marks = known[:n] & ~is_open[:n]
    ax.plot(np.radians(theta[:n][marks]), high[:n][marks], linestyle="none", marker="o",
            markersize=4, color=colour, gid=f"collapsed-{k}")  # fmt: skip
    if to_open.any():
        _, dotted = _dense(theta, high, to_open)
        ax.plot(t, dotted, color=colour, linewidth=1.2, linestyle=":", gid=f"to-open-{k}")
    ax.plot(t, lo, color=colour, linewidth=1.4, linestyle="--", gid=f"survived-{k}")
    if is_open[:n].any():
        ax.plot(np.radians(theta[:n][is_open[:n]]), high[:n][is_open[:n]], linestyle="none",
                marker="^", markersize=8, markerfacecolor="white", markeredgewidth=1.5,
                color=colour, gid=f"open-{k}", zorder=5)  # fmt: skip
    return bool(is_open.any())


def _ring(closed: bool, start: float, end: float) -> np.ndarray:
    """Angles [rad] of a ring over the turn or the sector."""
    lo, hi = (0.0, 360.0) if closed else (start, end)
    return np.radians(np.linspace(lo, hi, max(2, math.ceil((hi - lo) / STEP_DEG) + 1)))


def _sector(ax, start: float, end: float) -> None:
    """Show the sector [start, end] [deg] only, rounded out to SECTOR_ROUND, at least 90 deg
    wide."""
    lo = math.floor(start / SECTOR_ROUND) * SECTOR_ROUND
    hi = math.ceil(end / SECTOR_ROUND) * SECTOR_ROUND
    if hi - lo < 90.0:
        pad = math.ceil((90.0 - (hi - lo)) / 2.0 / SECTOR_ROUND) * SECTOR_ROUND
        lo, hi = lo - pad, hi + pad
    ax.set_thetamin(lo)
    ax.set_thetamax(min(hi, lo + 360.0))


def static_level(df: pd.DataFrame, config: Config | None) -> tuple[float, str] | None:
    """(level [g], name) at which the column starts to rock: the domain's static_multiplier
    column where it holds one value, else the config's (rbm_cli.report.plot_axes.uplift_level);
    None where the domain's values differ (an axis over the column) or neither is known."""
    if C.static_multiplier in df.columns:
        values = pd.to_numeric(df[C.static_multiplier], errors="coerce").to_numpy(float)
        values = values[np.isfinite(values)]
        if values.size and np.ptp(values) <= 1e-9 * abs(values[0]):
            return float(values[0]), "static multiplier"
        if values.size:
            return None
    return uplift_level(config) if config is not None else None


def draw_polar(ax, df: pd.DataFrame, config: Config | None = None, where: str = "the domain"):
    """Draw the polar picture of a domain over ``excitation.angle`` on a polar axes
    (module docstring); ``config``: the config it was swept with, for the level at which
    the column starts to rock (a dashed circle). Returns the axes."""
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.lines import Line2D

    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.patches import Patch

    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.ticker import FuncFormatter

    radii = polar_boundary(df, where)
    amplitudes = df[C.amplitude_g].to_numpy(float)
    top = float(np.nanmax(amplitudes)) if np.isfinite(amplitudes).any() else 1.0
    top = top if top > 0.0 else 1.0
    ring = OPEN_RING * top
    closed, start, end = is_closed_turn(radii["angle_deg"])
    curve = curve_columns(df)
    groups = [(tuple(values), rows) for values, rows in
              radii.groupby(curve, sort=False, dropna=False)]  # fmt: skip
    colours = point_colours(len(groups), _numeric(groups))
    handles, any_open = [], False
    for k, ((values, rows), colour) in enumerate(zip(groups, colours, strict=True)):
        label = curve_label(curve, values)
        any_open |= _draw_curve(ax, rows, k, colour, label, closed, start, ring)
        handles.append(Line2D([], [], color=colour, linewidth=1.8, marker="o", markersize=4,
                              label=label))  # fmt: skip
    grey = dict(color="0.25")
    handles += [
        Line2D([], [], linewidth=1.8, marker="o", markersize=4, label=COLLAPSED_LABEL, **grey),
        Line2D([], [], linewidth=1.4, linestyle="--", label=SURVIVED_LABEL, **grey),
        Patch(facecolor="0.25", alpha=BAND_ALPHA, label=BAND_LABEL),
    ]
    ring_theta = _ring(closed, start, end)
    outer = EDGE * top
    if any_open:
        ax.plot(ring_theta, np.full(ring_theta.shape, ring), color="0.45", linewidth=1.0,
                linestyle=":", gid="open-ring")  # fmt: skip
        handles.append(Line2D([], [], linestyle=":", marker="^", markersize=8,
                              markerfacecolor="white", markeredgewidth=1.5,
                              label=f"open: no collapse up to {top:.3g} g"
                              " (on the dotted ring)", **grey))  # fmt: skip
    static = static_level(df, config)
    if static is not None:
        level, name = static
        ax.plot(ring_theta, np.full(ring_theta.shape, level), gid="static", **STATIC)
        handles.append(Line2D([], [], label=f"{name} {level:.3g} g", **STATIC))
        outer = max(outer, 1.06 * level)
    failed = (_outcomes(df) == "failed").to_numpy()
    if failed.any():
        theta = _unwrap(_angles(df, where)[failed], start)
        ax.plot(np.radians(theta), amplitudes[failed], linestyle="none", marker="s",
                markersize=4, color="0.45", gid="failed", zorder=4)  # fmt: skip
        handles.append(Line2D([], [], linestyle="none", marker="s", markersize=4, color="0.45",
                              label=f"{FAILED_LABEL}: {int(failed.sum())}"))  # fmt: skip
    ax.set_rlim(0.0, outer)
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g} g"))
    ax.tick_params(axis="y", labelsize="small")
    if not closed:
        _sector(ax, start, end)
    ax.set_rlabel_position(start + 0.5 * (end - start) if not closed else 67.5)
    ax.grid(True, alpha=0.35)
    what = " and ".join(c.replace("_hz", "") for c in curve if c != C.frequency_hz or
                        radii[C.frequency_hz].notna().any())  # fmt: skip
    title = f"one curve per {what}" if what else ""
    if C.collapse_fraction in df.columns:
        title += f"\noutcome: the majority's (collapse fraction >= {MAJORITY:g})"
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.12, 1.0), borderaxespad=0.0,
              fontsize="small", title=title.strip() or None, title_fontsize="small")  # fmt: skip
    ax.text(1.12, 0.0, AXES_NOTE, transform=ax.transAxes, ha="left", va="bottom",
            fontsize="small", gid="axes-note")  # fmt: skip
    return ax
