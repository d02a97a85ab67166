"""`rbm fragility --damage-states`: a fragility curve per threshold of max_rotation_ratio.

The domains are made here: each record has a capacity drawn from a lognormal and a peak
rotation ratio that grows with the intensity. Expected values are re-derived, not copied:
each state's median, beta and intervals are those of a plain `rbm fragility` (a separate
call, the same seed) on the domain whose outcomes the test rewrites as "max_rotation_ratio
>= t or collapsed"; where the ratio is x / capacity, state t's capacity is t x capacity, so
its median is t x theta and its beta the generating one (within four standard errors).
Refusals: one line, exit 2, nothing written.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest
from scipy.stats import norm

import rbm
from rbm_cli.base.errors import RbmError
from rbm_cli.report import fragility_run
from rbm_cli.study.fragility_states import crossing_intensity
from tests.fragility_domains import exceeding, invoke, write

THETA, BETA = 0.4, 0.35
LEVELS = np.round(np.arange(0.05, 1.0001, 0.05), 10)
PNG = b"\x89PNG\r\n\x1a\n"


def suite(n_records=120, seed=3, exponent=None, failed=0):
    """Capacities ~ lognormal(THETA, BETA); a run collapses at x >= capacity, else its peak
    ratio is (x / capacity) ** g (g = 1, or per record from ``exponent``: a spread of the
    states' dispersions); ``failed`` runs marked failed at random."""
    rng = np.random.default_rng(seed)
    capacity = THETA * np.exp(BETA * rng.standard_normal(n_records))
    power = np.ones(n_records) if exponent is None else rng.uniform(*exponent, n_records)
    rows = []
    for r, (c, g) in enumerate(zip(capacity, power, strict=True)):
        for x in LEVELS:
            hit = bool(x >= c)
            rows.append({
                "record": f"rec{r:03d}",
                "amplitude_g": x,
                "status": "collapsed" if hit else "survived",
                "collapsed": int(hit),
                "max_rotation_ratio": 1.0 if hit else (x / c) ** g,
                "message": "",
            })  # fmt: skip
    df = pd.DataFrame(rows)
    if failed:
        i = rng.choice(len(df), failed, replace=False)
        df.loc[i, ["status", "collapsed", "max_rotation_ratio"]] = ["failed", 0, math.nan]
    return df


def states_table(folder):
    return pd.read_csv(folder / "fragility_states.csv")


def test_each_state_is_the_plain_fit_of_its_own_outcomes(tmp_path):
    """Each state's median, beta and intervals equal those of a separate plain fit of the
    domain whose outcomes are rewritten as 'ratio >= t or collapsed' (same seed); failed
    runs stay failed."""
    df = suite(exponent=(0.6, 1.6), failed=9)
    domain = write(tmp_path / "suite", df)
    thresholds = (0.15, 0.4, 0.7, 1.0)
    run = invoke(domain, "-o", tmp_path / "out", "--resamples", 200, "--seed", 11,
                 "--damage-states", ",".join(map(str, thresholds)))  # fmt: skip
    assert run.exit_code == 0, run.output
    table = states_table(tmp_path / "out")
    assert list(table["damage_state"]) == list(thresholds)
    for t, row in zip(thresholds, table.itertuples(), strict=True):
        plain = write(tmp_path / f"state_{t}", exceeding(df, "max_rotation_ratio", t))
        out = tmp_path / f"plain_{t}"
        again = invoke(plain, "-o", out, "--resamples", 200, "--seed", 11)
        assert again.exit_code == 0, again.output
        fit = json.loads((out / "fragility.json").read_text())
        assert row.median == pytest.approx(fit["median_g"], rel=1e-10)
        assert row.beta == pytest.approx(fit["beta"], rel=1e-10)
        assert [row.median_ci_low, row.median_ci_high] == pytest.approx(fit["median_ci_g"],
                                                                         rel=1e-10)  # fmt: skip
        assert [row.beta_ci_low, row.beta_ci_high] == pytest.approx(fit["beta_ci"], rel=1e-10)
        assert row.n_runs == fit["n_runs"] and row.n_failed == fit["n_failed"] == 9
    assert np.all(np.diff(table["median"]) > 0.0), "medians must rise with the threshold"
    summary = json.loads((tmp_path / "out" / "fragility.json").read_text())
    assert summary["damage_states"] == list(thresholds)


def test_states_of_a_scaled_capacity_have_its_median_and_dispersion(tmp_path):
    """Ratio x / capacity: a run exceeds state t where x >= t capacity, so state t's
    capacities are lognormal(t theta, beta): the fitted medians are t x theta and the
    dispersions beta, within four standard errors of 300 capacities."""
    n = 300
    df = suite(n_records=n, seed=5)
    thresholds = (0.25, 0.5, 1.0)
    res = rbm.fragility(df, damage_states=thresholds, n_resamples=0)
    se_log, se_beta = BETA / math.sqrt(n), BETA / math.sqrt(2 * n)
    for t, state in zip(thresholds, res.results, strict=True):
        assert abs(math.log(state.fit.median_g / (t * THETA))) < 4 * se_log + 0.02
        assert abs(state.fit.beta - BETA) < 4 * se_beta + 0.02
    medians = [r.fit.median_g for r in res.results]
    assert medians == sorted(medians)
    assert res.crossings == ()


def test_api_states_equal_the_api_fit_of_each_rewritten_domain():
    df = suite(n_records=40, exponent=(0.5, 2.0))
    res = rbm.fragility(df, damage_states=[0.2, 0.6, 1.0], n_resamples=50, seed=2)
    for t, state in zip(res.thresholds, res.results, strict=True):
        plain = rbm.fragility(exceeding(df, "max_rotation_ratio", t), n_resamples=50, seed=2)
        assert state.fit.median_g == pytest.approx(plain.fit.median_g, rel=1e-12)
        assert state.fit.beta == pytest.approx(plain.fit.beta, rel=1e-12)
        assert state.beta_ci == pytest.approx(plain.beta_ci, rel=1e-12)
    assert list(res.table()["damage_state"]) == [0.2, 0.6, 1.0]


def test_an_ensemble_domain_counts_member_0(tmp_path):
    """The domain holds member 0's peak rotation only: its collapse state is the plain fit
    with --ensemble-outcome member0 (each row its own run), not the members' count."""
    df = suite(n_records=50, seed=8)
    rng = np.random.default_rng(1)
    df["collapse_fraction"] = np.clip(df["collapsed"] + rng.uniform(-0.3, 0.3, len(df)), 0, 1)
    domain = write(tmp_path / "ens", df)
    run = invoke(domain, "-o", tmp_path / "a", "--resamples", 0, "--damage-states", "1")
    assert run.exit_code == 0, run.output
    assert "member 0" in run.output
    plain = invoke(domain, "-o", tmp_path / "b", "--resamples", 0, "--ensemble-outcome",
                   "member0")  # fmt: skip
    assert plain.exit_code == 0, plain.output
    fit = json.loads((tmp_path / "b" / "fragility.json").read_text())
    row = states_table(tmp_path / "a").iloc[0]
    assert row["median"] == pytest.approx(fit["median_g"], rel=1e-10)
    assert row["beta"] == pytest.approx(fit["beta"], rel=1e-10)


def test_figures_are_pngs_and_the_ida_marks_the_thresholds(tmp_path):
    df = suite(n_records=30)
    domain = write(tmp_path / "s", df)
    run = invoke(domain, "-o", tmp_path / "o", "--resamples", 20, "--damage-states",
                 "0.1,0.3,1.0")  # fmt: skip
    assert run.exit_code == 0, run.output
    for name in ("fragility_states.png", "ida.png", "fragility.png"):
        data = (tmp_path / "o" / name).read_bytes()
        assert data.startswith(PNG) and len(data) > 1000, name
    fig = fragility_run.ida_figure(df, "amplitude_g", "PGA [g]", thresholds=(0.1, 0.3, 1.0))
    ax = fig.axes[0]
    marks = {line.get_gid(): line.get_xdata()[0] for line in ax.lines
             if str(line.get_gid()).startswith("state:")}  # fmt: skip
    assert marks == {"state:0.1": 0.1, "state:0.3": 0.3}  # 1 is the collapse limit's line
    states = rbm.fragility(df, damage_states=(0.1, 0.3, 1.0), n_resamples=0)
    ax = fragility_run.states_figure(states, "PGA [g]").axes[0]
    fitted = {line.get_gid(): line for line in ax.lines}
    for t, res in zip(states.thresholds, states.results, strict=True):
        line = fitted[f"fitted:{t:g}"]
        x, y = line.get_xdata(), line.get_ydata()
        inside = x > 0
        expected = norm.cdf(np.log(x[inside] / res.fit.median_g) / res.fit.beta)
        assert np.allclose(y[inside], expected, atol=1e-12)


def test_crossing_intensity_is_where_the_curves_meet():
    x = crossing_intensity(0.3, 0.2, 0.5, 0.6)
    a = norm.cdf(math.log(x / 0.3) / 0.2)
    b = norm.cdf(math.log(x / 0.5) / 0.6)
    assert a == pytest.approx(b, abs=1e-12)
    assert math.isnan(crossing_intensity(0.3, 0.4, 0.5, 0.4))


def test_crossing_curves_are_reported(tmp_path):
    """A low state of wide dispersion and a collapse of narrow dispersion: the fitted
    curves cross inside the intensities tested (found here on a grid), and the output
    says so, naming both states."""
    rng = np.random.default_rng(4)
    n = 150
    c1 = 0.5 * np.exp(0.08 * rng.standard_normal(n))
    c_low = np.minimum(0.35 * np.exp(0.9 * rng.standard_normal(n)), c1)
    rows = []
    for r in range(n):
        for x in LEVELS:
            hit = x >= c1[r]
            ratio = 1.0 if hit else (0.6 if x >= c_low[r] else 0.2)
            rows.append({"record": f"r{r}", "amplitude_g": x, "collapsed": int(hit),
                         "status": "collapsed" if hit else "survived",
                         "max_rotation_ratio": ratio})  # fmt: skip
    df = pd.DataFrame(rows)
    states = rbm.fragility(df, damage_states=(0.5, 1.0), n_resamples=0)
    low, high = (r.fit for r in states.results)
    grid = np.linspace(LEVELS[0], LEVELS[-1], 2001)
    diff = norm.cdf(np.log(grid / low.median_g) / low.beta) - norm.cdf(
        np.log(grid / high.median_g) / high.beta
    )
    assert np.any(diff < 0) and np.any(diff > 0), "the case must cross inside the range"
    run = invoke(write(tmp_path / "x", df), "-o", tmp_path / "o", "--resamples", 0,
                 "--damage-states", "0.5,1")  # fmt: skip
    assert run.exit_code == 0, run.output
    warned = [line for line in run.output.splitlines() if line.startswith("warning:")]
    assert len(warned) == 1 and "0.5 and 1" in warned[0] and "cross" in warned[0], run.output


@pytest.mark.parametrize(
    "value, needle",
    [
        ("0", "> 0"),
        ("-0.1,1", "> 0"),
        ("0.2,1.5", "<= 1"),
        ("nan", "finite"),
        ("0.1,inf", "finite"),
        ("0.3,0.1", "strictly increasing"),
        ("0.2,0.2", "strictly increasing"),
        ("0.1,x", "separated by commas"),
        ("", "separated by commas"),
    ],
)
def test_bad_thresholds_are_refused_in_one_line(tmp_path, value, needle):
    domain = write(tmp_path / "s", suite(n_records=5))
    out = tmp_path / "out"
    run = invoke(domain, "-o", out, "--damage-states", value)
    assert run.exit_code == 2, run.output
    lines = run.output.strip().splitlines()
    assert len(lines) == 1 and "--damage-states" in lines[0] and needle in lines[0], run.output
    assert "Traceback" not in run.output
    assert not out.exists() or not any(out.iterdir())


def test_a_domain_without_the_ratio_is_refused_in_one_line(tmp_path):
    domain = write(tmp_path / "s", suite(n_records=5).drop(columns=["max_rotation_ratio"]))
    run = invoke(domain, "-o", tmp_path / "out", "--damage-states", "0.5")
    assert run.exit_code == 2, run.output
    assert len(run.output.strip().splitlines()) == 1 and "max_rotation_ratio" in run.output
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


@pytest.mark.parametrize("value", [[0.5, 0.2], [0.0], [1.2], [], "0.5", [True]])
def test_api_refuses_bad_thresholds_in_one_line(value):
    with pytest.raises(RbmError) as info:
        rbm.fragility(suite(n_records=5), damage_states=value, n_resamples=0)
    assert "damage_states" in str(info.value) and "\n" not in str(info.value)


def test_a_run_without_states_removes_the_states_of_the_set_it_replaces(tmp_path):
    """The folder never holds one run's damage states beside another run's fit: the states'
    files of the set being replaced go with it; a file of that name that no fragility.json
    claims is not the set's, and stays."""
    domain = write(tmp_path / "s", suite(n_records=30))
    out = tmp_path / "o"
    run = invoke(domain, "-o", out, "--resamples", 0, "--damage-states", "0.3,1.0")
    assert run.exit_code == 0, run.output
    assert (out / "fragility_states.csv").is_file() and (out / "fragility_states.png").is_file()
    run = invoke(domain, "-o", out, "--resamples", 0)
    assert run.exit_code == 0, run.output
    assert not (out / "fragility_states.csv").exists()
    assert not (out / "fragility_states.png").exists()
    assert "damage_states" not in json.loads((out / "fragility.json").read_text())
    mine = out / "fragility_states.csv"
    mine.write_text("the user's own table\n")
    run = invoke(domain, "-o", out, "--resamples", 0)
    assert run.exit_code == 0, run.output
    assert mine.read_text() == "the user's own table\n"
