"""Whole domains with the exact integrator against the step kernel: no missed event.

Sub-grids of the stored studies, the 8-drum CI band and a 2-drum grid are re-made with
`solver.method: exact` and with the compiled step kernel (DOP853) at rtol 1e-11 and 1e-12
(atol 1e-14 and 1e-16 of theta_u, so the tolerance is relative throughout):

- outcome: no robust cell of a stored domain (its `robust` column) may differ. A rocking
  column can be chaotic while its 16-member ensemble happens to agree; so a robust cell
  that differs is checked against 32 more members of the step kernel (the same robustness
  rule, finer spread): the test fails unless some of them give the exact method's outcome;
- on cells where the step kernel has converged (rtol 1e-11 and 1e-12 give the same outcome
  and event counts, and peak, top displacement and collapse time within 1e-9): the same
  outcome and events, and peak rotation ratio, top displacement and collapse time within
  1e-8 of rtol 1e-12. Event counts are not compared on runs stopped early after a
  half-sine pulse: where the free motion stops is decided at step ends (rbm_cli.models.rbm.
  exact.run._passed_peak), so the impacts counted before it are not a property of the run.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
import pytest

from rbm_cli.config.load import load_config
from rbm_cli.config.types import GridConfig
from rbm_cli.models.registry import make_runner
from rbm_cli.study.robustness import member_config, members
from rbm_cli.study.simulate import simulate

from .paths import CONFIGS, RESULTS

pytestmark = [pytest.mark.slow, pytest.mark.timeout(900)]

#: (study, amplitude stride, frequency stride) of the sub-grids compared.
STUDIES = [
    ("harmonic_monolithic", 3, 3),
    ("spanos_koh_slender", 3, 2),
    ("housner_halfsine", 6, 3),
    ("harmonic_multidrum", 4, 3),
]
SOLVERS = {
    "k11": ("DOP853", 1e-11, 1e-14),
    "k12": ("DOP853", 1e-12, 1e-16),
    "exact": ("exact", 1e-10, 1e-12),
}
EARLY_STOP = "free motion below the collapse barrier: stopped early"


def _with(cfg, method, rtol, atol):
    return dataclasses.replace(
        cfg, solver=dataclasses.replace(cfg.solver, method=method, rtol=rtol, atol=atol)
    )


def _run(cfg, cells, keys=tuple(SOLVERS)) -> pd.DataFrame:
    rows = [{"amplitude_g": a, "frequency_hz": f} for a, f in cells]
    for key in keys:
        c = _with(cfg, *SOLVERS[key])
        runner = make_runner(c)
        for row in rows:
            out = simulate(c, row["amplitude_g"], row["frequency_hz"], runner=runner)
            row.update({f"{key}_status": out.status, f"{key}_ratio": out.max_rotation_ratio,
                        f"{key}_top": out.max_top_displacement_m, f"{key}_tc": out.t_collapse_s,
                        f"{key}_events": (out.n_uplifts, out.n_impacts),
                        f"{key}_early": out.message == EARLY_STOP})  # fmt: skip
    return pd.DataFrame(rows)


def _close(x, y, rel):
    return (np.isnan(x) & np.isnan(y)) | (np.abs(x - y) <= rel * np.abs(y))


def _converged(d: pd.DataFrame) -> pd.Series:
    """Cells where the step kernel at rtol 1e-11 and 1e-12 agree (module docstring)."""
    return (
        (d.k11_status == d.k12_status) & (d.k11_events == d.k12_events)
        & _close(d.k11_ratio, d.k12_ratio, 1e-9) & _close(d.k11_top, d.k12_top, 1e-9)
        & _close(d.k11_tc, d.k12_tc, 1e-9)
    )  # fmt: skip


def _check_converged(d: pd.DataFrame) -> int:
    conv = d[_converged(d)]
    for _, r in conv.iterrows():
        cell = (r.amplitude_g, r.frequency_hz)
        assert r.exact_status == r.k12_status, cell
        if not (r.k12_early or r.exact_early):
            assert r.exact_events == r.k12_events, cell
        assert _close(np.float64(r.exact_ratio), np.float64(r.k12_ratio), 1e-8), cell
        assert _close(np.float64(r.exact_top), np.float64(r.k12_top), 1e-8), cell
        assert _close(np.float64(r.exact_tc), np.float64(r.k12_tc), 1e-8), cell
    return len(conv)


def _outcome_found_by_kernel(cfg, a, f, status) -> bool:
    """Whether some of 32 further ensemble members of the step kernel (finer spread of
    the robustness rule's perturbations) end with this status."""
    runner = make_runner(cfg)
    for member in members(33)[1:]:
        c, amp = member_config(cfg, a, member)
        if (
            simulate(c, amp, f, runner=make_runner(c) if c.solver != cfg.solver else runner).status
            == status
        ):
            return True
    return False


def _check_robust(cfg, d: pd.DataFrame, stored: pd.DataFrame) -> int:
    m = d.merge(stored[["amplitude_g", "frequency_hz", "status", "robust"]],
                on=["amplitude_g", "frequency_hz"], how="inner")  # fmt: skip
    robust = m[m.robust == 1]
    for _, r in robust[robust.exact_status != robust.status].iterrows():
        assert _outcome_found_by_kernel(cfg, r.amplitude_g, r.frequency_hz, r.exact_status), (
            f"robust cell {(r.amplitude_g, r.frequency_hz)}: exact {r.exact_status}, the step "
            f"kernel {r.status} in all of its members"
        )
    return len(robust)


@pytest.mark.parametrize(("study", "sa", "sf"), STUDIES)
def test_sub_grid_against_the_step_kernel(study, sa, sf):
    cfg = load_config(CONFIGS / f"{study}.yaml")
    cells = [(a, f) for f in cfg.grid.frequencies_hz[::sf] for a in cfg.grid.amplitudes_g[::sa]]
    d = _run(cfg, cells)
    stored = pd.read_csv(RESULTS / study / "domain.csv")
    assert _check_robust(cfg, d, stored) >= 0.75 * len(cells)
    assert _check_converged(d) >= 0.3 * len(cells)


def test_ci_band_robust_cells():
    """The 8-drum column's CI band (66 cells along its chaotic boundary): every robust cell
    has the stored outcome, or the step kernel reaches the exact method's outcome too under
    further perturbations (the cell is chaotic: at 0.35 g, 2.5 Hz it is, 5 of 40 randomly
    perturbed kernel runs survive)."""
    cfg = load_config(CONFIGS / "ci" / "harmonic_multidrum_ci.yaml")
    cells = [(a, f) for f in cfg.grid.frequencies_hz for a in cfg.grid.amplitudes_g]
    d = _run(cfg, cells, keys=("exact",))
    stored = pd.read_csv(RESULTS / "harmonic_multidrum_ci" / "domain.csv")
    assert _check_robust(cfg, d, stored) >= 40


def test_two_drum_grid():
    """A 2-drum column (the paper's, two equal drums): on the cells where the step kernel has
    converged, the same outcome and events and peaks within 1e-8."""
    cfg = load_config(CONFIGS / "harmonic_multidrum.yaml")
    grid = GridConfig(tuple(np.round(np.arange(0.1, 1.5, 0.2), 10)), (0.5, 1.0, 1.5, 2.5, 3.5))
    cfg = dataclasses.replace(cfg, grid=grid)
    cfg = dataclasses.replace(cfg, column=dataclasses.replace(cfg.column, drum_heights=(2.5, 2.5)))
    cells = [(a, f) for f in grid.frequencies_hz for a in grid.amplitudes_g]
    d = _run(cfg, cells)
    assert _check_converged(d) >= 0.4 * len(cells)
