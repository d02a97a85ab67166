"""One run: config + amplitude [g] + frequency [Hz] -> RunResult, through the model registry.

This is where a cell of a study meets a model: the edge values (g, Hz) are checked and turned
into a ground motion (SI), the config's model runs it (rbm_cli.models.registry), and its
outcome becomes the row a domain keeps. No physics here.
"""

from __future__ import annotations

import math
import time

import numpy as np

from rbm_cli.base.errors import RbmError
from rbm_cli.config.types import MODELS, Config
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.models.contract import DEFAULT_OUTPUT_DT, Runner
from rbm_cli.models.rbm.pieces import FRICTION_DURATION
from rbm_cli.models.registry import make_runner
from rbm_cli.structures.assembly import check_derived, model_from_config
from rbm_cli.study.result import RunResult

__all__ = ["check_derived", "make_runner", "model_from_config", "simulate"]


def simulate(
    config: Config,
    amplitude_g: float,
    frequency_hz: float | None,
    *,
    record: bool = False,
    output_dt: float | None = None,
    runner: Runner | None = None,
) -> RunResult:
    """Run the config's model for one excitation.

    Parameters
    ----------
    config : Config  Validated configuration (its model, excitation type and solver)
    amplitude_g : float  Peak ground acceleration [g] (ignored for `free`)
    frequency_hz : float or None  Excitation frequency [Hz] (ignored for `free` and `record`)
    record : bool  Keep a time history (sampled every output_dt [s])
    output_dt : float  Sampling interval of the history [s]; default 0.002 s
    runner : Runner  The model built for this column (rbm_cli.models.registry.make_runner);
        sweeps build it once per column and pass it with every cell

    Returns
    -------
    RunResult  Why the run stopped and its summary figures.

    Examples
    --------
    >>> from rbm_cli.config import load_config
    >>> cfg = load_config("configs/spanos_koh_slender.yaml")  # doctest: +SKIP
    >>> simulate(cfg, 0.5, 1.0).status  # doctest: +SKIP
    'collapsed'
    """
    if config.excitation.type != "free":
        if not (math.isfinite(amplitude_g) and amplitude_g >= 0):
            raise RbmError(f"amplitude must be a number >= 0 [g], got {amplitude_g}")
        if config.excitation.type == "record":
            frequency_hz = None  # a record has its own frequencies
        elif frequency_hz is None or not (math.isfinite(frequency_hz) and frequency_hz > 0):
            raise RbmError(f"frequency must be a number > 0 [Hz], got {frequency_hz}")
    start = time.perf_counter()
    if runner is None:
        runner = make_runner(config)
    motion = make_ground_motion(config.excitation, amplitude_g, frequency_hz)
    dt = output_dt if output_dt is not None else DEFAULT_OUTPUT_DT
    out = runner.run(motion, config.solver, record=record, output_dt=dt, early_stop=not record)
    return _result(config, out, amplitude_g, frequency_hz, out.history, start)


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
        frequency_hz=None if frequency_hz is None else float(frequency_hz),
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
        method=out.method,
        model=config.model,
        friction_limit=config.interface.friction_limit if MODELS[config.model].beam else None,
        slip=out.slip,
        energy=None if out.energy is None else out.energy.as_dict(),
        collapse_azimuth_deg=math.degrees(math.remainder(out.azimuth, 2.0 * math.pi)),
        wobble_turns=float(out.turns),
        three_d=config.three_d,
        residual_slip_m=float(out.residual_slip),
        residual_top_offset_m=float(out.residual_top),
        residual_tilt_ratio=float(out.residual_tilt),
        residual=MODELS[config.model].residual,
        friction_demand_peak=tuple(float(v) for v in out.friction_peak)
        if out.friction_peak is not None and MODELS[config.model].beam
        else (),
        friction_duration_s=FRICTION_DURATION if MODELS[config.model].beam else None,
    )
