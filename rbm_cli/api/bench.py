"""The work-precision benchmark for ``rbm bench``: run it (rbm_cli.study.bench), its
scaling study (rbm_cli.study.bench_scaling), their figures (rbm_cli.report.bench_figures)
and the accuracy targets. Imports pandas and matplotlib: imported when the bench runs."""

from __future__ import annotations

from rbm_cli.api.domains import save_figure
from rbm_cli.report.bench_figures import scaling_figure, work_precision_figure
from rbm_cli.study.bench import check_targets, run_bench

__all__ = [
    "check_targets",
    "run_bench",
    "run_scaling",
    "save_figure",
    "scaling_figure",
    "work_precision_figure",
]


def run_scaling(**options):
    """The scaling study (rbm_cli.study.bench_scaling.run_scaling: output, log)."""
    # lazy: loads pandas and joblib only where needed (docs/architecture.md, Start-up)
    from rbm_cli.study.bench_scaling import run_scaling as scaling

    return scaling(**options)
