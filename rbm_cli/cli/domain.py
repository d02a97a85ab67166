"""Domain commands of the CLI: plot-domain, compare (over study.domain; `rbm sweep` is in
rbm_cli.cli.sweep)."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from rbm_cli.api.errors import RbmError
from rbm_cli.cli.common import UserError, cli, load, one_line


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
    A domain over excitation.angle (housner-3d, rbm-3d) is drawn in polar axes: per
    angle [deg], the lowest collapsed and the highest survived amplitude below it [g] as
    radii, one curve per frequency (and point of other axes); --panels, --overlay or
    --dimensionless lay it out as above instead.

    \b
    Example:
        rbm plot-domain out/spanos_koh_slender/domain.csv -o slender.png
        rbm plot-domain out/a/domain.csv --compare results/a/domain.csv
        rbm plot-domain out/size_effect/domain.csv --dimensionless --overlay
        rbm plot-domain out/polar/domain.csv -o polar.png
    """
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.backend_bases import FigureCanvasBase

    # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
    from rbm_cli.api.domains import draw_domain, read_domain, save_figure

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
        fig = draw_domain(df, cfg, compare=dfs, labels=labels, dimensionless=dimensionless,
                            layout=layout, compare_configs=configs, where=domain_csv)  # fmt: skip
        save_figure(fig, target)
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
    # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
    from rbm_cli.api.domains import domain_config

    if config_path:
        return load(config_path)
    try:
        return domain_config(domain_csv)
    except RbmError as exc:
        raise UserError(f"the config stored beside {domain_csv}: {one_line(exc)}") from None


def _print_shifts(shifts) -> None:
    """The boundary shifts, one line per frequency (and point of any axes over config
    keys, whose columns come first)."""
    # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
    from rbm_cli.api.domains import axis_columns

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
    # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
    from rbm_cli.api.domains import compare_domains, has_robustness, read_domain

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
    if cmp.only_a or cmp.only_b:  # an incomplete domain is not "OK"
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
    robust = has_robustness(dom_a)
    if robust:
        # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
        from rbm_cli.api.domains import check_regression

        rule = check_regression(dom_a, dom_b)
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
    if max_cells is not None or max_shift is not None or robust:
        click.echo("OK: within the limits")


@cli.command("migrate")
@click.argument("folders", metavar="FOLDER...", nargs=-1, required=True, type=str)
def migrate_cmd(folders: tuple[str, ...]) -> None:
    """Bring domains stored by an earlier rbm to this version's config hash.

    Each FOLDER holds a finished domain (meta.json, domain.csv). Its meta.json gets this
    version's hash and schema once rbm has checked that the domain was made by the config
    this version reads from it (the same settings, no cell that ran out of a budget, the
    method this version runs); its rows and figures, those of the rbm that made them, are
    not touched (rbm compare judges them against this version's). A folder that does not
    pass is left as it is, named in one line (re-make it), and the exit status is 2.

    \b
    Example:
        rbm migrate results/*/
        rbm migrate old_results/slender old_results/thick
    """
    # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
    from rbm_cli.api import migrate

    refused = []
    for folder in folders:
        try:
            click.echo(migrate(folder))
        except RbmError as exc:
            refused.append(one_line(exc))
    if refused:
        for line in refused[:-1]:
            click.echo(f"Error: {line}", err=True)
        raise UserError(refused[-1])
