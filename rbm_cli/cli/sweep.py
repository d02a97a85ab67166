"""`rbm sweep`: a config's grid into a safe-unsafe domain (over rbm_cli.api.run_sweep)."""

from __future__ import annotations

import contextlib
import shlex

import click

from rbm_cli.api.errors import RbmError
from rbm_cli.cli.common import (
    Interrupted,
    UserError,
    cli,
    config_argument,
    load,
    one_line,
    output_option,
    work_starts,
)
from rbm_cli.cli.progress import Progress, duration


@cli.command()
@config_argument
@output_option
@click.option(
    "-j", "--jobs", type=int, default=2, show_default=True, help="Parallel workers (joblib)."
)
@click.option(
    "--backend",
    type=click.Choice(["loky", "threading", "sequential", "dask"]),
    default="loky",
    show_default=True,
    help="joblib backend; 'dask' runs on a Dask distributed cluster (see --scheduler).",
)
@click.option(
    "--scheduler",
    default=None,
    metavar="ADDRESS",
    help="Dask scheduler address (tcp://host:8786) for --backend dask; "
    "default: a local in-process cluster.",
)
@click.option(
    "--resume",
    is_flag=True,
    help="Finish an interrupted sweep of the same config (on a finished folder: nothing to do).",
)
@click.option(
    "--force",
    is_flag=True,
    help="Allow grids of more than 100,000 runs (cells x --ensemble; at most 1,000,000); "
    "set aside (to superseded/, never deleted) an unfinished journal or another config's "
    "result in the folder, and start again.",
)
@click.option(
    "--ensemble",
    type=click.IntRange(min=1),
    default=1,
    show_default=True,
    metavar="K",
    help="Run each cell K times, phase and amplitude perturbed by up to 1e-6 (rad, "
    "relative), and add the collapse_fraction column: which cells are robust. The runs "
    "(cells x K) count against the grid's limits (see --force).",
)
@click.option("-q", "--quiet", is_flag=True, help="No progress output and no notes.")
def sweep(
    config: str,
    output: str,
    jobs: int,
    backend: str,
    scheduler: str | None,
    resume: bool,
    force: bool,
    ensemble: int,
    quiet: bool,
) -> None:
    """Run the config's amplitude x frequency grid and write the safe-unsafe domain.

    Writes OUTPUT/<name>/domain.csv (one row per cell, its columns listed in the
    docs' Output files page),
    boundary.csv (lowest unsafe amplitude per frequency), meta.json (resolved
    config, versions, wall time, workers) and domain.png, all published in one
    step at the end. One sweep at a time writes a folder (a second one is
    refused). While it runs, finished cells go to a journal
    (domain.partial.jsonl): an interrupted or killed sweep keeps them and leaves
    nothing that looks complete, and --resume finishes it without redoing them.
    A folder with an unfinished journal is never started over without --resume or
    --force. Progress goes to stderr: a bar on a terminal, otherwise a line at
    most every 10 s. Ctrl-C says how many cells are kept and how to resume.
    Cells that fail numerically are recorded with status 'failed'; the sweep goes on.

    \b
    Example:
        rbm sweep configs/spanos_koh_slender.yaml
        rbm sweep configs/harmonic_multidrum.yaml -o out --jobs 2 --resume
        rbm sweep configs/harmonic_multidrum.yaml --backend dask --scheduler tcp://10.0.0.5:8786
    """
    cfg = load(config)
    if scheduler and backend != "dask":
        raise UserError("--scheduler needs --backend dask")
    # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
    from rbm_cli.api.sweeps import FigureProcess

    # before numba and matplotlib are imported: the child imports the figure's while
    # this process runs the cells (a shorter wall time)
    with FigureProcess.start() or contextlib.nullcontext() as painter:
        _sweep(cfg, config, output, jobs, backend, scheduler, resume, force, ensemble, quiet,
               painter)  # fmt: skip


def _sweep(cfg, config, output, jobs, backend, scheduler, resume, force, ensemble, quiet,
           painter) -> None:  # fmt: skip
    """The body of `rbm sweep` once the config is loaded (painter: the FigureProcess that
    draws domain.png, or None to draw it in this process)."""
    # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
    from rbm_cli.api.sweeps import SweepInterrupted, run_sweep

    reporter = None if quiet else Progress(cfg.name)

    def progress(done: int, total: int) -> None:  # first called once the kernel is loaded
        work_starts()
        if reporter is not None:
            reporter(done, total)

    command = _resume_command(config, output, jobs, backend, scheduler, ensemble, force)

    def note(text: str) -> None:
        if reporter is not None:
            reporter.close()
        click.echo(f"note: {text}", err=True)

    try:
        summary = run_sweep(
            cfg,
            output=output,
            jobs=jobs,
            backend=backend,
            scheduler=scheduler,
            resume=resume,
            force=force,
            progress=progress,
            ensemble=ensemble,
            notify=note,
            resume_command=command,
            figure_process=painter,
        )
    except RbmError as exc:
        raise UserError(one_line(exc)) from None
    except SweepInterrupted as exc:
        raise Interrupted(one_line(exc)) from None
    finally:
        if reporter is not None:
            reporter.close()
    _print_sweep_summary(summary, jobs)


def _where(summary, jobs: int) -> str:
    """Where the cells ran: a sweep starts a pool only when it pays."""
    if summary.workers == 0:
        return "in this process"
    n = jobs if summary.workers is None else summary.workers
    return f"on {n} worker" + ("s" if n != 1 else "")


def _print_sweep_summary(summary, jobs: int) -> None:
    """What a finished `rbm sweep` says on stdout (failed cells: a warning on stderr)."""
    if summary.already_finished:
        click.echo(
            f"{summary.folder} is already finished ({summary.n_cells} cells: domain.csv,"
            " boundary.csv, domain.png, meta.json): nothing to resume"
        )
        return
    compiled = (
        f" (+ {duration(summary.compile_s)} {summary.compile_what or 'loading the integrator'})"
        if (summary.compile_s >= 1.0)
        else ""
    )
    click.echo(
        f"{summary.n_cells} cells ({summary.n_run} run, {summary.n_resumed} resumed): "
        f"{summary.n_collapsed} collapsed, {summary.n_survived} survived, "
        f"{summary.n_failed} failed in {summary.wall_time_s:.3g} s {_where(summary, jobs)}"
        f"{compiled}"
    )
    click.echo(f"output: {summary.folder}")
    if summary.n_failed:
        click.echo(f"warning: {summary.n_failed} cell(s) failed; see their message", err=True)


def _resume_command(config, output, jobs, backend, scheduler, ensemble, force) -> str:
    """The exact command that resumes this sweep (quoted for a POSIX shell)."""
    words = ["rbm", "sweep", config, "-o", output]
    if jobs != 2:
        words += ["--jobs", str(jobs)]
    if backend != "loky":
        words += ["--backend", backend]
    if scheduler:
        words += ["--scheduler", scheduler]
    if ensemble != 1:
        words += ["--ensemble", str(ensemble)]
    if force:
        words.append("--force")
    return " ".join(shlex.quote(w) for w in words + ["--resume"])
