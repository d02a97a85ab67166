"""`rbm fragility DOMAIN.csv`: a record-suite domain to fragility files and figures.

The domain is made here by hand from a known lognormal: each of 200 records has a capacity
drawn from lognormal(median THETA, dispersion BETA) and collapses at every intensity at or
above it. Expected values: the generating THETA and BETA within four standard errors of
their estimates from 200 capacities (se of ln theta = beta / sqrt(n), se of beta ~
beta / sqrt(2 n)), per-level counts counted here from the capacities, figure data from
the capacities and from the closed form Phi(ln(x / theta) / beta). Refusals: one line,
exit 2, nothing written.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import resource
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from matplotlib.collections import PolyCollection
from scipy.stats import norm

from rbm_cli.base.errors import RbmError
from rbm_cli.cli import fragility as fragility_command
from rbm_cli.cli.main import cli
from rbm_cli.report import fragility_run
from rbm_cli.study.fragility import MAX_RESAMPLES

from .paths import RESULTS

THETA, BETA, N_RECORDS = 0.4, 0.35, 200
LEVELS = np.round(np.arange(0.05, 1.0001, 0.05), 10)  # 20 intensities [g]
OUTPUTS = {"fragility.csv", "fragility_curve.csv", "fragility.json", "fragility.png", "ida.png"}


def suite(seed=7, n_records=N_RECORDS, failed=0):
    """A record-suite domain: capacities ~ lognormal(THETA, BETA); `failed` runs at random
    (chosen independently of the outcome) are marked failed. Returns (rows, capacities)."""
    rng = np.random.default_rng(seed)
    capacity = THETA * np.exp(BETA * rng.standard_normal(n_records))
    rows = []
    for r, c in enumerate(capacity):
        for x in LEVELS:
            hit = bool(x >= c)
            rows.append({
                "record": f"rec{r:03d}",
                "excitation.file": f"records/rec{r:03d}.AT2",
                "amplitude_g": x,
                "frequency_hz": math.nan,
                "status": "collapsed" if hit else "survived",
                "collapsed": int(hit),
                "t_collapse_s": 3.0 if hit else math.nan,
                "max_rotation_ratio": 1.0 if hit else x / c,
                "message": "",
            })  # fmt: skip
    df = pd.DataFrame(rows)
    if failed:
        i = rng.choice(len(df), failed, replace=False)
        df.loc[i, ["status", "collapsed", "max_rotation_ratio"]] = ["failed", 0, math.nan]
    return df, capacity


def write_domain(folder, df) -> str:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "domain.csv"
    df.to_csv(path, index=False, float_format="%.12g")
    return str(path)


def invoke(*args):
    return CliRunner().invoke(cli, [str(a) for a in args])


@pytest.fixture
def figures(monkeypatch):
    """The figures `rbm fragility` renders into its PNG files, by order of rendering."""
    made = []
    original = fragility_run._png

    def keep(fig, dpi=150):
        made.append(fig)
        return original(fig, dpi)

    monkeypatch.setattr(fragility_run, "_png", keep)
    return made


# --------------------------------------------------------------------------- the fit


def test_recovers_the_generating_lognormal(tmp_path, figures):
    df, capacity = suite(failed=40)
    domain = write_domain(tmp_path / "suite", df)
    res = invoke("fragility", domain, "--resamples", 300, "--seed", 3)
    assert res.exit_code == 0, res.output
    assert "median" in res.output and "dispersion beta" in res.output
    folder = tmp_path / "suite"  # default: the domain's folder
    assert OUTPUTS <= {p.name for p in folder.iterdir()}
    assert not [p for p in folder.iterdir() if p.name.startswith(".")]  # no staging left

    summary = json.loads((folder / "fragility.json").read_text())
    n = N_RECORDS
    se_log_theta, se_beta = BETA / math.sqrt(n), BETA / math.sqrt(2 * n)  # 0.025, 0.018
    assert abs(math.log(summary["median_g"] / THETA)) < 4 * se_log_theta
    assert abs(summary["beta"] - BETA) < 4 * se_beta
    # closer: the sample's own lognormal (mean and standard deviation of ln capacity); the
    # levels only bin each capacity (bin 0.05 g, ln-width ~0.125 near the median: a spread
    # of 0.125 / sqrt(12) = 0.036 per record, 0.0026 on the mean of 200; Sheppard's
    # correction moves beta by ~0.125^2 / 12 / (2 beta) = 0.002)
    log_c = np.log(capacity)
    assert abs(math.log(summary["median_g"]) - log_c.mean()) < 0.01
    assert abs(summary["beta"] - log_c.std(ddof=1)) < 0.01
    # the bootstrap interval: around the estimate, as wide as the standard errors say
    # (5-95 %: 2 x 1.645 se), within a factor of two (interval censoring by the levels)
    lo, hi = summary["median_ci_g"]
    assert lo < summary["median_g"] < hi
    width = 2 * norm.ppf(0.95) * se_log_theta * summary["median_g"]
    assert 0.5 * width < hi - lo < 2.0 * width
    lo, hi = summary["beta_ci"]
    assert lo < summary["beta"] < hi
    assert 0.5 * 2 * norm.ppf(0.95) * se_beta < hi - lo < 2.0 * 2 * norm.ppf(0.95) * se_beta
    assert summary["n_records"] == n and summary["n_failed"] == 40
    assert summary["n_runs"] == n * LEVELS.size - 40
    assert summary["seed"] == 3 and summary["n_resamples"] == 300
    assert "Baker 2015" in summary["method"] and summary["domain"] == "domain.csv"
    assert summary["domain_sha256"] == hashlib.sha256(Path(domain).read_bytes()).hexdigest()

    # per intensity: counted here from the capacities and the failed rows
    table = pd.read_csv(folder / "fragility.csv")
    ok = df[df["status"] != "failed"]
    np.testing.assert_allclose(table["intensity_g"], LEVELS)
    for x, row in zip(LEVELS, table.itertuples(), strict=True):
        runs = ok[np.isclose(ok["amplitude_g"], x)]
        alive = set(runs["record"])
        hits = sum(1 for r, c in enumerate(capacity) if f"rec{r:03d}" in alive and x >= c)
        assert row.n_records == len(runs) and row.n_collapsed == hits
        assert row.n_failed == n - len(runs)
        assert row.fraction == pytest.approx(hits / len(runs), abs=1e-12)
        z = math.log(x / summary["median_g"]) / summary["beta"]
        assert row.fitted == pytest.approx(norm.cdf(z), abs=1e-9)

    # the figures written: fragility (points, curve, band) and IDA (a line per record)
    frag_ax, ida_ax = figures[0].axes[0], figures[1].axes[0]
    check_fragility_axes(frag_ax, table, summary)
    check_ida_axes(ida_ax, df, capacity)


def check_fragility_axes(ax, table, summary):
    lines = {line.get_gid(): line for line in ax.get_lines()}
    x, y = lines["observed"].get_data()
    np.testing.assert_allclose(x, table["intensity_g"])
    np.testing.assert_allclose(y, table["fraction"])
    x, y = lines["fitted"].get_data()
    expected = norm.cdf(np.log(np.maximum(x, 1e-300) / summary["median_g"]) / summary["beta"])
    np.testing.assert_allclose(y, expected, atol=1e-9)
    assert x.max() >= LEVELS.max()
    (band,) = [c for c in ax.collections if c.get_gid() == "band"]
    assert isinstance(band, PolyCollection)
    assert ax.get_xlabel() == "intensity: peak ground acceleration [g]"


def check_ida_axes(ax, df, capacity):
    records = {ln.get_gid(): ln for ln in ax.get_lines() if str(ln.get_gid()).startswith("rec")}
    assert len(records) == N_RECORDS
    ok = df[df["status"] != "failed"]
    for r in (0, 57, 199):
        name = f"rec{r:03d}"
        x, y = records[f"record:{name}"].get_data()  # response across, intensity up
        level = ok[ok["record"] == name].sort_values("amplitude_g")["amplitude_g"].to_numpy()
        ratio = np.where(level >= capacity[r], 1.0, level / capacity[r])
        if level.max() < capacity[r]:  # never collapsed: its runs
            np.testing.assert_allclose(y, level)
            np.testing.assert_allclose(x, ratio)
            continue
        k = int(np.argmax(level >= capacity[r]))  # its first collapse, then flat
        np.testing.assert_allclose(y, [*level[: k + 1], level[k]])
        np.testing.assert_allclose(x, [*ratio[: k + 1], ax.get_xlim()[1]])
    marks = [ln for ln in ax.get_lines() if str(ln.get_gid()).startswith("collapse:")]
    assert len(marks) == int((capacity <= LEVELS.max()).sum())


def test_output_folder_keeps_other_files_and_rewrites_its_own(tmp_path):
    df, _ = suite(n_records=30)
    domain = write_domain(tmp_path / "suite", df)
    out = tmp_path / "a" / "b"
    out.mkdir(parents=True)
    (out / "notes.txt").write_text("mine")
    (out / "fragility.json").write_text("an old one")
    res = invoke("fragility", domain, "-o", out, "--resamples", 0)
    assert res.exit_code == 0, res.output
    assert (out / "notes.txt").read_text() == "mine"
    assert set(os.listdir(out)) == OUTPUTS | {"notes.txt"}
    summary = json.loads((out / "fragility.json").read_text())
    assert summary["n_resamples"] == 0 and summary["median_ci_g"] == [None, None]
    assert summary["domain"] == os.path.relpath(domain, out)
    assert set(os.listdir(tmp_path / "suite")) == {"domain.csv"}  # nothing beside the domain
    assert (out / "ida.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_scale_factor_axis_label(tmp_path, figures):
    df, _ = suite(n_records=20)
    domain = write_domain(tmp_path / "suite", df)
    excitation = {"type": "record", "scale": "factor"}
    meta = {"name": "suite", "config_written": {"excitation": excitation}}
    (tmp_path / "suite" / "meta.json").write_text(json.dumps(meta))
    res = invoke("fragility", domain, "--resamples", 0)
    assert res.exit_code == 0, res.output
    frag, ida = (fig.axes[0] for fig in figures)  # the IDA's intensity on its y axis
    assert frag.get_xlabel() == ida.get_ylabel() == "intensity: scale factor of the records [-]"
    for fig in figures:
        assert fig.axes[0].get_title().startswith(("suite: 20 records", "IDA, suite: 20"))


def test_no_fit_is_reported_not_refused(tmp_path):
    df, _ = suite(n_records=10)
    df = df[df["amplitude_g"] < 0.05 + 1e-9].copy()  # 0.05 g: below every capacity here
    df["status"], df["collapsed"], df["max_rotation_ratio"] = "survived", 0, 0.1
    domain = write_domain(tmp_path / "low", df)
    res = invoke("fragility", domain)
    assert res.exit_code == 0, res.output
    assert "no fit: no record collapsed" in res.output
    assert json.loads((tmp_path / "low" / "fragility.json").read_text())["fitted"] is False


def test_help_lists_fragility():
    res = invoke("--help")
    assert res.exit_code == 0
    assert any(line.split()[:1] == ["fragility"] for line in res.output.splitlines())
    res = invoke("fragility", "--help")
    assert res.exit_code == 0 and "DOMAIN.csv" in res.output


# --------------------------------------------------------------------------- refusals


def assert_refused(res, *needles):
    lines = [line for line in res.output.splitlines() if line.strip()]
    assert res.exit_code == 2, res.output
    assert len(lines) == 1 and lines[0].startswith("Error:"), res.output
    assert "Traceback" not in res.output
    for needle in needles:
        assert needle in lines[0], lines[0]


def _harmonic(tmp_path):
    text = (RESULTS / "spanos_koh_slender" / "domain.csv").read_text()
    (tmp_path / "harmonic.csv").write_text(text)
    return tmp_path / "harmonic.csv"


def _no_records(tmp_path):
    df, _ = suite(n_records=3)
    df["record"] = ""
    return write_domain(tmp_path, df)


def _one_empty(tmp_path):
    df, _ = suite(n_records=3)
    df.loc[4, "record"] = ""
    return write_domain(tmp_path, df)


def _twice(tmp_path):
    df, _ = suite(n_records=3)
    return write_domain(tmp_path, pd.concat([df, df.iloc[[5]]], ignore_index=True))


def _not_csv(tmp_path):
    (tmp_path / "x.csv").write_bytes(b"\x00\xff\xfe binary \x00")
    return tmp_path / "x.csv"


def _no_status(tmp_path):
    (tmp_path / "x.csv").write_text("a,b\n1,2\n")
    return tmp_path / "x.csv"


def _header_only(tmp_path):
    df, _ = suite(n_records=1)
    (tmp_path / "domain.csv").write_text(",".join(df.columns) + "\n")
    return tmp_path / "domain.csv"


def _bad_intensity(tmp_path):
    df, _ = suite(n_records=3)
    df.loc[7, "amplitude_g"] = -0.1
    return write_domain(tmp_path, df)


def _failed_but_collapsed(tmp_path):
    df, _ = suite(n_records=3)
    df.loc[30, "status"] = "failed"  # rec001 at 0.55 g: a failed run that says it collapsed
    df.loc[30, "collapsed"] = 1
    return write_domain(tmp_path, df)


@pytest.mark.parametrize(
    ("make", "needles"),
    [
        (lambda p: p / "missing.csv", ("domain file not found", "missing.csv")),
        (_not_csv, ("x.csv",)),
        (_no_status, ("x.csv", "is not a domain CSV")),
        (_header_only, ("has no rows",)),
        (_harmonic, ("harmonic.csv", "amplitude x frequency sweep", "no record column")),
        (_no_records, ("amplitude x frequency sweep",)),
        (_one_empty, ("line 6", "record field is empty")),
        (_twice, ("a second run of record 'rec000'",)),
        (_bad_intensity, ("row 8", "amplitude_g must be a number > 0")),
        (_failed_but_collapsed, ("line 32", "status 'failed' but collapsed 1")),
    ],
)
def test_bad_domain_is_refused_in_one_line(tmp_path, make, needles):
    path = make(tmp_path)
    before = sorted(os.listdir(tmp_path))
    assert_refused(invoke("fragility", path), *needles)
    assert sorted(os.listdir(tmp_path)) == before  # nothing written


@pytest.mark.parametrize(
    ("args", "needles"),
    [
        (("--intensity-column", "pga"), ("--intensity must be an intensity measure, got 'pga'",)),
        (("--seed", "-1"), ("--seed",)),
        (("--resamples", "-5"), ("--resamples",)),
        (("--ci", "95", "5"), ("ci_percentiles",)),
        (("-o", ""), ("--output must name a folder",)),
    ],
)
def test_bad_options_are_refused_in_one_line(tmp_path, args, needles):
    df, _ = suite(n_records=5)
    domain = write_domain(tmp_path / "s", df)
    assert_refused(invoke("fragility", domain, *args), *needles)
    assert os.listdir(tmp_path / "s") == ["domain.csv"]


def test_output_that_is_a_file_is_refused(tmp_path):
    df, _ = suite(n_records=5)
    domain = write_domain(tmp_path / "s", df)
    (tmp_path / "f").write_text("a file")
    assert_refused(invoke("fragility", domain, "-o", tmp_path / "f" / "out"), "not a folder")
    assert (tmp_path / "f").read_text() == "a file"


def test_a_write_that_fails_leaves_the_folder_as_it_was(tmp_path):
    """A file that cannot be written whole (here: a file size limit, as a full disk) ends
    the command in one line, exit 2, with the folder's earlier set as it was and nothing
    of the failed run left behind."""
    df, _ = suite(n_records=20)
    domain = write_domain(tmp_path / "s", df)
    assert invoke("fragility", domain, "--resamples", 0).exit_code == 0
    before = {p.name: p.read_bytes() for p in (tmp_path / "s").iterdir()}
    df.loc[df["record"] == "rec000", "max_rotation_ratio"] *= 0.5  # another IDA figure
    df.to_csv(domain, index=False, float_format="%.12g")
    before["domain.csv"] = Path(domain).read_bytes()

    def small_files():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # EFBIG instead of a kill
        resource.setrlimit(resource.RLIMIT_FSIZE, (20_000, 20_000))  # the PNGs are larger

    command = [sys.executable, "-m", "rbm_cli", "fragility", domain, "--resamples", "0"]
    proc = subprocess.run(command, capture_output=True, text=True, preexec_fn=small_files,
                          env={**os.environ, "PYTHONPATH": str(Path(__file__).parents[1])},
                          timeout=120)  # fmt: skip
    lines = [line for line in proc.stderr.splitlines() if line.strip()]
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr
    assert "cannot write the fragility files (File too large)" in lines[0], lines[0]
    assert {p.name: p.read_bytes() for p in (tmp_path / "s").iterdir()} == before


def test_compare_draws_each_domain_fitted_in_one_figure(tmp_path, figures):
    """--compare: a second suite (capacities twice as large) is fitted with the same options
    and drawn in fragility.png beside the first, each fitted curve the closed form of its own
    fit, labelled by its folder; the compared domain's folder gets no files."""
    df, _ = suite(seed=7)
    strong = df.copy()
    strong["amplitude_g"] = strong["amplitude_g"] * 2.0  # every capacity doubled
    a = write_domain(tmp_path / "weak", df)
    b = write_domain(tmp_path / "strong", strong)
    res = invoke("fragility", a, "--compare", b, "--resamples", 50)
    assert res.exit_code == 0, res.output
    assert sorted(p.name for p in (tmp_path / "strong").iterdir()) == ["domain.csv"]
    summary = json.loads((tmp_path / "weak" / "fragility.json").read_text())
    ax = figures[0].axes[0]
    fitted = [line for line in ax.get_lines() if line.get_gid() == "fitted"]
    assert len(fitted) == 2
    labels = [line.get_label() for line in fitted]
    assert any("weak" in t for t in labels) and any("strong" in t for t in labels)
    medians = []
    for line in fitted:
        x, y = (np.asarray(v, float) for v in line.get_data())
        i = int(np.argmin(np.abs(y - 0.5)))
        medians.append(x[i])
    # the doubled suite's median is twice the first's (scaling the intensities scales it)
    assert medians[0] == pytest.approx(summary["median_g"], rel=0.02)
    assert medians[1] == pytest.approx(2 * summary["median_g"], rel=0.02)


def test_failed_run_marked_collapsed_is_refused_as_compare_refuses_it(tmp_path):
    """A row whose status is failed but whose collapsed is 1 was fitted as a collapse by
    `rbm fragility` while `rbm compare` refused it. Both refuse it now, in the same words,
    naming the line."""
    domain = _failed_but_collapsed(tmp_path)
    res = invoke("fragility", domain)
    assert_refused(res, "line 32", "status 'failed' but collapsed 1")
    other = invoke("compare", domain, domain)
    assert other.exit_code == 2 and other.output == res.output


# --------------------------------------------------------------------------- thin suites


def stored_suite() -> pd.DataFrame:
    return pd.read_csv(RESULTS / "suite_multidrum" / "domain.csv", dtype={"record": str},
                       keep_default_na=False, na_values=[""])  # fmt: skip


def test_one_record_gives_a_fit_without_a_band(tmp_path, figures):
    """A suite of one record once got a bootstrap band of zero width (every resample is
    that record: '0.5346-0.5346 g', as if certain). Its fit is shown, with no band and no
    intervals, and a note (output, fragility.json, the figure) that a band needs two
    records or more."""
    df = stored_suite()
    one = df[df["record"] == "rdk_13"]  # collapses at 0.6 and 0.9 g, survives between
    assert one["collapsed"].nunique() == 2
    domain = write_domain(tmp_path / "one", one)
    res = invoke("fragility", domain, "--resamples", 200)
    assert res.exit_code == 0, res.output
    assert "records: 1," in res.output and "median " in res.output
    assert " %: " not in res.output  # no interval printed
    note = [line for line in res.output.splitlines() if line.startswith("note: ")]
    assert len(note) == 1 and "1 record" in note[0] and "need 2 or more" in note[0], res.output
    summary = json.loads((tmp_path / "one" / "fragility.json").read_text())
    assert summary["fitted"] is True and summary["note"] == note[0].removeprefix("note: ")
    assert summary["median_ci_g"] == [None, None] and summary["beta_ci"] == [None, None]
    assert summary["n_resamples"] == 0 and summary["n_resamples_used"] == 0
    curve = pd.read_csv(tmp_path / "one" / "fragility_curve.csv")
    assert curve["lower"].isna().all() and curve["upper"].isna().all()
    ax = figures[0].axes[0]
    assert not [c for c in ax.collections if c.get_gid() == "band"]
    assert any("1 record" in t.get_text() for t in ax.texts)


def test_one_intensity_is_not_presented_as_a_fit(tmp_path):
    """With every run at one intensity the command said 'all runs survive up to 0.5 g and
    collapse from 0.5 g' as if a curve had been fitted. It says plainly that a curve needs
    two intensities, and gives the one fraction observed."""
    df = stored_suite()
    level = df[df["amplitude_g"] == 0.5]
    k, n = int(level["collapsed"].sum()), len(level)
    assert 0 < k < n  # mixed outcomes: the case a separated-outcomes message got wrong
    domain = write_domain(tmp_path / "level", level)
    res = invoke("fragility", domain, "--ensemble-outcome", "member0")  # the rows' runs
    assert res.exit_code == 0, res.output
    assert f"no fit: all runs are at one intensity (0.5 g, {k} of {n} collapsed)" in res.output
    assert "two intensities or more" in res.output
    assert "collapse from" not in res.output and "median" not in res.output
    summary = json.loads((tmp_path / "level" / "fragility.json").read_text())
    assert summary["fitted"] is False and summary["median_g"] is None
    table = pd.read_csv(tmp_path / "level" / "fragility.csv")
    assert table["fraction"].tolist() == [k / n]


# --------------------------------------------------------------------------- the bootstrap's cost


def _no_fit_domain(tmp_path) -> str:
    """A domain that has no fit (every run survives), so no bootstrap runs: a version
    without the bounds below ends at once instead of resampling for days."""
    df, _ = suite(n_records=5)
    df = df[df["amplitude_g"] < 0.05 + 1e-9].copy()
    df["status"], df["collapsed"] = "survived", 0
    return write_domain(tmp_path / "s", df)


@pytest.mark.parametrize("n", [MAX_RESAMPLES + 1, 1_000_000_000])
def test_resamples_above_the_maximum_are_refused(tmp_path, n):
    """--resamples 1000000000 once ran for about 12 days with no word. Above the
    documented maximum it is refused in one line; --help states the maximum."""
    domain = _no_fit_domain(tmp_path)
    assert_refused(invoke("fragility", domain, "--resamples", n), "--resamples",
                   f"{MAX_RESAMPLES:,}")  # fmt: skip
    assert os.listdir(tmp_path / "s") == ["domain.csv"]
    helped = " ".join(invoke("fragility", "--help").output.split())
    assert f"at most {MAX_RESAMPLES:,}" in helped


@pytest.mark.parametrize(
    ("option", "value"),
    [
        ("n_resamples", True),
        ("n_resamples", math.nan),
        ("n_resamples", -1),
        ("n_resamples", 2.5),
        ("n_resamples", MAX_RESAMPLES + 1),
        ("n_resamples", 10**12),
        ("seed", True),
        ("seed", math.nan),
        ("seed", -1),
        ("seed", 2**64),
        ("seed", "7"),
        ("ci_percentiles", (True, 95.0)),
        ("ci_percentiles", (math.nan, 95.0)),
        ("ci_percentiles", (5.0, math.inf)),
        ("ci_percentiles", (-1.0, 50.0)),
        ("ci_percentiles", (5.0,)),
        ("ci_percentiles", "5 95"),
        ("ci_percentiles", (np.float64(95.0), np.float64(5.0))),
    ],
)
def test_api_refuses_bad_options_in_one_line(tmp_path, option, value):
    """run_fragility (the API path) accepted a bool, ran into a TypeError on nan, and had
    no bound: each bad value is refused in one line naming the option, nothing written."""
    domain = _no_fit_domain(tmp_path)
    with pytest.raises(RbmError) as info:
        fragility_run.run_fragility(domain, **{option: value})
    text = str(info.value)
    assert option in text and "\n" not in text and "np.float64" not in text, text
    assert os.listdir(tmp_path / "s") == ["domain.csv"]


def test_progress_of_a_long_bootstrap_on_stderr(tmp_path, monkeypatch):
    """The bootstrap said nothing however long it ran. Past a few seconds (here: from the
    start) its progress is on stderr, the resamples of the compared domain counted too."""
    monkeypatch.setattr(fragility_command, "PROGRESS_AFTER_S", 0.0)
    a = write_domain(tmp_path / "a", suite(seed=1, n_records=20)[0])
    b = write_domain(tmp_path / "b", suite(seed=2, n_records=20)[0])
    res = CliRunner().invoke(cli, ["fragility", a, "--compare", b, "--resamples", "30"])
    assert res.exit_code == 0, res.output
    assert "bootstrap: 60/60 resamples (100 %)" in res.stderr
    assert "resamples" not in res.stdout


def test_api_progress_and_ctrl_c_during_the_bootstrap(tmp_path):
    """progress(done, total) follows the bootstrap to its end; a Ctrl-C during it (here
    raised from the callback) leaves the folder's set as it was, and no hidden file."""
    domain = write_domain(tmp_path / "s", suite(seed=3, n_records=20)[0])
    calls = []
    fragility_run.run_fragility(domain, n_resamples=25, progress=lambda d, t: calls.append((d, t)))
    assert calls == [(d, 25) for d in range(1, 26)]
    before = {p.name: p.read_bytes() for p in (tmp_path / "s").iterdir()}

    def interrupt(done, total):
        if done == 10:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        fragility_run.run_fragility(domain, n_resamples=25, seed=1, progress=interrupt)
    assert {p.name: p.read_bytes() for p in (tmp_path / "s").iterdir()} == before


def test_a_stored_suite_is_fitted_on_its_pgv(tmp_path):
    """The stored monolith suite (results/suite_monolithic) keeps each record cell's
    intensity measures: `rbm fragility --intensity pgv_m_s` fits on them, and the points it
    fits are the stored PGVs (each record's PGV is proportional to its scaling, so the
    ratio PGV / PGA is the same at every level of a record)."""
    stored = pd.read_csv(RESULTS / "suite_monolithic" / "domain.csv", dtype={"record": str})
    ratio = stored["pgv_m_s"] / stored["pga_g"]
    assert (ratio.groupby(stored["record"]).std() <= 1e-9 * ratio.mean()).all()
    res = CliRunner().invoke(cli, ["fragility", str(RESULTS / "suite_monolithic" / "domain.csv"),
                                   "--intensity", "pgv_m_s", "-o", str(tmp_path)])  # fmt: skip
    assert res.exit_code == 0, res.output
    assert "intensity: pgv_m_s [m/s]" in res.output and "median" in res.output
    table = pd.read_csv(tmp_path / "fragility.csv")
    np.testing.assert_allclose(np.sort(table["intensity_g"]),
                               np.sort(stored["pgv_m_s"].unique()), rtol=1e-11)  # fmt: skip
