"""Time per cell of the step kernel (DOP853, the config's rtol) and of the exact method
(compiled), as in docs/architecture.md, "The exact integrator".

    python tools/exact_timing.py cells        # 64 cells of the 8-drum domain (10 s)
    python tools/exact_timing.py kn           # 6 cells, k_n 5e7 .. 5e11 Pa/m
    python tools/exact_timing.py drums 1 2 4 8 16

Each line: the case, then per method the median and mean time per cell [ms], the total [s],
the cells that collapse, mean steps and right-hand sides (closed-form evaluations for the
exact method), and the 1-minute load average. Run on a quiet machine: both compiled
kernels are warmed on the first cell first (their compile time is not counted).
"""

from __future__ import annotations

import dataclasses
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

from rbm_cli.config.load import load_config
from rbm_cli.config.types import StiffnessConfig
from rbm_cli.models.registry import make_runner
from rbm_cli.study.simulate import simulate

ROOT = Path(__file__).resolve().parent.parent
CELLS = [(0.1, 1.0), (0.15, 2.0), (0.2, 1.5), (0.3, 1.5), (0.5, 1.0), (1.0, 3.0)]


def per_cell(cfg, cells, method):
    c = dataclasses.replace(cfg, solver=dataclasses.replace(cfg.solver, method=method))
    runner = make_runner(c)
    simulate(c, *cells[0], runner=runner)  # compile or load the kernel
    times, outs = [], []
    for a, f in cells:
        t = time.perf_counter()
        outs.append(simulate(c, a, f, runner=runner))
        times.append(time.perf_counter() - t)
    ts = np.array(times)
    return {
        "median_ms": round(float(np.median(ts)) * 1e3, 2),
        "mean_ms": round(float(ts.mean()) * 1e3, 2),
        "total_s": round(float(ts.sum()), 3),
        "collapsed": sum(o.status == "collapsed" for o in outs),
        "steps": round(float(np.mean([o.n_steps for o in outs]))),
        "rhs": round(float(np.mean([o.n_rhs for o in outs]))),
    }


def report(tag, cfg, cells):
    res = {m: per_cell(cfg, cells, m) for m in ("DOP853", "exact")}
    res["load"] = round(os.getloadavg()[0], 2)
    print(tag, json.dumps(res), flush=True)


def main(argv):
    base = load_config(ROOT / "configs" / "harmonic_multidrum.yaml")
    mode = argv[0] if argv else "cells"
    if mode == "cells":
        amps = np.round(np.linspace(0.1, 1.5, 40), 10)[::5]
        freqs = np.round(np.linspace(0.25, 4.0, 40), 10)[::5]
        report("8-drum, 64 cells", base, [(float(a), float(f)) for f in freqs for a in amps])
    elif mode == "kn":
        for kn in (5e7, 5e8, 5e9, 5e10, 5e11):
            stiff = StiffnessConfig("normal", (kn,))
            cfg = dataclasses.replace(
                base, interface=dataclasses.replace(base.interface, stiffness=stiff)
            )
            report(f"k_n {kn:g} Pa/m", cfg, CELLS)
    elif mode == "drums":
        for nd in [int(x) for x in argv[1:]] or [1, 2, 4, 8, 16]:
            column = dataclasses.replace(base.column, drum_heights=tuple([5.0 / nd] * nd))
            report(f"{nd} drums", dataclasses.replace(base, column=column), CELLS)


if __name__ == "__main__":
    main(sys.argv[1:])
