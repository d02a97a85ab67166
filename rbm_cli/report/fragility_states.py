"""Files and figures of the damage states and of the comparison of intensity measures
(:mod:`rbm_cli.study.fragility_states`, :mod:`rbm_cli.study.intensity_choice`).

- ``fragility_states.csv``: one row per damage state (its threshold of max_rotation_ratio,
  median and beta with their bootstrap intervals, counts, notes);
- ``fragility_states.png``: every state's observed fractions, fitted curve and band in one
  figure (:func:`plot_states`);
- ``fragility_residual.csv`` and ``fragility_residual.png``: the same of the residual
  states (thresholds of ``residual_slip_m``);
- ``fragility_intensities.csv``: one row per intensity measure, ranked by beta;
- the IDA's thresholds: a dotted vertical line per state below collapse
  (:func:`mark_thresholds`).

Plot functions draw on a given axes or a new figure's (no pyplot) and return the axes.
"""

from __future__ import annotations

import textwrap

from rbm_cli.study.fragility_states import PEAK, DamageStates, StateMeasure
from rbm_cli.study.intensity_choice import IntensityComparison

#: Float format of the CSV files (12 significant digits, as domain.csv).
FLOAT_FORMAT = "%.12g"
#: Colours of the damage states, lowest threshold first.
STATE_COLOURS = ("tab:green", "tab:olive", "tab:orange", "tab:red", "tab:purple", "tab:brown",
                 "tab:pink", "tab:gray", "tab:cyan", "tab:blue")  # fmt: skip


def states_csv(states: DamageStates) -> str:
    """The text of ``fragility_states.csv`` (empty cells where undefined)."""
    return states.table().to_csv(index=False, float_format=FLOAT_FORMAT, lineterminator="\n")


def intensities_csv(comparison: IntensityComparison) -> str:
    """The text of ``fragility_intensities.csv`` (empty cells where undefined)."""
    return comparison.table.to_csv(index=False, float_format=FLOAT_FORMAT, lineterminator="\n")


def _new_axes():
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.figure import Figure

    return Figure(figsize=(7, 5)).subplots()


def state_label(threshold: float, measure: StateMeasure = PEAK) -> str:
    """A state's name in the figures: collapse at the measure's upper bound (a peak
    rotation ratio of 1), else its column >= the threshold (with its unit)."""
    if measure.upper is not None and threshold >= measure.upper:
        return "collapse"
    unit = f" {measure.unit}" if measure.unit != "-" else ""
    return f"{measure.column} >= {threshold:g}{unit}"


def plot_states(states: DamageStates, ax=None, *, xlabel: str = "intensity"):
    """Every damage state's observed fractions (gid ``observed:<t>``), fitted lognormal
    curve (gid ``fitted:<t>``) and bootstrap band (gid ``band:<t>``), the lowest
    threshold first, with the crossings and the ensemble's note under the axes (gid
    ``crossing``, ``note``). Returns the axes."""
    ax = ax if ax is not None else _new_axes()
    unit = states.intensity_unit
    for k, (t, res) in enumerate(zip(states.thresholds, states.results, strict=True)):
        color = STATE_COLOURS[k % len(STATE_COLOURS)]
        name = state_label(t, states.measure)
        table = res.table
        (points,) = ax.plot(table["intensity_g"], table["fraction"], "o", ms=4, color=color,
                            label=f"{name}: observed fraction")  # fmt: skip
        points.set_gid(f"observed:{t:g}")
        if res.fit is None:
            points.set_label(f"{name}: observed fraction (no fit: {res.note})")
            continue
        curve = res.curve
        if res.n_resamples_used > 0:
            band = ax.fill_between(curve["intensity_g"], curve["lower"], curve["upper"],
                                   color=color, alpha=0.15, linewidth=0)  # fmt: skip
            band.set_gid(f"band:{t:g}")
        (line,) = ax.plot(curve["intensity_g"], curve["probability"], "-", color=color,
                          label=f"{name}: median {res.fit.median_g:.3g} {unit}, "
                          f"beta {res.fit.beta:.2f}")  # fmt: skip
        line.set_gid(f"fitted:{t:g}")
    lines = 0
    for gid, text in [*(("crossing", c) for c in states.crossings), ("note", states.note)]:
        if text:
            wrapped = textwrap.fill(text, 120)
            ax.text(0.0, -0.14 - 0.04 * lines, wrapped, transform=ax.transAxes, fontsize=7,
                    va="top", color="tab:red" if gid == "crossing" else "black",
                    gid=gid)  # fmt: skip
            lines += wrapped.count("\n") + 1
    lo, hi = states.results[0].ci_percentiles
    ax.set_xlabel(xlabel)
    ax.set_ylabel(f"probability of exceeding the state [-] (bands: bootstrap {lo:g}-{hi:g} %)")
    ax.set_ylim(-0.03, 1.03)
    ax.set_xlim(left=0.0)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    return ax


def states_figure(states: DamageStates, label: str, title: str = ""):
    """A new figure (no pyplot) with :func:`plot_states`."""
    ax = plot_states(states, xlabel=label)
    name = states.measure.name
    ax.set_title(f"{name}, {title}" if title else name, fontsize=9)
    return ax.figure


def mark_thresholds(ax, thresholds) -> list:
    """A dotted vertical line at each damage state's threshold below 1 on an IDA's axes
    (response horizontal; 1 is already its collapse limit), gid ``state:<t>``, the first
    labelled; returns the lines."""
    lines = []
    for t in thresholds:
        if t >= 1.0:
            continue
        line = ax.axvline(t, color="0.35", ls=":", lw=0.9,
                          label="damage states" if not lines else None)  # fmt: skip
        line.set_gid(f"state:{t:g}")
        ax.annotate(f"{t:g}", (t, 1.0), xycoords=("data", "axes fraction"), fontsize=7,
                    xytext=(2, -10), textcoords="offset points", color="0.35")  # fmt: skip
        lines.append(line)
    return lines


__all__ = [
    "FLOAT_FORMAT",
    "intensities_csv",
    "mark_thresholds",
    "plot_states",
    "state_label",
    "states_csv",
    "states_figure",
]
