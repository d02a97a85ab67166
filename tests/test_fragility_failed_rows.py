"""Failed runs never enter a fragility fit: a failed row of an ensemble domain (member 0's
run failed, the other members' fraction kept) is left out under every way of counting.

The fits are checked against the binomial likelihood written here and maximised by
scipy's Nelder-Mead on counts made by hand, never against the code's own output.
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
from rbm_cli.cli.main import cli

LEVELS = (0.2, 0.4, 0.6, 0.8)
#: Per record: the collapse fraction of its 16 members at each level, and member 0's run.
FRACTIONS = {
    "r1": (0.0, 0.25, 0.75, 1.0),
    "r2": (0.0, 0.0, 0.5, 1.0),
    "r3": (0.125, 0.5, 0.875, 1.0),
    "r4": (0.0, 0.0, 0.25, 0.625),
    "r5": (0.0, 0.375, 0.625, 1.0),
}
MEMBER0 = {"r1": (0, 1, 0, 1), "r2": (0, 0, 0, 1), "r3": (0, 1, 1, 1), "r4": (0, 0, 1, 0),
           "r5": (0, 0, 1, 1)}  # fmt: skip
#: Rows whose member 0 failed, their fraction (the other members') kept: all of them at
#: odds with the rest (collapses at the lowest level, a survival at the highest).
FAILED = {("r1", 0.2): 1.0, ("r2", 0.2): 1.0, ("r4", 0.8): 0.0}


def _mle(x, n, k):
    """The lognormal MLE of binomial counts (n trials, k collapses at intensities x)."""
    x, n, k = (np.asarray(v, float) for v in (x, n, k))

    def nll(params):
        theta, beta = math.exp(params[0]), math.exp(params[1])
        p = np.clip(norm.cdf(np.log(x / theta) / beta), 1e-300, 1 - 1e-16)
        return -np.sum(k * np.log(p) + (n - k) * np.log1p(-p))

    best = None
    for start in ([math.log(0.5), math.log(0.4)], [math.log(float(np.max(x))), 0.0]):
        res = minimize(nll, start, method="Nelder-Mead",
                       options={"xatol": 1e-10, "fatol": 1e-12, "maxiter": 20000})  # fmt: skip
        best = res if best is None or res.fun < best.fun else best
    return math.exp(best.x[0]), math.exp(best.x[1])


def ensemble_domain() -> pd.DataFrame:
    rows = []
    for record, fractions in FRACTIONS.items():
        for level, f, c in zip(LEVELS, fractions, MEMBER0[record], strict=True):
            failed = (record, level) in FAILED
            f = FAILED.get((record, level), f)
            status = "failed" if failed else "collapsed" if c else "survived"
            rows.append({"record": record, "amplitude_g": level, "status": status,
                         "collapsed": int(status == "collapsed"), "collapse_fraction": f,
                         "robust": int(f in (0.0, 1.0)),
                         "max_rotation_ratio": 1.0 if c else level})  # fmt: skip
    return pd.DataFrame(rows)


def counts_without_failed(how: str):
    """Per level: trials and collapses of the rows that did not fail, by hand."""
    n, k = [], []
    for j, level in enumerate(LEVELS):
        kept = [r for r in FRACTIONS if (r, level) not in FAILED]
        if how == "members":
            n.append(16.0 * len(kept))
            k.append(16.0 * sum(FRACTIONS[r][j] for r in kept))
        elif how == "majority":
            n.append(float(len(kept)))
            k.append(float(sum(FRACTIONS[r][j] >= 0.5 for r in kept)))
        else:
            n.append(float(len(kept)))
            k.append(float(sum(MEMBER0[r][j] for r in kept)))
    return n, k


@pytest.mark.parametrize("how", ["members", "majority", "member0"])
def test_failed_rows_of_an_ensemble_never_enter_the_fit(how):
    """A failed row of an ensemble domain (member 0's run failed; the fraction of the other
    members kept) was fitted under members and majority ('failed, left out: 0'). Every
    way of counting leaves it out: the fit is the MLE of the other rows' counts."""
    res = rbm.fragility(ensemble_domain(), n_resamples=0, ensemble_outcome=how, n_members=16)
    n, k = counts_without_failed(how)
    theta, beta = _mle(LEVELS, n, k)
    assert res.n_failed == len(FAILED)
    assert list(res.table["n_failed"]) == [2, 0, 0, 1]
    assert res.fit.median_g == pytest.approx(theta, rel=1e-5)
    assert res.fit.beta == pytest.approx(beta, rel=1e-5)


def test_the_command_line_counts_an_ensembles_failed_rows(tmp_path):
    """Through `rbm fragility` on a domain.csv with its meta.json (16 members a cell)."""
    folder = tmp_path / "suite"
    folder.mkdir()
    ensemble_domain().to_csv(folder / "domain.csv", index=False)
    (folder / "meta.json").write_text(json.dumps({"name": "suite", "ensemble": {"members": 16}}))
    res = CliRunner().invoke(cli, ["fragility", str(folder / "domain.csv"), "--resamples", "0"])
    assert res.exit_code == 0, res.output
    assert "(failed, left out: 3)" in res.output
    summary = json.loads((folder / "fragility.json").read_text())
    n, k = counts_without_failed("members")
    theta, beta = _mle(LEVELS, n, k)
    assert summary["n_failed"] == 3 and summary["median_g"] == pytest.approx(theta, rel=1e-5)
    assert summary["beta"] == pytest.approx(beta, rel=1e-5)
