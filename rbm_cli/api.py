"""The library's entry points for scripts and the CLI: load a config, run one cell, run a
sweep with its figure. Above report (it wires the report's figure into the study's sweep)
and below the CLI.
"""

from __future__ import annotations

import os
from collections.abc import Callable

import pandas as pd

from rbm_cli.config import load_config, parse_config
from rbm_cli.config.types import Config
from rbm_cli.report.domain_figure import domain_figure
from rbm_cli.study.simulate import simulate
from rbm_cli.study.sweep import SweepInterrupted, SweepSummary
from rbm_cli.study.sweep import run_sweep as _run_sweep

__all__ = [
    "SweepInterrupted",
    "SweepSummary",
    "domain_figure",
    "load_config",
    "parse_config",
    "run_sweep",
    "simulate",
]


def run_sweep(
    config: Config,
    output: str | os.PathLike = "out",
    *args,
    figure: Callable[[pd.DataFrame, Config], object] | None = None,
    **kwargs,
) -> SweepSummary:
    """Run a config's grid into OUTPUT/<name>/ (domain.csv, boundary.csv, domain.png,
    meta.json): rbm_cli.study.sweep.run_sweep with the domain figure of
    rbm_cli.report.domain_figure (or `figure`). Same parameters.

    Examples
    --------
    >>> from rbm_cli.api import load_config, run_sweep
    >>> summary = run_sweep(load_config("configs/ci/slender_small.yaml"), "out")  # doctest: +SKIP
    """
    draw = figure if figure is not None else domain_figure
    return _run_sweep(config, output, *args, figure=draw, **kwargs)
