"""Regression of the stored domains in results/ (re-made in CI and compared).

Each study is re-run here, whole where it is fast and on a stated sub-grid
where it is not, and compared with its stored domain with `rbm compare`
semantics (rbm_cli.domain.compare) and the tolerances of TOLERANCE:

- monolithic studies (deterministic, not chaotic): at most 1 % of cells may
  differ and the boundary may move by at most one amplitude step (0.05 g);
  on the machine that made them the difference is 0 cells.
- the 8-drum column is chaotic in parts of the plane (see issue 5): its CI
  sub-grid (configs/ci/harmonic_multidrum_ci.yaml, 15 cells of the full grid)
  may differ in at most 1 cell and 0.2 g of boundary.

A perturbed model (base width -10 %) must fail the same comparison, so this
test can catch a change to the model.
"""

from __future__ import annotations

import dataclasses

import pytest

from rbm_cli.config import load_config
from rbm_cli.domain import compare, read_domain
from rbm_cli.sweep import run_sweep

from .paths import CONFIGS, RESULTS

MONOLITHIC = {"max_cells": 0.01, "max_shift": 0.05 + 1e-9}
STUDIES = {
    # stored result name: (config, tolerance)
    "spanos_koh_slender": (CONFIGS / "spanos_koh_slender.yaml", MONOLITHIC),
    "spanos_koh_thick": (CONFIGS / "spanos_koh_thick.yaml", MONOLITHIC),
    "housner_halfsine": (CONFIGS / "housner_halfsine.yaml", MONOLITHIC),
    "spanos_koh_slender_linear": (CONFIGS / "spanos_koh_slender_linear.yaml", MONOLITHIC),
    "spanos_koh_thick_linear": (CONFIGS / "spanos_koh_thick_linear.yaml", MONOLITHIC),
    "spanos_koh_thick_housner_e": (CONFIGS / "spanos_koh_thick_housner_e.yaml", MONOLITHIC),
    "harmonic_monolithic": (CONFIGS / "harmonic_monolithic.yaml", MONOLITHIC),
    "harmonic_multidrum_ci": (
        CONFIGS / "ci" / "harmonic_multidrum_ci.yaml",
        {"max_cells": 1 / 15 + 1e-9, "max_shift": 0.2 + 1e-9},
    ),
}


def within(cmp, max_cells, max_shift) -> bool:
    """The acceptance rule of `rbm compare --max-cells --max-shift`."""
    return cmp.fraction <= max_cells and cmp.max_shift_g <= max_shift


@pytest.mark.parametrize("name", sorted(STUDIES))
def test_stored_domain_is_reproduced(name, tmp_path):
    config_path, tol = STUDIES[name]
    stored = read_domain(RESULTS / name / "domain.csv")
    cfg = load_config(config_path)
    summary = run_sweep(cfg, tmp_path, jobs=2)
    fresh = read_domain(summary.folder / "domain.csv")
    cmp = compare(stored, fresh)
    assert cmp.only_a == 0 and cmp.only_b == 0, "the stored grid differs from the config's"
    assert within(cmp, **tol), (
        f"{name}: {cmp.n_differ} of {cmp.n_common} cells differ, "
        f"boundary shift {cmp.max_shift_g:.3g} g"
    )


def test_multidrum_robust_cells_are_reproduced(tmp_path):
    """The whole 8-drum study (464 cells, seconds with the compiled kernel) against
    its stored ensemble domain (results/harmonic_multidrum_ensemble, made with
    --ensemble 8): on cells whose 8 perturbed members all agree (collapse_fraction
    0 or 1) the outcome must be the same; sensitive cells are not scored. At most
    1 % of robust cells may differ (8 members do not prove a cell robust; here 0)."""
    ens = read_domain(RESULTS / "harmonic_multidrum_ensemble" / "domain.csv")
    cfg = load_config(CONFIGS / "harmonic_multidrum.yaml")
    fresh = read_domain(run_sweep(cfg, tmp_path, jobs=2).folder / "domain.csv")
    merged = ens.merge(fresh, on=["amplitude_g", "frequency_hz"], suffixes=("_ens", ""))
    assert len(merged) == len(ens) == len(fresh)
    robust = merged[merged["collapse_fraction"].isin([0.0, 1.0])]
    assert len(robust) >= 0.8 * len(merged)
    differ = int((robust["collapse_fraction"] != robust["collapsed"]).sum())
    assert differ <= 0.01 * len(robust), f"{differ} of {len(robust)} robust cells differ"


def test_ci_subgrid_matches_the_full_stored_domain():
    """The CI sub-grid of the 8-drum study is the full study on those cells."""
    full = read_domain(RESULTS / "harmonic_multidrum" / "domain.csv")
    sub = read_domain(RESULTS / "harmonic_multidrum_ci" / "domain.csv")
    cmp = compare(full, sub)
    assert cmp.only_b == 0 and cmp.n_common == len(sub)
    assert cmp.n_differ == 0


def test_a_perturbed_model_fails_the_comparison(tmp_path):
    """Guards the regression itself: a 10 % narrower base (alpha 0.25 -> 0.225)
    must be caught by the tolerance used above."""
    cfg = load_config(STUDIES["spanos_koh_slender"][0])
    narrow = dataclasses.replace(cfg, column=dataclasses.replace(cfg.column, base_width=0.9))
    narrow = dataclasses.replace(narrow, column=dataclasses.replace(narrow.column, top_width=0.9))
    summary = run_sweep(narrow, tmp_path, jobs=2)
    stored = read_domain(RESULTS / "spanos_koh_slender" / "domain.csv")
    cmp = compare(stored, read_domain(summary.folder / "domain.csv"))
    assert not within(cmp, **MONOLITHIC)
