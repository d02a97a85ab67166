"""Running the cells of `rbm bench`: one row per cell, timed on `jobs` workers.

Three runners report the same row (:func:`_row`): the RBM through
:func:`rbm_cli.study.simulate.simulate`, the scipy baseline
(:mod:`rbm_cli.study.bench_baseline`) and the closed-form linearised Housner
solution (:mod:`rbm_cli.models.block.closed_form`).
"""

from __future__ import annotations

import time
from functools import partial

import joblib
import numpy as np
import pandas as pd

from rbm_cli.config.types import Config
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.models.block.closed_form import linear_run, warm_up
from rbm_cli.models.compile_ahead import compile_once
from rbm_cli.models.methods import compiled_codes
from rbm_cli.models.registry import make_runner
from rbm_cli.structures.assembly import model_from_config
from rbm_cli.structures.closed_forms import linear_rocking_parameters
from rbm_cli.study.bench_baseline import baseline_run
from rbm_cli.study.schema import C
from rbm_cli.study.simulate import simulate


def _row(a: float, f: float, status: str, t_collapse: float, peak: float, wall: float) -> dict:
    """One cell's outcome, as every runner of the benchmark reports it."""
    return {C.amplitude_g: a, C.frequency_hz: f, C.status: status,
            C.collapsed: int(status == "collapsed"), C.t_collapse_s: t_collapse,
            C.max_rotation_ratio: peak, "wall_time_s": wall}  # fmt: skip


def _run_rbm_chunk(cfg: Config, cells) -> list[dict]:
    for code in compiled_codes(cfg):  # load the compiled code in this worker before timing
        compile_once(code)
    runner = make_runner(cfg)
    rows = []
    for a, f in cells:
        r = simulate(cfg, a, f, runner=runner)
        row = _row(a, f, r.status, r.t_collapse_s, r.max_rotation_ratio, r.wall_time_s)
        rows.append(dict(row, n_uplifts=r.n_uplifts, n_impacts=r.n_impacts, n_steps=r.n_steps))
    return rows


def _run_baseline_chunk(cfg: Config, cells, budget_s: float = 120.0) -> list[dict]:
    model = model_from_config(cfg)
    rows = []
    for a, f in cells:
        motion = make_ground_motion(cfg.excitation, a, f)
        start = time.perf_counter()
        out = baseline_run(model, motion, budget_s=budget_s)
        wall = time.perf_counter() - start
        rows.append(_row(a, f, out.status, out.t_collapse, float(out.max_ratio[0]), wall))
    return rows


def _run_closed_form_chunk(cfg: Config, cells) -> list[dict]:
    warm_up()  # load the compiled closed form in this worker before timing runs
    model = model_from_config(cfg)
    alpha, p = linear_rocking_parameters(model.column)
    rows = []
    for a, f in cells:
        start = time.perf_counter()
        out = linear_run(alpha, p, make_ground_motion(cfg.excitation, a, f),
                                 restitution=model.restitution,
                                 collapse_ratio=cfg.collapse.ratio)  # fmt: skip
        rows.append(_row(a, f, out.status, out.t_collapse, float(np.max(out.max_ratio)),
                         time.perf_counter() - start))  # fmt: skip
    return rows


def run_cells(
    kind: str, cfg: Config, cells, jobs: int, budget_s: float = 120.0
) -> tuple[pd.DataFrame, float]:
    """Rows of `cells` and the wall time [s] on `jobs` workers (budget_s: per
    baseline run, which has no step budget of its own)."""
    fn = {"rbm": _run_rbm_chunk, "baseline": partial(_run_baseline_chunk, budget_s=budget_s),
          "closed-form": _run_closed_form_chunk}[kind]  # fmt: skip
    size = max(1, min(32, len(cells) // max(1, 8 * jobs)))
    chunks = [cells[i : i + size] for i in range(0, len(cells), size)]
    start = time.perf_counter()
    if jobs == 1:
        parts = [fn(cfg, c) for c in chunks]
    else:
        parts = joblib.Parallel(n_jobs=jobs)(joblib.delayed(fn)(cfg, c) for c in chunks)
    wall = time.perf_counter() - start
    return pd.DataFrame([r for p in parts for r in p]), wall
