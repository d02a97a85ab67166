"""Regression of the stored domains in results/ (re-made in CI and compared).

Every stored domain here was made as an ensemble of 16 (`rbm sweep --ensemble
16 -o results`): its rows are the plain runs, and its `robust` column says,
by the robustness rule (rbm_cli.study.robustness), which outcomes are facts and which
are accidents of rounding. The regression rule (rbm_cli.study.regression):

- each study is re-made whole as a plain domain, and every robust cell must
  have the same outcome: 0 may differ. Sensitive cells are reported, not scored;
- the 8-drum column is chaotic along its boundary: its CI band
  (configs/ci/harmonic_multidrum_ci.yaml, 66 cells) is re-made as an ensemble
  of 16 too, and its count of sensitive cells may not exceed the stated bound
  (rbm_cli.study.regression.sensitive_bound): a change that makes the model noisier
  fails even if no robust cell moves.

A perturbed model (base width -10 %) must fail the same rule, so this test can
catch a change to the model.
"""

from __future__ import annotations

import dataclasses
import json

import pytest

from rbm_cli.api import run_sweep
from rbm_cli.config.load import load_config
from rbm_cli.study.domain import compare, read_domain
from rbm_cli.study.regression import check
from rbm_cli.study.robustness import MEMBERS, RULE

from .paths import CONFIGS, RESULTS

#: Slow (whole domains re-made, processes killed, contact-engine runs):
#: `pytest -m 'not slow'` leaves this file out.
pytestmark = pytest.mark.slow

STUDIES = {
    # stored result name: config
    "spanos_koh_slender": CONFIGS / "spanos_koh_slender.yaml",
    "spanos_koh_thick": CONFIGS / "spanos_koh_thick.yaml",
    "housner_halfsine": CONFIGS / "housner_halfsine.yaml",
    "spanos_koh_slender_linear": CONFIGS / "spanos_koh_slender_linear.yaml",
    "spanos_koh_thick_linear": CONFIGS / "spanos_koh_thick_linear.yaml",
    "spanos_koh_thick_housner_e": CONFIGS / "spanos_koh_thick_housner_e.yaml",
    "harmonic_monolithic": CONFIGS / "harmonic_monolithic.yaml",
    "harmonic_monolithic_capital": CONFIGS / "harmonic_monolithic_capital.yaml",
    "harmonic_multidrum": CONFIGS / "harmonic_multidrum.yaml",
    "harmonic_multidrum_ci": CONFIGS / "ci" / "harmonic_multidrum_ci.yaml",
    # the exact block (housner) of each monolithic rigid RBM study (tests/test_model_error.py)
    "spanos_koh_slender_housner": CONFIGS / "spanos_koh_slender_housner.yaml",
    "spanos_koh_thick_housner": CONFIGS / "spanos_koh_thick_housner.yaml",
    "spanos_koh_thick_housner_e_housner": CONFIGS / "spanos_koh_thick_housner_e_housner.yaml",
    "housner_halfsine_housner": CONFIGS / "housner_halfsine_housner.yaml",
    "spanos_koh_slender_housner_e": CONFIGS / "spanos_koh_slender_housner_e.yaml",
    "spanos_koh_slender_housner_e_housner": CONFIGS / "spanos_koh_slender_housner_e_housner.yaml",
    # grids over config keys: the size effect, the drum count
    "size_effect": CONFIGS / "size_effect.yaml",
    "drum_count": CONFIGS / "drum_count.yaml",
    # record suites: the monolith whole, the 8-drum column by its CI band
    "suite_monolithic": CONFIGS / "suite_monolithic.yaml",
    "suite_multidrum_ci": CONFIGS / "ci" / "suite_multidrum_ci.yaml",
    # the colonnade (two 8-drum columns under an architrave) by its CI band
    "colonnade_harmonic_ci": CONFIGS / "ci" / "colonnade_harmonic_ci.yaml",
}


@pytest.mark.parametrize("name", sorted(STUDIES))
def test_stored_domain_is_an_ensemble_of_the_rule(name):
    meta = json.loads((RESULTS / name / "meta.json").read_text())
    assert meta["ensemble"]["members"] >= MEMBERS and meta["ensemble"]["rule"] == RULE
    assert "robust" in read_domain(RESULTS / name / "domain.csv").columns


@pytest.mark.parametrize("name", sorted(STUDIES))
def test_robust_cells_are_reproduced(name, tmp_path):
    stored = read_domain(RESULTS / name / "domain.csv")
    fresh = read_domain(run_sweep(load_config(STUDIES[name]), tmp_path, jobs=2).folder
                        / "domain.csv")  # fmt: skip
    result = check(stored, fresh)
    print(f"{name}: {result.summary()}")
    assert result.ok, f"{name}: {result.summary()}"


def test_multidrum_band_is_no_noisier(tmp_path):
    """The chaotic band of the 8-drum study as an ensemble of 16: robust cells the
    same, and no more sensitive cells than the bound."""
    name = "harmonic_multidrum_ci"
    stored = read_domain(RESULTS / name / "domain.csv")
    summary = run_sweep(load_config(STUDIES[name]), tmp_path, jobs=2, ensemble=MEMBERS)
    result = check(stored, read_domain(summary.folder / "domain.csv"))
    print(f"{name} (ensemble): {result.summary()}")
    assert result.fresh_sensitive is not None
    assert result.ok, result.summary()


def test_ci_band_matches_the_full_stored_domain():
    """The CI band of the 8-drum study is the full study on those cells."""
    full = read_domain(RESULTS / "harmonic_multidrum" / "domain.csv")
    sub = read_domain(RESULTS / "harmonic_multidrum_ci" / "domain.csv")
    cmp = compare(full, sub)
    assert cmp.only_b == 0 and cmp.n_common == len(sub)
    assert cmp.n_differ == 0
    merged = full.merge(sub, on=["amplitude_g", "frequency_hz"], suffixes=("", "_ci"))
    assert (merged["robust"] == merged["robust_ci"]).all()


def test_suite_band_matches_the_full_stored_suite():
    """The CI band of the 8-drum suite (4 records, every intensity) is the full stored
    suite on those cells (matched on record and intensity: the band names its files
    relative to configs/ci/)."""
    full = read_domain(RESULTS / "suite_multidrum" / "domain.csv")
    sub = read_domain(RESULTS / "suite_multidrum_ci" / "domain.csv")
    merged = full.merge(sub, on=["record", "amplitude_g"], suffixes=("", "_ci"))
    assert len(merged) == len(sub) == 4 * full["amplitude_g"].nunique()
    both = (merged["robust"] == 1) & (merged["robust_ci"] == 1)
    assert both.sum() >= 0.5 * len(merged)  # mostly robust cells, or the check says little
    assert (merged.loc[both, "collapsed"] == merged.loc[both, "collapsed_ci"]).all()


def test_a_perturbed_model_fails_the_rule(tmp_path):
    """Guards the regression itself: a 10 % narrower base (alpha 0.25 -> 0.225)
    must be caught by the rule used above."""
    cfg = load_config(STUDIES["spanos_koh_slender"])
    narrow = dataclasses.replace(cfg.column, base_width=0.9, top_width=0.9)
    summary = run_sweep(dataclasses.replace(cfg, column=narrow), tmp_path, jobs=2)
    stored = read_domain(RESULTS / "spanos_koh_slender" / "domain.csv")
    result = check(stored, read_domain(summary.folder / "domain.csv"))
    assert not result.ok and result.robust_differ > 10
