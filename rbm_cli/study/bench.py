"""Work-precision benchmark (`rbm bench`): run time against error, measured.

For each problem (a column, an excitation and a 40 x 40 grid) every method
and tolerance rbm offers is run over the whole grid, timed on `jobs`
workers, and compared with a reference:

- rigid monolithic columns: the closed-form `housner-linear` solution with
  the RBM's inertia (alpha = B/H, p from the true inertia), exact to round-off;
  A peak counts only where it is well-conditioned: a 1e-9 relative change of
  the amplitude moves the closed-form peak by at most 1e-6 relative;
- otherwise: converged compiled DOP853 runs at rtol 1e-10, 1e-11 and 1e-12.
  The reference values are those of the rtol 1e-12 run. A peak counts where
  rtol 1e-11 and 1e-12 agree to 1e-6 and a 1e-9 relative change of the
  amplitude moves it by at most 1e-6 (well-conditioned, as for the closed form),
  and these three runs count the same uplifts and impacts.

Which cells are scored: a cell counts (`converged`) only when its reference is
*robust* by the robustness rule (rbm_cli.study.robustness: 16 members, perturbations
1e-12..1e-6 of phase and amplitude, two tolerances, all agree), and, for
converged references, its outcome is also the same at rtol 1e-10, 1e-11 and
1e-12 and under a 1e-9 relative change of the amplitude. The others are
*sensitive* (chaos), counted but not scored. (Tolerance alone misses chaos that
every run of one algorithm shares: 21 of 1521 8-drum cells that agreed at the
three tolerances flipped under a change of the event handling that moves the
state by about 1e-13 rad per impact.)

Errors: (a) cells whose outcome differs from the reference (converged cells
only), (b) the largest boundary shift [g], (c) relative errors of the peak
rotation ratio (runs that survive in both; for converged references only
where rtol 1e-11 and 1e-12 agree to 1e-6) and of the collapse time (runs that
collapse in both), median and max.

The baseline is scipy's solve_ivp (RK45, rtol 1e-6, events), once per cell
(rbm_cli.study.bench_baseline), on a sample of cells measured in the same run; its domain
time is extrapolated from the mean time per run (marked `estimated`).

`rbm bench --quick` runs the default method (and a few baseline cells) on a
10 x 10 sub-grid of each problem against the stored references (made by the
full benchmark in results/bench/) and fails if the default's error exceeds
the accuracy targets.
"""

from __future__ import annotations

import dataclasses
import math
import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from rbm_cli.base.errors import RbmError
from rbm_cli.base.files import write_text_atomic
from rbm_cli.config.load import load_config
from rbm_cli.config.types import STEP_DEFAULT, Config, GridConfig, SolverConfig
from rbm_cli.models.methods import resolve_method
from rbm_cli.models.rbm.step import warm_up
from rbm_cli.study.bench_runs import run_cells
from rbm_cli.study.bench_scoring import agreement, cell_keys, errors
from rbm_cli.study.robustness import MEMBERS, member_config, members
from rbm_cli.study.schema import C

ROOT = Path(__file__).resolve().parents[2]  # the repository (rbm_cli/study/bench.py)


@dataclass(frozen=True)
class Problem:
    name: str
    config: str  # path relative to the repository
    amplitudes: tuple[float, float, int]  # g: start, stop, count
    frequencies: tuple[float, float, int]  # Hz
    reference: str  # 'closed-form' or 'converged'
    max_cells: float  # accuracy target: fraction of (converged) cells that may differ
    label: str


PROBLEMS = (
    Problem("slender", "configs/spanos_koh_slender.yaml", (0.1, 2.0, 40), (0.25, 3.0, 40),
            "closed-form", 0.005, "rigid monolithic Spanos-Koh slender block"),
    Problem("tapered", "configs/harmonic_monolithic.yaml", (0.1, 1.5, 40), (0.25, 4.0, 40),
            "converged", 0.01, "tapered monolithic column, finite K_M (k_n 5e9 Pa/m)"),
    Problem("multidrum", "configs/harmonic_multidrum.yaml", (0.1, 1.5, 40), (0.25, 4.0, 40),
            "converged", 0.01, "8-drum tapered column, k_n 5e9 Pa/m"),
    Problem("halfsine", "configs/housner_halfsine.yaml", (0.1, 3.0, 40), (0.1, 3.0, 40),
            "closed-form", 0.005, "rigid monolithic column, half-sine pulse"),
)  # fmt: skip

#: The exact integrator (`solver.method: exact`; it has no tolerance: its rtol is unused).
#: On the rigid monoliths the default (`auto`) is the block's closed form (`closed-form`,
#: no tolerance either), run beside these (_run_methods).
EXACT = ("compiled", "exact", SolverConfig().rtol)
#: Methods of the full benchmark: (implementation, method, rtol).
METHODS = (
    [("compiled", "DOP853", r) for r in (1e-6, 1e-7, 1e-8, 1e-9, 1e-10)]
    + [("compiled", "RK45", r) for r in (1e-5, 1e-6, 1e-7, 1e-8)]
    + [("python", "DOP853", SolverConfig().rtol), EXACT]
)
#: Cells of the sample on which the slow methods (the kernel uncompiled and the
#: baseline) run: the same cells for both, and the speed-up of every method is
#: the ratio of run times summed over these cells (paired, so the sample's mix
#: of cheap and costly cells does not bias it).
SAMPLE = {"slender": 64, "tapered": 32, "multidrum": 16, "halfsine": 64}
QUICK_SAMPLE = 4
REFERENCE_RTOLS = (1e-10, 1e-11, 1e-12)
#: Relative agreement of the peak at rtol 1e-11 and 1e-12 for a converged peak.
PEAK_CONVERGED = 1e-6
#: Accuracy target of the peak rotation, runs that survive.
PEAK_TARGET = 1e-4
REFERENCE_DIR = ROOT / "results" / "bench"


def problem_config(problem: Problem, stride: int = 1) -> Config:
    cfg = load_config(ROOT / problem.config)
    a0, a1, na = problem.amplitudes
    f0, f1, nf = problem.frequencies
    amps = np.round(np.linspace(a0, a1, na), 10)[::stride]
    freqs = np.round(np.linspace(f0, f1, nf), 10)[::stride]
    grid = GridConfig(tuple(float(a) for a in amps), tuple(float(f) for f in freqs))
    return dataclasses.replace(cfg, grid=grid, name=f"bench_{problem.name}")


def bench_cells(cfg: Config) -> list[tuple[float, float]]:
    return [(a, f) for f in cfg.grid.frequencies_hz for a in cfg.grid.amplitudes_g]


def _with_solver(cfg: Config, implementation: str, method: str, rtol: float) -> Config:
    solver = dataclasses.replace(cfg.solver, implementation=implementation, method=method,
                                 rtol=rtol)  # fmt: skip
    return dataclasses.replace(cfg, solver=solver)


# ---------------------------------------------------------------- references
def _close(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """|p - q| <= PEAK_CONVERGED |q|, elementwise (False where either is NaN)."""
    with np.errstate(invalid="ignore"):
        return np.abs(p - q) <= PEAK_CONVERGED * np.abs(q)


def make_reference(problem: Problem, cfg: Config, jobs: int) -> pd.DataFrame:
    """The reference rows of a problem, with its `converged` and `peak_converged` flags.

    A peak is scored only where it is well-conditioned: a 1e-9 relative change of
    the amplitude moves it by at most PEAK_CONVERGED (error amplification <= 1000);
    a long rocking run amplifies errors as exp(p t) between impacts. For converged
    references the runs at rtol 1e-11, 1e-12 and the nudged one must also count
    the same uplifts and impacts (one 8-drum cell kept its early peak in all three
    while its trajectories had parted: 2225 to 3431 uplifts)."""
    cells = bench_cells(cfg)
    nudged = [(a * (1.0 + 1e-9), f) for a, f in cells]
    if problem.reference == "closed-form":
        ref, _ = run_cells("closed-form", cfg, cells, jobs)
        other, _ = run_cells("closed-form", cfg, nudged, jobs)
        same = ref[C.collapsed].to_numpy() == other[C.collapsed].to_numpy()
        robust = robust_flags("closed-form", cfg, cells, ref, jobs)
        peak_ok = _close(
            other[C.max_rotation_ratio].to_numpy(), ref[C.max_rotation_ratio].to_numpy()
        )
    else:
        runs = [run_cells("rbm", _with_solver(cfg, "compiled", "DOP853", r), cells, jobs)[0]
                for r in REFERENCE_RTOLS]  # fmt: skip
        ref = runs[-1].copy()
        same = np.ones(len(ref), dtype=bool)
        for run in runs[:-1]:
            same &= run[C.collapsed].to_numpy() == ref[C.collapsed].to_numpy()
        tight = _with_solver(cfg, "compiled", "DOP853", REFERENCE_RTOLS[-1])
        other, _ = run_cells("rbm", tight, nudged, jobs)
        same &= other[C.collapsed].to_numpy() == ref[C.collapsed].to_numpy()
        robust = robust_flags("rbm", tight, cells, ref, jobs)
        p12 = ref[C.max_rotation_ratio].to_numpy()
        peak_ok = _close(runs[-2][C.max_rotation_ratio].to_numpy(), p12)
        peak_ok &= _close(other[C.max_rotation_ratio].to_numpy(), p12)
        # and the same sequence of discrete events: a chaotic run can keep an early
        # peak in all three runs while the trajectories have parted (a later, larger
        # peak then appears at another tolerance)
        for col in (C.n_uplifts, C.n_impacts):
            for run in (runs[-2], other):
                peak_ok &= run[col].to_numpy() == ref[col].to_numpy()
    ref[C.robust] = robust.astype(int)
    ref["converged"] = (robust & same).astype(int)
    ref["peak_converged"] = (robust & same & peak_ok).astype(int)
    return ref[_REF_COLUMNS]


def robust_flags(kind: str, cfg: Config, cells, ref: pd.DataFrame, jobs: int) -> np.ndarray:
    """The robustness rule (rbm_cli.study.robustness) on a reference: True where all
    MEMBERS members (ref is member 0) collapse or all survive and none fails."""
    flags = ref[C.collapsed].to_numpy()
    robust = (ref[C.status] != "failed").to_numpy().copy()
    for member in members(MEMBERS)[1:]:
        member_cfg, _ = member_config(cfg, 1.0, member)
        moved = [(a * (1.0 + member.amplitude_relative), f) for a, f in cells]
        run, _ = run_cells(kind, member_cfg, moved, jobs)
        robust &= (run[C.status] != "failed").to_numpy() & (run[C.collapsed].to_numpy() == flags)
    return robust


_REF_COLUMNS = [C.amplitude_g, C.frequency_hz, C.status, C.collapsed, C.t_collapse_s,
                C.max_rotation_ratio, C.robust, "converged", "peak_converged"]  # fmt: skip


# ---------------------------------------------------------------- the benchmark
def _sample(cells, k: int, seed: int = 5) -> list:
    rng = np.random.default_rng(seed)
    idx = np.sort(rng.choice(len(cells), size=min(k, len(cells)), replace=False))
    return [cells[i] for i in idx]


def run_bench(
    quick: bool = False,
    jobs: int = 2,
    output: str | os.PathLike = "bench",
    reference_dir: str | os.PathLike | None = None,
    problems: tuple[str, ...] | None = None,
    log=print,
    reuse_references: bool = False,
    pair: bool = False,
) -> pd.DataFrame:
    """Run the benchmark; write bench.csv (and, full, the references).

    Every run (quick, pair or full) has the default method (`auto` resolved: the closed
    form on the rigid monoliths, the step kernel elsewhere), the step kernel and the exact
    integrator, each row with its agreement with the default on the same cells.
    pair: only these (and the baseline) on the full grids.

    The figure (bench.png) is drawn by the caller from the returned table
    (:func:`rbm_cli.report.bench_figures.work_precision_figure`)."""
    ref_dir = Path(reference_dir) if reference_dir else REFERENCE_DIR
    out_dir = Path(output)
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise RbmError(f"cannot write to output folder {out_dir}: {exc.strerror}") from None
    warm_up()
    chosen = [p for p in PROBLEMS if problems is None or p.name in problems]
    rows = []
    for prob in chosen:
        cfg = problem_config(prob, stride=4 if quick else 1)
        cells = bench_cells(cfg)
        ref = _reference(prob, cfg, cells, ref_dir, quick, reuse_references, jobs, log)
        sample = _sample(cells, QUICK_SAMPLE if quick else SAMPLE[prob.name])
        results = _run_methods(cfg, cells, sample, quick or pair, jobs)
        for row in _method_rows(prob, results, sample, ref, jobs):
            rows.append(row)
            log(_line(row))
    table = pd.DataFrame(rows)
    write_text_atomic(out_dir / "bench.csv", table.to_csv(index=False, float_format="%.6g"))
    return table


def _reference(
    prob: Problem,
    cfg: Config,
    cells: list,
    ref_dir: Path,
    quick: bool,
    reuse_references: bool,
    jobs: int,
    log,
) -> pd.DataFrame:
    """The stored reference of a problem (quick, or full with reuse), or a new one, stored."""
    ref_path = ref_dir / f"{prob.name}_reference.csv"
    if quick or (reuse_references and ref_path.is_file()):
        if not ref_path.is_file():
            raise RbmError(f"no stored reference {ref_path}: run the full `rbm bench` first")
        ref = pd.read_csv(ref_path)
        if not quick and len(ref) != len(cells):
            raise RbmError(f"{ref_path} does not match the grid; run without --reuse-references")
        return ref
    start = time.perf_counter()
    ref = make_reference(prob, cfg, jobs)
    ref_dir.mkdir(parents=True, exist_ok=True)
    write_text_atomic(ref_path, ref.to_csv(index=False, float_format="%.12g"))
    log(f"{prob.name}: reference ({prob.reference}) in {time.perf_counter() - start:.1f} s")
    return ref


def _default_method(cfg: Config) -> tuple[str, str, float]:
    """(implementation, method, rtol) of rbm's default solver on a problem: `auto`
    resolved (the closed form on a rigid monolith, else DOP853)."""
    solver = SolverConfig()
    default = dataclasses.replace(cfg, solver=solver)
    return ("compiled", resolve_method(default), solver.rtol)


def _run_methods(cfg: Config, cells: list, sample: list, quick: bool, jobs: int) -> list:
    """Run every method (quick: the default, the step kernel if it is not the default,
    and the exact method) and the baseline.

    Returns (method triple, rows, wall time [s], whether on the sample only) per
    method, the baseline last; the uncompiled kernel and the baseline run the sample."""
    default = _default_method(cfg)
    step = ("compiled", STEP_DEFAULT, SolverConfig().rtol)
    if quick:
        methods = list(dict.fromkeys([default, step, EXACT]))
    else:
        methods = list(METHODS) + ([default] if default not in METHODS else [])
    results = []
    for impl, method, rtol in methods:
        part = sample if impl == "python" else cells
        df, wall = run_cells("rbm", _with_solver(cfg, impl, method, rtol), part, jobs)
        results.append(((impl, method, rtol), df, wall, part is sample))
    df, wall = run_cells("baseline", cfg, sample, jobs, budget_s=20.0 if quick else 60.0)
    results.append((("baseline", "solve_ivp RK45", 1e-6), df, wall, True))
    return results


def _method_rows(
    prob: Problem, results: list, sample: list, ref: pd.DataFrame, jobs: int
) -> list[dict]:
    """One table row per method of `results` (from :func:`_run_methods`): times and errors."""
    default = _default_method(problem_config(prob, stride=40))
    # paired times: each method's run times summed over the sample's cells
    on_sample = set(cell_keys(pd.DataFrame(sample, columns=[C.amplitude_g, C.frequency_hz])))
    paired = [
        float(d.loc[cell_keys(d).isin(on_sample), "wall_time_s"].sum()) for _, d, _, _ in results
    ]
    base_sum = paired[-1]
    k_default = next(k for k, r in enumerate(results) if r[0] == default)
    rows = []
    for (triple, df, wall, sampled), own in zip(results, paired, strict=True):
        impl, method, rtol = triple
        row = {
            "problem": prob.name,
            "implementation": impl,
            "method": method,
            "rtol": rtol,
            "default": int(triple == default),
            "cells_run": len(df),
            "time_per_run_ms_median": 1e3 * float(df["wall_time_s"].median()),
            "time_per_run_ms_mean": 1e3 * float(df["wall_time_s"].mean()),
            "sample_time_s": own,
            # a sampled method's whole domain: the default's wall time x the paired ratio
            "domain_wall_s": results[k_default][2] * own / paired[k_default]
            if sampled and paired[k_default] > 0
            else (math.nan if sampled else wall),
            "domain_estimated": int(sampled),
            "jobs": jobs,
            "speedup_vs_baseline": base_sum / own if own > 0 else math.nan,
            "steps_median": float(df[C.n_steps].median()) if C.n_steps in df else math.nan,
        }
        row.update(errors(df, ref))
        row.update(agreement(df, results[k_default][1], ref))
        rows.append(row)
    return rows


def _line(r: dict) -> str:
    closed = r["method"] in ("exact", "closed-form")  # no tolerance; pieces, not steps
    rtol = "" if closed else f" rtol {r['rtol']:.0e}"
    steps = r.get("steps_median", math.nan)
    unit = "pieces" if closed else "steps"
    steps = f", {steps:.0f} {unit}" if steps == steps else ""
    return (
        f"{r['problem']:10s} {r['implementation']:9s} {r['method'] + rtol:21s}: "
        f"{r['time_per_run_ms_mean']:9.3f} ms/run{steps}, domain {r['domain_wall_s']:8.2f} s"
        f"{' (est.)' if r['domain_estimated'] else ''}, x{r['speedup_vs_baseline']:.0f} vs "
        f"baseline; differ {r['cells_differ']}/{r['n_converged']} "
        f"(sensitive {r['n_sensitive']}), boundary {r['boundary_err_g']:.3g} g, "
        f"peak err median {r['peak_err_median']:.2g} max {r['peak_err_max']:.2g}; vs the "
        f"default: x{r['speedup_vs_default']:.2f}, differ {r['differ_vs_default']}, peak diff "
        f"max {r['peak_diff_vs_default_max']:.2g}"
    )


def check_targets(table: pd.DataFrame) -> list[str]:
    """Accuracy targets of the default method; returns the failures."""
    fails = []
    for prob in PROBLEMS:
        rows = table[(table["problem"] == prob.name) & (table["default"] == 1)]
        if rows.empty:
            continue
        r = rows.iloc[0]
        if r["fraction_differ"] > prob.max_cells:
            fails.append(f"{prob.name}: {r['cells_differ']} of {r['n_converged']} cells differ "
                         f"from the reference (target <= {prob.max_cells:.1%})")  # fmt: skip
        if r["n_peak"] and r["peak_err_max"] >= PEAK_TARGET:
            fails.append(f"{prob.name}: peak rotation error {r['peak_err_max']:.2g} "
                         f"(target < {PEAK_TARGET:g})")  # fmt: skip
    return fails
