"""Bad arguments to the library and the command line end in one line naming the argument
(rbm.RbmError / rbm.ConfigError, exit status 2), never a raw Python exception or a value
taken for another; an ensemble's members count against the grid's limits; the smallest
capital a config takes runs within the step budget.

The block is rigid and monolithic, H = 2 m, B = 0.5 m (it rocks above B/H = 0.25 g).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import rbm
from rbm_cli.cli.main import cli

BLOCK = {
    "name": "errors",
    "column": {"height": 2.0, "base_width": 0.5},
    "interface": {"stiffness": "rigid", "restitution": 0.9},
    "grid": {"amplitudes": [0.1, 0.2], "frequencies": [1.0]},
}


def one_line(call, *words, kind=rbm.RbmError) -> str:
    """The one-line message of the library error ``call()`` raises, holding ``words``."""
    with pytest.raises(kind) as bad:
        call()
    message = str(bad.value)
    assert "\n" not in message, message
    for word in words:
        assert word in message, (word, message)
    return message


def cli_error(*args, words=()) -> str:
    """Exit status 2, one line 'Error: ...' holding ``words``, no traceback."""
    res = CliRunner().invoke(cli, [str(a) for a in args])
    lines = [line for line in res.output.splitlines() if line.strip()]
    assert res.exit_code == 2, res.output
    assert len(lines) == 1 and lines[0].startswith("Error:"), res.output
    assert "Traceback" not in res.output
    for word in words:
        assert word in lines[0], (word, lines[0])
    return lines[0]


def never_runs(done, total):
    raise AssertionError(f"the sweep started its {total} cells: it should have been refused")


# --------------------------------------------------------------------------- ensembles


def test_an_ensembles_members_count_against_the_grids_limits(tmp_path):
    """cells x members are the runs: 2 cells x 10^9 members is refused outright (more than
    the 1,000,000 runs a sweep takes), 2 x 60,000 needs force (more than 100,000), before
    any cell runs and before any folder is made."""
    cfg = rbm.load_config(BLOCK)
    one_line(lambda: rbm.sweep(cfg, ensemble=10**9, progress=never_runs),
             "2 cells x 1,000,000,000 ensemble members = 2,000,000,000 runs",
             "more than the 1,000,000")  # fmt: skip
    one_line(lambda: rbm.sweep(cfg, ensemble=10**9, force=True, progress=never_runs),
             "more than the 1,000,000")  # fmt: skip
    one_line(lambda: rbm.sweep(cfg, tmp_path, ensemble=60_000, progress=never_runs),
             "120,000 runs", "force")  # fmt: skip
    assert not (tmp_path / "errors").exists()


def test_the_command_line_counts_an_ensembles_members(tmp_path):
    config = tmp_path / "errors.yaml"
    config.write_text(
        "name: errors\ncolumn: {height: 2.0, base_width: 0.5}\n"
        "grid: {amplitudes: [0.1, 0.2], frequencies: [1.0]}\n"
    )
    out = tmp_path / "out"
    cli_error("sweep", config, "-o", out, "--ensemble", "1000000000",
              words=("2,000,000,000 runs", "1,000,000"))  # fmt: skip
    cli_error("sweep", config, "-o", out, "--ensemble", "60000", words=("120,000 runs", "--force"))
    assert not (out / "errors").exists()


# --------------------------------------------------------------------------- arguments


def _domain(**columns) -> pd.DataFrame:
    base = {"amplitude_g": [0.1, 0.2], "frequency_hz": [1.0, 1.0],
            "status": ["survived", "collapsed"]}  # fmt: skip
    return pd.DataFrame({**base, **columns})


@pytest.mark.parametrize(
    "call, words",
    [
        (lambda cfg: rbm.compare(cfg, _domain()), ("compare: a must be a domain", "Config")),
        (lambda cfg: rbm.compare(_domain(), None), ("compare: b must be a domain", "NoneType")),
        (lambda cfg: rbm.compare(_domain().drop(columns="status"), _domain()),
         ("compare: a is not a domain", "'status'")),
        (lambda cfg: rbm.compare(_domain(), _domain(status=["survived", "fell"])),
         ("compare: b: row 1: status must be one of", "'fell'")),
        (lambda cfg: rbm.compare(_domain(), _domain(amplitude_g=[0.1, "x"])),
         ("compare: b: row 1: amplitude_g must be a finite number",)),
        (lambda cfg: rbm.with_value(cfg, {"column.height": 3.0}, 1.0),
         ("with_value takes one key path", "rbm.with_values")),
        (lambda cfg: rbm.with_value(None, "column.height", 3.0),
         ("with_value: config must be a Config", "NoneType")),
        (lambda cfg: rbm.with_values({"name": "x"}, {"column.height": 3.0}),
         ("with_values: config must be a Config", "dict")),
        (lambda cfg: rbm.with_values(cfg, None), ("changes must be a mapping",)),
        (lambda cfg: rbm.sweep(cfg, jbos=2), ("sweep: unknown option 'jbos'", "allowed: jobs")),
        (lambda cfg: rbm.sweep(cfg, force="no"), ("force must be True or False", "'no'")),
        (lambda cfg: rbm.run(cfg, 0.1, 1.0, record="no"), ("record must be True or False",)),
        (lambda cfg: rbm.run(cfg, 0.1, 1.0, record=1), ("record must be True or False",)),
        (lambda cfg: rbm.run(cfg, 0.5, 2.0, motion=rbm.motion_from_arrays([0, 1], [0, 1])),
         ("frequency_hz does not apply to a motion given as arrays", "got 2")),
    ],
    ids=["compare-config", "compare-none", "compare-no-status", "compare-bad-status",
         "compare-bad-amplitude", "with_value-dict", "with_value-none", "with_values-dict",
         "with_values-none", "sweep-unknown", "sweep-flag", "run-record-no", "run-record-1",
         "run-motion-frequency"],
)  # fmt: skip
def test_bad_arguments_are_one_line_errors(call, words):
    one_line(lambda: call(rbm.load_config(BLOCK)), *words)


def test_an_unknown_sweep_option_is_named_before_a_folder_is_made(tmp_path):
    """With an output folder an unknown keyword was a TypeError of an inner function."""
    one_line(lambda: rbm.sweep(BLOCK, tmp_path, resum=True), "sweep: unknown option 'resum'")
    assert not (tmp_path / "errors").exists()


def test_a_records_frequency_is_refused(tmp_path):
    """A record config has no frequency: rbm.run(cfg, A, f) said nothing of it."""
    csv = tmp_path / "r.csv"
    csv.write_text("time_s,acceleration_g\n0.0,0.0\n0.5,0.3\n1.0,0.0\n")
    cfg = rbm.load_config({**BLOCK, "excitation": {"type": "record", "file": str(csv)},
                           "grid": {"amplitudes": [0.1]}})  # fmt: skip
    one_line(lambda: rbm.run(cfg, 0.1, 1.0), "frequency_hz does not apply to a record")
    assert rbm.run(cfg, 0.1).status == "survived"


@pytest.mark.parametrize("column", [{"capital": None}, {"top_mass": None}])
def test_an_empty_capital_or_top_mass_is_refused(column):
    """``capital: null`` (a section written without contents) was read as no capital."""
    key = next(iter(column))
    one_line(lambda: rbm.load_config({**BLOCK, "column": {**BLOCK["column"], **column}}),
             f"column.{key} is empty (null)", f"delete column.{key}",
             kind=rbm.ConfigError)  # fmt: skip


# --------------------------------------------------------------------------- fragility


def _suite(**extra) -> pd.DataFrame:
    """Three records at four amplitudes [g], each collapsing from its own capacity, with an
    ensemble's collapse_fraction (every member agreeing) and the run's counts."""
    rows = [{"record": r, "amplitude_g": a, "status": "collapsed" if a >= c else "survived",
             "collapsed": int(a >= c), "collapse_fraction": float(a >= c), "n_rhs": 100 + k}
            for k, (r, c) in enumerate((("r1", 0.3), ("r2", 0.5), ("r3", 0.7)))
            for a in (0.2, 0.4, 0.6, 0.8)]  # fmt: skip
    return pd.DataFrame(rows)


@pytest.mark.parametrize("n_members", [0, -3, math.nan, "3", True, 2.5])
def test_n_members_must_be_a_whole_number_of_members(n_members):
    """n_members 0, -3, nan, "3" (and a boolean, a fraction) were taken as 1."""
    one_line(lambda: rbm.fragility(_suite(), n_resamples=0, n_members=n_members),
             "n_members must be a whole number >= 1", repr(n_members))  # fmt: skip
    assert rbm.fragility(_suite(), n_resamples=0, n_members=np.int64(16)).fit is not None


def test_an_intensity_must_be_an_intensity_measure(tmp_path):
    """A count of the run (n_rhs) is not an intensity: refused by rbm.fragility and by
    rbm fragility --intensity; a record's measure and a spectral acceleration are taken."""
    one_line(lambda: rbm.fragility(_suite(), n_resamples=0, intensity="n_rhs"),
             "intensity must be an intensity measure, got 'n_rhs'", "pga_g")  # fmt: skip
    one_line(lambda: rbm.fragility(_suite(), n_resamples=0, intensity_column="t1_s"),
             "intensity_column must be an intensity measure")  # fmt: skip
    measured = _suite().assign(sa_0p5s_g=lambda d: 2.0 * d["amplitude_g"])
    fit = rbm.fragility(measured, n_resamples=0, intensity="sa_0p5s_g").fit
    assert fit.median_g == pytest.approx(2.0 * rbm.fragility(_suite(), n_resamples=0).fit.median_g)
    domain = tmp_path / "domain.csv"
    _suite().drop(columns="collapse_fraction").to_csv(domain, index=False)
    cli_error("fragility", domain, "--intensity", "n_rhs", "--resamples", "0",
              words=("--intensity must be an intensity measure", "'n_rhs'"))  # fmt: skip
    assert not any(p.name.startswith("fragility") for p in tmp_path.iterdir())


# --------------------------------------------------------------------------- capital


def test_the_smallest_capital_runs_and_a_smaller_one_is_refused():
    """A capital rocks on the shaft's top joint with its own small inertia: the smaller
    it is, the faster that mode, until a run exhausts the step budget (a 1e-4 m capital,
    the smallest once taken, failed at 2e-6 s). At the smallest now taken, 0.1 m, a 10 s
    harmonic on a 0.5 m shaft at the paper's k_n 5e9 Pa/m runs to its end within the
    default budget; a capital below it is refused in one line that names the key and the
    top mass for a smaller body."""
    shaft = {"height": 2.0, "base_width": 0.5}
    stiff = {"stiffness": {"normal": 5e9}}
    smallest = {"height": 0.1, "width": 0.1, "depth": 0.1}
    cfg = rbm.load_config({"name": "cap", "column": {**shaft, "capital": smallest},
                           "interface": stiff})  # fmt: skip
    cell = rbm.run(cfg, 0.1, 1.0, record=False)
    assert cell.status == "survived", cell.result.message
    assert cell.result.n_steps < cfg.solver.for_run(10.0, 2).max_steps  # its budget
    for key in ("height", "width", "depth"):
        capital = {**smallest, key: 0.0999}
        one_line(lambda capital=capital: rbm.load_config(
            {"name": "cap", "column": {**shaft, "capital": capital}, "interface": stiff}),
            f"column.capital.{key} must be in [0.1, ", "column.top_mass",
            kind=rbm.ConfigError)  # fmt: skip
