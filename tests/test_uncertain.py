"""Uncertain config keys (rbm_cli.config.uncertain): the Latin hypercube design, the sweep's
rows per cell and sample, the samples' majority in the figure, the refusal of bad
distributions, the sensitivity ranking and the design read back.

The oracles: scipy.stats' own distributions (a key's drawn values through its CDF fall one
in each of the design's strata); a sweep of the same column without uncertain keys (a
point mass draws the deterministic domain); Housner's block, whose rocking does not depend
on its density (the equation of motion has the mass on both sides) and depends on the
restitution (the energy kept at each impact).
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
import yaml
from click.testing import CliRunner
from scipy import stats

import rbm
from rbm_cli.api import run_sweep
from rbm_cli.base.errors import RbmError
from rbm_cli.cli.main import cli
from rbm_cli.report.domain_figure import column_note

#: A rigid block 2 m x 0.5 m (B/H = 0.25) under a harmonic of 4 s: a cell takes ~10 ms.
BLOCK = {
    "name": "block",
    "model": "housner",
    "column": {"height": 2.0, "base_width": 0.5},
    "interface": {"restitution": 0.9},
    "excitation": {"type": "harmonic", "duration": 4.0},
    "grid": {"amplitudes": [0.3, 0.4, 0.5, 0.6], "frequencies": [1.0, 2.0]},
}
#: The outcome columns of a row (what a run gave).
OUTCOME = ("status", "collapsed", "t_collapse_s", "max_rotation_ratio",
           "max_top_displacement_m", "n_uplifts", "n_impacts", "message")  # fmt: skip


def _config(tmp_path, uncertain=None, name="block", **changes) -> str:
    data = json.loads(json.dumps(BLOCK))
    data["name"] = name
    data.update(changes)
    if uncertain is not None:
        data["uncertain"] = uncertain
    path = tmp_path / f"{name}_{abs(hash(json.dumps(data, sort_keys=True)))}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return str(path)


def _sweep(config: str, out) -> object:
    return CliRunner().invoke(cli, ["sweep", config, "-o", str(out), "-j", "1"])


def test_a_point_mass_sweeps_the_deterministic_domain(tmp_path):
    """beta 0 and equal bounds draw one value: every sample's rows are the deterministic
    sweep's, and domain.png and boundary.csv are its own, byte for byte."""
    plain = _config(tmp_path)
    point = _config(tmp_path, {"samples": 4, "seed": 3, "keys": {
        "interface.restitution": {"uniform": [0.9, 0.9]},
        "column.density": {"lognormal": {"median": 2700.0, "beta": 0.0}},
        "column.height": {"truncnorm": {"mean": 2.0, "std": 0.1, "bounds": [2.0, 2.0]}},
    }})  # fmt: skip
    a, b = _sweep(plain, tmp_path / "a"), _sweep(point, tmp_path / "b")
    assert a.exit_code == 0 and b.exit_code == 0, a.output + b.output
    fa, fb = tmp_path / "a" / "block", tmp_path / "b" / "block"
    da, db = pd.read_csv(fa / "domain.csv", dtype=str), pd.read_csv(fb / "domain.csv", dtype=str)
    assert len(db) == 4 * len(da)
    assert sorted(db["sample"].unique()) == ["0", "1", "2", "3"]
    assert set(db["uncertain.interface.restitution"]) == {"0.9"}
    assert set(db["uncertain.column.density"]) == {"2700"}
    assert set(db["uncertain.column.height"]) == {"2"}
    cols = ["amplitude_g", "frequency_hz", *OUTCOME]
    for s in range(4):
        mine = db[db["sample"] == str(s)][cols].reset_index(drop=True)
        pd.testing.assert_frame_equal(mine, da[cols])
    assert (fb / "domain.png").read_bytes() == (fa / "domain.png").read_bytes()
    assert (fb / "boundary.csv").read_bytes() == (fa / "boundary.csv").read_bytes()


def _strata(values, cdf, n: int) -> list[int]:
    return sorted(int(k) for k in np.floor(np.asarray(cdf(values)) * n))


KEYS = {
    "interface.restitution": ({"uniform": [0.6, 0.95]}, stats.uniform(0.6, 0.35).cdf),
    "column.density": (
        {"lognormal": {"median": 2500.0, "beta": 0.3}},
        stats.lognorm(s=0.3, scale=2500.0).cdf,
    ),
    "column.height": (
        {"truncnorm": {"mean": 2.0, "std": 0.2, "bounds": [1.8, 2.5]}},
        stats.truncnorm(-1.0, 2.5, loc=2.0, scale=0.2).cdf,
    ),
    "column.base_width": (
        {"normal": {"mean": 0.5, "std": 0.01}},
        stats.norm(0.5, 0.01).cdf,
    ),
}


@pytest.mark.parametrize("n", [4, 16, 37])
def test_the_hypercube_puts_one_sample_in_each_stratum_of_every_key(n):
    """Through each key's CDF (scipy.stats, written here), the n values drawn fall one in
    each of the n strata [k/n, (k+1)/n)."""
    cfg = dict(BLOCK, uncertain={"samples": n, "seed": 7,
                                 "keys": {k: d for k, (d, _) in KEYS.items()}})  # fmt: skip
    design = rbm.read_design(cfg)
    assert list(design["sample"]) == list(range(n))
    for key, (_, cdf) in KEYS.items():
        assert _strata(design[f"uncertain.{key}"], cdf, n) == list(range(n)), key


def test_the_sweep_writes_the_values_each_run_used(tmp_path):
    """domain.csv holds, per row, the sample's values (one per stratum through the CDF),
    the rows of a sample run with them (the static multiplier B/H follows column.height),
    and meta.json the design, which rbm.read_design reads back."""
    keys = {"interface.restitution": KEYS["interface.restitution"][0],
            "column.height": KEYS["column.height"][0]}  # fmt: skip
    config = _config(tmp_path, {"samples": 4, "seed": 2, "keys": keys})
    res = _sweep(config, tmp_path)
    assert res.exit_code == 0, res.output
    folder = tmp_path / "block"
    df = rbm.read_domain(folder / "domain.csv")
    assert len(df) == 4 * 8 and list(df.columns[:3]) == [
        "sample", "uncertain.interface.restitution", "uncertain.column.height"]  # fmt: skip
    per_sample = df.groupby("sample").first()
    h = per_sample["uncertain.column.height"].to_numpy()
    assert _strata(h, KEYS["column.height"][1], 4) == [0, 1, 2, 3]
    np.testing.assert_allclose(per_sample["static_multiplier"], 0.5 / h, rtol=1e-10)
    assert (df.groupby("sample")["uncertain.column.height"].nunique() == 1).all()
    meta = json.loads((folder / "meta.json").read_text())
    assert meta["uncertain"]["seed"] == 2 and meta["uncertain"]["samples"] == 4
    assert meta["uncertain"]["keys"]["column.height"] == {
        "truncnorm": {"mean": 2.0, "std": 0.2, "bounds": [1.8, 2.5]}}  # fmt: skip
    design = rbm.read_design(folder)
    np.testing.assert_array_equal(design["uncertain.column.height"], h)
    assert design.attrs["uncertain"]["seed"] == 2


def test_the_same_seed_draws_the_same_design_and_another_seed_another():
    keys = {k: d for k, (d, _) in KEYS.items()}
    one = rbm.read_design(dict(BLOCK, uncertain={"samples": 8, "seed": 1, "keys": keys}))
    again = rbm.read_design(dict(BLOCK, uncertain={"samples": 8, "seed": 1, "keys": keys}))
    other = rbm.read_design(dict(BLOCK, uncertain={"samples": 8, "seed": 2, "keys": keys}))
    pd.testing.assert_frame_equal(one, again)
    for key in keys:
        assert not np.array_equal(one[f"uncertain.{key}"], other[f"uncertain.{key}"]), key
    assert rbm.read_design(BLOCK) is None


@pytest.mark.parametrize(
    "keys, says",
    [
        ({"interface.restitution": {"gamma": {"k": 2}}}, "unknown distribution 'gamma'"),
        ({"column.density": {"lognormal": {"median": 2700, "beta": -0.1}}}, "beta must be >= 0"),
        ({"interface.restitution": {"uniform": [0.95, 0.85]}}, "lo <= hi"),
        ({"column.height": {"truncnorm": {"mean": 2.0, "std": 0.1, "bounds": [3, 1]}}},
         "lo <= hi"),
        ({"column.height": {"truncnorm": {"mean": 2.0, "std": 0.1}}}, "bounds is required"),
        ({"interface.restitution": {"normal": {"mean": 0.9, "std": -0.1}}}, "std must be >= 0"),
        # the support allows values the key refuses: a stiffness must be > 0
        ({"interface.stiffness.normal": {"normal": {"mean": 5.0e9, "std": 2.0e9}}},
         "interface.stiffness.normal must be a number > 0"),
        ({"interface.restitution": {"uniform": [0.9, 1.2]}}, "can draw 1.05"),
        ({"interface.restitutoin": {"uniform": [0.8, 0.9]}}, "unknown key 'restitutoin'"),
        ({"excitation.type": {"uniform": [1, 2]}}, "excitation.type must be one of"),
        ({"grid.amplitudes": {"uniform": [1, 2]}}, "grid cannot be uncertain"),
    ],
)  # fmt: skip
def test_a_bad_distribution_is_one_line_at_load_time(tmp_path, keys, says):
    config = _config(tmp_path, {"samples": 4, "seed": 1, "keys": keys})
    res = _sweep(config, tmp_path / "out")
    assert res.exit_code == 2, res.output
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in res.output, res.output
    assert says in lines[0] and "uncertain" in lines[0], lines[0]
    key = next(iter(keys))
    assert key in lines[0] or key.split(".")[0] in lines[0]
    assert not (tmp_path / "out" / "block").exists()


@pytest.mark.parametrize("samples", [0, 2.5, "four"])
def test_a_bad_number_of_samples_is_refused(tmp_path, samples):
    keys = {"interface.restitution": {"uniform": [0.8, 0.9]}}
    config = _config(tmp_path, {"samples": samples, "seed": 1, "keys": keys})
    res = _sweep(config, tmp_path / "out")
    assert res.exit_code == 2 and "uncertain.samples" in res.output, res.output
    assert len(res.output.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_the_sensitivity_ranks_the_restitution_above_the_density(tmp_path):
    """A Housner block: the restitution moves the peak rotation, the density does not (it
    cancels from the equation of motion); the ranking says so, through the CLI."""
    config = _config(tmp_path, {"samples": 8, "seed": 1, "keys": {
        "interface.restitution": {"uniform": [0.5, 0.95]},
        "column.density": {"lognormal": {"median": 2700.0, "beta": 0.3}},
    }})  # fmt: skip
    assert _sweep(config, tmp_path).exit_code == 0
    domain = tmp_path / "block" / "domain.csv"
    res = CliRunner().invoke(cli, ["sensitivity", str(domain), "-o", str(tmp_path / "s")])
    assert res.exit_code == 0, res.output
    table = pd.read_csv(tmp_path / "s" / "sensitivity.csv")
    assert (tmp_path / "s" / "sensitivity.png").stat().st_size > 0
    ratio = table[table["outcome"] == "max_rotation_ratio"].set_index("key")
    assert list(ratio.index) == ["interface.restitution", "column.density"]
    assert ratio.loc["interface.restitution", "prcc"] > 0.4
    assert ratio.loc["interface.restitution", "prcc_p"] < 0.01
    assert abs(ratio.loc["column.density", "prcc"]) < ratio.loc["interface.restitution", "prcc"]
    # the density's rows are those of the same restitution: it moves nothing
    df = pd.read_csv(domain)
    same = df.groupby(["uncertain.interface.restitution", "amplitude_g", "frequency_hz"])
    assert (same["max_rotation_ratio"].nunique() == 1).all()


def test_the_sensitivity_of_a_domain_without_samples_is_one_line(tmp_path):
    assert _sweep(_config(tmp_path), tmp_path).exit_code == 0
    res = CliRunner().invoke(cli, ["sensitivity", str(tmp_path / "block" / "domain.csv")])
    assert res.exit_code == 2 and "no samples of uncertain keys" in res.output
    assert len(res.output.strip().splitlines()) == 1


def test_an_interrupted_sweep_of_samples_resumes_to_the_same_domain(tmp_path):
    keys = {"interface.restitution": {"uniform": [0.6, 0.95]}}
    cfg = rbm.load_config(dict(BLOCK, uncertain={"samples": 4, "seed": 5, "keys": keys}))
    straight = run_sweep(cfg, tmp_path / "straight", jobs=1)
    with pytest.raises(RbmError, match="stopped after"):
        run_sweep(cfg, tmp_path / "cut", jobs=1, stop_after=2)
    resumed = run_sweep(cfg, tmp_path / "cut", jobs=1, resume=True)
    assert 0 < resumed.n_resumed < resumed.n_cells == 32
    for name in ("domain.csv", "boundary.csv", "domain.png"):
        a = (straight.folder / name).read_bytes()
        assert (resumed.folder / name).read_bytes() == a, name


def test_an_ensemble_of_samples_has_a_row_per_cell_and_sample(tmp_path):
    keys = {"interface.restitution": {"uniform": [0.6, 0.95]}}
    cfg = rbm.load_config(dict(BLOCK, uncertain={"samples": 2, "seed": 5, "keys": keys}))
    df = rbm.sweep(cfg, jobs=1, ensemble=3)
    assert len(df) == 2 * 8 and {"collapse_fraction", "sample"} <= set(df.columns)


def test_the_figure_shows_the_samples_majority(tmp_path):
    """domain.png draws a cell collapsed where half its samples or more collapsed: the
    figure of a domain whose rows are replaced by their majority is the same."""
    keys = {"interface.restitution": {"uniform": [0.5, 0.95]}}
    config = _config(tmp_path, {"samples": 4, "seed": 1, "keys": keys})
    assert _sweep(config, tmp_path).exit_code == 0
    df = rbm.read_domain(tmp_path / "block" / "domain.csv")
    cfg = rbm.load_config(config)
    share = df.groupby(["amplitude_g", "frequency_hz"], sort=False)["collapsed"].mean()
    assert ((share > 0) & (share < 1)).any()  # cells where the samples disagree
    lines = pd.read_csv(tmp_path / "block" / "boundary.csv")
    for _, line in lines.iterrows():
        f = line["frequency_hz"]
        collapsed = sorted(a for (a, ff), s in share.items() if ff == f and s >= 0.5)
        assert (collapsed[0] if collapsed else np.nan) == pytest.approx(
            line["lowest_unsafe_g"], nan_ok=True
        )
    note = column_note(cfg)
    assert "e = uncertain" in note and "the majority of 4 samples" in note
