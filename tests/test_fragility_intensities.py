"""`rbm fragility --compare-intensities`: the suite fitted on every measure it carries.

The domain is made here so that the answer is known: each record's capacity is lognormal
in PGV with a small dispersion (BETA_V), and its PGV per g of PGA scatters from record to
record (lognormal, SPREAD), so in PGA the capacities scatter as sqrt(BETA_V^2 + SPREAD^2):
PGV must rank first, with beta near BETA_V, PGA after it near that root sum of squares. A
measure proportional to PGA (PGA / (g tan alpha) of one column) has PGA's beta. Each row
is re-derived by a separate plain fit with --intensity and the same seed.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from tests.fragility_domains import invoke, write

from .paths import RESULTS

LEVELS = np.round(np.arange(0.05, 1.0001, 0.05), 10)
BETA_V, SPREAD, TAN_ALPHA = 0.15, 0.4, 0.25
#: The intensity measures the made domain carries (d5_95_s, which does not grow with the
#: record's scale, is no intensity).
MEASURES = {"pga_g", "pgv_m_s", "arias_m_s", "cav_m_s", "sa_t1_g", "pga_over_g_tan_alpha"}


def suite(n_records=120, seed=2):
    rng = np.random.default_rng(seed)
    v_per_g = 0.8 * np.exp(SPREAD * rng.standard_normal(n_records))  # PGV [m/s] at 1 g
    capacity_v = 0.35 * np.exp(BETA_V * rng.standard_normal(n_records))  # [m/s]
    arias_per_g2 = 2.0 * np.exp(0.8 * rng.standard_normal(n_records))
    cav_per_g = 5.0 * np.exp(0.5 * rng.standard_normal(n_records))
    rows = []
    for r in range(n_records):
        for x in LEVELS:
            pgv = x * v_per_g[r]
            hit = bool(pgv >= capacity_v[r])
            rows.append({
                "record": f"rec{r:03d}",
                "amplitude_g": x,
                "status": "collapsed" if hit else "survived",
                "collapsed": int(hit),
                "max_rotation_ratio": 1.0 if hit else pgv / capacity_v[r],
                "pga_g": x,
                "pgv_m_s": pgv,
                "arias_m_s": x * x * arias_per_g2[r],
                "cav_m_s": x * cav_per_g[r],
                "d5_95_s": 10.0,
                "t1_s": math.nan,
                "sa_t1_g": math.nan,
                "pga_over_g_tan_alpha": x / TAN_ALPHA,
            })  # fmt: skip
    return pd.DataFrame(rows)


def test_every_measure_ranked_by_beta_each_the_plain_fit(tmp_path):
    n = 120
    domain = write(tmp_path / "s", suite(n))
    run = invoke(domain, "-o", tmp_path / "o", "--resamples", 100, "--seed", 4,
                 "--compare-intensities")  # fmt: skip
    assert run.exit_code == 0, run.output
    table = pd.read_csv(tmp_path / "o" / "fragility_intensities.csv", keep_default_na=False,
                        na_values=[""])  # fmt: skip
    assert sorted(table["intensity_column"]) == sorted(MEASURES)  # one row per measure
    fitted = table[table["beta"].notna()]
    assert list(fitted["rank"]) == list(range(1, len(fitted) + 1))
    assert np.all(np.diff(fitted["beta"].round(6)) >= 0.0)  # equal to 6 decimals: ties
    empty = table[table["intensity_column"] == "sa_t1_g"].iloc[0]
    assert math.isnan(empty["beta"]) and "empty" in empty["note"]
    assert table["intensity_column"].iat[-1] == "sa_t1_g"
    # the known answer: PGV first, near BETA_V; PGA near the root sum of squares
    beta = dict(zip(table["intensity_column"], table["beta"], strict=True))
    assert table["intensity_column"].iat[0] == "pgv_m_s"
    se = 4.0 / math.sqrt(2 * n)
    assert abs(beta["pgv_m_s"] - BETA_V) < BETA_V * se + 0.03
    both = math.hypot(BETA_V, SPREAD)
    assert abs(beta["pga_g"] - both) < both * se + 0.03
    assert beta["pga_over_g_tan_alpha"] == pytest.approx(beta["pga_g"], rel=1e-6)
    assert "lowest dispersion (most efficient): pgv_m_s" in run.output
    assert sum(line.strip().startswith(("1 ", "2 ", "3 ", "4 ", "5 ", "- "))
               for line in run.output.splitlines()) == len(MEASURES)  # fmt: skip
    # each row is the plain fit with --intensity, the same seed
    for column in ("pga_g", "pgv_m_s", "arias_m_s"):
        out = tmp_path / f"plain_{column}"
        plain = invoke(domain, "-o", out, "--resamples", 100, "--seed", 4, "--intensity", column)
        assert plain.exit_code == 0, plain.output
        fit = json.loads((out / "fragility.json").read_text())
        row = table[table["intensity_column"] == column].iloc[0]
        assert row["beta"] == pytest.approx(fit["beta"], rel=1e-10)
        assert row["median"] == pytest.approx(fit["median_g"], rel=1e-10)
        assert [row["beta_ci_low"], row["beta_ci_high"]] == pytest.approx(fit["beta_ci"],
                                                                           rel=1e-10)  # fmt: skip
    summary = json.loads((tmp_path / "o" / "fragility.json").read_text())
    assert summary["intensity_best"] == "pgv_m_s"


def test_a_stored_suite_has_a_row_per_measure_it_carries(tmp_path):
    """results/suite_monolithic (read only): a row per intensity measure in its header;
    for one column PGV p / (g tan alpha) is PGV times a constant, so its beta is PGV's."""
    domain = RESULTS / "suite_monolithic" / "domain.csv"
    header = pd.read_csv(domain, nrows=0).columns
    carried = {"pga_g", "pgv_m_s", "pgd_m", "arias_m_s", "cav_m_s", "sa_t1_g",
               "pga_over_g_tan_alpha", "pgv_p_over_g_tan_alpha"} & set(header)  # fmt: skip
    run = invoke(domain, "-o", tmp_path, "--resamples", 0, "--compare-intensities")
    assert run.exit_code == 0, run.output
    table = pd.read_csv(tmp_path / "fragility_intensities.csv")
    assert set(table["intensity_column"]) == carried and len(table) == len(carried)
    beta = dict(zip(table["intensity_column"], table["beta"], strict=True))
    assert beta["pgv_p_over_g_tan_alpha"] == pytest.approx(beta["pgv_m_s"], rel=1e-6)
    assert beta["pga_over_g_tan_alpha"] == pytest.approx(beta["pga_g"], rel=1e-6)
    rank = dict(zip(table["intensity_column"], table["rank"], strict=True))
    for measure, scaled in (("pgv_m_s", "pgv_p_over_g_tan_alpha"),
                            ("pga_g", "pga_over_g_tan_alpha")):  # fmt: skip
        assert rank[scaled] == rank[measure] + 1  # a tie: next to it, in the domain's order


def test_a_domain_without_measures_is_refused_in_one_line(tmp_path):
    df = suite(20).drop(columns=sorted(MEASURES) + ["d5_95_s", "t1_s"])
    run = invoke(write(tmp_path / "s", df), "-o", tmp_path / "o", "--compare-intensities")
    assert run.exit_code == 2, run.output
    assert len(run.output.strip().splitlines()) == 1 and "no intensity measure" in run.output
    assert not (tmp_path / "o").exists() or not any((tmp_path / "o").iterdir())
