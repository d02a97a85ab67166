"""`rbm run` and `rbm info`: one run of a config, and its derived properties."""

from __future__ import annotations

import contextlib
import math
import sys
from pathlib import Path

import click

from rbm_cli.api.errors import RbmError
from rbm_cli.cli.common import (
    EXIT_RUN_FAILED,
    Interrupted,
    UserError,
    cli,
    config_argument,
    first_use,
    load,
    one_line,
    output_option,
    work_starts,
)


def _check_excitation(cfg, amplitude: float | None, frequency: float | None):
    """Validate --amplitude [g] and --frequency [Hz] for the config's excitation type (the
    grid's ranges: rbm_cli.api.configs.check_options). Returns (amplitude [g], frequency
    [Hz] or None for a record)."""
    # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
    from rbm_cli.api.configs import check_options

    try:
        return check_options(cfg, amplitude, frequency)
    except RbmError as exc:
        raise UserError(one_line(exc)) from None


def _slide_lines(result) -> list[tuple[str, str]]:
    """Where model rbm's friction demand was first held above interface.friction (given)."""
    mu = result.friction_limit
    if mu is None:
        return []
    if result.slip is None:
        return [("slides", f"no: |T/N| stays <= interface.friction {mu:.4g}")]
    t, where = result.slip
    tau = result.friction_duration_s
    if tau:
        return [("slides", f"|T/N| > interface.friction {mu:.4g} held for {tau:.4g} s from"
                           f" t = {t:.6g} s, interface {where}")]  # fmt: skip
    return [("slides", f"|T/N| > interface.friction {mu:.4g} first at t = {t:.6g} s, interface"
                       f" {where}")]  # fmt: skip


def _demand_text(result) -> str:
    """The friction demand: held for its duration, with the instantaneous peak apart."""
    if not math.isfinite(result.max_friction_demand):
        return "- (not computed by this model)"
    text = f"max |T/N| = {result.max_friction_demand:.4g}"
    tau = result.friction_duration_s
    if tau:
        text += f" held for {tau:.4g} s (instantaneous peak {result.max_friction_demand_peak:.4g})"
    return text


def _residual_lines(result) -> list[tuple[str, str]]:
    """The contact engine's residual state where the run ended (none for the other
    models; n/a where it collapsed or failed)."""
    if "residual_slip_m" not in result:
        return []
    if not math.isfinite(result["residual_slip_m"]):
        return [("residual", "n/a (the run did not survive)")]
    return [(
        "residual",
        f"slip {result['residual_slip_m']:.4g} m (largest joint), top offset"
        f" {result['residual_top_offset_m']:.4g} m, tilt"
        f" {result['residual_tilt_ratio']:.3g} alpha (where the run ended)",
    )]  # fmt: skip


def _print_summary(result, folder: Path) -> None:
    lines = [("status", result.status), ("method", result.method or "-")]
    if result.collapsed:
        where = result.collapse_interface if result.collapse_interface is not None else "?"
        lines.append(("collapse", f"t = {result.t_collapse_s:.6g} s at interface {where}"))
    lines += [
        ("max rotation ratio", f"{result.max_rotation_ratio:.4g}"),
        ("max top displacement", f"{result.max_top_displacement_m:.4g} m (relative to base)"),
        *_residual_lines(result),
        ("friction demand", _demand_text(result)),
        *_slide_lines(result),
        ("uplifts / impacts", f"{result.n_uplifts} / {result.n_impacts}"),
    ]
    if result.energy is not None:
        e = result.energy
        lines.append((
            "energy",
            f"ground work {e['ground_work_J']:.4g} J, taken by damping {e['damping_J']:.4g} J"
            f" and impacts {e['impacts_J']:.4g} J, kept {e['final_J'] - e['initial_J']:.4g} J"
            f" (balance residual {e['residual_J']:.2g} J)",
        ))  # fmt: skip
    lines += [
        ("steps / rhs", f"{result.n_steps} / {result.n_rhs}"),
        ("wall time", f"{result.wall_time_s:.3g} s"),
    ]
    if result.message:
        lines.append(("message", result.message))
    lines.append(("output", str(folder)))
    width = max(len(k) for k, _ in lines)
    for key, value in lines:
        click.echo(f"{key + ':':<{width + 1}} {value}")


@cli.command()
@config_argument
@click.option(
    "-a",
    "--amplitude",
    type=float,
    default=None,
    help="Peak ground acceleration [g], >= 0 (not used by 'free'); for a 'record', its"
    " PGA after scaling (or the scale factor with excitation.scale: factor).",
)
@click.option(
    "-f",
    "--frequency",
    type=float,
    default=None,
    help="Excitation frequency [Hz], > 0 (not used by 'free' and 'record').",
)
@click.option(
    "--dt",
    "output_dt",
    type=float,
    default=None,
    help="Sampling interval of history.csv [s]; default: the library's choice.",
)
@output_option
def run(
    config: str,
    amplitude: float | None,
    frequency: float | None,
    output_dt: float | None,
    output: str,
) -> None:
    """Simulate one excitation and write its history, plots and summary.

    Writes OUTPUT/<name>/run_A<A>_f<F>/ (run_free for a free excitation):
    history.csv (t, ground acceleration and displacement, node displacements
    relative to the ground, drum rotations), history.png (base and top
    displacement, as the paper's fig. 4), shapes.png (the deformed column at six
    instants, as fig. 3) and summary.json. The folder is created only once the
    simulation has succeeded. Exit status 1 if the integration failed (the
    files are still written), 2 on bad input.

    \b
    Example:
        rbm run configs/spanos_koh_slender.yaml --amplitude 0.5 --frequency 1
        rbm run configs/harmonic_multidrum.yaml -a 0.3 -f 2 -o /tmp/rbm-out
        rbm run my_record.yaml --amplitude 0.4     (excitation.type: record)
    """
    cfg = load(config)
    kind = cfg.excitation.type
    amplitude_g, frequency_hz = _check_excitation(cfg, amplitude, frequency)
    if kind == "free" and (amplitude is not None or frequency is not None):
        click.echo("note: excitation.type is 'free': --amplitude/--frequency are ignored", err=True)
    if kind == "record" and frequency is not None:
        click.echo("note: excitation.type is 'record': --frequency is ignored", err=True)
    _check_output_dt(cfg, output_dt)
    _say_which_point(cfg)

    # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
    from rbm_cli.api.sweeps import RUN_IMPORTS, FigureProcess

    # before numba and matplotlib are imported: the child imports the figures' while this
    # process loads the integrator and runs (a shorter wall time)
    with FigureProcess.start(RUN_IMPORTS) or contextlib.nullcontext() as painter:
        result, folder = _run(cfg, config, amplitude_g, frequency_hz, output_dt, output, painter)
    _print_summary(result, folder)
    if result.status == "failed":
        reason = " ".join(str(result.message).split()) or "no reason given"
        click.echo(f"Error: run failed: {reason}", err=True)
        sys.exit(EXIT_RUN_FAILED)


def _check_output_dt(cfg, output_dt: float | None) -> None:
    """--dt checked as the library checks output_dt (rbm_cli.api.configs.check_output_dt)."""
    # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
    from rbm_cli.api.configs import check_output_dt

    try:
        check_output_dt(cfg, output_dt)
    except RbmError as exc:
        raise UserError(one_line(exc).replace("output_dt", "--dt")) from None


def _say_which_point(cfg) -> None:
    """A note when the config's grid has axes over config keys (a suite of records, a
    column.height axis...): one run is the config's own point, named here."""
    # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
    from rbm_cli.api.column_info import own_point_note

    note = own_point_note(cfg)
    if note is not None:
        click.echo(f"note: {note}", err=True)


def _run(cfg, config, amplitude_g, frequency_hz, output_dt, output, painter):
    """The body of `rbm run` once its inputs are checked: (RunResult, run folder). painter:
    the FigureProcess that draws history.png and shapes.png, or None to draw them here."""
    # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
    from rbm_cli.api.cells import check_run_output, write_run_folder
    from rbm_cli.api.cells import run as run_cell

    try:
        column = check_run_output(cfg, output)
        first_use(cfg)  # compiled before the run: the answer of every later run
        work_starts()
        result = run_cell(cfg, amplitude_g, frequency_hz, output_dt=output_dt).result
        folder = write_run_folder(cfg, column, result, output, config, amplitude_g,
                                  frequency_hz, output_dt, figure_process=painter)  # fmt: skip
    except RbmError as exc:
        raise UserError(one_line(exc)) from None
    except KeyboardInterrupt:
        raise Interrupted("interrupted (Ctrl-C): no run folder was written") from None

    return result, folder


# --------------------------------------------------------------------------- info


@cli.command()
@config_argument
@click.option("--json", "as_json", is_flag=True, help="Print the figures as JSON instead.")
def info(config: str, as_json: bool) -> None:
    """Print derived properties of a column: masses, strengths, frequencies.

    Per interface: width B_i, drum height, mass and inertia I_Gi, normal force
    N_i, moment capacity M_u,i, zero-moment rotation theta_u,i, stiffness K_M,i
    [N m/rad] and the joint normal stiffness k_n,i [Pa/m] that gives it, and the
    elastic limit; globally: total mass, static multiplier, rocking
    parameter p and the elastic frequencies.

    \b
    Example:
        rbm info configs/harmonic_multidrum.yaml
        rbm info configs/spanos_koh_thick.yaml --json
    """
    # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
    from rbm_cli.api.column_info import describe, format_info, info_json

    cfg = load(config)
    try:
        text = info_json(cfg) if as_json else format_info(describe(cfg))
    except RbmError as exc:
        raise UserError(one_line(exc)) from None
    click.echo(text)
