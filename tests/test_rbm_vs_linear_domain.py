"""The rigid RBM with n = 1 against housner-linear with the mapping of the RBM's
rigid monolith to the linear block: alpha = B/H, p from the true inertia.

The two are the same equation (alpha = B/H, p^2 = m g (H/2) / (I_G + m H^2/4)); the
RBM integrates it numerically, housner-linear solves it in closed form (cosh/sinh
pieces, no integration). So on a sub-grid of each study, run here through both models,
the outcome of every cell is the same and the peaks and collapse times agree to the
integration error; on the whole stored domains at most 1 % of cells differ, and only
next to the boundary, where the outcome is decided by a near-grazing of |theta| = alpha.
"""

from __future__ import annotations

import dataclasses
import math

import pandas as pd
import pytest

from rbm_cli.config.load import load_config
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.models.block.closed_form import linear_run
from rbm_cli.structures.closed_forms import linear_rocking_parameters
from rbm_cli.structures.column import build_column
from rbm_cli.study.domain import read_domain
from rbm_cli.study.simulate import model_from_config, simulate

from .paths import CONFIGS, RESULTS


def linear_domain(cfg) -> pd.DataFrame:
    alpha, p = linear_rocking_parameters(build_column(cfg.column, cfg.interface))
    rows = []
    for f in cfg.grid.frequencies_hz:
        for a in cfg.grid.amplitudes_g:
            motion = make_ground_motion(cfg.excitation, a, f)
            out = linear_run(alpha, p, motion, restitution=1.0)
            rows.append(
                {"amplitude_g": a, "frequency_hz": f, "collapsed": int(out.status == "collapsed")}
            )
    return pd.DataFrame(rows)


def next_to_boundary(df: pd.DataFrame, a: float, f: float, flag: int) -> bool:
    """A neighbour in amplitude at the same frequency has the other outcome."""
    col = df[df.frequency_hz == f].sort_values("amplitude_g").reset_index(drop=True)
    i = int(col.index[(col.amplitude_g - a).abs() < 1e-9][0])
    neighbours = [col.collapsed[j] for j in (i - 1, i + 1) if 0 <= j < len(col)]
    return any(c != flag for c in neighbours)


@pytest.mark.parametrize("study", ["spanos_koh_slender", "spanos_koh_thick", "housner_halfsine"])
def test_rigid_rbm_domain_equals_the_linear_model(study):
    cfg = load_config(CONFIGS / f"{study}.yaml")
    rbm = read_domain(RESULTS / study / "domain.csv")  # made by rbm sweep, re-made in CI
    lin = linear_domain(cfg)
    merged = rbm.merge(lin, on=["amplitude_g", "frequency_hz"], suffixes=("_rbm", "_lin"))
    assert len(merged) == len(rbm) == len(lin)
    differ = merged[merged.collapsed_rbm != merged.collapsed_lin]
    assert len(differ) <= 0.01 * len(merged)
    for row in differ.itertuples():
        assert next_to_boundary(lin, row.amplitude_g, row.frequency_hz, row.collapsed_lin)


#: Largest |peak theta / alpha| and |t_collapse| differences [-, s] on the sub-grid of
#: each study, about 10x those measured (slender 1.2e-8 / 1.4e-8 s; thick 5.9e-6 /
#: 2.5e-4 s, a cell with 13 impacts in 10 s, where the error of rtol 1e-10 accumulates
#: from impact to impact; half-sine 3e-11 / 7e-11 s).
AGREE = {
    "spanos_koh_slender": (1e-7, 1e-7),
    "spanos_koh_thick": (1e-4, 3e-3),
    "housner_halfsine": (1e-9, 1e-9),
}


def both_models(cfg, a: float, f: float):
    """(RBM result, housner-linear outcome) of one cell: the RBM through simulate, the
    closed form with the mapped (alpha, p) and the RBM's restitution and collapse ratio.
    The RBM runs its step integrator (DOP853): `auto` would run its own closed form."""
    cfg = dataclasses.replace(cfg, solver=dataclasses.replace(cfg.solver, method="DOP853"))
    model = model_from_config(cfg)
    alpha, p = linear_rocking_parameters(model.column)
    motion = make_ground_motion(cfg.excitation, a, f)
    lin = linear_run(
        alpha, p, motion, restitution=model.restitution, collapse_ratio=cfg.collapse.ratio
    )
    return simulate(cfg, a, f), lin


@pytest.mark.parametrize("study", sorted(AGREE))
def test_rigid_rbm_runs_equal_the_linear_model_on_a_sub_grid(study):
    """Every 4th frequency x every 5th amplitude of the study (24-96 cells, both
    outcomes present), both models run here: the same status in every cell, peaks
    and collapse times within AGREE."""
    cfg = load_config(CONFIGS / f"{study}.yaml")
    peak_tol, t_tol = AGREE[study]
    statuses = set()
    for f in cfg.grid.frequencies_hz[::4]:
        for a in cfg.grid.amplitudes_g[::5]:
            rbm, lin = both_models(cfg, a, f)
            where = f"{study} {a:g} g {f:g} Hz: RBM {rbm.status}, linear {lin.status}"
            assert rbm.status == lin.status, where
            statuses.add(rbm.status)
            assert abs(rbm.max_rotation_ratio - lin.max_ratio[0]) <= peak_tol, where
            if rbm.status == "collapsed":
                assert abs(rbm.t_collapse_s - lin.t_collapse) <= t_tol, where
            else:
                assert math.isnan(rbm.t_collapse_s) and math.isnan(lin.t_collapse), where
    assert statuses == {"collapsed", "survived"}


def test_the_gap_is_integration_error():
    """The largest gap of the sub-grids (thick block, 1.85 g, 2.25 Hz: 5.9e-6 of alpha
    at rtol 1e-10) shrinks with the solver tolerance: the RBM converges to the closed
    form, it does not solve another equation."""
    cfg = load_config(CONFIGS / "spanos_koh_thick.yaml")
    gaps = []
    for rtol in (1e-10, 1e-12):
        c = dataclasses.replace(cfg, solver=dataclasses.replace(cfg.solver, rtol=rtol))
        rbm, lin = both_models(c, 1.85, 2.25)
        assert rbm.status == lin.status == "survived"
        gaps.append(abs(rbm.max_rotation_ratio - lin.max_ratio[0]))
    assert gaps[0] > 1e-7 and gaps[1] < gaps[0] / 10, gaps


def test_a_restart_at_theta_zero_is_not_taken_for_an_impact():
    """The paper's tapered column as a rigid monolith under the synthetic record rdk_01 at
    0.9 g, restitution 1: the block rocks through impacts at rates down to ~6e-4 rad/s.
    housner-linear, with the mapped (alpha, p), started each piece after an impact at
    theta = 0, where s theta's round-off has either sign; when it was positive, the root
    of s theta next to the start was taken for the next impact (three within 3e-14 s, then
    a million, and the run 'failed' on its piece budget). Now the closed form (compiled, and
    uncompiled with the same bits) collapses after the RBM's 174 impacts; given the RBM's
    convention for where an impact is placed (s theta = -eps, then theta = 0, instead of
    s theta = 0), at the RBM step integrator's time. The two conventions' collapse times
    differ by ~1e-4 s after 174 impacts."""
    from rbm_cli.config.load import parse_config
    from rbm_cli.config.types import SolverConfig
    from rbm_cli.models.block.closed_form import linear_block, run_closed_form
    from rbm_cli.models.block.piece import B_AT_ZERO

    cfg = parse_config({
        "name": "restart",
        "column": {"height": 5.0, "base_width": 0.96, "top_width": 0.66, "drums": 1},
        "interface": {"stiffness": "rigid", "restitution": 1.0},
        "excitation": {"type": "record", "file": str(CONFIGS / "records/synthetic/rdk_01.AT2")},
        "solver": {"method": "DOP853"},
    })  # fmt: skip
    rbm = simulate(cfg, 0.9, None)
    assert rbm.status == "collapsed"
    alpha, p = linear_rocking_parameters(model_from_config(cfg).column)
    motion = make_ground_motion(cfg.excitation, 0.9, None)
    python = linear_run(alpha, p, motion, solver=SolverConfig(implementation="python"))
    block = linear_block(alpha, p, 1.0)
    compiled = run_closed_form(block, motion, 0.0, 0.0, SolverConfig())
    params = block.params.copy()
    params[B_AT_ZERO] = 0.0
    rbm_convention = run_closed_form(block._replace(params=params), motion, 0.0, 0.0,
                                     SolverConfig())  # fmt: skip
    for lin in (python, compiled, rbm_convention):
        assert lin.status == "collapsed", lin.message
        assert lin.n_impacts == rbm.n_impacts == 174
    assert python.t_collapse == compiled.t_collapse
    assert abs(rbm_convention.t_collapse - rbm.t_collapse_s) <= 1e-7
