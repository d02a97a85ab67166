"""What the robustness rule's solver check costs against the ensemble's members: every cell of
a config's grid run as the rule runs it (member 0, the other members, the check's runs), in
one process, the CPU time of each kind of run summed (time.process_time). The ratio holds when
the machine's speed drifts, since the kinds are interleaved cell by cell.

    python tools/check_cost.py configs/ci/harmonic_multidrum_ci.yaml [--members 16]
"""

from __future__ import annotations

import argparse
import time

from rbm_cli.config.load import load_config
from rbm_cli.models.registry import make_runner
from rbm_cli.study.cells import grid_cells, grid_points, tasks
from rbm_cli.study.robustness import check_config, member_config, members, solver_checks
from rbm_cli.study.simulate import simulate


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("config")
    parser.add_argument("--members", type=int, default=16)
    args = parser.parse_args()
    config = load_config(args.config)
    chunks = tasks(config, grid_points(config), grid_cells(config), 1)
    cpu = {"member 0": 0.0, "other members": 0.0}
    n_cells = 0
    for point, cells in chunks:
        runner = make_runner(point)
        checks = [check_config(point, s) for s in solver_checks(point)]
        for c in [point, *checks]:  # compiled code loaded before timing
            simulate(c, *cells[0][:2], runner=runner)
        for a, f, _ in cells:
            n_cells += 1
            t = time.process_time()
            simulate(point, a, f, runner=runner)
            cpu["member 0"] += time.process_time() - t
            for m in members(args.members)[1:]:
                t = time.process_time()
                simulate(*member_config(point, a, m), f, runner=runner)
                cpu["other members"] += time.process_time() - t
            for c in checks:
                key = f"check {c.solver.method} rtol {c.solver.rtol:g}"
                t = time.process_time()
                simulate(c, a, f, runner=runner)
                cpu[key] = cpu.get(key, 0.0) + time.process_time() - t
    ensemble = cpu["member 0"] + cpu["other members"]
    print(f"{args.config}: {n_cells} cells, {args.members} members")
    for key, value in cpu.items():
        print(f"  {key:32s} {value:8.1f} s CPU  ({value / ensemble:6.1%} of the ensemble)")
    check = sum(v for k, v in cpu.items() if k.startswith("check"))
    print(f"  solver check in all             {check:8.1f} s CPU  ({check / ensemble:6.1%})")


if __name__ == "__main__":
    main()
