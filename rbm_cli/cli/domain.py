"""Domain commands of the CLI: sweep, plot-domain, compare (over study.sweep, study.domain)."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from rbm_cli.base.errors import RbmError
from rbm_cli.cli.common import (
    Interrupted,
    UserError,
    cli,
    compile_notice,
    config_argument,
    load,
    one_line,
    output_option,
)


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
    help="Allow grids of more than 100,000 cells; set aside (to superseded/, never deleted) "
    "an unfinished journal or another config's result in the folder, and start again.",
)
@click.option(
    "--ensemble",
    type=click.IntRange(min=1),
    default=1,
    show_default=True,
    metavar="K",
    help="Run each cell K times, phase and amplitude perturbed by up to 1e-6 (rad, "
    "relative), and add the collapse_fraction column: which cells are robust.",
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

    Writes OUTPUT/<name>/domain.csv (one row per cell, SPEC section 5),
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
    from rbm_cli.api import SweepInterrupted, run_sweep
    from rbm_cli.cli.progress import Progress

    cfg = load(config)
    if scheduler and backend != "dask":
        raise UserError("--scheduler needs --backend dask")
    if not quiet:
        compile_notice(cfg)
    reporter = None if quiet else Progress(cfg.name)
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
            progress=reporter,
            ensemble=ensemble,
            notify=note,
            resume_command=command,
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
    """Where the cells ran: a sweep starts a pool only when it pays (issue 18)."""
    if summary.workers == 0:
        return "in this process"
    n = jobs if summary.workers is None else summary.workers
    return f"on {n} worker" + ("s" if n != 1 else "")


def _print_sweep_summary(summary, jobs: int) -> None:
    """What a finished `rbm sweep` says on stdout (failed cells: a warning on stderr)."""
    from rbm_cli.cli.progress import duration

    if summary.already_finished:
        click.echo(
            f"{summary.folder} is already finished ({summary.n_cells} cells: domain.csv,"
            " boundary.csv, domain.png, meta.json): nothing to resume"
        )
        return
    compiled = (
        f" (+ {duration(summary.compile_s)} loading the integrator)"
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
    import shlex

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


@cli.command("plot-domain")
@click.argument("domain_csv", metavar="DOMAIN.csv", type=str)
@click.option(
    "-o",
    "--output",
    "png",
    default=None,
    help="PNG to write; default: domain.png beside DOMAIN.csv.",
)
@click.option(
    "--compare",
    "others",
    multiple=True,
    metavar="OTHER.csv",
    help="Another domain whose boundary is overlaid (repeatable).",
)
@click.option(
    "--config",
    "config_path",
    default=None,
    help="Config of the domain (for the static multiplier and closed forms); "
    "default: the meta.json beside DOMAIN.csv if any.",
)
@click.option(
    "--dimensionless",
    is_flag=True,
    help="Axes omega/p (x) and A/(g tan alpha) (y), in which geometrically similar "
    "columns of every size share one boundary.",
)
@click.option(
    "--panels",
    is_flag=True,
    help="A domain over more axes: one panel per point of the others (the default).",
)
@click.option(
    "--overlay",
    is_flag=True,
    help="A domain over more axes: one axes, each point's boundary as a line of its own.",
)
def plot_domain_cmd(
    domain_csv: str,
    png: str | None,
    others: tuple[str, ...],
    config_path: str | None,
    dimensionless: bool,
    panels: bool,
    overlay: bool,
) -> None:
    """Draw a safe-unsafe domain: safe (o) and unsafe (x) cells, the boundary,
    the static multiplier and, for rigid monolithic half-sine studies, Housner's
    and the exact linear closed-form curves; other domains overlaid.

    A domain over axes beside amplitude and frequency (a grid over config keys) is
    drawn as one panel per point (--panels), or as one axes with each point's boundary
    (--overlay); with one frequency, the innermost axis goes on x instead of the
    frequency. --dimensionless draws any domain in omega/p and A/(g tan alpha).

    \b
    Example:
        rbm plot-domain out/spanos_koh_slender/domain.csv -o slender.png
        rbm plot-domain out/a/domain.csv --compare results/a/domain.csv
        rbm plot-domain out/size_effect/domain.csv --dimensionless --overlay
    """
    from matplotlib.backend_bases import FigureCanvasBase

    from rbm_cli.base.files import save_figure_atomic
    from rbm_cli.report.domain_figure import domain_figure
    from rbm_cli.study.domain import read_domain

    if png is not None and not png.strip():
        raise UserError("--output must name an image file (e.g. domain.png), got ''")
    if panels and overlay:
        raise UserError("--panels and --overlay exclude each other: give one")
    layout = "panels" if panels else "overlay" if overlay else "auto"
    try:
        df = read_domain(domain_csv)
        dfs = [read_domain(p) for p in others]
        cfg = _config_for(domain_csv, config_path)
        target = Path(png) if png else Path(domain_csv).with_name("domain.png")
        kinds = FigureCanvasBase.get_supported_filetypes()
        if target.suffix and target.suffix.lstrip(".").lower() not in kinds:
            raise UserError(
                f"--output {target}: unknown image type {target.suffix!r}"
                f" (allowed: {', '.join(sorted(kinds))})"
            )
        labels = [Path(domain_csv).parent.name or "domain"] + [Path(p).parent.name for p in others]
        configs = [_config_for(p, None) for p in others] if dimensionless else None
        fig = domain_figure(df, cfg, compare=dfs, labels=labels, dimensionless=dimensionless,
                            layout=layout, compare_configs=configs, where=domain_csv)  # fmt: skip
        save_figure_atomic(fig, target)
    except RbmError as exc:
        raise UserError("--" + one_line(exc) if _names_a_layout(exc) else one_line(exc)) from None
    except OSError as exc:
        raise UserError(f"cannot write {png}: {exc.strerror or exc}") from None
    click.echo(f"wrote {target}")


def _names_a_layout(exc: RbmError) -> bool:
    """The message starts with the layout refused (panels/overlay): the CLI names the flag."""
    return str(exc).startswith(("panels", "overlay"))


def _config_for(domain_csv: str, config_path: str | None):
    """The config of a domain: given, or the one stored in meta.json beside it (as the
    user wrote it); None when neither is there (the plot then lacks the curves that
    need the column)."""
    from rbm_cli.study.domain import domain_config

    if config_path:
        return load(config_path)
    try:
        return domain_config(domain_csv)
    except RbmError as exc:
        raise UserError(f"the config stored beside {domain_csv}: {one_line(exc)}") from None


def _print_shifts(shifts) -> None:
    """The boundary shifts, one line per frequency (and point of any axes over config
    keys, whose columns come first)."""
    from rbm_cli.study.domain import axis_columns

    axes = axis_columns(shifts.columns)
    head = "".join(f"{p:>22} " for p in axes)
    click.echo(f"{head}{'frequency [Hz]':>15} {'A [g]':>8} {'B [g]':>8} {'shift [g]':>10}")
    for _, r in shifts.iterrows():
        point = "".join(f"{str(r[p]):>22} " for p in axes)
        click.echo(
            f"{point}{r.frequency_hz:>15.6g} {r.boundary_a_g:>8.4g} {r.boundary_b_g:>8.4g} "
            f"{r.shift_g:>+10.4g}"
        )


@cli.command()
@click.argument("a_csv", metavar="A.csv", type=str)
@click.argument("b_csv", metavar="B.csv", type=str)
@click.option(
    "--max-cells",
    type=float,
    default=None,
    metavar="FRACTION",
    help="Fail if more than this fraction of common cells differ (e.g. 0.01).",
)
@click.option(
    "--max-shift",
    type=float,
    default=None,
    metavar="G",
    help="Fail if the boundary moves by more than this at any frequency [g].",
)
def compare(a_csv: str, b_csv: str, max_cells: float | None, max_shift: float | None) -> None:
    """Compare two domains: cells that differ and the boundary shift per frequency.

    Exit status 0 when within the limits, 1 beyond either, 2 on bad input. A
    frequency where a domain has no collapsed cell has its boundary one grid step
    above its highest amplitude. When A is a stored ensemble domain (it has a
    `robust` column), the regression rule applies too (the check CI uses): exit 1
    if a robust cell differs, or if B is an ensemble with more sensitive cells
    than the stated bound; sensitive cells are reported, not scored.

    \b
    Example:
        rbm compare results/spanos_koh_slender/domain.csv out/spanos_koh_slender/domain.csv \\
            --max-cells 0.01 --max-shift 0.05
    """
    from rbm_cli.study.domain import compare as compare_domains
    from rbm_cli.study.domain import read_domain

    for name, value in (("--max-cells", max_cells), ("--max-shift", max_shift)):
        if value is not None and not value >= 0:
            raise UserError(f"{name} must be >= 0, got {value:g}")
    try:
        dom_a, dom_b = read_domain(a_csv), read_domain(b_csv)
        cmp = compare_domains(dom_a, dom_b)
    except RbmError as exc:
        raise UserError(one_line(exc)) from None
    if cmp.n_common == 0:
        raise UserError("the two domains have no cell in common")
    if cmp.only_a or cmp.only_b:  # an incomplete domain is not "OK" (issue 14)
        first = cmp.first_missing
        raise UserError(
            f"the domains do not cover the same cells: {cmp.only_a} only in {a_csv}, "
            f"{cmp.only_b} only in {b_csv} (first: {first[0]} g, {first[1] or 'no'} Hz"
            f"{''.join(', ' + v for v in first[2:])}); compare "
            "complete domains of the same grid"
        )
    click.echo(
        f"cells: {cmp.n_common} in common, {cmp.n_differ} differ "
        f"({100 * cmp.fraction:.3g} %); only in A: {cmp.only_a}, only in B: {cmp.only_b}"
    )
    click.echo(f"largest boundary shift: {cmp.max_shift_g:.4g} g")
    _print_shifts(cmp.shifts)
    failed = []
    if "robust" in dom_a.columns:
        from rbm_cli.study.regression import check

        rule = check(dom_a, dom_b)
        click.echo(f"regression rule: {rule.summary()}")
        if not rule.ok:
            failed.append("the regression rule fails (robust cells must not differ)")
    if max_cells is not None and cmp.fraction > max_cells:
        failed.append(f"{cmp.fraction:.4g} of cells differ (limit {max_cells:g})")
    if max_shift is not None and cmp.max_shift_g > max_shift:
        failed.append(f"boundary shift {cmp.max_shift_g:.4g} g (limit {max_shift:g} g)")
    if failed:
        click.echo("FAIL: " + "; ".join(failed), err=True)
        sys.exit(1)
    if max_cells is not None or max_shift is not None or "robust" in dom_a.columns:
        click.echo("OK: within the limits")
