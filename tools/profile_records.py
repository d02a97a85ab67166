"""Where a record run's time goes: the 8-drum column of the stored record suite, run by
run (docs/performance.md, "Record suites: where the time goes").

    python tools/profile_records.py            # 4 records x 10 levels, one process: ~2 min

The runs of `configs/ci/suite_multidrum_ci.yaml` (the paper's column in 8 drums, k_n 5e9
Pa/m, the first 4 synthetic records of 30 s plus 5 s of free motion, PGA 0.1-1.0 g), each
run twice in this process with the default method (the compiled step kernel): as
configured, and with no free motion after the record (`free_time: 0`), after one run that
compiles. Per run it reads the wall time and the kernel's counters (accepted steps,
right-hand sides, events: kinks and impacts) and prints, for the survivors and the
collapsed runs apart: their wall time, the share of the survivors' time in the free tail,
steps per second of motion and per sample interval of the record, events per second,
right-hand sides per step, the wall time per step. Runs are timed one at a time on one
core: say the load.
"""

from __future__ import annotations

import dataclasses
import os
import time
from pathlib import Path

import numpy as np

from rbm_cli.config.load import load_config, parse_config
from rbm_cli.config.points import expand
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.models.registry import make_runner

ROOT = Path(__file__).resolve().parent.parent
CONFIG = ROOT / "configs" / "ci" / "suite_multidrum_ci.yaml"


def points(config):
    """(record name, config) of every point of the grid (one record each), in grid order."""
    for point in expand(config, parse_config, base_dir=config.base_dir):
        yield Path(str(point.config.excitation.file)).stem, point.config


def _runs(config):
    """(record name, PGA [g], config, runner) of every cell, in grid order (one runner a
    point, as a sweep makes)."""
    for name, cfg in points(config):
        runner = make_runner(cfg)
        for a in config.grid.amplitudes_g:
            yield name, a, cfg, runner


def _timed(config, runner, amplitude_g):
    motion = make_ground_motion(config.excitation, amplitude_g)
    start = time.perf_counter()
    out = runner.run(motion, config.solver)
    return time.perf_counter() - start, out, motion


def profile() -> list[dict]:
    """One row per run: record, pga_g, status, wall_s, wall_forced_s (free_time 0),
    motion_s (simulated to its end or collapse), steps, rhs, events, sample_dt_s."""
    config = load_config(CONFIG)
    rows = []
    first = True
    for name, a, cfg, runner in _runs(config):
        if first:  # compile outside the timings
            _timed(cfg, runner, a)
            first = False
        forced = dataclasses.replace(
            cfg, excitation=dataclasses.replace(cfg.excitation, free_time=0.0)
        )
        wall, out, motion = _timed(cfg, runner, a)
        wall_forced, _, _ = _timed(forced, runner, a)
        knots = np.asarray(motion.knots)
        rows.append({
            "record": name, "pga_g": a, "status": out.status, "wall_s": wall,
            "wall_forced_s": wall_forced,
            "motion_s": out.t_collapse if out.status == "collapsed" else motion.t_end,
            "steps": out.n_steps, "rhs": out.n_rhs, "events": out.n_events,
            "sample_dt_s": float(np.median(np.diff(knots))),
        })  # fmt: skip
    return rows


def report(rows: list[dict]) -> str:
    """The Markdown lines of the profile (medians over runs, the tail's share summed)."""
    lines = []
    for status in ("survived", "collapsed"):
        part = [r for r in rows if r["status"] == status]
        if not part:
            continue
        wall = np.array([r["wall_s"] for r in part])
        per_s = np.array([r["steps"] / r["motion_s"] for r in part])
        per_sample = per_s * np.array([r["sample_dt_s"] for r in part])
        events = np.array([r["events"] / r["motion_s"] for r in part])
        rhs = np.array([r["rhs"] / max(r["steps"], 1) for r in part])
        step_us = 1e6 * wall.sum() / sum(r["steps"] for r in part)
        lines.append(
            f"| {status} | {len(part)} | {np.median(wall):.3f} ({wall.min():.3f}-{wall.max():.3f})"
            f" | {wall.sum():.1f} | {np.median(per_s):,.0f} | {np.median(per_sample):.1f}"
            f" | {np.median(events):,.0f} (max {events.max():,.0f}) | {np.median(rhs):.1f}"
            f" | {step_us:.1f} |"
        )
    survivors = [r for r in rows if r["status"] == "survived"]
    total = sum(r["wall_s"] for r in rows)
    tail = sum(r["wall_s"] - r["wall_forced_s"] for r in survivors)
    head = [
        "| runs | n | wall per run [s], median (range) | wall, sum [s] | steps per s of motion"
        " | steps per sample interval | events per s of motion | rhs per step | us per step |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    foot = (
        f"\nAll {len(rows)} runs: {total:.1f} s; the survivors' free tails (wall as"
        f" configured less wall with free_time 0): {tail:.1f} s, {100 * tail / total:.0f} % of"
        f" the whole; load {os.getloadavg()[0]:.1f} at the end."
    )
    return "\n".join(head + lines) + foot


if __name__ == "__main__":
    print(report(profile()))
