"""`rbm bench`: the work-precision benchmark (thin, over rbm_cli.api.bench)."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from rbm_cli.api.errors import RbmError
from rbm_cli.cli.common import UserError, check_output, cli, one_line


@cli.command()
@click.option("--quick", is_flag=True,
              help="Default method on 10 x 10 sub-grids against the stored references; "
              "exit 1 if it misses an accuracy target.")  # fmt: skip
@click.option("-o", "--output", default="bench", show_default=True, metavar="DIR",
              callback=check_output,
              help="Folder for bench.csv and bench.png.")  # fmt: skip
@click.option("-j", "--jobs", type=click.IntRange(min=1), default=2, show_default=True,
              help="Parallel workers.")  # fmt: skip
@click.option("--problem", "problems", multiple=True,
              type=click.Choice(["slender", "tapered", "multidrum", "halfsine"]),
              help="Run only these problems (repeatable). Default: all.")  # fmt: skip
@click.option("--references", default=None, metavar="DIR",
              help="Folder of the stored references [default: results/bench].")  # fmt: skip
@click.option("--scaling", is_flag=True,
              help="Also measure time per run against drums, K_M and duration, and the "
              "speed-up of 2 workers over 1 (scaling.csv, scaling.png).")  # fmt: skip
@click.option("--reuse-references", is_flag=True,
              help="Full run: keep the stored references instead of re-making them.")  # fmt: skip
@click.option("--pair", is_flag=True,
              help="Whole grids, two methods only: the default step kernel and the exact "
              "integrator (and the baseline's sample).")  # fmt: skip
def bench(quick, output, jobs, problems, references, scaling, reuse_references, pair) -> None:
    """Measure run time against error for every method and tolerance rbm offers.

    Problems: the rigid Spanos-Koh slender block, the tapered monolithic column
    with finite K_M, the 8-drum column and a half-sine domain, 40 x 40 cells
    each. References: the closed form (rigid monolithic) or converged runs at
    rtol 1e-10/1e-11/1e-12 (sensitive cells are counted, not scored). The
    baseline is scipy solve_ivp (RK45, rtol 1e-6) on a sample of cells. Both
    methods run every problem: the step kernel (DOP853) and the exact
    integrator (solver.method exact), with their agreement on the same cells.

    \b
    Example:
        rbm bench --quick
        rbm bench --pair --reuse-references --problem multidrum
        rbm bench -o bench --scaling
    """
    # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
    from rbm_cli.api.bench import (
        check_targets,
        run_bench,
        run_scaling,
        save_figure,
        scaling_figure,
        work_precision_figure,
    )

    def log(line: str) -> None:
        click.echo(line)
        sys.stdout.flush()  # progress shows when stdout is a file

    try:
        table = run_bench(quick=quick, jobs=jobs, output=output, reference_dir=references,
                          problems=tuple(problems) or None, reuse_references=reuse_references,
                          pair=pair, log=log)  # fmt: skip
        save_figure(work_precision_figure(table), Path(output) / "bench.png")
        if scaling:
            scaling_table = run_scaling(output=output, log=log)
            save_figure(scaling_figure(scaling_table), Path(output) / "scaling.png")
    except RbmError as exc:
        raise UserError(one_line(exc)) from None
    click.echo(f"output: {output}/bench.csv, {output}/bench.png")
    fails = check_targets(table)
    for f in fails:
        click.echo(f"target missed: {f}", err=True)
    if fails:
        raise SystemExit(1)
    click.echo("accuracy targets of the default method: met")
