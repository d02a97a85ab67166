"""Which method a record run of the 8-drum column wants, and what its events cost
(docs/performance.md, "Record suites: the method and the events").

    python tools/profile_methods.py            # the 40 runs, both methods: ~2 min
    python tools/profile_methods.py --events   # first steps after each kind of event: ~1 min

The runs of `configs/ci/suite_multidrum_ci.yaml` (the paper's column in 8 drums, k_n 5e9
Pa/m, the first 4 synthetic records of 30 s plus 5 s of free motion, PGA 0.1-1.0 g), one
at a time in this process, compiled, after one run of each method that compiles:

- each run with the step kernel (DOP853, the default) and with the exact integrator
  (`solver.method: exact`), the median wall time of 3;
- when a joint first opens: the first sample (every 0.2 ms of a recorded step-kernel run)
  at which a joint's law argument is beyond its elastic branch, and the share of the
  samples after it with a joint open;
- the cost of the motion up to that time with either method (the record cut at the sample
  before it), which is all a switch to the exact integrator while every joint is closed
  could save.

`--events` runs the step kernel's own source uncompiled (`solver.implementation: python`)
over the first 10 s of record rdk_01 at 0.2 g and counts, by the kind of the event before
it, the steps whose first attempt was rejected (the step size carried over the event too
large for the new set of law pieces).

Runs are timed one at a time on one core: say the load.
"""

from __future__ import annotations

import collections
import dataclasses
import os
import sys
import time

import numpy as np
from profile_records import CONFIG, points  # the script beside this one

from rbm_cli.base.jit import plain
from rbm_cli.config.load import load_config
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.models.rbm.pieces import IMPACT, KINK, UPLIFT
from rbm_cli.models.rbm.step import stepper
from rbm_cli.models.registry import make_runner
from rbm_cli.numerics.rk import TAB_NS
from rbm_cli.structures.arrays import column_arrays

#: The kinds of event a step follows, by what the column's switch returns (a rest counts
#: as an impact).
KINDS = {UPLIFT: "uplift", KINK: "kink (here: a joint back on its elastic branch)",
         IMPACT: "impact"}  # fmt: skip
#: Sample interval of the recorded run that finds the first opening [s].
OPEN_DT = 2e-4
REPEATS = 3


def _with_method(config, method: str, implementation: str = "compiled"):
    solver = dataclasses.replace(config.solver, method=method, implementation=implementation)
    return dataclasses.replace(config, solver=solver)


def _wall(runner, motion, solver) -> tuple[float, object]:
    walls, out = [], None
    for _ in range(REPEATS):
        start = time.perf_counter()
        out = runner.run(motion, solver)
        walls.append(time.perf_counter() - start)
    return float(np.median(walls)), out


def _until(motion, t_stop: float):
    """The record cut at its last sample before t_stop [s]."""
    knots = np.asarray(motion.knots)
    keep = knots < t_stop
    t_last = float(knots[keep][-1])
    return dataclasses.replace(motion, knots=knots[keep], values=np.asarray(motion.values)[keep],
                               t_end=t_last, pulse_end=min(motion.pulse_end, t_last))  # fmt: skip


def _opening(runner, motion, solver) -> tuple[float, float]:
    """(time a joint first opens [s] (inf: never), share of the samples after it with a
    joint open)."""
    out = runner.run(motion, solver, record=True, output_dt=OPEN_DT)
    arrays = column_arrays(runner.model)
    x = np.asarray(out.history.rotations) @ np.asarray(arrays.argmap).T
    open_ = np.any(np.abs(x) >= np.asarray(arrays.edges)[:, 0], axis=1)
    if not open_.any():
        return np.inf, 0.0
    first = int(np.argmax(open_))
    return float(out.history.t[first]), float(open_[first:].mean())


def profile() -> list[dict]:
    """One row per run: record, pga_g, status (step kernel), wall_step_s, wall_exact_s,
    t_open_s, open_share, prefix_step_s, prefix_exact_s, steps, rhs, events, motion_s."""
    config = load_config(CONFIG)
    rows = []
    for i, (name, cfg) in enumerate(points(config)):
        step_cfg, exact_cfg = _with_method(cfg, "DOP853"), _with_method(cfg, "exact")
        step, exact = make_runner(step_cfg), make_runner(exact_cfg)  # one each a point
        for a in config.grid.amplitudes_g:
            motion = make_ground_motion(cfg.excitation, a)
            if i == 0 and a == config.grid.amplitudes_g[0]:  # compile outside the timings
                step.run(motion, step_cfg.solver)
                exact.run(motion, exact_cfg.solver)
            rows.append(_profile_run(name, a, motion, step, step_cfg.solver, exact,
                                     exact_cfg.solver))  # fmt: skip
    return rows


def _profile_run(name, a, motion, step, step_solver, exact, exact_solver) -> dict:
    """One row of :func:`profile`."""
    wall_step, out = _wall(step, motion, step_solver)
    wall_exact, _ = _wall(exact, motion, exact_solver)
    t_open, share = _opening(step, motion, step_solver)
    if np.isinf(t_open):  # the whole run is before an opening
        prefix_step, prefix_exact = wall_step, wall_exact
    elif t_open > float(motion.knots[1]):
        head = _until(motion, t_open)
        prefix_step, _ = _wall(step, head, step_solver)
        prefix_exact, _ = _wall(exact, head, exact_solver)
    else:  # open within the record's first sample interval
        prefix_step = prefix_exact = 0.0
    return {
        "record": name, "pga_g": a, "status": out.status, "wall_step_s": wall_step,
        "wall_exact_s": wall_exact, "t_open_s": t_open, "open_share": share,
        "prefix_step_s": prefix_step, "prefix_exact_s": prefix_exact,
        "steps": out.n_steps, "rhs": out.n_rhs, "events": out.n_events,
        "motion_s": out.t_collapse if out.status == "collapsed" else motion.t_end,
    }  # fmt: skip


def report(rows: list[dict]) -> str:
    """The Markdown lines of the profile."""
    lines = [
        "| runs | n | step kernel, sum [s] | exact, sum [s] | exact / step kernel, median"
        " (range) | joint first open at [s], median | motion with a joint open after it |",
        "|---|---|---|---|---|---|---|",
    ]
    groups = {
        "no joint opens": [r for r in rows if np.isinf(r["t_open_s"])],
        "survived": [r for r in rows if r["status"] == "survived" and np.isfinite(r["t_open_s"])],
        "collapsed": [r for r in rows if r["status"] == "collapsed"],
    }
    for label, part in groups.items():
        if not part:
            continue
        step = np.array([r["wall_step_s"] for r in part])
        exact = np.array([r["wall_exact_s"] for r in part])
        ratio = exact / step
        t_open = np.array([r["t_open_s"] for r in part])
        share = np.array([r["open_share"] for r in part])
        opened = np.isfinite(t_open)
        when = f"{np.median(t_open[opened]):.2f}" if opened.any() else "never"
        during = (f"{100 * np.median(share[opened]):.0f} % ({100 * share[opened].min():.0f}-"
                  f"{100 * share[opened].max():.0f} %)" if opened.any() else "-")  # fmt: skip
        lines.append(
            f"| {label} | {len(part)} | {step.sum():.2f} | {exact.sum():.2f} |"
            f" {np.median(ratio):.2f} ({ratio.min():.2f}-{ratio.max():.2f}) | {when} | {during} |"
        )
    total_step = sum(r["wall_step_s"] for r in rows)
    total_exact = sum(r["wall_exact_s"] for r in rows)
    pre_step = sum(r["prefix_step_s"] for r in rows)
    pre_exact = sum(r["prefix_exact_s"] for r in rows)
    steps = sum(r["steps"] for r in rows)
    events = sum(r["events"] for r in rows)
    rhs = sum(r["rhs"] for r in rows)
    lines.append(
        f"\nAll {len(rows)} runs: step kernel {total_step:.1f} s, exact {total_exact:.1f} s."
        f" Up to the first opening: step kernel {pre_step:.2f} s"
        f" ({100 * pre_step / total_step:.1f} % of its whole), exact {pre_exact:.2f} s: the"
        f" exact integrator while every joint is closed would save"
        f" {pre_step - pre_exact:.2f} s ({100 * (pre_step - pre_exact) / total_step:.1f} %)."
        f" Step kernel: {steps / events:.2f} steps and {rhs / events:.1f} right-hand sides an"
        f" event, {1e6 * total_step / events:.1f} us an event. Load"
        f" {os.getloadavg()[0]:.1f} at the end."
    )
    return "\n".join(lines)


def first_attempts(seconds: float = 10.0, pga_g: float = 0.2) -> tuple[str, dict, str]:
    """The step kernel's source run uncompiled (the run loop's step and the column's switch
    wrapped while it runs) over the first ``seconds`` of the CI band's first record at
    ``pga_g``: (the record's name, {the kind of event before a step (KINDS' labels, or
    "none"): [(its first attempt rejected, accepted / attempted size), ...]}, the run's
    status)."""
    config = load_config(CONFIG)
    name, cfg = next(points(config))
    cfg = _with_method(cfg, "DOP853", "python")
    motion = make_ground_motion(cfg.excitation, pga_g)
    motion = _until(motion, seconds + 1e-9)
    last = ["none"]
    seen: dict = collections.defaultdict(list)
    # the run loop calls the step from its own names (numerics.loop.loop_for), the event's
    # functions call switch from the stepper's; both run uncompiled here (base.jit.plain)
    loop_names = getattr(stepper.run_plane, "py_func", stepper.run_plane).__globals__
    attempt, switch = plain(loop_names["attempt_step"]), plain(stepper.switch)
    compiled = loop_names["attempt_step"], stepper.switch

    def counted_attempt(mc, t, y, f, h_abs, *rest):
        res = attempt(mc, t, y, f, h_abs, *rest)
        seen[last[0]].append((res[4] > TAB_NS[mc], res[2] / h_abs))
        last[0] = "none"
        return res

    def counted_switch(*args):
        what = switch(*args)
        last[0] = KINDS.get(what, KINDS[IMPACT])
        return what

    loop_names["attempt_step"], stepper.switch = counted_attempt, counted_switch
    try:
        out = make_runner(cfg).run(motion, cfg.solver)
    finally:
        loop_names["attempt_step"], stepper.switch = compiled
    return name, seen, out.status


def after_events(seconds: float = 10.0, pga_g: float = 0.2) -> dict:
    """Steps after each kind of event (and after none) whose first attempt was rejected:
    {kind: (steps, of them rejected, median accepted / attempted size of those)}
    (first_attempts)."""
    name, seen, _ = first_attempts(seconds, pga_g)
    out = {}
    for kind, steps in seen.items():
        rejected = [ratio for was_rejected, ratio in steps if was_rejected]
        out[kind] = (len(steps), len(rejected), float(np.median(rejected)) if rejected else 1.0)
    print(f"{name} at {pga_g} g, its first {seconds:g} s, uncompiled", file=sys.stderr)
    return out


if __name__ == "__main__":
    if "--events" in sys.argv[1:]:
        print("| after | steps | first attempt rejected | accepted / attempted, median |")
        print("|---|---|---|---|")
        for kind, (n, n_rej, ratio) in sorted(after_events().items()):
            print(f"| {kind} | {n:,} | {n_rej:,} ({100 * n_rej / n:.0f} %) | {ratio:.2f} |")
    else:
        print(report(profile()))
