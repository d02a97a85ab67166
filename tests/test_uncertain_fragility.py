"""The fragility of a record suite over samples of uncertain keys (rbm fragility on a domain
with a sample column): every run of every sample fitted, the dispersion split into the
records' and the keys' (rbm_cli.study.fragility_samples), and a curve per tercile of a key.

The oracles: the suite swept without uncertain keys (a point mass of every key draws it:
the keys then add no dispersion, beta_U = 0, and the records' dispersion is the
deterministic domain's); and rbm.fragility's fit of the rows of each sample or each
tercile taken apart in the test, from which the split's formulas (Vamvatsikos and
Fragiadakis 2010) are evaluated here.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest
import yaml
from click.testing import CliRunner

import rbm
from rbm_cli.cli.main import cli

from .paths import CONFIGS

RECORDS = [str(CONFIGS / "records" / "synthetic" / f"rdk_0{k}.AT2") for k in (1, 2, 3, 4)]
#: A Housner block 2 m x 0.5 m under 4 synthetic records at 5 PGAs, 2 s of free motion.
SUITE = {
    "name": "suite",
    "model": "housner",
    "column": {"height": 2.0, "base_width": 0.5},
    "interface": {"restitution": 0.9},
    "excitation": {
        "type": "record",
        "file": RECORDS,
        "units": "g",
        "scale": "pga",
        "free_time": 2.0,
    },  # fmt: skip
    "grid": {"amplitudes": [0.2, 0.3, 0.4, 0.6, 0.8]},
}


def _sweep(tmp_path, uncertain=None, out="out") -> str:
    data = json.loads(json.dumps(SUITE))
    if uncertain is not None:
        data["uncertain"] = uncertain
    path = tmp_path / f"{out}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    res = CliRunner().invoke(cli, ["sweep", str(path), "-o", str(tmp_path / out), "-j", "1"])
    assert res.exit_code == 0, res.output
    return str(tmp_path / out / "suite" / "domain.csv")


def _fragility(domain: str, *args: str):
    res = CliRunner().invoke(cli, ["fragility", domain, "--resamples", "0", *args])
    assert res.exit_code == 0, res.output
    return res, json.loads((pd.io.common.Path(domain).parent / "fragility.json").read_text())


def test_a_point_mass_adds_no_dispersion_to_the_records(tmp_path):
    plain = _sweep(tmp_path, out="plain")
    point = _sweep(tmp_path, {"samples": 3, "seed": 1, "keys": {
        "interface.restitution": {"uniform": [0.9, 0.9]},
        "column.density": {"lognormal": {"median": 2700.0, "beta": 0.0}},
    }}, out="point")  # fmt: skip
    _, deterministic = _fragility(plain)
    res, sampled = _fragility(point)
    split = sampled["dispersion"]
    assert deterministic["dispersion"] is None and split["n_fitted"] == split["n_samples"] == 3
    assert split["beta_u"] == 0.0
    assert split["beta_rtr"] == pytest.approx(deterministic["beta"], rel=1e-6)
    assert split["beta_total"] == pytest.approx(deterministic["beta"], rel=1e-6)
    # three copies of each run: the same likelihood's maximum
    assert sampled["median_g"] == pytest.approx(deterministic["median_g"], rel=1e-5)
    assert sampled["beta"] == pytest.approx(deterministic["beta"], rel=1e-5)
    assert sampled["n_runs"] == 3 * deterministic["n_runs"]
    assert "beta_RTR" in res.output and "beta_U 0" in res.output


@pytest.fixture(scope="module")
def uncertain_suite(tmp_path_factory):
    tmp_path = tmp_path_factory.mktemp("suite")
    return _sweep(tmp_path, {"samples": 6, "seed": 1, "keys": {
        "interface.restitution": {"uniform": [0.6, 0.95]},
        "column.density": {"lognormal": {"median": 2700.0, "beta": 0.3}},
    }})  # fmt: skip


def test_the_split_is_the_fits_of_the_samples_taken_apart(uncertain_suite):
    _, summary = _fragility(uncertain_suite)
    df = rbm.read_domain(uncertain_suite)
    fits = [rbm.fragility(df[df["sample"] == s], n_resamples=0).fit for s in range(6)]
    betas = np.array([f.beta for f in fits])
    medians = np.array([f.median_g for f in fits])
    split = summary["dispersion"]
    rtr, u = math.sqrt(np.mean(betas**2)), float(np.std(np.log(medians), ddof=1))
    assert split["beta_rtr"] == pytest.approx(rtr, rel=1e-6)
    assert split["beta_u"] == pytest.approx(u, rel=1e-6) and u > 0
    assert split["beta_total"] == pytest.approx(math.hypot(rtr, u), rel=1e-6)
    assert [p["median"] for p in split["per_sample"]] == pytest.approx(list(medians), rel=1e-6)
    # the fit over every run: records and keys together
    assert summary["beta"] == pytest.approx(split["beta_pooled"], rel=1e-9)
    assert summary["n_runs"] == len(df) == 6 * 20


def test_by_draws_a_fit_per_tercile_of_the_key(uncertain_suite, tmp_path):
    out = tmp_path / "by"
    res = CliRunner().invoke(cli, ["fragility", uncertain_suite, "--resamples", "0",
                                   "--by", "interface.restitution", "-o", str(out)])  # fmt: skip
    assert res.exit_code == 0, res.output
    table = pd.read_csv(out / "fragility_by.csv")
    assert (out / "fragility_by.png").stat().st_size > 0
    df = rbm.read_domain(uncertain_suite)
    value = df.groupby("sample")["uncertain.interface.restitution"].first().sort_values()
    assert list(table["tercile"]) == ["lower third", "middle third", "upper third"]
    for k, row in table.iterrows():
        samples = list(value.index[2 * k : 2 * k + 2])
        fit = rbm.fragility(df[df["sample"].isin(samples)], n_resamples=0).fit
        assert row["median"] == pytest.approx(fit.median_g, rel=1e-6)
        assert row["beta"] == pytest.approx(fit.beta, rel=1e-6)
        assert row["lowest"] == value[samples].min() and row["highest"] == value[samples].max()
    # a more elastic impact (a larger restitution) keeps more energy: a lower median
    assert table["median"].iloc[2] < table["median"].iloc[0]


def test_by_a_key_the_domain_does_not_have_is_one_line(uncertain_suite, tmp_path):
    res = CliRunner().invoke(cli, ["fragility", uncertain_suite, "--resamples", "0",
                                   "--by", "column.height", "-o", str(tmp_path)])  # fmt: skip
    assert res.exit_code == 2, res.output
    assert "column.height is not an uncertain key of the domain" in res.output
    assert len(res.output.strip().splitlines()) == 1
    assert not list(tmp_path.glob("fragility*"))


def test_a_stored_suite_of_samples_draws_and_compares_as_its_sweep_did(uncertain_suite, tmp_path):
    """Read back from domain.csv (a record's frequency an empty field), the domain is drawn
    and compared as the samples' majority, as the sweep drew domain.png and boundary.csv."""
    folder = pd.io.common.Path(uncertain_suite).parent
    png = tmp_path / "again.png"
    res = CliRunner().invoke(cli, ["plot-domain", uncertain_suite, "-o", str(png)])
    assert res.exit_code == 0, res.output
    assert png.read_bytes() == (folder / "domain.png").read_bytes()
    lines = pd.read_csv(folder / "boundary.csv")
    shifts = rbm.compare(uncertain_suite, uncertain_suite).shifts
    # (compare takes a line without collapse one grid step above the grid)
    has = lines["lowest_unsafe_g"].notna().to_numpy()
    assert has.any() and len(shifts) == len(lines)
    assert list(shifts["boundary_a_g"][has]) == list(lines["lowest_unsafe_g"][has])
