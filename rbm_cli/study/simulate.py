"""One run: config + amplitude [g] + frequency [Hz] -> RunResult."""

from __future__ import annotations

import math
import time

import numpy as np

from rbm_cli.base.errors import RbmError
from rbm_cli.config.types import Config
from rbm_cli.models.rbm.python import integrate
from rbm_cli.models.result import History, RunResult
from rbm_cli.physics.block import block_geometry
from rbm_cli.physics.column import Column, build_column
from rbm_cli.physics.equations import Model, build_model
from rbm_cli.physics.excitation import make_ground_motion
from rbm_cli.physics.restitution import block_restitution, column_restitution, resolve


def model_from_config(config: Config, column: Column | None = None) -> Model:
    """Assemble the model of a config (column may be overridden, e.g. in tests).

    Raises RbmError if a derived quantity (mass, inertia, capacity, stiffness, the
    mass matrix or its inverse, a law's pieces, p) is not finite: see check_derived."""
    with np.errstate(over="ignore", invalid="ignore", divide="ignore", under="ignore"):
        if column is None:
            column = build_column(config.column, config.interface)
        e = resolve(config.interface.restitution, lambda: column_restitution(column))
        try:
            model = build_model(
                column,
                xi=config.interface.xi,
                restitution=float(e),
                formulation=config.interface.formulation,
                collapse_ratio=config.collapse.ratio,
            )
        except (ArithmeticError, ValueError, np.linalg.LinAlgError) as exc:
            raise RbmError(
                f"the column's model cannot be assembled ({type(exc).__name__}: {exc}): its"
                " inputs are outside the range where the arithmetic is sound"
            ) from None
        check_derived(model)
    return model


def check_derived(model: Model) -> None:
    """Every derived quantity of a model finite (and positive where it must be), before a
    run starts: a density of 1e307 once made masses overflow and a collapsing column
    report 'survived' (issue 14). Raises RbmError naming the first bad quantity."""
    col = model.column
    positive = {
        "drum masses": col.masses,
        "drum inertias": col.inertias,
        "normal forces N_i": col.normal_forces,
        "moment capacities M_u,i": col.moment_capacity,
        "rotation capacities theta_u,i": col.rotation_capacity,
        "lever arms": col.lever_arms,
    }
    finite = {
        "mass matrix": model.mass,
        "inverse mass matrix": model.mass_inv,
        "gravity matrix": model.gravity,
        "ground load": model.ground_load,
        "collapse limits": model.collapse_limit,
    }
    for i, law in enumerate(model.laws):
        finite[f"law of interface {i + 1}"] = np.concatenate(
            [law.edges, law.intercepts, law.slopes]
        )
    stiff = col.stiffness
    bad_stiffness = not np.all(np.isinf(stiff) | (np.isfinite(stiff) & (stiff > 0)))
    for name, values in positive.items():
        v = np.asarray(values, dtype=float)
        if not (np.all(np.isfinite(v)) and np.all(v > 0)):
            _derived_error(name, v)
    for name, values in finite.items():
        v = np.asarray(values, dtype=float)
        if not np.all(np.isfinite(v)):
            _derived_error(name, v)
    if bad_stiffness:
        _derived_error("joint stiffnesses K_M,i", stiff)
    p = model.rocking_p
    if not (math.isfinite(p) and p > 0):
        _derived_error("rocking parameter p", np.array([p]))


def _derived_error(name: str, values: np.ndarray) -> None:
    shown = ", ".join(f"{x:.4g}" for x in values.ravel()[:3])
    raise RbmError(
        f"the column's {name} are not finite and positive ({shown}...): the inputs are"
        " outside the range where the arithmetic is sound (check column sizes, density"
        " and interface.stiffness)"
    )


def simulate(
    config: Config,
    amplitude_g: float,
    frequency_hz: float,
    *,
    record: bool = False,
    output_dt: float | None = None,
    model: Model | None = None,
) -> RunResult:
    """Run the Rigid Beam Model for one excitation.

    Parameters
    ----------
    config : Config  Validated configuration
    amplitude_g : float  Peak ground acceleration [g] (ignored for `free`)
    frequency_hz : float  Excitation frequency [Hz] (ignored for `free`)
    record : bool  Keep a time history (sampled every output_dt [s])
    output_dt : float  Sampling interval of the history [s]; default 0.002 s
    model : Model  Pre-assembled model (sweeps assemble once per column)

    Returns
    -------
    RunResult  Why the run stopped and its summary figures.
    """
    if config.excitation.type != "free":
        if not (math.isfinite(amplitude_g) and amplitude_g >= 0):
            raise RbmError(f"amplitude must be a number >= 0 [g], got {amplitude_g}")
        if not (math.isfinite(frequency_hz) and frequency_hz > 0):
            raise RbmError(f"frequency must be a number > 0 [Hz], got {frequency_hz}")
    start = time.perf_counter()
    if config.model == "bullet":
        return _engine_run(config, amplitude_g, frequency_hz, record, output_dt, start)
    if config.model != "rbm":
        return _reference_run(config, amplitude_g, frequency_hz, record, output_dt, start)
    if model is None:
        model = model_from_config(config)
    n = model.n
    motion = make_ground_motion(config.excitation, amplitude_g, frequency_hz)
    init = config.excitation.initial
    theta0 = np.zeros(n) if not init.rotations else np.asarray(init.rotations, float)
    rate0 = np.zeros(n) if not init.velocities else np.asarray(init.velocities, float)
    dt = output_dt if output_dt is not None else 0.002
    run = integrate
    if config.solver.implementation == "compiled":
        from rbm_cli.models.rbm.kernel import integrate_compiled as run
    try:
        out = run(
            model,
            motion,
            theta0,
            rate0,
            config.solver,
            record=record,
            output_dt=dt,
            early_stop=not record,
        )
    except (FloatingPointError, np.linalg.LinAlgError, ValueError, ZeroDivisionError) as exc:
        from rbm_cli.models.outcome import Outcome

        out = Outcome(status="failed", message=f"numerical failure: {exc}")
        out.max_ratio = np.full(n, np.nan)
        out.friction = np.full(n, np.nan)
    history = _history(model.node_map, motion, out.samples) if record else None
    return _result(config, out, amplitude_g, frequency_hz, history, start)


def _result(config, out, amplitude_g, frequency_hz, history, start) -> RunResult:
    wall = time.perf_counter() - start
    if config.excitation.type == "free":
        amplitude_g, frequency_hz = 0.0, 0.0
    if not out.message:
        out.message = {
            "survived": "no interface reached its collapse limit",
        }.get(out.status, "")
    return RunResult(
        status=out.status,
        amplitude_g=float(amplitude_g),
        frequency_hz=float(frequency_hz),
        t_collapse_s=float(out.t_collapse),
        collapse_interface=out.collapse_interface,
        max_rotation_ratio=float(np.max(out.max_ratio)),
        max_top_displacement_m=float(out.max_top),
        n_uplifts=out.n_uplifts,
        n_impacts=out.n_impacts,
        n_steps=out.n_steps,
        n_rhs=out.n_rhs,
        message=out.message,
        friction_demand=tuple(float(v) for v in out.friction),
        wall_time_s=wall,
        history=history,
    )


def _engine_run(config, amplitude_g, frequency_hz, record, output_dt, start) -> RunResult:
    """`bullet`: the drums in PyBullet's contact dynamics (history from drum positions)."""
    from rbm_cli.models.bullet.run import bullet_run

    motion = make_ground_motion(config.excitation, amplitude_g, frequency_hz)
    dt = output_dt if output_dt is not None else 0.002
    out, history = bullet_run(config, motion, record=record, output_dt=dt, early_stop=not record)
    return _result(config, out, amplitude_g, frequency_hz, history, start)


def _reference_run(config, amplitude_g, frequency_hz, record, output_dt, start) -> RunResult:
    """`housner` and `housner-linear`: single rigid blocks with their true geometry."""
    from rbm_cli.models.housner import housner_run
    from rbm_cli.models.housner_linear import housner_linear_run

    geometry = block_geometry(config.column)
    motion = make_ground_motion(config.excitation, amplitude_g, frequency_hz)
    init = config.excitation.initial
    initial = (
        float(init.rotations[0]) if init.rotations else 0.0,
        float(init.velocities[0]) if init.velocities else 0.0,
    )
    e = resolve(config.interface.restitution, lambda: block_restitution(geometry))
    dt = output_dt if output_dt is not None else 0.002
    common = dict(
        restitution=e,
        collapse_ratio=config.collapse.ratio,
        record=record,
        output_dt=dt,
        initial=initial,
        early_stop=not record,
    )
    if config.model == "housner":
        out = housner_run(geometry, motion, solver=config.solver, **common)
    else:
        out = housner_linear_run(
            geometry.slenderness,
            geometry.frequency_parameter,
            motion,
            height=config.column.height,
            **common,
        )
    node_map = np.array([[0.0], [config.column.height]])
    history = _history(node_map, motion, out.samples) if record else None
    return _result(config, out, amplitude_g, frequency_hz, history, start)


def _history(node_map: np.ndarray, motion, samples) -> History:
    n = node_map.shape[1]
    if samples:
        t = np.array([s[0] for s in samples])
        theta = np.array([s[1] for s in samples])
        rates = np.array([s[2] for s in samples])
    else:
        t, theta, rates = np.zeros(0), np.zeros((0, n)), np.zeros((0, n))
    return History(
        t=t,
        ground_acceleration=np.asarray(motion.accel(t), dtype=float),
        ground_displacement=motion.displacement(t),
        node_displacements=theta @ node_map.T,
        rotations=theta,
        rates=rates,
    )
