"""Where a record run's time goes inside the compiled integrators: the processor's cycles
per part of the run loop, per event (docs/performance.md, "Record suites: inside an event").

    python tools/profile_cycles.py           # the 40 runs, both integrators: ~5 min
    python tools/profile_cycles.py --drums 8 16   # one record run a column, ~4 min

The compiled code cannot be profiled by Python's profilers, and the uncompiled code spends
its time elsewhere. So this script copies the package to a temporary folder, adds a read of
the processor's cycle counter (LLVM's readcyclecounter: the time-stamp counter on x86-64)
around each part of the run loops of the step kernel (numerics.loop with the planar column's
functions, models.rbm.step.stepper) and of the exact integrator (models.rbm.exact.run),
compiles that copy (its own numba cache: two compiles, about 3 min) and runs the 40 runs of
`configs/ci/suite_multidrum_ci.yaml` with each method, one at a time in one process, after
one run that compiles. It prints, for each part, the cycles it took per event of the runs
and its share of the runs' cycles. With --drums N ..., it runs instead the band's column cut
into N drums (each N in turn) under its first record at 0.2 g with the step kernel: how an
event's parts grow with the drums.
The package itself is not changed. The counters cost a few percent: the shares, not the
totals, are the result. Say the load.

The parts are found by lines of the run loops (ANCHORS below): a run loop that changes
them stops the script with a one-line error (tests/test_profile_cycles.py checks that they
are found in today's source).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LOOP = Path("rbm_cli/numerics/loop.py")
STEPPER = Path("rbm_cli/models/rbm/step/stepper.py")
EXACT_RUN = Path("rbm_cli/models/rbm/exact/run.py")

#: The cycle counter, as a numba intrinsic (the instrumented copy's rbm_cli/base/cycles.py).
CYCLES = """from llvmlite import ir
from numba.core import cgutils, types
from numba.extending import intrinsic


@intrinsic
def cycles(typingctx):
    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.IntType(64), [])
        fn = cgutils.get_or_insert_function(builder.module, fnty, "llvm.readcyclecounter")
        return builder.call(fn, [])

    return types.uint64(), codegen
"""

TICK = "float(cycles() - c0)"
STEP_PARTS = ["RK steps (attempts, rejections)", "the new step end's event distances",
              "the reach test", "dense output", "the crossing search",
              "the event's state", "peaks", "friction demand", "the event's law pieces",
              "a new stepper after an event"]  # fmt: skip
EXACT_PARTS = ["certified search (next_point)", "peak intervals (note_interval)",
               "samples and friction demand", "a new piece (modes, rows, first point)",
               "the event's law pieces", "peaks at the end (settle_peaks)"]  # fmt: skip

#: (file, anchor, replacement): each anchor must occur once in its file.
ANCHORS = [
    (LOOP, "from rbm_cli.base.jit import jit\n",
     "from rbm_cli.base.jit import jit\nfrom rbm_cli.base.cycles import cycles\n"),
    (LOOP, "    n_upl, n_imp, n_steps, n_rhs, n_ev, t = 0, 0, 0, 0, 0, 0.0\n",
     "    n_upl, n_imp, n_steps, n_rhs, n_ev, t = 0, 0, 0, 0, 0, 0.0\n"
     "    prof = np.zeros(11)\n    c_all = cycles()\n"),
    (LOOP, "            # a new stepper from (t, y)",
     "            c0 = cycles()\n            # a new stepper from (t, y)"),
    (LOOP, "            event = False\n            running = True\n",
     f"            prof[9] += {TICK}\n            event = False\n            running = True\n"),
    (LOOP, "                taken, t_new, h, h_abs, calls = attempt_step(",
     "                c0 = cycles()\n"
     "                taken, t_new, h, h_abs, calls = attempt_step("),
    (LOOP, "                code, n_steps = step_verdict(",
     f"                prof[0] += {TICK}\n                code, n_steps = step_verdict("),
    (LOOP, "find_event(W, mc, t_old, t_new, h, gr)",
     "find_event(W, mc, t_old, t_new, h, gr, prof)"),
    (LOOP, "                if hit >= 0:\n",
     "                c0 = cycles()\n                if hit >= 0:\n"),
    (LOOP, "                    event = True\n                # the structure's figures",
     f"                    event = True\n                prof[5] += {TICK}\n"
     "                # the structure's figures"),
    (LOOP, "W, mc, t_old, t_new, h, gr, event, dense_ready, account, n_out, next_out\n",
     "W, mc, t_old, t_new, h, gr, event, dense_ready, account, n_out, next_out, prof\n"),
    (LOOP, "            code, uplifts, impacts, at_rest, which, angle = at_event(",
     "            c0 = cycles()\n"
     "            code, uplifts, impacts, at_rest, which, angle = at_event("),
    (LOOP, "            n_upl += uplifts\n",
     f"            prof[8] += {TICK}\n            n_upl += uplifts\n"),
    (LOOP, "                return run_end(W, COLLAPSED,",
     "                prof[10] += float(cycles() - c_all)\n"
     "                print('CYCLES', prof[0], prof[1], prof[2], prof[3], prof[4], prof[5], "
     "prof[6], prof[7], prof[8], prof[9], prof[10], n_ev)\n"
     "                return run_end(W, COLLAPSED,"),
    (LOOP, "    return run_end(W, SURVIVED,",
     "    prof[10] += float(cycles() - c_all)\n"
     "    print('CYCLES', prof[0], prof[1], prof[2], prof[3], prof[4], prof[5], prof[6], "
     "prof[7], prof[8], prof[9], prof[10], n_ev)\n"
     "    return run_end(W, SURVIVED,"),
    (STEPPER, "from rbm_cli.base.jit import jit\n",
     "from rbm_cli.base.jit import jit\nfrom rbm_cli.base.cycles import cycles\n"),
    (STEPPER, "def find_event(W, mc, t_old, t_new, h, gr):\n",
     "def find_event(W, mc, t_old, t_new, h, gr, prof):\n"),
    (STEPPER, "    copy_into(W.acc_old, W.acc)\n",
     "    c0 = cycles()\n    copy_into(W.acc_old, W.acc)\n"),
    (STEPPER, "    if not within_reach(W.d_old, W.d_new, W.dd_old, W.dd_new, W.d2_old, W.d2_new, "
     "t_new - t_old,\n                        W.near):  # fmt: skip\n",
     f"    prof[1] += {TICK}\n    c0 = cycles()\n"
     "    reach = within_reach(W.d_old, W.d_new, W.dd_old, W.dd_new, W.d2_old, W.d2_new, "
     f"t_new - t_old, W.near)\n    prof[2] += {TICK}\n    c0 = cycles()\n    if not reach:\n"),
    (STEPPER, "    t_e, row = first_crossing(",
     f"    prof[3] += {TICK}\n    c0 = cycles()\n    t_e, row = first_crossing("),
    (STEPPER, "    return t_e, row, True, calls\n",
     f"    prof[4] += {TICK}\n    return t_e, row, True, calls\n"),
    (STEPPER, "def step_figures(W, mc, t_old, t_new, h, gr, event, dense_ready, account, n_out, "
     "next_out):\n",
     "def step_figures(W, mc, t_old, t_new, h, gr, event, dense_ready, account, n_out, "
     "next_out, prof):\n"),
    (STEPPER, "    affine(W.track, W.y_new, 0, W.no_offset, W.z_new)\n",
     "    c0 = cycles()\n    affine(W.track, W.y_new, 0, W.no_offset, W.z_new)\n"),
    (STEPPER, "    shear_ratios(g_new, 0.0, gam_new,",
     f"    prof[6] += {TICK}\n    c0 = cycles()\n    shear_ratios(g_new, 0.0, gam_new,"),
    (STEPPER, "    # the step's end is the next step's start\n    copy_into(W.z_prev, W.z_old)\n",
     f"    prof[7] += {TICK}\n"
     "    # the step's end is the next step's start\n    copy_into(W.z_prev, W.z_old)\n"),
    (EXACT_RUN, "from rbm_cli.base.jit import jit\n",
     "from rbm_cli.base.jit import jit\nfrom rbm_cli.base.cycles import cycles\n"),
    (EXACT_RUN,
     "        row, s.st[H], ev, fresh = next_point(pc, pts, s.st[H], seg_end, wk.mb, wk.fb)\n",
     "        c0 = cycles()\n"
     "        row, s.st[H], ev, fresh = next_point(pc, pts, s.st[H], seg_end, wk.mb, wk.fb)\n"
     "        s.cnt[8] += cycles() - c0\n        c0 = cycles()\n"),
    (EXACT_RUN, "            s.cnt[RHS_PEAKS] += ev\n        if se[4] != 0.0:\n",
     "            s.cnt[RHS_PEAKS] += ev\n        s.cnt[9] += cycles() - c0\n"
     "        c0 = cycles()\n        if se[4] != 0.0:\n"),
    (EXACT_RUN, "        if can_stop and _passed_peak(mdl, pc, pts):",
     "        s.cnt[10] += cycles() - c0\n        if can_stop and _passed_peak(mdl, pc, pts):"),
    (EXACT_RUN, "        pc = make_piece(mdl, cache, s.side, s.k, s.pending, s.awaiting, fc)\n",
     "        c0 = cycles()\n"
     "        pc = make_piece(mdl, cache, s.side, s.k, s.pending, s.awaiting, fc)\n"),
    (EXACT_RUN, "        row = _march(mdl, pc, wk, s, se, seg_end, can_stop, sure_stop, samples)\n",
     "        s.cnt[11] += cycles() - c0\n"
     "        row = _march(mdl, pc, wk, s, se, seg_end, can_stop, sure_stop, samples)\n"),
    (EXACT_RUN, "            code = _handle(mdl, pc, row, s, se)\n",
     "            c0 = cycles()\n            code = _handle(mdl, pc, row, s, se)\n"
     "            s.cnt[12] += cycles() - c0\n"),
    (EXACT_RUN, "              np.zeros(8, dtype=np.int64), held, np.zeros(mf), np.zeros(mf),\n"
     "              np.zeros(n))  # fmt: skip\n",
     "              np.zeros(14, dtype=np.int64), held, np.zeros(mf), np.zeros(mf),\n"
     "              np.zeros(n))  # fmt: skip\n    c_all = cycles()\n"),
    (EXACT_RUN, "        ev = settle_peaks(mdl, cache, wk.notes, seg_fc, s.maxima, wk)\n",
     "        c0 = cycles()\n"
     "        ev = settle_peaks(mdl, cache, wk.notes, seg_fc, s.maxima, wk)\n"
     "        s.cnt[13] += cycles() - c0\n"),
    (EXACT_RUN, "    return code, s.st, s.cnt, s.maxima, s.fric\n",
     "    print('CYCLES', s.cnt[8], s.cnt[9], s.cnt[10], s.cnt[11], s.cnt[12], s.cnt[13], "
     "cycles() - c_all, s.cnt[EVENTS])\n    return code, s.st, s.cnt, s.maxima, s.fric\n"),
]  # fmt: skip


def instrumented(source: Path, target: Path) -> None:
    """Copy the package under source to target with the counters added (ANCHORS); exits
    with a one-line error when an anchor is not found once."""
    shutil.copytree(source / "rbm_cli", target / "rbm_cli",
                    ignore=shutil.ignore_patterns("__pycache__"))  # fmt: skip
    (target / "rbm_cli" / "base" / "cycles.py").write_text(CYCLES)
    texts = {f: (target / f).read_text() for f in (LOOP, STEPPER, EXACT_RUN)}
    for f, anchor, replacement in ANCHORS:
        if texts[f].count(anchor) != 1:
            sys.exit(f"profile_cycles: {f} changed: this line is not found once: "
                     f"{anchor.strip().splitlines()[0]!r}")  # fmt: skip
        texts[f] = texts[f].replace(anchor, replacement)
    for f, text in texts.items():
        (target / f).write_text(text)


def _child(method: str, drums: int) -> None:
    """Run the 40 runs with the method, or (drums > 0) the band's first record at 0.2 g on
    its column in that many drums (in the instrumented copy: the counters print)."""
    import dataclasses

    sys.path.insert(0, str(ROOT / "tools"))
    from profile_records import CONFIG, points

    from rbm_cli.api import with_value
    from rbm_cli.config.load import load_config
    from rbm_cli.inputs.excitation import make_ground_motion
    from rbm_cli.models.registry import make_runner

    config = load_config(CONFIG)
    cells = [(cfg, a) for _, cfg in points(config) for a in config.grid.amplitudes_g]
    if drums > 0:
        cells = [(with_value(cells[0][0], "column.drums", drums), 0.2)]
    first = True
    for cfg, a in cells:
        cfg = dataclasses.replace(cfg, solver=dataclasses.replace(cfg.solver, method=method))
        runner = make_runner(cfg)
        motion = make_ground_motion(cfg.excitation, a)
        if first:  # compiles; its counters are left out
            runner.run(motion, cfg.solver)
            print("COMPILED", flush=True)
            first = False
        runner.run(motion, cfg.solver)


def _table(lines: list[str], parts: list[str]) -> None:
    rows = [[float(x) for x in line.split()[1:]] for line in lines]
    total = sum(r[len(parts)] for r in rows)
    events = sum(r[len(parts) + 1] for r in rows)
    print(f"{len(rows)} runs, {events:,.0f} events, {total / 1e9:.2f} G cycles, "
          f"{total / events:,.0f} cycles an event")  # fmt: skip
    print("| part | cycles an event | share |\n|---|---|---|")
    for i, name in enumerate(parts):
        part = sum(r[i] for r in rows)
        print(f"| {name} | {part / events:,.0f} | {100 * part / total:.1f} % |")
    rest = total - sum(sum(r[: len(parts)]) for r in rows)
    print(f"| the rest of the loop | {rest / events:,.0f} | {100 * rest / total:.1f} % |")


def main() -> None:
    if len(sys.argv) == 4 and sys.argv[1] == "--child":
        _child(sys.argv[2], int(sys.argv[3]))
        return
    jobs = [("DOP853", STEP_PARTS, 0), ("exact", EXACT_PARTS, 0)]
    if len(sys.argv) > 1:
        counts = sys.argv[2:]
        usable = all(a.isdigit() and int(a) > 0 for a in counts)
        if sys.argv[1] != "--drums" or not counts or not usable:
            sys.exit("profile_cycles: usage: profile_cycles.py [--drums N [N ...]]")
        jobs = [("DOP853", STEP_PARTS, int(a)) for a in counts]
    with tempfile.TemporaryDirectory(prefix="rbm-cycles-") as tmp:
        instrumented(ROOT, Path(tmp))
        env = dict(os.environ, PYTHONPATH=tmp, NUMBA_CACHE_DIR=str(Path(tmp) / "cache"))
        for method, parts, drums in jobs:
            done = subprocess.run([sys.executable, __file__, "--child", method, str(drums)],
                                  env=env, capture_output=True, text=True, check=False)  # fmt: skip
            if done.returncode != 0:
                sys.exit(f"profile_cycles: the {method} runs failed: "
                         f"{(done.stderr.strip().splitlines() or ['?'])[-1]}")  # fmt: skip
            out = done.stdout.split("COMPILED", 1)[1].splitlines()
            print(f"\n{method}" + (f", {drums} drums:" if drums else ":"))
            _table([line for line in out if line.startswith("CYCLES")], parts)


if __name__ == "__main__":
    main()
