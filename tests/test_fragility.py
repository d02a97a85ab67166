"""Fragility fitting (lognormal MLE, bootstrap), its files and figures.

Expected values come from closed forms (two levels: the curve passes through both observed
fractions), from a known generating lognormal (record capacities drawn from it), or from the
likelihood written out again here with scipy.stats.
"""

import json
import math

import numpy as np
import pandas as pd
import pytest
from matplotlib.collections import PolyCollection
from scipy.stats import norm

from rbm_cli.base.errors import RbmError
from rbm_cli.report.fragility_report import plot_fragility, plot_ida, write_fragility
from rbm_cli.study.fragility import collapse_probability, fit_lognormal, fragility

LEVELS = np.round(np.arange(0.05, 1.0001, 0.05), 10)


def _ida(n_records, theta, beta, seed, levels=LEVELS, column="intensity_g"):
    """Each record has a capacity ~ lognormal(theta, beta): it collapses at x >= capacity."""
    rng = np.random.default_rng(seed)
    capacity = theta * np.exp(beta * rng.standard_normal(n_records))
    rows = []
    for r, c in enumerate(capacity):
        for x in levels:
            hit = x >= c
            rows.append(
                {
                    "record": f"rec{r:04d}",
                    column: x,
                    "status": "collapsed" if hit else "survived",
                    "collapsed": int(hit),
                    "max_rotation_ratio": 1.0 if hit else x / c,
                }
            )
    return pd.DataFrame(rows)


def _log_likelihood(x, c, theta, beta):
    p = norm.cdf(np.log(np.asarray(x) / theta) / beta)
    c = np.asarray(c)
    return float(np.sum(c * np.log(p) + (1 - c) * np.log1p(-p)))


# --------------------------------------------------------------------------- the fit


def test_two_levels_closed_form():
    """With two levels the MLE curve passes through both fractions (saturated model)."""
    x = [0.2] * 10 + [0.5] * 10
    c = [1] * 3 + [0] * 7 + [1] * 8 + [0] * 2
    fit = fit_lognormal(x, c)
    z1, z2 = norm.ppf(0.3), norm.ppf(0.8)
    beta = (math.log(0.5) - math.log(0.2)) / (z2 - z1)
    theta = math.exp(math.log(0.2) - beta * z1)
    assert fit.beta == pytest.approx(beta, rel=1e-6)
    assert fit.median_g == pytest.approx(theta, rel=1e-6)
    assert collapse_probability(0.2, fit.median_g, fit.beta) == pytest.approx(0.3, abs=1e-7)
    assert fit.log_likelihood == pytest.approx(_log_likelihood(x, c, theta, beta), rel=1e-9)


def test_mle_is_the_maximum_and_consistent():
    """2000 records from lognormal(0.4 g, 0.35): estimates within ~3 standard errors."""
    df = _ida(2000, 0.4, 0.35, seed=21)
    fit = fit_lognormal(df["intensity_g"], df["collapsed"])
    assert fit.median_g == pytest.approx(0.4, rel=0.03)  # se of ln theta ~ 0.008
    assert fit.beta == pytest.approx(0.35, rel=0.06)  # se of beta ~ 0.006
    ll = _log_likelihood(df["intensity_g"], df["collapsed"], fit.median_g, fit.beta)
    assert fit.log_likelihood == pytest.approx(ll, rel=1e-10)
    for dt, db in ((1.01, 1.0), (0.99, 1.0), (1.0, 1.02), (1.0, 0.98)):
        other = _log_likelihood(
            df["intensity_g"], df["collapsed"], fit.median_g * dt, fit.beta * db
        )
        assert other < ll


@pytest.mark.slow
def test_bootstrap_interval_covers_the_generating_lognormal():
    """40 records (a realistic suite): the 5-95 % intervals contain theta and beta."""
    df = _ida(40, 0.4, 0.35, seed=3)
    res = fragility(df, n_resamples=500, seed=1)
    assert res.fitted and res.note == ""
    lo, hi = res.median_ci_g
    assert lo < 0.4 < hi
    assert lo < res.fit.median_g < hi
    lo, hi = res.beta_ci
    assert lo < 0.35 < hi
    assert res.n_resamples == 500 and res.n_resamples_used >= 490
    # the band brackets the fitted curve where it is informative
    mid = np.argmin(np.abs(res.curve["intensity_g"] - res.fit.median_g))
    row = res.curve.iloc[mid]
    assert row["lower"] < row["probability"] < row["upper"]
    assert np.all(res.curve["lower"] <= res.curve["upper"])
    # seeded: the same seed gives the same numbers, another seed other ones
    again = fragility(df, n_resamples=500, seed=1)
    assert again.median_ci_g == res.median_ci_g
    assert fragility(df, n_resamples=500, seed=2).median_ci_g != res.median_ci_g


def test_per_intensity_table_with_failed_runs():
    df = pd.DataFrame(
        {
            "record": ["a", "b", "c", "a", "b", "c", "a", "b", "c"],
            "amplitude_g": [0.1, 0.1, 0.1, 0.2, 0.2, 0.2, 0.3, 0.3, 0.3],
            "status": [
                "survived",
                "failed",
                "survived",
                "collapsed",
                "survived",
                "failed",
                "collapsed",
                "collapsed",
                "survived",
            ],
            "collapsed": [0, 0, 0, 1, 0, 0, 1, 1, 0],
        }
    )
    res = fragility(df, n_resamples=50, seed=0)
    t = res.table
    assert list(t["intensity_g"]) == [0.1, 0.2, 0.3]
    assert list(t["n_records"]) == [2, 2, 3]
    assert list(t["n_failed"]) == [1, 1, 0]
    assert list(t["n_collapsed"]) == [0, 1, 2]
    np.testing.assert_allclose(t["fraction"], [0.0, 0.5, 2 / 3])
    assert res.n_failed == 2 and res.n_runs == 7 and res.n_records == 3
    assert res.intensity_column == "amplitude_g"


@pytest.mark.parametrize(
    ("collapsed", "fragment"),
    [
        ([0, 0, 0, 0, 0, 0], "no record collapsed"),
        ([1, 1, 1, 1, 1, 1], "every record collapsed"),
        ([0, 0, 0, 0, 1, 1], "separated"),  # survive to 0.2 g, collapse from 0.3 g
        ([0, 0, 0, 1, 1, 1], "separated"),  # quasi-separated: mixed only at 0.2 g
        ([1, 1, 0, 1, 0, 0], "no increasing lognormal"),  # collapse falls with intensity
    ],
)
def test_degenerate_data_flagged(tmp_path, collapsed, fragment):
    df = pd.DataFrame(
        {
            "record": list("abababab")[:6],
            "intensity_g": [0.1, 0.1, 0.2, 0.2, 0.3, 0.3],
            "collapsed": collapsed,
        }
    )
    df["record"] = ["a", "b"] * 3
    with pytest.raises(RbmError, match=fragment) as info:
        fit_lognormal(df["intensity_g"], df["collapsed"])
    assert "\n" not in str(info.value)
    res = fragility(df, n_resamples=20)
    assert not res.fitted and fragment in res.note
    assert res.table["n_collapsed"].sum() == sum(collapsed)
    assert res.n_resamples_used == 0
    write_fragility(res, tmp_path)
    data = json.loads((tmp_path / "fragility.json").read_text())
    assert data["fitted"] is False and data["median_g"] is None and fragment in data["note"]
    ax = plot_fragility(res)
    assert not [ln for ln in ax.get_lines() if ln.get_gid() == "fitted"]
    assert any("no fit" in t.get_text() for t in ax.texts)


def test_one_intensity_has_no_curve():
    """Runs at one intensity were called 'separated' ('survive up to 0.3 g and collapse
    from 0.3 g'): a curve through one fraction has no dispersion, and says so."""
    with pytest.raises(RbmError) as info:
        fit_lognormal([0.3] * 4, [1, 0, 1, 0])
    assert "all runs are at one intensity (0.3 g, 2 of 4 collapsed)" in str(info.value)
    assert "collapse from" not in str(info.value)


@pytest.mark.parametrize(
    ("change", "fragment"),
    [
        (lambda d: d.drop(columns="record"), "missing column 'record'"),
        (lambda d: d.drop(columns="intensity_g"), "missing column 'intensity_g'"),
        (lambda d: d.assign(intensity_g=[0.1, 0.0, 0.2, 0.2]), "row 2 (record 'b'): intensity_g"),
        (lambda d: d.assign(collapsed=[0, 2, 1, 0]), "row 2 (record 'b'): collapsed must be"),
        (lambda d: d.assign(status=["ok"] * 4), "row 1 (record 'a'): status must be one of"),
        (lambda d: d.assign(status=["collapsed"] * 4), "row 1 (record 'a'): status 'collapsed'"),
        (lambda d: d.assign(record=["a", "a", "a", "b"]), "row 2: a second run of record 'a'"),
        (lambda d: d.assign(status=["failed"] * 4, collapsed=0), "all 4 runs failed"),
        # a failed run is not a collapse: collapsed 1 beside it is refused, as compare does
        (
            lambda d: d.assign(status=["survived", "failed", "collapsed", "survived"]),
            "row 2 (record 'b'): status 'failed' but collapsed = 1",
        ),
        (lambda d: d.iloc[:0], "no rows"),
    ],
)
def test_bad_input_refused_in_one_line(change, fragment):
    df = pd.DataFrame(
        {
            "record": ["a", "b", "a", "b"],
            "intensity_g": [0.1, 0.1, 0.2, 0.2],
            "collapsed": [0, 1, 1, 0],
        }
    )
    with pytest.raises(RbmError) as info:
        fragility(change(df))
    assert fragment in str(info.value) and "\n" not in str(info.value)


def test_other_argument_refusals():
    df = _ida(5, 0.4, 0.3, seed=1)
    with pytest.raises(RbmError, match="DataFrame"):
        fragility(df.to_dict())
    with pytest.raises(RbmError, match="n_resamples"):
        fragility(df, n_resamples=-1)
    with pytest.raises(RbmError, match="ci_percentiles"):
        fragility(df, ci_percentiles=(95, 5))


# --------------------------------------------------------------------------- files


def test_write_fragility_files(tmp_path):
    df = _ida(30, 0.5, 0.4, seed=4)
    res = fragility(df, n_resamples=100, seed=9)
    paths = write_fragility(res, tmp_path / "out")
    assert [p.name for p in paths] == ["fragility.csv", "fragility_curve.csv", "fragility.json"]
    table = pd.read_csv(paths[0])
    assert list(table.columns) == [
        "intensity_g",
        "n_records",
        "n_failed",
        "n_collapsed",
        "fraction",
        "fitted",
        "band_lower",
        "band_upper",
    ]
    np.testing.assert_allclose(table["fraction"], res.table["fraction"], rtol=1e-11)
    np.testing.assert_allclose(
        table["fitted"],
        norm.cdf(np.log(table["intensity_g"] / res.fit.median_g) / res.fit.beta),
        rtol=1e-10,
    )
    curve = pd.read_csv(paths[1])
    assert len(curve) == 201 and curve["intensity_g"].iloc[-1] == pytest.approx(1.1)

    def no_nan(token):
        raise AssertionError(f"non-strict JSON constant {token}")

    data = json.loads(paths[2].read_text(), parse_constant=no_nan)
    assert data["median_g"] == pytest.approx(res.fit.median_g, rel=1e-15)
    assert data["beta"] == pytest.approx(res.fit.beta, rel=1e-15)
    assert data["median_ci_g"] == pytest.approx(list(res.median_ci_g))
    assert data["seed"] == 9 and data["n_resamples"] == 100 and data["n_records"] == 30
    assert "maximum likelihood" in data["method"] and data["ci_percentiles"] == [5.0, 95.0]


# --------------------------------------------------------------------------- figures


def test_plot_fragility_artists_carry_the_data():
    res = fragility(_ida(25, 0.45, 0.3, seed=8), n_resamples=100, seed=2)
    ax = plot_fragility(res, label="column A")
    lines = {ln.get_gid(): ln for ln in ax.get_lines()}
    x, y = lines["fitted"].get_data()
    np.testing.assert_allclose(
        y, norm.cdf(np.log(np.maximum(x, 1e-300) / res.fit.median_g) / res.fit.beta), atol=1e-12
    )
    px, py = lines["observed"].get_data()
    np.testing.assert_allclose(px, res.table["intensity_g"])
    np.testing.assert_allclose(py, res.table["n_collapsed"] / res.table["n_records"])
    band = [c for c in ax.collections if isinstance(c, PolyCollection) and c.get_gid() == "band"]
    assert len(band) == 1
    vy = band[0].get_paths()[0].vertices[:, 1]
    assert vy.min() == pytest.approx(res.curve["lower"].min())
    assert vy.max() == pytest.approx(res.curve["upper"].max())
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any(t.startswith("column A: observed") for t in texts)
    assert any("lognormal MLE: median" in t for t in texts)
    assert any("bootstrap 5-95 % band (100 resamples" in t for t in texts)
    counts = {t.get_text() for t in ax.texts}
    assert {
        f"{k}/{n}" for k, n in zip(res.table["n_collapsed"], res.table["n_records"], strict=True)
    } <= counts
    other = fragility(_ida(25, 0.7, 0.3, seed=9), n_resamples=0)
    assert plot_fragility(other, ax=ax, label="column B", counts=False) is ax
    assert sum(ln.get_gid() == "fitted" for ln in ax.get_lines()) == 2


def test_plot_ida_one_line_per_record():
    """A curve per record, intensity up and response across, up to the first collapse
    (each record of _ida collapses at every level from its capacity on), then flat."""
    df = _ida(6, 0.4, 0.3, seed=5, column="amplitude_g")
    df.loc[3, "status"] = "failed"  # record rec0000 at its 4th level: left out
    df = df.sample(frac=1.0, random_state=1)  # unsorted rows: the plot sorts by intensity
    ax = plot_ida(df)
    right = ax.get_xlim()[1]
    lines = {ln.get_gid(): ln for ln in ax.get_lines() if ln.get_gid()}
    for name, group in df[df["status"] != "failed"].groupby("record"):
        group = group.sort_values("amplitude_g")
        x, y = lines[f"record:{name}"].get_data()
        hit = group[group["collapsed"] == 1]
        kept = group[group["amplitude_g"] <= (hit["amplitude_g"].min() if len(hit) else 9)]
        if len(hit):
            np.testing.assert_array_equal(y, [*kept["amplitude_g"], kept["amplitude_g"].max()])
            np.testing.assert_array_equal(x, [*kept["max_rotation_ratio"], right])
            mx, my = lines[f"collapse:{name}"].get_data()
            np.testing.assert_array_equal(mx, hit["max_rotation_ratio"][:1])
            np.testing.assert_array_equal(my, hit["amplitude_g"][:1])
        else:
            np.testing.assert_array_equal(y, group["amplitude_g"])
            np.testing.assert_array_equal(x, group["max_rotation_ratio"])
    assert len([g for g in lines if g.startswith("record:")]) == 6
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [f"rec{k:04d}" for k in range(6)]
    with pytest.raises(RbmError, match="max_rotation_ratio"):
        plot_ida(df.drop(columns="max_rotation_ratio"))
