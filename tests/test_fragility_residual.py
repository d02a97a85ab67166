"""`rbm fragility --residual-states`: a fragility curve per threshold of the residual slip.

The domains are made here, as a contact engine's suite would hold them: each record has a
collapse capacity drawn from a lognormal, and a run below it slides for good by
SLIP x (x / capacity) metres (``residual_slip_m``; empty where it collapsed). Expected
values are re-derived, not copied: each state's median, beta and intervals are those of a
plain `rbm fragility` (a separate call, the same seed) on the domain whose outcomes the test
rewrites as "residual_slip_m >= t or collapsed"; and state t's capacity is (t / SLIP) x
capacity, so its median is (t / SLIP) x theta and its beta the generating one (within four
standard errors). Refusals: one line, exit 2, nothing written.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

import rbm
from rbm_cli.base.errors import RbmError
from tests.fragility_domains import exceeding, invoke, write

THETA, BETA = 0.4, 0.35
#: The residual slip a run reaches just below its collapse [m].
SLIP = 0.1
LEVELS = np.round(np.arange(0.05, 1.0001, 0.05), 10)


def suite(n_records=120, seed=3, failed=0):
    """Capacities ~ lognormal(THETA, BETA); a run collapses at x >= capacity (no residual
    slip: empty), else it slid SLIP x (x / capacity) [m]; ``failed`` runs at random."""
    rng = np.random.default_rng(seed)
    capacity = THETA * np.exp(BETA * rng.standard_normal(n_records))
    rows = []
    for r, c in enumerate(capacity):
        for x in LEVELS:
            hit = bool(x >= c)
            rows.append({
                "record": f"rec{r:03d}",
                "amplitude_g": x,
                "status": "collapsed" if hit else "survived",
                "collapsed": int(hit),
                "max_rotation_ratio": 1.0 if hit else 0.5 * x / c,
                "residual_slip_m": math.nan if hit else SLIP * x / c,
                "message": "",
            })  # fmt: skip
    df = pd.DataFrame(rows)
    if failed:
        i = rng.choice(len(df), failed, replace=False)
        df.loc[i, ["status", "collapsed", "residual_slip_m"]] = ["failed", 0, math.nan]
    return df


def test_each_residual_state_is_the_plain_fit_of_its_own_outcomes(tmp_path):
    """Each residual state's median, beta and intervals equal those of a separate plain
    fit of the domain whose outcomes are rewritten as 'residual slip >= t or collapsed'
    (same seed); failed runs stay failed; one csv, one figure, fragility.json names them."""
    df = suite(failed=9)
    domain = write(tmp_path / "suite", df)
    thresholds = (0.02, 0.05, 0.08)
    run = invoke(domain, "-o", tmp_path / "out", "--resamples", 200, "--seed", 11,
                 "--residual-states", ",".join(map(str, thresholds)))  # fmt: skip
    assert run.exit_code == 0, run.output
    assert "residual states (residual_slip_m, amplitude_g):" in run.output
    out = tmp_path / "out"
    table = pd.read_csv(out / "fragility_residual.csv")
    assert (out / "fragility_residual.png").read_bytes().startswith(b"\x89PNG\r\n\x1a\n")
    assert not (out / "fragility_states.csv").exists()
    assert list(table["damage_state"]) == list(thresholds)
    assert set(table["state_column"]) == {"residual_slip_m"}
    for t, row in zip(thresholds, table.itertuples(), strict=True):
        plain = write(tmp_path / f"state_{t}", exceeding(df, "residual_slip_m", t))
        again = invoke(plain, "-o", tmp_path / f"plain_{t}", "--resamples", 200, "--seed", 11)
        assert again.exit_code == 0, again.output
        fit = json.loads((tmp_path / f"plain_{t}" / "fragility.json").read_text())
        assert row.median == pytest.approx(fit["median_g"], rel=1e-10)
        assert row.beta == pytest.approx(fit["beta"], rel=1e-10)
        assert [row.median_ci_low, row.median_ci_high] == pytest.approx(fit["median_ci_g"],
                                                                         rel=1e-10)  # fmt: skip
        assert [row.beta_ci_low, row.beta_ci_high] == pytest.approx(fit["beta_ci"], rel=1e-10)
        assert row.n_runs == fit["n_runs"] and row.n_failed == fit["n_failed"] == 9
    summary = json.loads((out / "fragility.json").read_text())
    assert summary["residual_states"] == list(thresholds)


def test_residual_states_of_a_scaled_capacity_have_its_median_and_dispersion():
    """Residual slip SLIP x / capacity: a run exceeds state t where x >= (t / SLIP)
    capacity, so the state's capacities are lognormal((t / SLIP) theta, beta): the fitted
    medians are (t / SLIP) theta and the dispersions beta, within four standard errors of
    300 capacities (through the library)."""
    n = 300
    states = rbm.fragility(suite(n_records=n, seed=5), residual_states=[0.025, 0.05],
                           n_resamples=0)  # fmt: skip
    assert states.measure.column == "residual_slip_m"
    for t, res in zip(states.thresholds, states.results, strict=True):
        median = (t / SLIP) * THETA
        # the intensities are 0.05 apart: the capacity is read to that step
        se = BETA / math.sqrt(n) + 0.05 / median
        assert math.log(res.fit.median_g / median) == pytest.approx(0.0, abs=4 * se)
        assert res.fit.beta == pytest.approx(BETA, abs=4 * BETA / math.sqrt(2 * n) + 0.1)


def test_the_library_gives_the_command_s_states(tmp_path):
    """rbm.fragility(..., residual_states=...) gives the medians and betas of the command's
    fragility_residual.csv."""
    df = suite(n_records=40)
    domain = write(tmp_path / "s", df)
    run = invoke(domain, "-o", tmp_path / "o", "--resamples", 0, "--residual-states", "0.01,0.04")
    assert run.exit_code == 0, run.output
    table = pd.read_csv(tmp_path / "o" / "fragility_residual.csv")
    states = rbm.fragility(domain, residual_states=(0.01, 0.04), n_resamples=0)
    assert list(states.table()["median"]) == pytest.approx(list(table["median"]), rel=1e-12)
    assert list(states.table()["beta"]) == pytest.approx(list(table["beta"]), rel=1e-12)


def test_damage_and_residual_states_together_and_the_residual_files_go_with_their_set(tmp_path):
    """Both options in one run write both sets of files; a later run without
    --residual-states removes the residual states' files of the set it replaces."""
    domain = write(tmp_path / "s", suite(n_records=30))
    out = tmp_path / "o"
    run = invoke(domain, "-o", out, "--resamples", 0, "--damage-states", "0.3,1.0",
                 "--residual-states", "0.02")  # fmt: skip
    assert run.exit_code == 0, run.output
    for name in ("fragility_states.csv", "fragility_residual.csv", "fragility_residual.png"):
        assert (out / name).is_file(), name
    assert pd.read_csv(out / "fragility_states.csv")["state_column"].iat[0] == "max_rotation_ratio"
    run = invoke(domain, "-o", out, "--resamples", 0, "--damage-states", "0.3,1.0")
    assert run.exit_code == 0, run.output
    assert (out / "fragility_states.csv").is_file()
    assert not (out / "fragility_residual.csv").exists()
    assert not (out / "fragility_residual.png").exists()


@pytest.mark.parametrize(
    ("value", "needle"),
    [("0", "> 0"), ("-0.01", "> 0"), ("0.05,0.02", "increasing"), ("abc", "separated by"),
     ("nan", "finite"), ("inf", "finite"), ("0.01,0.01", "increasing")],
)  # fmt: skip
def test_bad_thresholds_are_refused_in_one_line(tmp_path, value, needle):
    domain = write(tmp_path / "s", suite(n_records=5))
    out = tmp_path / "out"
    run = invoke(domain, "-o", out, "--residual-states", value)
    assert run.exit_code == 2, run.output
    lines = run.output.strip().splitlines()
    assert len(lines) == 1 and "--residual-states" in lines[0] and needle in lines[0], run.output
    assert "Traceback" not in run.output
    assert not out.exists() or not any(out.iterdir())


def test_a_slip_of_a_metre_and_more_is_a_threshold_not_collapse(tmp_path):
    """A residual state has no upper bound (unlike a peak rotation ratio's 1): 1.5 m is a
    threshold, which no run of this suite reaches short of collapse."""
    states = rbm.fragility(suite(n_records=30), residual_states=[1.5], n_resamples=0)
    plain = rbm.fragility(suite(n_records=30), n_resamples=0)
    assert states.results[0].fit.median_g == pytest.approx(plain.fit.median_g, rel=1e-12)


def test_a_domain_without_the_residual_slip_is_refused_in_one_line(tmp_path):
    """A domain of a model without residual slip (no residual_slip_m column, as every model
    but the contact engine writes) is refused in one line naming the option."""
    domain = write(tmp_path / "s", suite(n_records=5).drop(columns=["residual_slip_m"]))
    run = invoke(domain, "-o", tmp_path / "out", "--residual-states", "0.01")
    assert run.exit_code == 2, run.output
    lines = run.output.strip().splitlines()
    assert len(lines) == 1 and "--residual-states" in lines[0], run.output
    assert "residual_slip_m" in lines[0] and "Traceback" not in run.output
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


@pytest.mark.parametrize("value", [[0.05, 0.02], [0.0], [-1.0], [], "0.5", [True], [math.inf]])
def test_api_refuses_bad_thresholds_in_one_line(value):
    with pytest.raises(RbmError) as info:
        rbm.fragility(suite(n_records=5), residual_states=value, n_resamples=0)
    assert "residual_states" in str(info.value) and "\n" not in str(info.value)


def test_api_refuses_both_sets_at_once_and_a_domain_without_the_column():
    with pytest.raises(RbmError, match="give one"):
        rbm.fragility(suite(n_records=5), damage_states=[0.5], residual_states=[0.01])
    with pytest.raises(RbmError, match="residual_states") as info:
        rbm.fragility(suite(n_records=5).drop(columns=["residual_slip_m"]),
                      residual_states=[0.01], n_resamples=0)  # fmt: skip
    assert "\n" not in str(info.value)
