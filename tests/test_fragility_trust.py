"""What a fragility fit says: an extrapolated fit is flagged, a fit that cannot be made
says why, and the bootstrap says how many of its resamples it dropped and why.

The fits are checked against the binomial likelihood written here and maximised by
scipy's Nelder-Mead on counts made by hand, never against the code's own output.
"""

from __future__ import annotations

import itertools
import json
import math
import warnings

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from scipy.optimize import minimize
from scipy.stats import norm

import rbm
from rbm_cli.cli.main import cli
from rbm_cli.report.fragility_report import plot_fragility


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


def stripes(collapses, levels=(0.2, 0.4, 0.6), records: int = 10) -> pd.DataFrame:
    """A suite of ``records`` records at ``levels``: at level j the first collapses[j]
    records collapse."""
    rows = [{"record": f"r{r:02d}", "amplitude_g": a, "collapsed": int(r < k),
             "status": "collapsed" if r < k else "survived",
             "max_rotation_ratio": 1.0 if r < k else 0.5}
            for a, k in zip(levels, collapses, strict=True) for r in range(records)]  # fmt: skip
    return pd.DataFrame(rows)


@pytest.mark.parametrize(
    ("collapses", "side"),
    [((0, 1, 2), "above the highest"), ((8, 9, 10), "below the lowest")],
)
def test_a_median_outside_the_intensities_tested_is_flagged(tmp_path, collapses, side):
    """1 and 2 of 10 collapsed at the two top levels: the MLE's median lies above the
    highest level (the fit is the curve's lower tail, extrapolated); mirrored, below the
    lowest. Said in the result, fragility.json, the command's output and the figure."""
    df = stripes(collapses)
    theta, _ = _mle((0.2, 0.4, 0.6), [10] * 3, collapses)
    assert (theta > 0.6) if side.startswith("above") else (theta < 0.2)  # the premise
    res = rbm.fragility(df, n_resamples=0)
    assert res.fit.median_g == pytest.approx(theta, rel=1e-5)
    assert res.fit_warning.startswith("extrapolated fit") and side in res.fit_warning
    folder = tmp_path / "suite"
    folder.mkdir()
    df.to_csv(folder / "domain.csv", index=False)
    out = CliRunner().invoke(cli, ["fragility", str(folder / "domain.csv"), "--resamples", "0"])
    assert out.exit_code == 0, out.output
    assert f"warning: {res.fit_warning}" in out.output.splitlines()
    assert json.loads((folder / "fragility.json").read_text())["fit_warning"] == res.fit_warning
    ax = plot_fragility(res)  # the figure: the warning under the axes, in red
    (note,) = [t for t in ax.texts if t.get_gid() == "fit-warning"]
    assert note.get_color() == "tab:red" and "extrapolated fit" in note.get_text()


def test_a_dispersion_wider_than_the_intensities_tested_is_flagged():
    """1, 2, 3 of 5 at 0.2, 0.4, 0.6 g: the MLE's curve rises from 16 % to 84 % over a
    factor e^(2 beta) wider than the factor 3 the levels span, though its median lies
    among them; a suite whose levels span its curve's rise is not flagged."""
    theta, beta = _mle((0.2, 0.4, 0.6), [5] * 3, (1, 2, 3))
    assert 0.2 < theta < 0.6 and math.exp(2 * beta) > 3.0  # the premise
    res = rbm.fragility(stripes((1, 2, 3), records=5), n_resamples=0)
    assert res.fit_warning.startswith("extrapolated dispersion"), res.fit_warning
    levels = (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0)
    capacities = np.exp(np.log(0.45) + 0.3 * norm.ppf((np.arange(20) + 0.5) / 20))
    rows = [{"record": f"r{r:02d}", "amplitude_g": a, "collapsed": int(a >= c)}
            for r, c in enumerate(capacities) for a in levels]  # fmt: skip
    theta, beta = _mle(levels, [20] * 10, [sum(a >= c for c in capacities) for a in levels])
    assert 0.1 < theta < 1.0 and math.exp(2 * beta) < 10.0  # within the span: no warning
    assert rbm.fragility(pd.DataFrame(rows), n_resamples=0).fit_warning == ""


def test_every_degenerate_suite_says_why():
    """Every suite of 3 records at 3 levels (all 64 tables of collapse counts): with no
    fit its note says why; with a fit but resamples asked and none used, the note on the
    resamples says why; with resamples dropped, how many and why, their counts adding up;
    and no floating-point warning escapes (a fit far out overflowed in the likelihood)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for collapses in itertools.product(range(4), repeat=3):
            res = rbm.fragility(stripes(collapses, records=3), n_resamples=12, seed=3)
            if res.fit is None:
                assert res.note, collapses
                continue
            dropped = sum(count for _, count in res.resamples_dropped)
            assert dropped == 12 - res.n_resamples_used, collapses
            if dropped:
                assert res.resamples_note.startswith(
                    "all 12" if dropped == 12 else f"{dropped} of 12"
                ), res.resamples_note
                for what, count in res.resamples_dropped:
                    assert f"{count} drew {what}" in res.resamples_note
            else:
                assert res.resamples_note == ""


def test_one_mixed_level_says_what_it_saw():
    """0, 0, 1 of 4: only the top level is mixed; the note says so (it said 'all runs
    survive up to 0.6 g and collapse from 0.6 g')."""
    res = rbm.fragility(stripes((0, 0, 1), records=4), n_resamples=0)
    assert res.fit is None
    assert "mixed at one intensity only (0.6 g: 1 of 4 collapsed; every run below it" in res.note
    assert "collapse from" not in res.note


def test_dropped_resamples_are_counted_by_why(tmp_path):
    """One record of 10 collapses (at the two top levels, survives between): a resample
    draws no collapse when it misses that record, with probability (9/10)^10 = 0.349. The
    dropped resamples are counted as such, near that share, and said in the output and
    fragility.json."""
    df = stripes((0, 0, 0, 1, 0, 1), levels=(0.1, 0.2, 0.3, 0.4, 0.5, 0.6))
    res = rbm.fragility(df, n_resamples=600, seed=7)
    reasons = dict(res.resamples_dropped)
    assert sum(reasons.values()) == 600 - res.n_resamples_used
    share = reasons["no collapse"] / 600
    assert abs(share - 0.9**10) < 4 * math.sqrt(0.9**10 * (1 - 0.9**10) / 600)
    assert f"{reasons['no collapse']} drew no collapse" in res.resamples_note
    folder = tmp_path / "suite"
    folder.mkdir()
    df.to_csv(folder / "domain.csv", index=False)
    out = CliRunner().invoke(cli, ["fragility", str(folder / "domain.csv"), "--resamples",
                                   "600", "--seed", "7"])  # fmt: skip
    assert out.exit_code == 0, out.output
    assert f"note: {res.resamples_note}" in out.output.splitlines()
    summary = json.loads((folder / "fragility.json").read_text())
    assert summary["resamples_dropped"] == reasons
    assert summary["resamples_note"] == res.resamples_note
