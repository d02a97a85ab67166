"""Fragility on any intensity measure, and of ensemble domains (members or majority).

The fits are checked against the binomial likelihood written here and maximised by
scipy.optimize on counts computed by hand from the synthetic domain, never against the
code's own output.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from scipy.optimize import minimize
from scipy.stats import norm

import rbm
from rbm_cli.base.errors import RbmError
from rbm_cli.cli.main import cli
from rbm_cli.report.fragility_report import fragility_summary
from rbm_cli.report.fragility_run import intensity_label
from rbm_cli.study.fragility import fragility

LEVELS = (0.2, 0.4, 0.6, 0.8)
#: Per record: the collapse fraction of its 16 members at each level, and member 0's own
#: outcome. Member 0 is the row; the majority collapses where the fraction >= 0.5.
FRACTIONS = {
    "r1": (0.0, 0.25, 0.75, 1.0),
    "r2": (0.0, 0.0, 0.5, 1.0),
    "r3": (0.125, 0.5, 0.875, 1.0),
    "r4": (0.0, 0.0, 0.25, 0.625),
    "r5": (0.0, 0.375, 0.625, 1.0),
}
MEMBER0 = {
    "r1": (0, 1, 0, 1),  # differs from the majority at 0.4 and 0.6
    "r2": (0, 0, 0, 1),  # differs at 0.6 (fraction 0.5: the majority collapses)
    "r3": (0, 1, 1, 1),
    "r4": (0, 0, 1, 0),  # differs at 0.6 and 0.8
    "r5": (0, 0, 1, 1),
}


def _domain() -> pd.DataFrame:
    rows = []
    for record, fractions in FRACTIONS.items():
        for level, f, c in zip(LEVELS, fractions, MEMBER0[record], strict=True):
            rows.append({"record": record, "amplitude_g": level,
                         "pgv_m_s": 0.5 * level * (1 + int(record[1:]) / 10),
                         "status": "collapsed" if c else "survived", "collapsed": c,
                         "collapse_fraction": f, "robust": int(f in (0.0, 1.0)),
                         "max_rotation_ratio": 1.0 if c else level})  # fmt: skip
    return pd.DataFrame(rows)


def _mle(x, n, k):
    """The lognormal MLE of binomial counts (n trials, k collapses at intensities x),
    written here: scipy's Nelder-Mead on the negative log-likelihood."""
    x, n, k = (np.asarray(v, float) for v in (x, n, k))

    def nll(params):
        theta, beta = math.exp(params[0]), math.exp(params[1])
        p = np.clip(norm.cdf(np.log(x / theta) / beta), 1e-300, 1 - 1e-16)
        return -np.sum(k * np.log(p) + (n - k) * np.log1p(-p))

    res = minimize(nll, [math.log(0.5), math.log(0.4)], method="Nelder-Mead",
                   options={"xatol": 1e-10, "fatol": 1e-12, "maxiter": 20000})  # fmt: skip
    return math.exp(res.x[0]), math.exp(res.x[1])


def _counts(outcomes: dict, weight: float = 1.0):
    """Per level: trials and collapses, counted by hand from per-record outcomes."""
    n = [weight * len(outcomes)] * len(LEVELS)
    k = [weight * sum(o[j] for o in outcomes.values()) for j in range(len(LEVELS))]
    return n, k


@pytest.mark.parametrize("how", ["member0", "majority", "members"])
def test_each_outcome_fits_its_own_counts(how):
    if how == "member0":
        n, k = _counts(MEMBER0)
    elif how == "majority":
        n, k = _counts({r: [int(f >= 0.5) for f in fs] for r, fs in FRACTIONS.items()})
    else:
        n, k = _counts(FRACTIONS, 16.0)
    theta, beta = _mle(LEVELS, n, k)
    res = fragility(_domain(), n_resamples=0, ensemble_outcome=how, n_members=16)
    assert res.fit.median_g == pytest.approx(theta, rel=1e-5)
    assert res.fit.beta == pytest.approx(beta, rel=1e-5)
    assert res.ensemble_outcome == how
    np.testing.assert_allclose(res.table["n_collapsed"], k)
    if how == "members":
        assert list(res.table["n_trials"]) == [80] * 4


def test_member0_and_majority_differ():
    """The synthetic domain is built so the two fits differ: majority has 0, 1, 4, 5
    collapses of 5 at the four levels, member 0 has 0, 2, 3, 4."""
    a = fragility(_domain(), n_resamples=0, ensemble_outcome="member0")
    b = fragility(_domain(), n_resamples=0, ensemble_outcome="majority")
    assert list(a.table["n_collapsed"]) == [0, 2, 3, 4]
    assert list(b.table["n_collapsed"]) == [0, 1, 4, 5]
    assert abs(a.fit.median_g - b.fit.median_g) > 0.01 or abs(a.fit.beta - b.fit.beta) > 0.05


def test_members_without_their_number_is_the_same_fit():
    known = fragility(_domain(), n_resamples=0, ensemble_outcome="members", n_members=16)
    unknown = fragility(_domain(), n_resamples=0, ensemble_outcome="members")
    assert unknown.fit.median_g == pytest.approx(known.fit.median_g, rel=1e-6)
    assert unknown.fit.beta == pytest.approx(known.fit.beta, rel=1e-6)
    assert "unknown" in unknown.outcome and "16 per cell" in known.outcome


def test_a_plain_domain_ignores_the_ensemble_outcome():
    df = _domain().drop(columns=["collapse_fraction", "robust"])
    a = fragility(df, n_resamples=0, ensemble_outcome="majority")
    assert a.ensemble_outcome is None and a.outcome == "each run a trial"
    assert list(a.table["n_collapsed"]) == [0, 2, 3, 4]


def test_all_members_failed_is_a_failed_run_and_failures_at_the_top_warn():
    df = _domain()
    top = df["amplitude_g"] == 0.8
    df.loc[top & df["record"].isin(["r1", "r2"]), ["collapse_fraction", "status", "collapsed"]] = (
        np.nan, "failed", 0)  # fmt: skip
    res = fragility(df, n_resamples=0, ensemble_outcome="majority")
    assert list(res.table["n_failed"]) == [0, 0, 0, 2]
    assert "2 of the 2 failed runs" in res.warning
    summary = fragility_summary(res)
    assert summary["failed_by_intensity"][-1] == {"intensity": 0.8, "n_failed": 2}
    assert summary["warning"] == res.warning and summary["ensemble_outcome"] == "majority"
    json.dumps(summary, allow_nan=False)
    low = _domain()
    low.loc[(low["amplitude_g"] == 0.2) & low["record"].isin(["r1", "r2"]),
            ["collapse_fraction", "status", "collapsed"]] = (np.nan, "failed", 0)  # fmt: skip
    assert fragility(low, n_resamples=0, ensemble_outcome="majority").warning == ""


def test_fit_on_another_intensity_measure():
    df = _domain()
    res = rbm.fragility(df, n_resamples=0, intensity="pgv_m_s", ensemble_outcome="member0")
    x = df["pgv_m_s"].to_numpy()
    theta, beta = _mle(x, np.ones(x.size), df["collapsed"].to_numpy())
    assert res.fit.median_g == pytest.approx(theta, rel=1e-5)
    assert res.fit.beta == pytest.approx(beta, rel=1e-5)
    assert res.intensity_unit == "m/s" and res.intensity_column == "pgv_m_s"
    assert intensity_label("pgv_m_s") == "intensity: peak ground velocity PGV [m/s]"
    assert intensity_label("sa_0p5s_g") == "intensity: Sa(0.5 s, 5 %) [g]"
    assert intensity_label("pga_over_g_tan_alpha").endswith("[-]")
    with pytest.raises(RbmError, match="name two columns"):
        rbm.fragility(df, intensity="pgv_m_s", intensity_column="amplitude_g")
    with pytest.raises(RbmError, match="missing column 'sa_t1_g'"):
        rbm.fragility(df, intensity="sa_t1_g")


def test_cli_intensity_and_ensemble_outcome(tmp_path):
    folder = tmp_path / "suite"
    folder.mkdir()
    _domain().to_csv(folder / "domain.csv", index=False)
    (folder / "meta.json").write_text(json.dumps({"name": "suite", "ensemble": {"members": 16}}))
    res = CliRunner().invoke(cli, ["fragility", str(folder / "domain.csv"), "--resamples", "0",
                                   "--intensity", "pgv_m_s", "--ensemble-outcome", "majority",
                                   "-o", str(tmp_path / "out")])  # fmt: skip
    assert res.exit_code == 0, res.output
    assert "intensity: pgv_m_s [m/s]; trials: each cell a trial, collapsed when most" in res.output
    assert " m/s, dispersion beta" in res.output
    saved = json.loads((tmp_path / "out" / "fragility.json").read_text())
    assert saved["ensemble_outcome"] == "majority" and saved["intensity_unit"] == "m/s"
    res = CliRunner().invoke(cli, ["fragility", str(folder / "domain.csv"), "--resamples", "0",
                                   "-o", str(tmp_path / "out2")])  # fmt: skip
    assert res.exit_code == 0, res.output
    assert "every ensemble member a trial (16 per cell)" in res.output
    bad = CliRunner().invoke(cli, ["fragility", str(folder / "domain.csv"),
                                   "--ensemble-outcome", "most"])  # fmt: skip
    assert bad.exit_code != 0 and "Traceback" not in bad.output
