"""`rbm sensitivity`: which uncertain key moves a domain's outcome most (thin, over
rbm_cli.api.uncertain)."""

from __future__ import annotations

import math

import click

from rbm_cli.api.errors import RbmError
from rbm_cli.cli.common import UserError, check_output, cli, one_line


@cli.command()
@click.argument("domain", metavar="DOMAIN.csv", type=str)
@click.option("-o", "--output", default=None, metavar="DIR", callback=check_output,
              help="Folder for the files  [default: the domain's folder]")  # fmt: skip
def sensitivity(domain: str, output: str | None) -> None:
    """Rank the uncertain keys of a domain by how much they move its outcome.

    DOMAIN.csv is the domain.csv of a sweep of a config with an uncertain section (a
    row per cell and sample). Per key, for the peak rotation ratio and for collapse:
    Spearman's rank correlation and the partial rank correlation coefficient (PRCC:
    the ranks of the key and of the outcome cleared of the amplitude, the frequency,
    the grid's axes and the other keys), with p-values. Failed runs are left out.

    Writes sensitivity.csv and sensitivity.png (a tornado per outcome, the key that
    moves the peak rotation ratio most on top).

    \b
    Example:
        rbm sensitivity out/block/domain.csv
        rbm sensitivity out/block/domain.csv -o out/block_sensitivity
    """
    # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
    from rbm_cli.api.uncertain import write_sensitivity

    try:
        table, paths = write_sensitivity(domain, output)
    except RbmError as exc:
        raise UserError(one_line(exc)) from None
    for outcome, rows in table.groupby("outcome", sort=False):
        click.echo(f"{outcome}:")
        for row in rows.itertuples():
            prcc = "n/a" if math.isnan(row.prcc) else f"{row.prcc:+.3f} (p {row.prcc_p:.2g})"
            rho = "n/a" if math.isnan(row.spearman) else f"{row.spearman:+.3f}"
            click.echo(f"  {row.key}: PRCC {prcc}, Spearman {rho}, runs {row.n_runs}")
    click.echo(f"output: {paths[0].parent}/ " + ", ".join(p.name for p in paths))
