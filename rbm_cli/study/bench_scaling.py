"""Scaling measurements of `rbm bench --scaling`: time per run against the number of
drums, the joint stiffness (elastic frequency) and the duration, for both methods (the
step kernel, DOP853, and the exact integrator) on two cells, one that stays elastic and
one that rocks, and the speed-up of 2 workers over 1 on whole domains (all measured in
one run). The figure is drawn by rbm_cli.report.bench_figures."""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np
import pandas as pd

from rbm_cli.base.files import write_text_atomic
from rbm_cli.config.load import parse_config
from rbm_cli.models.registry import make_runner
from rbm_cli.structures.assembly import model_from_config
from rbm_cli.study.schema import C
from rbm_cli.study.simulate import simulate

#: The paper's tapered column (5 m, 0.96 -> 0.66 m), one cell that stays elastic
#: for all drum counts (0.05 g, 2 Hz; at 0.15 g joints of 32-50 thin drums chatter), 10 s.
COLUMN = {"height": 5.0, "base_width": 0.96, "top_width": 0.66, "section": "rectangular",
          "density": 2700}  # fmt: skip
CELL = (0.05, 2.0)
#: A cell whose joints open and close (rocking, impacts) [g, Hz].
ROCKING_CELL = (0.3, 2.0)
DRUMS = (1, 2, 4, 8, 16, 32, 50)
STIFFNESS = (5e7, 1.5e8, 5e8, 1.5e9, 5e9, 1.5e10, 5e10, 1.5e11, 5e11)  # k_n [Pa/m]
#: The methods compared: (label, solver.method).
METHODS = (("step kernel (DOP853)", "DOP853"), ("exact", "exact"))
#: Wall-clock budget of one scaling run [s] (a run over it is reported failed).
RUN_BUDGET_S = 120.0
DURATIONS = (2.5, 5.0, 10.0, 20.0, 40.0)  # s


def _config(drums: int = 8, k_n: float = 5e9, duration: float = 10.0, method="DOP853"):
    return parse_config(
        {
            "name": "scaling",
            "column": dict(COLUMN, drums=drums),
            "interface": {"stiffness": {"normal": k_n}},
            "excitation": {"type": "harmonic", "duration": duration},
            "solver": {"method": method, "max_wall_time": RUN_BUDGET_S},
        }
    )


def _elastic_hz(cfg) -> float:
    return max(model_from_config(cfg).elastic_frequencies_hz())


def _time(cfg, cell=CELL, repeats: int = 3) -> dict:
    """Median time of a run of one cell [s] (after one untimed run that loads the code)."""
    runner = make_runner(cfg)
    res = simulate(cfg, *cell, runner=runner)
    walls = [res.wall_time_s]
    if res.wall_time_s < 5.0:
        walls = []
        for _ in range(repeats):
            res = simulate(cfg, *cell, runner=runner)
            walls.append(res.wall_time_s)
    return {"time_per_run_s": float(np.median(walls)), C.n_steps: res.n_steps,
            C.n_rhs: res.n_rhs, C.status: res.status, "peak": res.max_rotation_ratio}  # fmt: skip


def _series(series: str, xs, make, log) -> list[dict]:
    """Rows of one series: every x, both methods, both cells."""
    rows = []
    for x in xs:
        for label, method in METHODS:
            cfg = make(x, method)
            for cell_name, cell in (("elastic", CELL), ("rocking", ROCKING_CELL)):
                rows.append({"series": series, "x": x, "method": label, "cell": cell_name,
                             "elastic_hz": _elastic_hz(cfg), **_time(cfg, cell)})  # fmt: skip
                unit = "pieces" if method == "exact" else "steps"
                log(f"scaling: {series} {x:g}, {label}, {cell_name} cell: "
                    f"{rows[-1]['time_per_run_s'] * 1e3:.1f} ms/run, {rows[-1][C.n_steps]} "
                    f"{unit}, {rows[-1][C.status]}")  # fmt: skip
    return rows


def run_scaling(output: str | os.PathLike = "bench", log=print) -> pd.DataFrame:
    """Measure the scaling series and write scaling.csv to `output`.

    The figure (scaling.png) is drawn by the caller from the returned table
    (:func:`rbm_cli.report.bench_figures.scaling_figure`)."""
    # lazy: loads joblib, pandas only where needed (docs/architecture.md, Start-up)
    from rbm_cli.study.bench import PROBLEMS, bench_cells, problem_config, run_cells

    rows = _series("drums", DRUMS, lambda n, m: _config(drums=n, method=m), log)
    rows += _series("k_n", STIFFNESS, lambda k, m: _config(drums=4, k_n=k, method=m), log)
    rows += _series("duration", DURATIONS, lambda d, m: _config(duration=d, method=m), log)
    for prob in PROBLEMS:
        if prob.name not in ("slender", "multidrum"):
            continue
        cfg = problem_config(prob, stride=1 if prob.name == "slender" else 4)
        cells = bench_cells(cfg)
        walls = {}
        for jobs in (1, 2):
            start = time.perf_counter()
            run_cells("rbm", cfg, cells, jobs)
            walls[jobs] = time.perf_counter() - start
        rows.append({"series": "workers", "x": prob.name, "time_per_run_s": walls[2] / len(cells),
                     "wall_1_s": walls[1], "wall_2_s": walls[2],
                     "speedup_2_over_1": walls[1] / walls[2], "cells": len(cells)})  # fmt: skip
        log(f"scaling: {prob.name} {len(cells)} cells: 1 worker {walls[1]:.2f} s, "
            f"2 workers {walls[2]:.2f} s, speed-up {walls[1] / walls[2]:.2f}")  # fmt: skip
    table = pd.DataFrame(rows)
    out = Path(output)
    out.mkdir(parents=True, exist_ok=True)
    write_text_atomic(out / "scaling.csv", table.to_csv(index=False, float_format="%.6g"))
    return table


__all__ = ["ROCKING_CELL", "run_scaling"]
