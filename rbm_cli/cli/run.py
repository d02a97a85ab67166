"""`rbm run` and `rbm info`: one run of a config, and its derived properties."""

from __future__ import annotations

import contextlib
import math
import sys
from pathlib import Path

import click

from rbm_cli.base.errors import RbmError
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


def _check_excitation(kind: str, amplitude: float | None, frequency: float | None):
    """Validate --amplitude [g] and --frequency [Hz] for the excitation type (the
    grid's ranges, rbm_cli.config.load.AMPLITUDE_RANGE_G and FREQUENCY_RANGE_HZ).
    Returns (amplitude [g], frequency [Hz] or None for a record)."""
    from rbm_cli.config.load import AMPLITUDE_RANGE_G, FREQUENCY_RANGE_HZ

    if amplitude is not None and not (math.isfinite(amplitude) and amplitude >= 0.0):
        raise UserError(f"--amplitude must be a finite number >= 0 [g], got {amplitude:g}")
    if frequency is not None and not (math.isfinite(frequency) and frequency > 0.0):
        raise UserError(f"--frequency must be a finite number > 0 [Hz], got {frequency:g}")
    for name, value, (lo, hi), unit in (
        ("--amplitude", amplitude, AMPLITUDE_RANGE_G, "g"),
        ("--frequency", frequency, FREQUENCY_RANGE_HZ, "Hz"),
    ):
        if value is not None and not lo <= value <= hi:
            raise UserError(f"{name} must be in [{lo:g}, {hi:g}] [{unit}], got {value:g}")
    if kind == "free":
        return 0.0, 0.0
    if amplitude is None:
        raise UserError(f"--amplitude [g] is required for excitation.type '{kind}'")
    if kind == "record":
        return float(amplitude), None
    if frequency is None:
        raise UserError(f"--frequency [Hz] is required for excitation.type '{kind}'")
    return float(amplitude), float(frequency)


def _print_summary(result, folder: Path) -> None:
    lines = [("status", result.status), ("method", result.method or "-")]
    if result.collapsed:
        where = result.collapse_interface if result.collapse_interface is not None else "?"
        lines.append(("collapse", f"t = {result.t_collapse_s:.6g} s at interface {where}"))
    lines += [
        ("max rotation ratio", f"{result.max_rotation_ratio:.4g}"),
        ("max top displacement", f"{result.max_top_displacement_m:.4g} m (relative to base)"),
        (
            "friction demand",
            f"max |T/N| = {result.max_friction_demand:.4g}"
            if math.isfinite(result.max_friction_demand)
            else "- (not computed by this model)",
        ),
        ("uplifts / impacts", f"{result.n_uplifts} / {result.n_impacts}"),
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
    amplitude_g, frequency_hz = _check_excitation(kind, amplitude, frequency)
    if kind == "free" and (amplitude is not None or frequency is not None):
        click.echo("note: excitation.type is 'free': --amplitude/--frequency are ignored", err=True)
    if kind == "record" and frequency is not None:
        click.echo("note: excitation.type is 'record': --frequency is ignored", err=True)
    _check_output_dt(cfg, output_dt)
    _say_which_point(cfg)

    from rbm_cli.report.figure_process import RUN_IMPORTS, FigureProcess

    # before numba and matplotlib are imported: the child imports the figures' while this
    # process loads the integrator and runs (issue 18)
    with FigureProcess.start(RUN_IMPORTS) or contextlib.nullcontext() as painter:
        result, folder = _run(cfg, config, amplitude_g, frequency_hz, output_dt, output, painter)
    _print_summary(result, folder)
    if result.status == "failed":
        reason = " ".join(str(result.message).split()) or "no reason given"
        click.echo(f"Error: run failed: {reason}", err=True)
        sys.exit(EXIT_RUN_FAILED)


def _check_output_dt(cfg, output_dt: float | None) -> None:
    """--dt checked as the library checks output_dt (rbm_cli.api.check_output_dt)."""
    from rbm_cli.api import check_output_dt

    try:
        check_output_dt(cfg, output_dt)
    except RbmError as exc:
        raise UserError(one_line(exc).replace("output_dt", "--dt")) from None


def _say_which_point(cfg) -> None:
    """A note when the config's grid has axes over config keys (a suite of records, a
    column.height axis...): one run is the config's own point, named here."""
    axes = cfg.grid.axes
    if not axes:
        return
    n_points = math.prod(len(axis.points) for axis in axes)
    own = ", ".join(f"{path} = {_value_at(cfg, path)}" for path in cfg.grid.axis_paths)
    click.echo(
        f"note: the grid has {n_points} points over {', '.join(cfg.grid.axis_paths)};"
        f" this run is the config's own point ({own}): set another value in the config"
        " to run it, or sweep them all with rbm sweep",
        err=True,
    )


def _value_at(cfg, path: str) -> str:
    """The value a run of the config takes for a grid axis's key path, as written."""
    from rbm_cli.config.grid import VIRTUAL_PATHS

    if path in VIRTUAL_PATHS:
        return "as written"
    if path in ("excitation.file", "excitation.vertical"):  # a suite's first record
        return str(getattr(cfg.excitation, path.split(".")[1]))
    node = cfg.written or {}
    for key in path.split("."):
        node = node.get(key) if isinstance(node, dict) else None
    if node is None:
        return "its default"
    return str(node) if not isinstance(node, dict) else "as written"


def _run(cfg, config, amplitude_g, frequency_hz, output_dt, output, painter):
    """The body of `rbm run` once its inputs are checked: (RunResult, run folder). painter:
    the FigureProcess that draws history.png and shapes.png, or None to draw them here."""
    from rbm_cli.api import run as run_cell
    from rbm_cli.base.files import check_writable_dir
    from rbm_cli.physics.column import build_column
    from rbm_cli.report.run_folder import run_folder_name, run_summary, write_run

    try:
        check_writable_dir(Path(output) / cfg.name)
        column = build_column(cfg.column, cfg.interface)
        cfg = first_use(cfg)
        work_starts()
        result = run_cell(cfg, amplitude_g, frequency_hz, output_dt=output_dt).result
        summary = run_summary(
            result,
            cfg,
            config_path=config,
            amplitude_g=amplitude_g,
            frequency_hz=frequency_hz,
            output_dt=output_dt,
        )
        folder = write_run(
            output,
            cfg.name,
            run_folder_name(amplitude_g, frequency_hz, cfg.excitation.type),
            result,
            summary,
            widths=column.widths,
            elevations=list(column.bottoms) + [column.height],
            figure_process=painter,
        )
    except RbmError as exc:
        raise UserError(one_line(exc)) from None
    except KeyboardInterrupt:
        raise Interrupted("interrupted (Ctrl-C): no run folder was written") from None

    return result, folder


# --------------------------------------------------------------------------- info


def _fmt(value, spec: str = ".4g") -> str:
    if value is None:
        return "-"
    if isinstance(value, float) and math.isinf(value):
        return "inf"
    if isinstance(value, int | float):
        return format(value, spec)
    return str(value)


#: Columns of the per-interface table of ``rbm info``: (key, header, unit).
INTERFACE_COLUMNS = (
    ("interface", "i", "-"),
    ("width_m", "B_i", "m"),
    ("drum_height_m", "h_i", "m"),
    ("drum_mass_kg", "m_i", "kg"),
    ("drum_inertia_kgm2", "I_Gi", "kg m2"),
    ("normal_force_N", "N_i", "N"),
    ("moment_capacity_Nm", "M_u,i", "N m"),
    ("rotation_capacity_rad", "theta_u,i", "rad"),
    ("stiffness_Nm_per_rad", "K_M,i", "N m/rad"),
    ("normal_stiffness_Pa_per_m", "k_n,i", "Pa/m"),
    ("elastic_limit_rad", "elastic lim", "rad"),
)


def format_info(info: dict) -> str:
    """The text printed by ``rbm info``: global figures, then one row per interface."""
    n = info.get("n_drums")
    freqs = info.get("elastic_frequencies_hz") or []
    rows = [
        ("name", info.get("name")),
        ("drums", n),
        ("formulation", info.get("formulation")),
        ("total mass", f"{_fmt(info.get('total_mass_kg'))} kg"),
        ("height", f"{_fmt(info.get('height_m'))} m"),
        ("static multiplier", f"{_fmt(info.get('static_multiplier_g'))} g"),
        (
            "uplift acceleration",
            f"{_fmt(info.get('uplift_acceleration_g'))} g"
            if info.get("uplift_acceleration_g") is not None
            else "- (elastic interfaces)",
        ),
        ("rocking p", f"{_fmt(info.get('rocking_p_rad_s'))} rad/s"),
        ("rocking frequency", f"{_fmt(info.get('rocking_frequency_hz'))} Hz"),
        (
            "elastic frequencies",
            (", ".join(_fmt(f) for f in freqs) + " Hz") if freqs else "- (rigid)",
        ),
    ]
    if info.get("engine_uplift_g") is not None:
        rows.append(
            (
                "engine uplift",
                f"{_fmt(info['engine_uplift_g'])} g (model: bullet, true solids, friction "
                f"{_fmt(info.get('friction'))}; the figures above are the RBM's)",
            )
        )
    width = max(len(k) for k, _ in rows)
    lines = [f"{k + ':':<{width + 1}} {v}" for k, v in rows]

    table = [[h for _, h, _ in INTERFACE_COLUMNS], [f"[{u}]" for _, _, u in INTERFACE_COLUMNS]]
    for row in info.get("interfaces", []):
        table.append(
            [
                _fmt(row.get(key), "d" if key == "interface" else ".4g")
                for key, _, _ in INTERFACE_COLUMNS
            ]
        )
    widths = [max(len(r[c]) for r in table) for c in range(len(INTERFACE_COLUMNS))]
    lines.append("")
    lines.append("interfaces (i = 1 at the ground):")
    for r in table:
        lines.append("  ".join(cell.rjust(w) for cell, w in zip(r, widths, strict=True)))
    return "\n".join(lines)


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
    from rbm_cli.report.info import describe

    cfg = load(config)
    try:
        figures = describe(cfg)
    except RbmError as exc:
        raise UserError(one_line(exc)) from None
    if as_json:
        import json

        from rbm_cli.base.files import json_ready

        click.echo(json.dumps(json_ready(figures), indent=2))
    else:
        click.echo(format_info(figures))
