"""`rbm fragility`: fragility curve and IDA of a record-suite domain (thin, over
rbm_cli.api.fragility_curves)."""

from __future__ import annotations

import math
import time

import click

from rbm_cli.api.errors import RbmError
from rbm_cli.cli.common import Interrupted, UserError, check_output, cli, one_line
from rbm_cli.cli.progress import Progress, duration

#: Most --resamples (rbm_cli.api.fragility_curves.MAX_RESAMPLES, which refuses more; written
#: here so that `rbm --help` does not import the fit).
MAX_RESAMPLES_SHOWN = "100,000"
#: Seconds of bootstrap before its progress is shown (a short one says nothing).
PROGRESS_AFTER_S = 2.0


class MeasureOption(click.Option):
    """--intensity, whose help lists the measures of the registry of intensity measures
    (rbm_cli.api.fragility_curves.intensity_help), read when the help is shown."""

    @property
    def help(self) -> str:
        # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
        from rbm_cli.api.fragility_curves import intensity_help

        return intensity_help()

    @help.setter
    def help(self, value) -> None:  # click sets it from the decorator: none given
        pass


@cli.command()
@click.argument("domain", metavar="DOMAIN.csv", type=str)
@click.option("-o", "--output", default=None, metavar="DIR", callback=check_output,
              help="Folder for the files  [default: the domain's folder]")  # fmt: skip
@click.option("--resamples", type=click.IntRange(min=0), default=500, show_default=True,
              help="Bootstrap resamples of the records (0: no band, no intervals; at most "
              f"{MAX_RESAMPLES_SHOWN}, a few minutes).")  # fmt: skip
@click.option("--seed", type=click.IntRange(min=0, max=2**64 - 1), default=0, show_default=True,
              help="Seed of the bootstrap (0 to 2^64 - 1).")  # fmt: skip
@click.option("--intensity", "--intensity-column", "intensity_column", default=None,
              metavar="NAME", cls=MeasureOption)  # fmt: skip
@click.option("--ensemble-outcome", type=click.Choice(["members", "majority", "member0"]),
              default="members", show_default=True,
              help="An ensemble domain's trials: every member of each cell (all the runs "
              "the sweep made), each cell's majority, or its member 0's run.")  # fmt: skip
@click.option("--ci", nargs=2, type=float, default=(5.0, 95.0), show_default=True,
              metavar="LOW HIGH",
              help="Percentiles of the bootstrap intervals and band.")  # fmt: skip
@click.option("--compare", "others", multiple=True, metavar="OTHER.csv",
              help="Another record-suite domain whose fragility is drawn in fragility.png "
              "beside this one (repeatable; its own files are not written).")  # fmt: skip
@click.option("--damage-states", "damage_states", default=None, metavar="T1,T2,...",
              help="Thresholds of max_rotation_ratio (0 < t <= 1, increasing; 1 is "
              "collapse): a fragility curve per damage state, in fragility_states.csv and "
              "fragility_states.png, marked in ida.png.")  # fmt: skip
@click.option("--residual-states", "residual_states", default=None, metavar="S1,S2,...",
              help="Thresholds of residual_slip_m in metres (> 0, increasing), a domain of "
              "the contact engine (model bullet): a fragility curve per residual state, in "
              "fragility_residual.csv and fragility_residual.png.")  # fmt: skip
@click.option("--compare-intensities", is_flag=True, default=False,
              help="Also fit the suite on every intensity measure the domain carries and "
              "rank them by dispersion beta (fragility_intensities.csv).")  # fmt: skip
@click.option("--by", "by", default=None, metavar="KEY",
              help="A domain over samples of uncertain keys: a curve per tercile of KEY's "
              "sampled values (fragility_by.png, fragility_by.csv).")  # fmt: skip
def fragility(domain, output, resamples, seed, intensity_column, ensemble_outcome, ci,
              others, damage_states, residual_states, compare_intensities,
              by) -> None:  # fmt: skip
    """Fit a lognormal fragility curve to a record-suite domain and draw its IDA.

    DOMAIN.csv is the domain.csv of a sweep over records x intensities (one row
    per record and intensity, with its record's name). Per intensity: records,
    collapses and the fraction; the lognormal fragility P = Phi(ln(x/median)/beta)
    fitted by maximum likelihood on the per-record outcomes (Baker 2015), with a
    bootstrap over records for the intervals and the band (it needs 2 records or
    more; progress on stderr when it takes more than a few seconds). Failed runs
    are left out and counted, per intensity in fragility.json, with a warning
    when they gather at the high intensities. A curve needs runs at 2
    intensities or more. --intensity fits on a record's intensity measure
    instead of the amplitude. An ensemble domain (rbm sweep --ensemble) counts
    every member of a cell as a trial, or its majority (--ensemble-outcome).
    A domain over samples of uncertain keys (the config's uncertain section) fits
    every run of every sample, and splits the dispersion into the records'
    (beta_RTR) and the keys' (beta_U); --by KEY draws a curve per tercile of a key.

    --damage-states fits a curve per threshold of the peak rotation ratio (a run
    exceeds a state when its max_rotation_ratio reaches the threshold or it
    collapsed), each as the plain fit of its own outcomes; curves that cross
    within the intensities tested are reported, not adjusted.
    --residual-states does the same with thresholds of the residual slip [m]
    that the contact engine (model bullet) writes to domain.csv: a run exceeds
    a state when its residual_slip_m reaches the threshold or it collapsed.
    --compare-intensities fits the same runs on every intensity measure the
    domain carries and ranks them by beta (lower: more efficient).

    Writes fragility.csv, fragility_curve.csv, fragility.json, fragility.png and
    ida.png (intensity against peak rotation ratio, a curve per record, flat from
    its first collapse, the records named), all moved into place together at the
    end: a Ctrl-C or a kill leaves the old set or the new one, never a mix. One
    run writes a folder at a time.

    \b
    Example:
        rbm fragility out/suite/domain.csv
        rbm fragility out/suite/domain.csv -o out/suite_fragility --resamples 2000
        rbm fragility out/suite/domain.csv --damage-states 0.1,0.3,1.0
        rbm fragility out/suite_bullet/domain.csv --residual-states 0.005,0.02,0.05
        rbm fragility out/suite/domain.csv --compare-intensities -o /tmp/ims
        rbm fragility results/suite_multidrum/domain.csv \
            --compare results/suite_monolithic/domain.csv -o docs/figures/suite
    """
    # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
    from rbm_cli.api.fragility_curves import (
        MAX_RESAMPLES,
        check_intensity,
        damage_states_of,
        residual_states_of,
        run_fragility,
    )

    try:
        check_intensity(intensity_column, "--intensity")
        thresholds = damage_states_of(damage_states, "--damage-states")
        slips = residual_states_of(residual_states, "--residual-states")
    except RbmError as exc:
        raise UserError(one_line(exc)) from None
    if resamples > MAX_RESAMPLES:
        raise UserError(
            f"--resamples must be at most {MAX_RESAMPLES:,} (each is a refit), got {resamples:,}"
        )
    progress = _BootstrapProgress("bootstrap")
    try:
        made = run_fragility(domain, output, n_resamples=resamples, seed=seed,
                             intensity_column=intensity_column, ci_percentiles=tuple(ci),
                             compare=others, progress=progress,
                             ensemble_outcome=ensemble_outcome, damage_states=thresholds,
                             compare_intensities=compare_intensities, by=by,
                             residual_states=slips)  # fmt: skip
    except RbmError as exc:
        raise UserError(one_line(exc)) from None
    except KeyboardInterrupt:
        raise Interrupted(
            "interrupted (Ctrl-C): the fragility files are as they were, or all new if it "
            "came as they were moved into place"
        ) from None
    finally:
        progress.close()
    res = made.result
    click.echo(f"records: {res.n_records}, runs: {res.n_runs} (failed, left out: "
               f"{res.n_failed}), intensities: {len(res.table)}")  # fmt: skip
    click.echo(f"intensity: {res.intensity_column} [{res.intensity_unit}]; trials: {res.outcome}")
    if res.warning:
        click.echo(f"warning: {res.warning}")
    if res.fit is None:
        click.echo(f"no fit: {res.note}")
    else:
        median, beta = _fit_texts(res)
        click.echo(f"median {median}, dispersion beta {beta}")
        if res.note:
            click.echo(f"note: {res.note}")
        if res.fit_warning:
            click.echo(f"warning: {res.fit_warning}")
        if res.resamples_note:
            click.echo(f"note: {res.resamples_note}")
    if res.dispersion is not None:
        click.echo(_dispersion(res.dispersion))
    for states in (made.states, made.residual):
        if states is not None:
            _echo_states(states)
    if made.intensities is not None:
        _echo_intensities(made.intensities)
    folder = made.paths[0].parent
    click.echo(f"output: {folder}/ " + ", ".join(p.name for p in made.paths))


def _echo_states(states) -> None:
    """One line per damage or residual state (median, beta and their intervals), then the
    crossings."""
    measure = states.measure
    click.echo(f"{measure.name} ({measure.column}, {states.intensity_column}):")
    unit = f" {measure.unit}" if measure.unit != "-" else ""
    for t, res in zip(states.thresholds, states.results, strict=True):
        if res.fit is None:
            click.echo(f"  {t:g}{unit}: no fit: {res.note}")
            continue
        median, beta = _fit_texts(res)
        click.echo(f"  {t:g}{unit}: median {median}, beta {beta}")
        if res.fit_warning:
            click.echo(f"    warning: {res.fit_warning}")
    for line in states.crossings:
        click.echo(f"warning: {line}")
    if states.note:
        click.echo(f"note: {states.note}")


def _echo_intensities(comparison) -> None:
    """The intensity measures ranked by beta, a line each, then the best."""
    click.echo("intensity measures by dispersion beta (lower: more efficient):")
    for _, row in comparison.table.iterrows():
        rank = f"{row['rank']:.0f}" if math.isfinite(row["rank"]) else "-"
        if math.isfinite(row["beta"]):
            ci = ""
            if math.isfinite(row["beta_ci_low"]):
                ci = f" ({row['beta_ci_low']:.3g}-{row['beta_ci_high']:.3g})"
            median = f"median {row['median']:.4g} {row['unit']}"
            click.echo(f"  {rank:>2} {row['intensity_column']:<24} beta {row['beta']:.3f}{ci}"
                       f", {median}")  # fmt: skip
        else:
            click.echo(f"  {rank:>2} {row['intensity_column']:<24} {row['note']}")
    click.echo(comparison.statement)


def _dispersion(split) -> str:
    """The records' and the uncertain keys' dispersion, one line."""

    def shown(x: float) -> str:
        return "n/a" if not math.isfinite(x) else f"{x:.3g}"

    return (
        f"dispersion over {split.n_samples} samples ({split.n_fitted} fitted alone):"
        f" beta_RTR {shown(split.beta_rtr)}, beta_U {shown(split.beta_u)}, total"
        f" sqrt(RTR^2 + U^2) {shown(split.beta_total)} (one fit of every run:"
        f" {shown(split.beta_pooled)})"
    )


def _fit_texts(res) -> tuple[str, str]:
    """A fit's median (in the intensity's unit) and beta, each with its interval."""
    lo, hi = res.ci_percentiles
    unit = f" {res.intensity_unit}"
    median = f"{res.fit.median_g:.4g}{unit}" + _interval(res.median_ci_g, lo, hi, unit)
    return median, f"{res.fit.beta:.3g}" + _interval(res.beta_ci, lo, hi, "")


def _interval(ci: tuple[float, float], lo: float, hi: float, unit: str) -> str:
    if not all(math.isfinite(v) for v in ci):
        return ""
    return f" ({lo:g}-{hi:g} %: {ci[0]:.4g}-{ci[1]:.4g}{unit})"


class _BootstrapProgress(Progress):
    """The bootstrap's progress on stderr (a bar on a terminal, plain lines otherwise),
    once it has run for PROGRESS_AFTER_S."""

    def __call__(self, done: int, total: int) -> None:
        now = time.monotonic()
        if self.start is None:
            self.start, self.done0 = now, 0
        if self.drawn or now - self.start >= PROGRESS_AFTER_S:
            super().__call__(done, total)

    def text(self, now: float) -> str:
        rate = self.rate(now)
        left = self.total - self.done
        eta = duration(left / rate) if rate > 0 else "?"
        pct = 100.0 * self.done / self.total if self.total else 100.0
        return (
            f"{self.label}: {self.done:,}/{self.total:,} resamples ({pct:.0f} %), "
            f"ETA {eta if left else '0 s'}"
        )
