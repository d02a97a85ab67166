"""Fragility for ``rbm fragility``: a record-suite domain to its fragility files and figures
(rbm_cli.report.fragility_run.run_fragility). Imports the fit: a command imports this
module when it runs, not when its help is shown."""

from __future__ import annotations

from rbm_cli.report.fragility_run import run_fragility
from rbm_cli.study.fragility import MAX_RESAMPLES

__all__ = ["MAX_RESAMPLES", "run_fragility"]
