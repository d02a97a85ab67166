"""Measure the numbers and draw the figures of docs/engine.md (`model: bullet`).

    python tools/make_engine.py impact      # the engine's impact loss vs Housner's e (~1 min)
    python tools/make_engine.py grid        # 6 x 5 grid, engine vs housner, 3 time steps (~5 min)
    python tools/make_engine.py timestep    # 24 8-drum cells at 3 time steps, each run twice
                                           # (amplitude x (1 + 1e-6)) (~25 min)
    python tools/make_engine.py cost        # CPU of 10 s 8-drum cells at 1e-4 s, 3 runs each
    python tools/make_engine.py emap        # housner's outcome against e in the knife-edge cells
    python tools/make_engine.py fine        # the 6 x 5 grid at 5e-5 s, engine vs housner (~3 min)
    python tools/make_engine.py converge    # the 6 x 5 grid as ensembles of 4 at 1e-4, 5e-5
                                           # and 2.5e-5 s, engine vs housner (~15 min, 2 jobs)
    python tools/make_engine.py chaos       # one chaotic 8-drum cell, K = 4, 2 time steps
    python tools/make_engine.py monolithic  # the monolithic study: RBM, housner, engine (~2 min)
    python tools/make_engine.py rbm_e       # 8-drum RBM with e < 1 vs engine; friction demand
    python tools/make_engine.py normals     # the engine's contact normals at the 8-drum joints
                                           # against the faces', with the friction demand
    python tools/make_engine.py multidrum   # RBM formulations vs engine fractions (figure;
                                           # runs the RBM on the engine's grid)

Everything goes through the library API. Each part prints what it measures and
stores it in docs/engine_data/<part>.json; figures go to docs/figures/engine_*.png.
CPU times are process times of this machine (2 cores, shared).
"""

from __future__ import annotations

import argparse
import dataclasses as dc
import json
import sys
import tempfile
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from rbm_cli.api import run_sweep  # noqa: E402
from rbm_cli.config.load import load_config, parse_config  # noqa: E402
from rbm_cli.config.types import GridConfig  # noqa: E402
from rbm_cli.inputs.excitation import make_ground_motion  # noqa: E402
from rbm_cli.models.bullet.convergence import (  # noqa: E402
    ensemble_agreement,
    outcome_marks,
    step_agreement,
)
from rbm_cli.models.bullet.impact import (  # noqa: E402
    engine_restitution,
    impact_rate_ratios,
    measure_restitution,
)
from rbm_cli.models.bullet.normals import NormalCensus  # noqa: E402
from rbm_cli.models.bullet.run import bullet_run  # noqa: E402
from rbm_cli.models.bullet.settings import EngineSettings  # noqa: E402
from rbm_cli.structures.block import block_geometry  # noqa: E402
from rbm_cli.structures.restitution import block_restitution  # noqa: E402
from rbm_cli.study.domain import boundary, read_domain  # noqa: E402
from rbm_cli.study.simulate import simulate  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "docs" / "engine_data"
FIGURES = ROOT / "docs" / "figures"

COLUMNS = {
    "block 4 x 1 m": {"height": 4.0, "base_width": 1.0, "depth": 1.0},
    "block 2 x 1 m": {"height": 2.0, "base_width": 1.0, "depth": 1.0},
    "tapered 5 m column": {"height": 5.0, "base_width": 0.96, "top_width": 0.66},
}
#: The study's 6 x 5 harmonic grid (g, Hz), for both monolithic columns.
GRID_AMPLITUDES = (0.3, 0.5, 0.7, 0.9, 1.1, 1.3)
GRID_FREQUENCIES = (0.5, 1.0, 1.5, 2.0, 2.5)
TIME_STEPS = (1e-4, 2e-4, 5e-4)
#: 8-drum cells of the time-step study (g, Hz): spread over the engine's domain
#: (results/harmonic_multidrum_bullet), on and away from its boundary.
MULTI_CELLS = [
    *[(a, 0.5) for a in (0.25, 0.3, 0.5)],
    *[(a, 1.0) for a in (0.4, 0.5, 0.6, 0.7, 0.9)],
    *[(a, 1.5) for a in (0.6, 0.8, 0.9, 1.1)],
    *[(a, 2.0) for a in (0.8, 1.0, 1.1, 1.3)],
    *[(a, 2.5) for a in (0.6, 1.0, 1.3, 1.5)],
    *[(a, 3.0) for a in (1.0, 1.5)],
    *[(a, 4.0) for a in (0.8, 1.5)],
]
#: Engine variants of the time-step study: (label, time step [s]).
VARIANTS = [("1e-4", 1e-4), ("2e-4", 2e-4), ("5e-4", 5e-4)]
#: Relative amplitude change of the second run of each cell (chaos marker).
NUDGE = 1e-6


def column_config(column: dict, model: str = "bullet", **interface):
    data = {"name": "engine_doc", "model": model, "column": dict(column)}
    if interface:
        data["interface"] = interface
    return parse_config(data)


def with_step(cfg, dt: float):
    return dc.replace(cfg, solver=dc.replace(cfg.solver, time_step=dt))


def dump(part: str, data) -> None:
    DATA.mkdir(parents=True, exist_ok=True)
    (DATA / f"{part}.json").write_text(json.dumps(data, indent=1, default=float) + "\n")


def timed(fn, *args):
    t = time.process_time()
    out = fn(*args)
    return out, time.process_time() - t


# ------------------------------------------------------------------------- parts


def part_impact() -> None:
    """Both readings of the engine's impact loss (rbm_cli.models.bullet.impact): from the
    energy of successive peaks (the one used) and from 2 ms line fits of the
    angular velocity around each impact; at erp 0.2 (the engine's) and 0.05."""
    rows = []
    for name, column in COLUMNS.items():
        cfg = column_config(column)
        e_h = block_restitution(block_geometry(cfg.column))
        for erp in (0.2, 0.05):
            s = EngineSettings(erp=erp)
            for frac in (0.2, 0.5, 0.8):
                energy = measure_restitution(cfg, tilt_fraction=frac, impacts=4, settings=s)
                rates = impact_rate_ratios(cfg, tilt_fraction=frac, impacts=4, settings=s)
                rows.append(
                    dict(
                        column=name,
                        erp=erp,
                        tilt=frac,
                        housner=e_h,
                        energy=list(energy),
                        rates=list(rates),
                    )
                )
                print(
                    f"{name:20s} erp {erp} tilt {frac} alpha: e from peaks {np.round(energy, 4)},"
                    f" from rates {np.round(rates, 4)}; Housner {e_h:.4f}"
                )
    dump("impact", rows)


def part_grid() -> None:
    """Engine vs housner (e: the mean measured ratio) on the 6 x 5 grid: friction 1.0
    at three time steps, and friction 2.0 (no sliding below 2 g, Housner's assumption).
    A differing cell is 'sensitive' when housner's own outcome changes for an e
    within the measured spread (min..max of the ratios)."""
    out = {}
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
    cells = [(a, f) for f in GRID_FREQUENCIES for a in GRID_AMPLITUDES]
    for ax, name in zip(axes, ("block 4 x 1 m", "tapered 5 m column"), strict=True):
        out[name] = _grid_column(name, cells, ax)
    axes[0].set_ylabel("amplitude [g]")
    fig.tight_layout()
    fig.savefig(FIGURES / "engine_monolithic_vs_housner.png", dpi=110, bbox_inches="tight")
    dump("grid", out)


def _grid_column(name, cells, ax) -> dict:
    """part_grid for one column: housner at the measured e (and across its spread,
    and at the e read from the rates) against the engine at every setting."""
    ratios = measure_restitution(column_config(COLUMNS[name]), impacts=4)
    e = float(np.mean(ratios))
    spread = np.linspace(ratios.min(), ratios.max(), 5)
    e_rates = float(np.mean(impact_rate_ratios(column_config(COLUMNS[name]), impacts=4)))

    def housner(e_):
        ref = column_config(COLUMNS[name], model="housner", restitution=round(float(e_), 4))
        return {c: simulate(ref, *c).status for c in cells}

    ref = housner(e)
    varied = [housner(x) for x in spread]
    old = housner(e_rates)
    res = {"e": e, "e_min": float(ratios.min()), "e_max": float(ratios.max())}
    res["e_rates"] = e_rates
    res["housner"] = {f"{a} {f}": s for (a, f), s in ref.items()}
    for friction, dt in [(1.0, t) for t in TIME_STEPS] + [(2.0, TIME_STEPS[0])]:
        cfg = with_step(column_config(COLUMNS[name], friction=friction), dt)
        runs = [timed(simulate, cfg, a, f) for a, f in cells]
        status = {c: r.status for c, (r, _) in zip(cells, runs, strict=True)}
        differ = [c for c in cells if status[c] != ref[c]]
        sensitive = [c for c in differ if len({v[c] for v in varied}) > 1]
        slip = {
            f"{a} {f}": r.message.split("max slip: ")[-1]
            for (a, f), (r, _) in zip(cells, runs, strict=True)
            if (a, f) in differ
        }
        cpu = sum(t for _, t in runs)
        differ_rates = [c for c in cells if status[c] != old[c]]
        res[f"mu {friction} dt {dt:g}"] = dict(
            status={f"{a} {f}": s for (a, f), s in status.items()},
            differ=differ,
            differ_with_e_rates=differ_rates,
            sensitive=sensitive,
            slip_of_differing=slip,
            cpu_s=cpu,
        )
        print(
            f"{name}, e = {e:.3f} ({ratios.min():.3f}-{ratios.max():.3f}), friction"
            f" {friction}, dt {dt:g}: {len(differ)} of {len(cells)} differ {differ}"
            f" (sensitive to e: {sensitive}), slips {slip}, {cpu:.1f} s CPU; with e from"
            f" rates ({e_rates:.4f}): {len(differ_rates)} differ {differ_rates}"
        )
        if friction == 1.0 and dt == TIME_STEPS[0]:
            _grid_axes(ax, name, cells, ref, res[f"mu {friction} dt {dt:g}"]["status"], e)
    return res


def _grid_axes(ax, name, cells, housner, engine_status, e) -> None:
    for a, f in cells:
        h = housner[(a, f)] == "collapsed"
        b = engine_status[f"{a} {f}"] == "collapsed"
        ax.plot(f, a, "x" if h else "o", color="k", mfc="none", ms=9)
        if h != b:
            ax.plot(f, a, "s", color="tab:red", mfc="none", ms=15)
    ax.set_title(
        f"{name}: housner (e = {e:.3f}, o safe / x collapsed);\nred square: engine differs"
    )
    ax.set_xlabel("frequency [Hz]")


def part_timestep() -> None:
    """24 8-drum cells (MULTI_CELLS), each run by every engine variant (VARIANTS) at
    its amplitude a and at a (1 + NUDGE): a cell whose two runs differ under one
    variant is chaotic there. CPU time of every run (the medians are printed)."""
    cfg = load_config(ROOT / "configs" / "harmonic_multidrum_bullet.yaml")
    rows = []
    for a, f in MULTI_CELLS:
        for label, dt in VARIANTS:
            settings = EngineSettings(time_step=dt, friction=cfg.interface.friction)
            for amp in (a, a * (1.0 + NUDGE)):
                r, cpu = timed(_engine_cell, with_step(cfg, dt), amp, f, settings)
                rows.append(
                    dict(
                        variant=label,
                        a=a,
                        f=f,
                        nudged=amp != a,
                        status=r.status,
                        t_c=r.t_collapse,
                        ratio=float(np.max(r.max_ratio)),
                        friction=[float(v) for v in r.friction],
                        cpu_s=cpu,
                        message=r.message,
                    )
                )
                print(json.dumps(rows[-1]), flush=True)
        dump("timestep", rows)
    _timestep_summary(rows)


def _engine_cell(cfg, amplitude_g, frequency_hz, settings=None, observe=None):
    """The engine's Outcome of one cell (bullet_run, as simulate runs it)."""
    motion = make_ground_motion(cfg.excitation, amplitude_g, frequency_hz)
    out, _ = bullet_run(cfg, motion, settings=settings, observe=observe)
    return out


def _timestep_summary(rows) -> dict:
    """Per cell: each variant's outcome (C/S, '?' when its two runs differ)."""
    table, summary = {}, {}
    for r in rows:
        table.setdefault((r["a"], r["f"]), {}).setdefault(r["variant"], []).append(r["status"])
    ref = VARIANTS[0][0]
    for label, _ in VARIANTS:
        cpu = [r["cpu_s"] for r in rows if r["variant"] == label]
        surv = [r["cpu_s"] for r in rows if r["variant"] == label and r["status"] == "survived"]
        summary[label] = dict(
            median_cpu_s=float(np.median(cpu)),
            median_cpu_survived_s=float(np.median(surv)) if surv else None,
            n_survived_runs=len(surv),
            **step_agreement(table, label, ref),
        )
        print(label, summary[label])
    for (a, f), marks in outcome_marks(table).items():
        print(f"  {a:4.2f} g {f:3.1f} Hz: {marks}")
    return summary


def part_cost() -> None:
    """CPU of surviving 10 s 8-drum cells at the default step (1e-4 s): three cells,
    three runs each, one process (the medians are printed)."""
    cfg = with_step(load_config(ROOT / "configs" / "harmonic_multidrum_bullet.yaml"), 1e-4)
    rows = []
    for _ in range(3):
        for a, f in ((0.25, 1.0), (0.4, 2.5), (0.6, 2.5)):
            r, cpu = timed(simulate, cfg, a, f)
            rows.append(dict(a=a, f=f, status=r.status, cpu_s=cpu))
            print(json.dumps(rows[-1]), flush=True)
    cpu = [r["cpu_s"] for r in rows if r["status"] == "survived"]
    print(f"median {np.median(cpu):.2f} s, range {min(cpu):.2f}-{max(cpu):.2f} s ({len(cpu)} runs)")
    dump("cost", rows)


#: Grid cells where the engine and `housner` have differed at some setting.
EDGE_CELLS = {
    "block 4 x 1 m": [(0.3, 0.5), (0.9, 1.5), (1.1, 2.0)],
    "tapered 5 m column": [(0.9, 1.5), (1.3, 2.0)],
}


def part_emap() -> None:
    """housner's outcome in EDGE_CELLS for e from 0.895 to 0.950 in steps of 0.0025:
    how close to a flip each cell is."""
    out = {}
    for name, cells in EDGE_CELLS.items():
        for a, f in cells:
            row = {}
            for e in np.round(np.arange(0.895, 0.9501, 0.0025), 4):
                r = simulate(column_config(COLUMNS[name], model="housner", restitution=e), a, f)
                row[f"{e:.4f}"] = r.status[0].upper()
            out[f"{name}: {a} g {f} Hz"] = row
            print(f"{name:20s} {a} g {f} Hz: " + " ".join(f"{k}:{v}" for k, v in row.items()))
    dump("emap", out)


def part_fine() -> None:
    """Engine (5e-5 s) against housner (e from the engine's peaks) on the 6 x 5 grid."""
    cells = [(a, f) for f in GRID_FREQUENCIES for a in GRID_AMPLITUDES]
    out = {}
    for name in ("block 4 x 1 m", "tapered 5 m column"):
        cfg = column_config(COLUMNS[name])
        e = round(engine_restitution(cfg, impacts=4), 4)
        ref = column_config(COLUMNS[name], model="housner", restitution=e)
        runs = [timed(simulate, with_step(cfg, 5e-5), a, f) for a, f in cells]
        differ = [
            c for c, (r, _) in zip(cells, runs, strict=True) if r.status != simulate(ref, *c).status
        ]
        out[name] = dict(e=e, differ=differ, cpu_s=sum(t for _, t in runs))
        print(f"{name}, dt 5e-5, e = {e}: {len(differ)} of {len(cells)} differ {differ}")
    dump("fine", out)


#: Time steps of the convergence study of the monolithic grid [s] and its ensemble size.
CONVERGE_STEPS = (1e-4, 5e-5, 2.5e-5)
CONVERGE_MEMBERS = 4


def _converge_run(name: str, model: str, dt: float, e: float, a: float, f: float, j: int):
    from rbm_cli.study.robustness import members
    from rbm_cli.study.sweep import ensemble_member

    if model == "bullet":
        cfg = with_step(column_config(COLUMNS[name]), dt)
    else:
        cfg = column_config(COLUMNS[name], model="housner", restitution=e)
    cfg, amplitude = ensemble_member(cfg, a, members(CONVERGE_MEMBERS)[j])
    r, cpu = timed(simulate, cfg, amplitude, f)
    return dict(column=name, model=model, dt=dt, a=a, f=f, member=j, status=r.status, cpu_s=cpu)


def part_converge(jobs: int) -> None:
    """The 6 x 5 grid of both monoliths as ensembles (the sweep's offsets: phase and
    relative amplitude within 1e-6) at CONVERGE_STEPS, and housner (e from the
    engine's peaks) at the same offsets. A cell is robust in a model when all its
    members agree; a chaotic cell counts as a cell that differs."""
    from joblib import Parallel, delayed

    cells = [(a, f) for f in GRID_FREQUENCIES for a in GRID_AMPLITUDES]
    names = ("block 4 x 1 m", "tapered 5 m column")
    e = {n: round(engine_restitution(column_config(COLUMNS[n]), impacts=4), 4) for n in names}
    tasks = [
        (n, "housner", 0.0, e[n], a, f, j)
        for n in names
        for a, f in cells
        for j in range(CONVERGE_MEMBERS)
    ]
    tasks += [
        (n, "bullet", dt, e[n], a, f, j)
        for dt in CONVERGE_STEPS
        for n in names
        for a, f in cells
        for j in range(CONVERGE_MEMBERS)
    ]
    rows = Parallel(n_jobs=jobs, verbose=5)(delayed(_converge_run)(*t) for t in tasks)
    dump("converge", dict(e=e, members=CONVERGE_MEMBERS, rows=rows))
    _converge_summary(rows)


def _converge_summary(rows) -> dict:
    """Per column and step: cells where both are robust and agree, where both are
    robust and differ, and where either is chaotic (listed with both fractions)."""
    cells = sorted({(r["a"], r["f"]) for r in rows}, key=lambda c: (c[1], c[0]))
    df = pd.DataFrame(rows)
    fraction = (df.status == "collapsed").groupby([df.column, df.model, df.dt, df.a, df.f]).mean()
    out = {}
    for name in sorted(df.column.unique()):
        ref = {c: float(fraction[(name, "housner", 0.0, *c)]) for c in cells}
        for dt in CONVERGE_STEPS:
            eng = {c: float(fraction[(name, "bullet", dt, *c)]) for c in cells}
            cpu = sum(r["cpu_s"] for r in rows if r["column"] == name and r["dt"] == dt)
            res = dict(**ensemble_agreement(eng, ref), cpu_s=cpu)
            out[f"{name} dt {dt:g}"] = res
            print(f"{name}, dt {dt:g}: {res}")
    return out


#: 8-drum cells (g, Hz, time step [s]) of the contact-normal census.
NORMAL_CELLS = [(0.25, 1.0, 2e-4), (0.6, 1.0, 2e-4), (0.9, 1.5, 2e-4), (1.1, 2.0, 2e-4)]
NORMAL_CELLS += [(0.7, 1.0, 5e-4)]
#: A contact normal further than this from its joint's faces' normals is "off" [rad].
NORMAL_OFF = 0.02


def part_normals() -> None:
    """Where the engine's friction demand (friction 1.0) reads above mu: after every
    engine step, the normal of each of Bullet's contact points at each joint against
    the range between the joint's two faces' normals (the admissible ones,
    `joint_friction`); the share of the normal force on points more than NORMAL_OFF
    off that range and the largest departure (NormalCensus, bullet_run's observe)."""
    base = load_config(ROOT / "configs" / "harmonic_multidrum_bullet.yaml")
    rows = []
    for a, f, dt in NORMAL_CELLS:
        census = NormalCensus(NORMAL_OFF)
        r = _engine_cell(with_step(base, dt), a, f, observe=census)
        rows.append(
            dict(
                a=a,
                f=f,
                dt=dt,
                status=r.status,
                friction_demand=[float(v) for v in r.friction],
                share_off=census.share_off,
                max_off_rad=census.max_off,
                message=r.message,
            )
        )
        print(json.dumps(rows[-1]), flush=True)
    dump("normals", rows)


def part_chaos() -> None:
    """The 8-drum cell (0.6 g, 1 Hz) that changed with the time step: K = 4 runs with
    the sweep's ensemble offsets (phase, relative amplitude up to 1e-6) at 1e-4 and 5e-4 s."""
    from rbm_cli.study.robustness import members
    from rbm_cli.study.sweep import ensemble_member

    base = load_config(ROOT / "configs" / "harmonic_multidrum_bullet.yaml")
    rows = []
    for dt in (1e-4, 5e-4):
        for member in members(4):
            phase, rel = member.phase_rad, member.amplitude_relative
            cfg, amplitude = ensemble_member(with_step(base, dt), 0.6, member)
            r, cpu = timed(simulate, cfg, amplitude, 1.0)
            rows.append(
                dict(
                    dt=dt,
                    phase=phase,
                    rel=rel,
                    status=r.status,
                    t_c=r.t_collapse_s,
                    ratio=r.max_rotation_ratio,
                    cpu_s=cpu,
                )
            )
            print(json.dumps(rows[-1]))
    dump("chaos", rows)


def part_monolithic(jobs: int) -> None:
    """The monolithic study: RBM, housner (e = 1; the engine's e of the column from
    the energy of its peaks; 0.929, the earlier reading from the rates) and the
    engine's stored domain, cells that differ pairwise."""
    base = load_config(ROOT / "configs" / "harmonic_monolithic.yaml")
    eng = read_domain(ROOT / "results" / "harmonic_monolithic_bullet" / "domain.csv")
    rbm = read_domain(ROOT / "results" / "harmonic_monolithic" / "domain.csv")
    engine_cfg = load_config(ROOT / "configs" / "harmonic_monolithic_bullet.yaml")
    e_engine = round(engine_restitution(engine_cfg, impacts=4), 4)
    ref = {}
    with tempfile.TemporaryDirectory() as tmp:
        for e in (1.0, e_engine, 0.929):
            cfg = dc.replace(
                base,
                name=f"h{e}",
                model="housner",
                interface=dc.replace(base.interface, restitution=e),
            )
            ref[e] = read_domain(run_sweep(cfg, tmp, jobs=jobs).folder / "domain.csv")

    def differ(a, b):
        m = a.merge(b, on=["amplitude_g", "frequency_hz"])
        return int((m.collapsed_x != m.collapsed_y).sum()), len(m)

    out = {
        "e_engine": e_engine,
        "rbm vs housner e=1": differ(rbm, ref[1.0]),
        f"housner e=1 vs e={e_engine}": differ(ref[1.0], ref[e_engine]),
        f"housner e={e_engine} vs engine": differ(ref[e_engine], eng),
        "housner e=0.929 vs engine": differ(ref[0.929], eng),
        "rbm vs engine": differ(rbm, eng),
    }
    print(out)
    dump("monolithic", out)


def part_multidrum(jobs: int) -> None:
    """RBM (relative, absolute, geometric) vs the engine's collapse fraction."""
    engine = pd.read_csv(ROOT / "results" / "harmonic_multidrum_bullet" / "domain.csv")
    rbm_cfg = load_config(ROOT / "configs" / "harmonic_multidrum.yaml")
    amps = tuple(sorted(engine["amplitude_g"].unique()))
    freqs = tuple(sorted(engine["frequency_hz"].unique()))
    grid = GridConfig(amplitudes_g=amps, frequencies_hz=freqs)
    domains, summary = {}, {}
    for form in ("relative", "absolute", "geometric"):
        cfg = dc.replace(
            rbm_cfg,
            name=f"engine_doc_{form}",
            grid=grid,
            interface=dc.replace(rbm_cfg.interface, formulation=form),
        )
        with tempfile.TemporaryDirectory() as tmp:
            summary_ = run_sweep(cfg, tmp, jobs=jobs)
            df = read_domain(summary_.folder / "domain.csv")
        domains[form] = df
        print(f"RBM {form}: {len(df)} cells in {summary_.wall_time_s:.0f} s wall")
    frac_col = "collapse_fraction" if "collapse_fraction" in engine else "collapsed"
    eng = engine.set_index(["amplitude_g", "frequency_hz"])[frac_col]
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), sharey=True)
    for ax, (form, df) in zip(axes, domains.items(), strict=True):
        r = df.set_index(["amplitude_g", "frequency_hz"])["collapsed"].reindex(eng.index)
        agree = float(np.mean(np.abs(r.to_numpy() - eng.to_numpy()) < 0.5))
        mean_diff = float(np.mean(r.to_numpy() - eng.to_numpy()))
        summary[form] = dict(
            agree=agree,
            rbm_minus_engine=mean_diff,
            rbm_boundary=_boundary(df),
            engine_boundary=_boundary_frac(engine, frac_col),
        )
        sc = ax.scatter(
            [f for _, f in eng.index],
            [a for a, _ in eng.index],
            c=eng.to_numpy(),
            cmap="coolwarm",
            vmin=0,
            vmax=1,
            s=60,
            marker="s",
        )
        for (a, f), c in r.items():
            ax.plot(f, a, "x" if c else ".", color="k", ms=6 if c else 3)
        ax.set_title(f"RBM {form} (x collapsed, . safe)\nover engine collapse fraction (colour)")
        ax.set_xlabel("frequency [Hz]")
        print(form, summary[form])
    axes[0].set_ylabel("amplitude [g]")
    fig.colorbar(sc, ax=axes, label="engine collapse fraction")
    fig.savefig(FIGURES / "engine_multidrum_rbm_vs_engine.png", dpi=110, bbox_inches="tight")
    dump("multidrum", summary)


def part_rbm_e(jobs: int) -> None:
    """The 8-drum RBM (relative) with impact loss e < 1 (the engine's own e of the
    monolith, read from its peaks, and 0.8) against the engine's fractions; the
    friction demand max |T/N| of the RBM and of the engine (friction 1.0 and 10,
    the latter too high to slide) in three cells."""
    engine = pd.read_csv(ROOT / "results" / "harmonic_multidrum_bullet" / "domain.csv")
    eng = engine.set_index(["amplitude_g", "frequency_hz"])["collapse_fraction"]
    base = load_config(ROOT / "configs" / "harmonic_multidrum.yaml")
    mono = load_config(ROOT / "configs" / "harmonic_monolithic_bullet.yaml")
    e_engine = round(engine_restitution(mono, impacts=4), 3)
    grid = GridConfig(
        amplitudes_g=tuple(sorted({a for a, _ in eng.index})),
        frequencies_hz=tuple(sorted({f for _, f in eng.index})),
    )
    out = {"e_engine": e_engine}
    for e in (1.0, e_engine, 0.8):
        cfg = dc.replace(
            base, name=f"rbm_e{e}", grid=grid, interface=dc.replace(base.interface, restitution=e)
        )
        with tempfile.TemporaryDirectory() as tmp:
            df = read_domain(run_sweep(cfg, tmp, jobs=jobs).folder / "domain.csv")
        r = df.set_index(["amplitude_g", "frequency_hz"])["collapsed"].reindex(eng.index)
        agree = float(np.mean(np.abs(r.to_numpy() - eng.to_numpy()) < 0.5))
        out[f"e {e}"] = dict(agree=agree, rbm_boundary=_boundary(df))
        print(f"RBM relative, e = {e}: agrees with the engine on {agree:.3f}", _boundary(df))
    engine_cfg = load_config(ROOT / "configs" / "harmonic_multidrum_bullet.yaml")
    demand = []
    for a, f in ((0.25, 1.0), (0.25, 3.0), (0.45, 3.5)):
        r = simulate(base, a, f)
        row = dict(a=a, f=f, status=r.status, max_friction_demand=r.max_friction_demand)
        for mu in (1.0, 10.0):
            cfg = dc.replace(engine_cfg, interface=dc.replace(engine_cfg.interface, friction=mu))
            er = simulate(cfg, a, f)
            row[f"engine mu {mu:g}"] = dict(
                status=er.status,
                friction_demand=list(er.friction_demand),
                message=er.message,
            )
        demand.append(row)
        print(json.dumps(row))
    out["friction_demand"] = demand
    dump("rbm_e", out)


def _boundary(df) -> dict:
    """Lowest collapsed amplitude per frequency [g] (None: none), from domain.boundary, by
    the rows' status (an ensemble's member 0: without its fraction, not the majority's)."""
    b = boundary(df.drop(columns=["collapse_fraction"], errors="ignore"))
    return {
        float(f): None if np.isnan(a) else float(a)
        for f, a in zip(b["frequency_hz"], b["lowest_unsafe_g"], strict=True)
    }


def _boundary_frac(df, col) -> dict:
    """_boundary of an ensemble domain, a cell collapsed where its fraction is >= 0.5."""
    majority = np.where(df[col] >= 0.5, "collapsed", "survived")
    return _boundary(df.assign(status=majority))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parts = ["impact", "grid", "timestep", "cost", "emap", "fine", "chaos", "monolithic"]
    parts += ["multidrum", "rbm_e", "converge", "normals"]
    ap.add_argument("part", choices=parts)
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args(argv)
    FIGURES.mkdir(parents=True, exist_ok=True)
    if args.part == "multidrum":
        part_multidrum(args.jobs)
    elif args.part == "monolithic":
        part_monolithic(args.jobs)
    elif args.part == "rbm_e":
        part_rbm_e(args.jobs)
    elif args.part == "converge":
        part_converge(args.jobs)
    else:
        parts = {"impact": part_impact, "grid": part_grid, "timestep": part_timestep}
        parts.update(chaos=part_chaos, cost=part_cost, emap=part_emap, fine=part_fine)
        parts.update(normals=part_normals)
        parts[args.part]()
    return 0


if __name__ == "__main__":
    sys.exit(main())
