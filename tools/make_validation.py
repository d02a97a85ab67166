"""Regenerate docs/validation.md and its figures (the validation report).

    python tools/make_validation.py            # full report into docs/ (< 10 min on 2 cores)
    python tools/make_validation.py --quick    # smaller grids, shorter runs (< 60 s)
    python tools/make_validation.py --quick --out /tmp/val

Everything goes through the library API (no CLI calls); every number written
into validation.md is printed as it is measured. Sweeps write into a
temporary folder that is removed at the end.
"""

from __future__ import annotations

import argparse
import dataclasses as dc
import datetime as _dt
import math
import os
import platform
import sys
import tempfile
import time
import traceback
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from validation_measures import (  # noqa: E402  (the module beside this script)
    differing_cells,
    linear_domain,
    period_from_crossings,
    zero_crossings,
)

from rbm_cli.api import run_sweep  # noqa: E402
from rbm_cli.config.load import load_config, parse_config  # noqa: E402
from rbm_cli.config.types import ExcitationConfig, GridConfig, InitialConfig  # noqa: E402
from rbm_cli.inputs.excitation import make_ground_motion  # noqa: E402
from rbm_cli.models.block.closed_form import linear_run  # noqa: E402
from rbm_cli.report.plot_domain import plot_domain  # noqa: E402
from rbm_cli.structures.block import block_geometry  # noqa: E402
from rbm_cli.structures.closed_forms import (  # noqa: E402
    free_rocking_period,
    halfsine_threshold_curves,
    linear_rocking_parameters,
)
from rbm_cli.structures.column import build_column  # noqa: E402
from rbm_cli.study.domain import boundary, compare, read_domain  # noqa: E402
from rbm_cli.study.simulate import model_from_config, simulate  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
CONFIGS = ROOT / "configs"
RESULTS = ROOT / "results"


# ----------------------------------------------------------------------------- helpers


#: The line under every figure of the report: what made it, when, where.
FIGURE_NOTE = (
    f"*Made by `python tools/make_validation.py` on "
    f"{_dt.datetime.now().astimezone().strftime('%Y-%m-%d')}, {platform.machine()}, "
    f"{os.cpu_count()} cores.*"
)


class Report:
    """Markdown lines, printed as they are written."""

    def __init__(self):
        self.lines: list[str] = []

    def __call__(self, text: str = "") -> None:
        print(text, flush=True)
        self.lines.append(text)
        if text.startswith("!["):  # every figure names the script, date and machine
            self("")
            self(FIGURE_NOTE)

    def table(self, header: list[str], rows: list[list]) -> None:
        self("| " + " | ".join(header) + " |")
        self("|" + "|".join("---" for _ in header) + "|")
        for row in rows:
            self("| " + " | ".join(str(v) for v in row) + " |")
        self()


def fmt(x, digits: int = 3) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    return f"{x:.{digits}g}"


def save(fig, out: Path, name: str) -> str:
    path = out / "figures" / f"validation_{name}.png"
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return f"figures/{path.name}"


def sweep_domain(cfg, tmp: Path, jobs: int) -> tuple[pd.DataFrame, float]:
    """run_sweep into a temporary folder; the domain and the sweep's wall time [s]."""
    summary = run_sweep(cfg, tmp, jobs=jobs)
    return read_domain(summary.folder / "domain.csv"), summary.wall_time_s


def mark_cells(ax, cells: list[dict], label: str) -> None:
    if cells:
        ax.plot(
            [c["frequency_hz"] for c in cells],
            [c["amplitude_g"] for c in cells],
            "s",
            mfc="none",
            mec="red",
            ms=11,
            mew=1.5,
            label=label,
        )
        ax.legend(loc="best", fontsize="small")


def legend_outside(ax) -> None:
    """Move the legend of a domain plot to the right of the axes (it hides cells inside)."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")


def legend_below(ax) -> None:
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2, fontsize="small")


# ----------------------------------------------------------------------------- section 1


def slender_mapping():
    """The slender study's config, column, mapped (alpha, p) and the RBM's restitution."""
    cfg = load_config(CONFIGS / "spanos_koh_slender.yaml")
    column = build_column(cfg.column, cfg.interface)
    alpha, p = linear_rocking_parameters(column)
    e = model_from_config(cfg, column).restitution  # the rule the RBM runs with
    return cfg, column, alpha, p, e


def section1(rep: Report, out: Path, tmp: Path, quick: bool, jobs: int) -> None:
    cfg, column, alpha, p, e = slender_mapping()
    rep(
        "Column: `configs/spanos_koh_slender.yaml` (rectangle H 4 m x B 1 m, rigid law, xi 1, "
        f"e {e:g}). Mapping of the RBM's rigid monolith to the linear block: "
        f"alpha = B/H = {alpha:.6g} rad, "
        f"p = sqrt(m g (H/2) / (I_G + m H^2/4)) = {p:.6g} rad/s "
        "(`closed_forms.linear_rocking_parameters`). The closed form is "
        "`block.closed_form.linear_run` with these alpha and p (cosh/sinh pieces, "
        "events by root finding, no numerical integration)."
    )
    rep()
    rep("### 1a. Time histories")
    rep()
    worst = section1a(rep, out, cfg, alpha, p, e)
    rep("### 1b. The whole domain")
    rep()
    section1b(rep, out, tmp, quick, jobs, (cfg, column, alpha, p, e), worst)


def history_case(cfg, a, f, alpha, p, e, dt, axes) -> list:
    """One time-history case of 1a: RBM and closed form drawn on axes (top, bottom);
    the table row."""
    res = simulate(cfg, a, f, record=True, output_dt=dt)
    h = res.history
    motion = make_ground_motion(cfg.excitation, a, f)
    lin = linear_run(alpha, p, motion, restitution=e, record=True, output_dt=dt, early_stop=False)
    tl = np.array([s[0] for s in lin.samples])
    thl = np.array([s[1][0] for s in lin.samples])
    n = min(len(h.t), len(tl))
    assert np.allclose(h.t[:n], tl[:n], atol=1e-9), "sample times differ"
    th_r = h.rotations[:n, 0]
    err = np.abs(th_r - thl[:n]) / alpha
    peak_r = float(np.max(np.abs(h.rotations[:, 0])) / alpha)
    peak_l = float(np.max(np.abs(thl)) / alpha)
    row = [
        f"{a:g} g, {f:g} Hz",
        res.status,
        lin.status,
        fmt(res.t_collapse_s, 9),
        fmt(lin.t_collapse, 9),
        f"{res.n_impacts} / {lin.n_impacts}",
        f"{peak_r:.6f} / {peak_l:.6f}",
        f"{err.max():.2e}",
    ]
    ax, ax_err = axes
    ax.plot(tl, thl / alpha, color="C1", lw=2.5, alpha=0.6, label="closed form (linear_run)")
    ax.plot(h.t, h.rotations[:, 0] / alpha, color="C0", lw=1.0, label="RBM n = 1 (simulate)")
    ax.axhline(1, color="0.5", ls=":", lw=0.8)
    ax.axhline(-1, color="0.5", ls=":", lw=0.8)
    ax.set_title(f"{a:g} g, {f:g} Hz: RBM {res.status}, closed form {lin.status}")
    ax.set_ylabel("theta / alpha [-]")
    ax.legend(fontsize="small", loc="lower left")
    ax.grid(alpha=0.3)
    ax_err.semilogy(tl[:n], np.maximum(err, 1e-16), color="C3", lw=0.8)
    ax_err.set_ylabel("|RBM - closed| / alpha")
    ax_err.set_xlabel("t [s]")
    ax_err.grid(alpha=0.3)
    return row


def section1a(rep: Report, out: Path, cfg, alpha: float, p: float, e: float) -> str:
    """Time histories; returns the worst max |error| / alpha (text)."""
    dt = 0.002
    cases = [(0.5, 1.0), (1.0, 2.0)]
    fig, axes = plt.subplots(
        2, len(cases), figsize=(11, 6), sharex="col", gridspec_kw={"height_ratios": [2, 1]}
    )
    rows = [
        history_case(cfg, a, f, alpha, p, e, dt, (axes[0, j], axes[1, j]))
        for j, (a, f) in enumerate(cases)
    ]
    fig.suptitle(
        "Rigid RBM n = 1 vs the closed form of the linear rocking equation "
        f"(alpha {alpha:.4g}, p {p:.4g} rad/s)"
    )
    fig.tight_layout()
    rep(f"![time histories]({save(fig, out, 'time_history')})")
    rep()
    rep(
        f"RBM `simulate(..., record=True, output_dt={dt})` (DOP853, rtol {cfg.solver.rtol:g}) "
        "against the closed form sampled at the same times."
    )
    rep()
    rep.table(
        [
            "case",
            "RBM",
            "closed form",
            "RBM t_collapse [s]",
            "closed t_collapse [s]",
            "impacts RBM / closed",
            "peak theta/alpha RBM / closed",
            "max |error| / alpha",
        ],
        rows,
    )
    return f"{max(float(r[-1]) for r in rows):.2e}"


def section1b(rep: Report, out: Path, tmp: Path, quick: bool, jobs: int, mapped, worst: str):
    """The whole domain of the slender block, RBM sweep vs the mapped closed form."""
    cfg, column, alpha, p, e = mapped
    if quick:
        g = cfg.grid
        cfg = dc.replace(cfg, grid=GridConfig(g.amplitudes_g[::3], g.frequencies_hz[::3]))
        rep("*--quick: every third amplitude and frequency of the study grid.*")
        rep()
    rbm_df, wall = sweep_domain(cfg, tmp / "s1", jobs)
    lin_df = linear_domain(cfg, alpha, p, e)
    cmp = compare(rbm_df, lin_df)
    diff = differing_cells(rbm_df, lin_df)
    near = sum(c["near"] for c in diff)
    fig, ax = plt.subplots(figsize=(8, 5.5))
    plot_domain(
        rbm_df,
        ax=ax,
        compare=[lin_df],
        labels=["RBM n = 1 (run_sweep)", "closed form, mapped (alpha, p)"],
        column=column,
    )
    mark_cells(ax, diff, "cells that differ")
    legend_outside(ax)
    ax.set_title("Spanos-Koh slender block: RBM domain vs the mapped closed form")
    rep(f"![domain]({save(fig, out, 'domain_rbm_vs_linear')})")
    rep()
    na, nf = len(cfg.grid.amplitudes_g), len(cfg.grid.frequencies_hz)
    rep(
        f"Grid {na} amplitudes x {nf} frequencies = {cmp.n_common} cells "
        f"({min(cfg.grid.amplitudes_g):g}-{max(cfg.grid.amplitudes_g):g} g, "
        f"{min(cfg.grid.frequencies_hz):g}-{max(cfg.grid.frequencies_hz):g} Hz); the RBM sweep "
        f"took {wall:.1f} s on {jobs} workers."
    )
    rep()
    report_differences(rep, cmp, diff, near)
    rep(
        f"**What it shows:** the rigid RBM with n = 1 integrates the piecewise-linear rocking "
        f"equation to within {worst} of alpha along whole histories, and its domain "
        + (
            "is the closed form's, cell for cell."
            if cmp.n_differ == 0
            else f"differs from the closed form's in {cmp.n_differ} cell(s) "
            f"({near} of them next to the boundary), i.e. where a run grazes the collapse limit."
        )
    )
    rep()


def report_differences(rep: Report, cmp, diff: list[dict], near: int) -> None:
    """The cells that differ between the RBM and the closed form, one line each."""
    rep(
        f"- cells that differ: **{cmp.n_differ}** of {cmp.n_common} "
        f"({100 * cmp.fraction:.2f} %), of which {near} next to the boundary "
        "(an amplitude neighbour at the same frequency has the other status)"
    )
    rep(
        f"- max boundary shift (lowest collapsed amplitude per frequency): "
        f"**{cmp.max_shift_g:.3g} g**"
    )
    for c in diff:
        rep(
            f"  - {c['amplitude_g']:g} g, {c['frequency_hz']:g} Hz: RBM "
            f"{'collapsed' if c['a'] else 'survived'}, closed form "
            f"{'collapsed' if c['b'] else 'survived'}, next to the boundary: {c['near']}"
        )
    rep()


# ----------------------------------------------------------------------------- section 2


def block_row(base, ratio: float, height: float, units, tmp: Path, jobs: int):
    """housner vs housner-linear for one block H/B = ratio on a grid in its own units
    (A/alpha, omega/p): the table row, the curve point (alpha, % differ, max shift /
    alpha, mean |shift| / alpha) and whether every differing cell is next to the boundary."""
    amp_units, freq_units = units
    col = dc.replace(
        base.column, base_width=height / ratio, top_width=height / ratio, height=height
    )
    geo = block_geometry(col)
    alpha, p = geo.slenderness, geo.frequency_parameter
    grid = GridConfig(
        tuple(float(x) for x in alpha * amp_units),
        tuple(float(x) for x in p * freq_units / (2 * math.pi)),
    )
    doms = {}
    for model in ("housner", "housner-linear"):
        cfg = dc.replace(base, name=f"hb{ratio}_{model}", model=model, column=col, grid=grid)
        doms[model], _ = sweep_domain(cfg, tmp / "s2", jobs)
    cmp = compare(doms["housner"], doms["housner-linear"])
    diff = differing_cells(doms["housner"], doms["housner-linear"])
    near = sum(c["near"] for c in diff)
    mean_shift = float(cmp.shifts["shift_g"].abs().mean()) / alpha
    point = (alpha, 100 * cmp.fraction, cmp.max_shift_g / alpha, mean_shift)
    row = [
        f"{ratio:g}",
        f"{alpha:.4f}",
        f"{p:.4f}",
        f"{cmp.n_differ} / {cmp.n_common}",
        f"{100 * cmp.fraction:.1f}",
        str(near),
        f"{cmp.max_shift_g:.3g}",
        f"{cmp.max_shift_g / alpha:.3g}",
        f"{mean_shift:.3g}",
    ]
    return row, point, near == len(diff)


def section2(rep: Report, out: Path, tmp: Path, quick: bool, jobs: int) -> None:
    base = load_config(CONFIGS / "spanos_koh_slender.yaml")
    ratios = [10, 4, 2] if quick else [10, 6, 4, 3, 2]
    amp_units = np.array([1.5, 2.25, 3.0, 3.75, 4.5, 5.25, 6.0, 7.0, 8.0, 9.0])
    freq_units = np.arange(1.0, 9.0)
    if quick:
        amp_units, freq_units = amp_units[::3], freq_units[::3]
    H = 4.0
    rep(
        f"Rectangular blocks of the same height H = {H:g} m (depth 1 m) and H/B = "
        f"{', '.join(str(r) for r in ratios)}; both models use the block's true geometry "
        "(`housner.block_geometry`: alpha = atan(B/H), p = sqrt(m g R / I_O)), e = 1, "
        "harmonic 10 s. Grid in the block's own units: A/alpha = "
        f"{', '.join(f'{x:g}' for x in amp_units)} and omega/p = "
        f"{', '.join(f'{x:g}' for x in freq_units)} ({len(amp_units)} x {len(freq_units)} = "
        f"{len(amp_units) * len(freq_units)} cells per block). `housner` uplifts at tan(alpha) g, "
        "`housner-linear` at alpha g."
    )
    rep()
    rows, curve, all_near = [], [], True
    for r in ratios:
        row, point, every_near = block_row(base, r, H, (amp_units, freq_units), tmp, jobs)
        rows.append(row)
        curve.append(point)
        all_near = all_near and every_near
    rep.table(
        [
            "H/B",
            "alpha [rad]",
            "p [rad/s]",
            "cells that differ",
            "% differ",
            "next to boundary",
            "max boundary shift [g]",
            "max shift / alpha",
            "mean abs shift / alpha",
        ],
        rows,
    )
    a_, pc, sh, msh = (np.array(v) for v in zip(*curve, strict=True))
    fig = alpha_figure(a_, pc, sh, msh, ratios)
    rep(f"![housner vs linear]({save(fig, out, 'housner_vs_linear')})")
    rep()
    monotone = bool(np.all(np.diff(pc) >= 0) and pc[-1] > pc[0])
    trend = (
        "the linearisation degrades as alpha grows"
        if monotone
        else "there is no monotonic trend with alpha on this grid: the cells that differ sit "
        + ("next to the boundary at every alpha" if all_near else "mostly at the boundary")
        + ", i.e. the sensitivity of undamped (e = 1) harmonic "
        "rocking to small differences dominates the linearisation error at this resolution "
        "(the time-history difference itself grows as alpha^2, the validation table of the docs)"
    )
    rep(
        f"**What it shows:** the cells that differ go from {pc[0]:.1f} % at alpha "
        f"{a_[0]:.3f} (H/B {ratios[0]}) to {pc[-1]:.1f} % at alpha {a_[-1]:.3f} "
        f"(H/B {ratios[-1]}), with boundary shifts up to {sh.max():.2g} alpha; on a coarse grid "
        f"single cells decide these numbers, so read the trend, not the digits: {trend}."
    )
    rep()


def alpha_figure(a_, pc, sh, msh, ratios):
    """% of cells that differ and boundary shifts against alpha (section 2)."""
    fig, ax = plt.subplots(figsize=(7, 4.2))
    ax.plot(a_, pc, "o-", color="C0", label="% cells that differ")
    ax.set_xlabel("alpha = atan(B/H) [rad]")
    ax.set_ylabel("cells that differ [%]", color="C0")
    ax2 = ax.twinx()
    ax2.plot(a_, sh, "s--", color="C3", label="max boundary shift / alpha")
    ax2.plot(a_, msh, "^:", color="C2", label="mean |boundary shift| / alpha")
    ax2.set_ylabel("boundary shift / alpha [-]", color="C3")
    for x, r in zip(a_, ratios, strict=True):
        ax.annotate(
            f"H/B={r}",
            (x, 0),
            textcoords="offset points",
            xytext=(0, 4),
            fontsize="x-small",
            ha="center",
        )
    ax.set_ylim(bottom=0)
    ax2.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.set_title("housner (large rotations) vs housner-linear as alpha grows")
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, loc="upper left", fontsize="small")
    return fig


# ----------------------------------------------------------------------------- section 3


def halfsine_rows(bnd: pd.DataFrame, curves: dict, p: float) -> tuple[list, int]:
    """Per frequency: the stored boundary, the exact linear and Housner thresholds, and
    whether the exact one lies in (highest safe, lowest unsafe]; and how many do."""
    rows, inside = [], 0
    for k, fr in enumerate(bnd["frequency_hz"].to_numpy(float)):
        lo, hi = bnd["highest_safe_g"].iloc[k], bnd["lowest_unsafe_g"].iloc[k]
        ex, ho = curves["linear"][k], curves["housner"][k]
        ok = (math.isnan(lo) or lo < ex + 1e-9) and (math.isnan(hi) or ex <= hi + 1e-9)
        inside += ok
        rows.append(
            [
                f"{fr:g}",
                f"{2 * math.pi * fr / p:.3f}",
                fmt(lo),
                fmt(hi),
                f"{ex:.4f}",
                f"{ho:.4f}",
                f"{100 * (ex / ho - 1):+.1f}",
                "yes" if ok else "**no**",
            ]
        )
    return rows, inside


def section3(rep: Report, out: Path, tmp: Path, quick: bool, jobs: int) -> None:
    cfg = load_config(CONFIGS / "housner_halfsine.yaml")
    column = build_column(cfg.column, cfg.interface)
    alpha, p = linear_rocking_parameters(column)
    df = read_domain(RESULTS / "housner_halfsine" / "domain.csv")
    bnd = boundary(df)
    f = bnd["frequency_hz"].to_numpy(float)
    curves = halfsine_threshold_curves(column, f)
    step = float(np.min(np.diff(np.sort(df["amplitude_g"].unique()))))
    rep(
        "The stored domain `results/housner_halfsine/domain.csv` (not recomputed; rigid RBM "
        "monolith of the paper's tapered column, half-sine pulse) against the exact "
        "threshold of the linear equation the RBM integrates and Housner's approximation "
        f"A/alpha = sqrt(1 + (w/p)^2) (`closed_forms.halfsine_threshold_curves`; alpha "
        f"{alpha:.4g} rad, p {p:.4g} rad/s). Grid step {step:g} g."
    )
    rep()
    fig, ax = plt.subplots(figsize=(8, 5.5))
    plot_domain(
        df,
        ax=ax,
        column=column,
        excitation_type="half-sine",
        labels=["RBM boundary (stored domain)"],
    )
    legend_outside(ax)
    ax.set_title("Half-sine: stored RBM domain vs exact linear threshold and Housner")
    rep(f"![half-sine]({save(fig, out, 'halfsine')})")
    rep()
    rows, inside = halfsine_rows(bnd, curves, p)
    rep.table(
        [
            "f [Hz]",
            "w/p",
            "highest safe [g]",
            "lowest unsafe [g]",
            "exact linear [g]",
            "Housner [g]",
            "exact vs Housner [%]",
            "exact in (safe, unsafe]",
        ],
        rows,
    )
    band = (f >= 0.3 - 1e-9) & (f <= 0.7 + 1e-9)
    gap = 100 * (curves["linear"][band] / curves["housner"][band] - 1)
    onset = f[np.argmax(curves["housner"] - curves["linear"] > step)]
    rep(
        f"The exact threshold brackets the stored boundary at {inside} of {len(f)} frequencies. "
        f"At 0.3-0.7 Hz it lies {-gap.max():.1f} % to {-gap.min():.1f} % below Housner's "
        f"approximation; the gap exceeds one grid step ({step:g} g) from {onset:g} Hz up."
    )
    rep()
    rep(
        "**What it shows:** the RBM follows the exact threshold of its own equation; the paper's "
        "'lower than Housner at 0.3-0.7 Hz' is Housner's approximation (which drops the "
        "exponential term) being too high there, and the gap keeps growing with frequency "
        "above 0.7 Hz, where the paper did not report it."
    )
    rep()


# ----------------------------------------------------------------------------- section 4


def free_rocking_case(cfg, alpha: float, p: float, r: float, dt: float, ax) -> list:
    """Free rocking from theta0 = r alpha: the periods of the RBM (zero crossings of its
    recorded history) and of the closed form (its impacts) against T; drawn on ax."""
    T = float(free_rocking_period(p, r))
    exc = ExcitationConfig(
        type="free", duration=4.2 * T, initial=InitialConfig(rotations=(r * alpha,))
    )
    c = dc.replace(cfg, excitation=exc)
    res = simulate(c, 0.0, 0.0, record=True, output_dt=dt)
    h = res.history
    t_rbm = period_from_crossings(zero_crossings(h.t, h.rotations[:, 0], h.rates[:, 0]))
    ev: list = []
    linear_run(
        alpha,
        p,
        make_ground_motion(exc, 0.0, 0.0),
        restitution=1.0,
        initial=(r * alpha, 0.0),
        events=ev,
    )
    imp = [t for t, kind in ev if kind == "impact"]
    t_lin = period_from_crossings(imp)
    ax.plot(h.t / T, h.rotations[:, 0] / alpha, label=f"theta0/alpha = {r:g}")
    return [
        f"{r:g}",
        f"{T:.9f}",
        f"{t_rbm:.9f}",
        f"{t_rbm / T - 1:.1e}",
        f"{t_lin:.9f}",
        f"{t_lin / T - 1:.1e}",
        str(res.n_impacts),
    ]


def section4(rep: Report, out: Path, tmp: Path, quick: bool, jobs: int) -> None:
    cfg = load_config(CONFIGS / "spanos_koh_slender.yaml")
    column = build_column(cfg.column, cfg.interface)
    alpha, p = linear_rocking_parameters(column)
    dt = 1e-3
    rep(
        f"Rigid RBM monolith of `spanos_koh_slender` (alpha {alpha:.6g}, p {p:.6g} rad/s by "
        "the mapping), e = 1, excitation `free` from rest at theta0. RBM: "
        f"`simulate(record=True, output_dt={dt:g})`, zero crossings located on the cubic "
        "Hermite interpolant of the recorded (theta, theta') and refined by brentq; period = 2 x "
        "the mean spacing of the crossings over about 4 periods. Closed form: "
        "`linear_run(events=[])`, period = 2 x the mean spacing of the impacts. "
        "Reference: T = (4/p) arccosh(1 / (1 - theta0/alpha))."
    )
    rep()
    fig, ax = plt.subplots(figsize=(8, 4.2))
    rows = [free_rocking_case(cfg, alpha, p, r, dt, ax) for r in (0.1, 0.5, 0.9)]
    ax.set_xlabel("t / T (closed-form period)")
    ax.set_ylabel("theta / alpha [-]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    ax.set_title("Free rocking of the rigid RBM monolith (time in closed-form periods)")
    rep(f"![free rocking]({save(fig, out, 'free_rocking')})")
    rep()
    rep.table(
        [
            "theta0/alpha",
            "closed-form T [s]",
            "RBM T [s]",
            "RBM rel. error",
            "housner_linear T [s]",
            "linear rel. error",
            "RBM impacts",
        ],
        rows,
    )
    worst = max(abs(float(x[3])) for x in rows)
    rep(
        f"**What it shows:** the RBM's free-rocking period matches the closed form to "
        f"{worst:.0e} relative (integration tolerance and the interpolation of the recorded "
        "history), and the closed-form code to round-off; with e = 1 the history repeats "
        "itself period after period (the curves fall on integer multiples of T)."
    )
    rep()


# ----------------------------------------------------------------------------- section 5


def energy_config(formulation: str, duration: float):
    return parse_config(
        {
            "name": f"energy4_{formulation}",
            "column": {"height": 4.0, "base_width": 0.8, "drums": 4},
            "interface": {"stiffness": {"normal": 1e8}, "xi": 0.8, "formulation": formulation},
            "excitation": {
                "type": "free",
                "duration": duration,
                "initial": {"velocities": [0.15, 0.15, 0.15, 0.3]},
            },
            "solver": {"rtol": 1e-10},
        }
    )


FORMS = ("relative", "geometric", "absolute")


def section5(rep: Report, out: Path, tmp: Path, quick: bool, jobs: int) -> None:
    rep("### 5a. Energy in free motion")
    rep()
    section5a(rep, out, quick)
    rep("### 5b. The paper's 8-drum column, three formulations")
    rep()
    section5b(rep, out, tmp, quick, jobs)


def energy_case(form: str, duration: float, k: int, axes) -> list:
    """One formulation of 5a: its energy history drawn on axes; the table row."""
    cfg = energy_config(form, duration)
    res = simulate(cfg, 0.0, 0.0, record=True, output_dt=0.01)
    h = res.history
    E = model_from_config(cfg).energy(h.rotations, h.rates)
    rel = E / E[0] - 1.0
    axes[0].plot(h.t, E / E[0], color=f"C{k}", label=form)
    axes[1].semilogy(h.t, np.maximum(np.abs(rel), 1e-16), color=f"C{k}", lw=0.8, label=form)
    return [
        form,
        f"{E[0]:.6g}",
        f"{E[-1]:.6g}",
        f"{np.max(E) / E[0]:.3g}",
        f"{np.max(np.abs(rel)):.2e}",
        res.status,
        f"{res.wall_time_s:.1f}",
    ]


def section5a(rep: Report, out: Path, quick: bool) -> None:
    duration = 5.0 if quick else 20.0
    rep(
        f"4-drum elastic column (H 4 m, B 0.8 m, square, 2700 kg/m^3, k_n 1e8 Pa/m, xi 0.8, "
        f"e 1), free motion for {duration:g} s from initial rates [0.15, 0.15, 0.15, 0.3] rad/s, "
        "rtol 1e-10; energy `model_from_config(cfg).energy(rotations, rates)` of the recorded "
        "history (every 0.01 s)."
    )
    rep()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    rows = [energy_case(form, duration, k, axes) for k, form in enumerate(FORMS)]
    axes[0].set_ylabel("E / E0 [-]")
    axes[1].set_ylabel("|E / E0 - 1| [-]")
    for ax in axes:
        ax.set_xlabel("t [s]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize="small")
    fig.suptitle("4-drum elastic column in free motion: energy vs time, three formulations")
    fig.tight_layout()
    rep(f"![energy]({save(fig, out, 'energy')})")
    rep()
    rep.table(
        [
            "formulation",
            "E0 [J]",
            f"E({duration:g} s) [J]",
            "max E/E0",
            "max |E/E0 - 1|",
            "status",
            "wall [s]",
        ],
        rows,
    )
    rep(
        "**What it shows:** `relative` and `geometric` conserve energy to the integration "
        f"tolerance ({rows[0][4]} and {rows[1][4]}); `absolute` (the paper's literal wording) "
        f"does not: its energy wanders up to {rows[2][3]} x E0 and ends at "
        f"{float(rows[2][2]) / float(rows[2][1]):.2f} x E0. "
        "(An earlier measurement of a 4-drum elastic column in free motion went from 0.040 J "
        f"to 0.109 J in 20 s; this column's E0 is {rows[0][1]} J, so that column had another "
        "size or density; the qualitative drift is the same.)"
    )
    rep()


def multidrum_config(rep: Report, quick: bool):
    """The 8-drum study on a coarse grid (--quick: 3 x 3 cells, 1 s); config, amplitudes
    and frequencies."""
    cfg = load_config(CONFIGS / "harmonic_multidrum.yaml")
    if quick:
        amps, freqs = (0.4, 0.7, 1.0), (1.0, 2.0, 3.0)
        cfg = dc.replace(cfg, excitation=dc.replace(cfg.excitation, duration=1.0))
        rep(
            "*--quick: 3 x 3 grid and 1 s of excitation instead of 10 s (a smoke test, not "
            "the study).*"
        )
        rep()
    else:
        amps = tuple(round(0.1 + 0.15 * i, 10) for i in range(7))
        freqs = tuple(0.5 * i for i in range(1, 9))
    return dc.replace(cfg, grid=GridConfig(amps, freqs)), amps, freqs


def section5b(rep: Report, out: Path, tmp: Path, quick: bool, jobs: int) -> None:
    cfg, amps, freqs = multidrum_config(rep, quick)
    column = build_column(cfg.column, cfg.interface)
    rep(
        f"`configs/harmonic_multidrum.yaml` (8 drums, k_n 5e9 Pa/m, xi 1, e 1, harmonic "
        f"{cfg.excitation.duration:g} s) on a coarse grid: amplitudes "
        f"{', '.join(f'{a:g}' for a in amps)} g x frequencies {', '.join(f'{f:g}' for f in freqs)}"
        f" Hz ({len(amps) * len(freqs)} cells), run_sweep on {jobs} workers per formulation."
    )
    rep()
    doms, walls = {}, {}
    for form in FORMS:
        c = dc.replace(
            cfg, name=f"multidrum_{form}", interface=dc.replace(cfg.interface, formulation=form)
        )
        doms[form], walls[form] = sweep_domain(c, tmp / "s5", jobs)
        counts = doms[form]["status"].value_counts().to_dict()
        rep(f"- `{form}`: {walls[form]:.1f} s, status counts {counts}")
    rep()
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.8), sharey=True)
    for ax, form in zip(axes, FORMS, strict=True):
        plot_domain(doms[form], ax=ax, column=column, labels=[f"{form} boundary"])
        ax.set_title(f"formulation: {form}")
        legend_below(ax)
    fig.suptitle("8-drum column (harmonic_multidrum), coarse grid")
    fig.tight_layout()
    rep(f"![multidrum]({save(fig, out, 'multidrum_formulations')})")
    rep()
    formulations_summary(rep, doms, column, amps, freqs)


def formulations_summary(rep: Report, doms: dict, column, amps, freqs) -> None:
    """5b's table of pairs of formulations and what it shows."""
    rows = []
    for a, b in (("relative", "geometric"), ("relative", "absolute"), ("geometric", "absolute")):
        cmp = compare(doms[a], doms[b])
        near = sum(c["near"] for c in differing_cells(doms[a], doms[b]))
        rows.append(
            [f"{a} vs {b}", f"{cmp.n_differ} / {cmp.n_common}", str(near), f"{cmp.max_shift_g:.3g}"]
        )
    rep.table(["pair", "cells that differ", "next to boundary", "max boundary shift [g]"], rows)
    ab = boundary(doms["absolute"])
    low = ab["lowest_unsafe_g"].to_numpy(float)
    rep(
        f"`absolute`: lowest collapsed amplitude per frequency "
        f"{', '.join(fmt(x) for x in low)} g (static multiplier "
        f"{column.static_multiplier:.3g} g); `relative`: "
        f"{', '.join(fmt(x) for x in boundary(doms['relative'])['lowest_unsafe_g'])} g."
    )
    rep()
    n_rg = int(rows[0][1].split()[0])
    similar = "similar" if n_rg <= 0.15 * len(amps) * len(freqs) else "different"
    first = min(a for a in amps if a > column.static_multiplier)
    collapse_low = bool(np.all(low <= first + 1e-9))
    absolute = (
        f"collapses at the lowest grid amplitude above the static multiplier ({first:g} g) "
        "at every frequency, as expected of a formulation that gains energy (an earlier 10 s "
        "measurement: ~0.3 g at every frequency)"
        if collapse_low
        else f"does not collapse at the lowest grid amplitude above the static multiplier "
        f"({first:g} g) at every frequency here, unlike the collapse at ~0.3 g that an earlier "
        "measurement of 10 s runs found"
    )
    rep(
        f"**What it shows:** `relative` and `geometric` give {similar} domains ({rows[0][1]} "
        f"cells differ), while `absolute`, which is not energy-conserving, {absolute}; the "
        f"coarse grid only bounds the boundaries to one step ({amps[1] - amps[0]:g} g)."
    )
    rep()


SECTIONS = [
    ("1. RBM n = 1 vs the closed-form linear solution", section1),
    ("2. housner vs housner-linear as alpha grows", section2),
    ("3. Half-sine study vs Housner's approximation and the exact linear threshold", section3),
    ("4. Free-rocking period", section4),
    ("5. Multi-drum column in the three formulations", section5),
]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small grids (< 60 s)")
    parser.add_argument(
        "--out",
        type=Path,
        default=ROOT / "docs",
        help="folder for validation.md and figures/ (default docs/)",
    )
    parser.add_argument("--jobs", type=int, default=2, help="sweep workers (default 2)")
    args = parser.parse_args(argv)
    out = args.out
    (out / "figures").mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    bodies, walls, failed = [], [], []
    with tempfile.TemporaryDirectory(prefix="rbm-validation-") as tmpname:
        tmp = Path(tmpname)
        for title, func in SECTIONS:
            rep = Report()
            print(f"\n## {title}\n", flush=True)
            t0 = time.perf_counter()
            try:
                func(rep, out, tmp, args.quick, args.jobs)
            except Exception:  # report the failure in validation.md, keep going
                failed.append(title)
                rep("**This section could not be finished:**")
                rep()
                rep("```")
                rep(traceback.format_exc().rstrip())
                rep("```")
                rep()
            walls.append(time.perf_counter() - t0)
            bodies.append((title, rep.lines))
    total = time.perf_counter() - start
    cmd = "python tools/make_validation.py" + (" --quick" if args.quick else "")
    head = [
        "# Validation report",
        "",
        f"Regenerate with `{cmd}` (from the repository root; `--quick` for a < 60 s smoke "
        "run, `--out DIR` to write elsewhere). Every number below is measured by that script.",
        "",
        f"- machine: {platform.platform()}, {platform.processor() or platform.machine()}, "
        f"os.cpu_count() = {os.cpu_count()}, Python {platform.python_version()}",
        f"- date: {_dt.datetime.now().astimezone().strftime('%Y-%m-%d %H:%M %Z')}",
        f"- mode: {'--quick (reduced grids; not the study)' if args.quick else 'full'}, "
        f"{args.jobs} sweep workers",
        f"- total wall time: {total:.1f} s",
        "",
        "| section | wall time [s] |",
        "|---|---|",
    ]
    head += [f"| {t} | {w:.1f} |" for (t, _), w in zip(bodies, walls, strict=True)]
    head.append("")
    if failed:
        head += [f"**Sections that did not finish:** {'; '.join(failed)}", ""]
    text = head[:]
    for (title, lines), w in zip(bodies, walls, strict=True):
        text += [f"## {title}", "", f"*Wall time {w:.1f} s.*", "", *lines]
    (out / "validation.md").write_text("\n".join(text).rstrip() + "\n")
    print(f"\nwrote {out / 'validation.md'} in {total:.1f} s", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
