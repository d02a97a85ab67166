"""`rbm sweep --ensemble K`: each cell run K times with tiny, documented
perturbations of phase, amplitude and tolerance (rbm_cli.study.robustness);
collapse_fraction and robust show which cells are robust."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from click.testing import CliRunner

from rbm_cli.api import run_sweep
from rbm_cli.cli.main import cli
from rbm_cli.config.load import load_config
from rbm_cli.config.types import GridConfig
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.models.block.closed_form import linear_run
from rbm_cli.structures.closed_forms import linear_rocking_parameters
from rbm_cli.study.domain import read_domain
from rbm_cli.study.robustness import LARGEST, RULE, SMALLEST, member_config, members, tight_rtol
from rbm_cli.study.simulate import model_from_config, simulate

from .paths import CONFIGS


def slender(amps=(0.2, 0.3, 0.5, 0.8), freqs=(0.5, 1.0, 2.0)):
    cfg = load_config(CONFIGS / "spanos_koh_slender.yaml")
    return dataclasses.replace(cfg, grid=GridConfig(amplitudes_g=amps, frequencies_hz=freqs))


def test_members_span_the_rule_and_start_unperturbed():
    """Member 0 is the cell; the others span 1e-12..1e-6 (log-spaced), all four sign
    pairs of (phase, amplitude), and two tolerances, as the rule says."""
    ms = members(16)
    assert (ms[0].phase_rad, ms[0].amplitude_relative, ms[0].tight) == (0.0, 0.0, False)
    eps = np.array([abs(m.phase_rad) for m in ms[1:]])
    np.testing.assert_array_equal(eps, [abs(m.amplitude_relative) for m in ms[1:]])
    assert eps.min() == pytest.approx(SMALLEST, rel=1e-12)
    assert eps.max() == pytest.approx(LARGEST, rel=1e-12)
    np.testing.assert_allclose(np.diff(np.log10(eps)), 6 / 14, rtol=1e-9)
    signs = {(np.sign(m.phase_rad), np.sign(m.amplitude_relative)) for m in ms[1:]}
    assert signs == {(1, 1), (1, -1), (-1, 1), (-1, -1)}
    assert {m.tight for m in ms[1:]} == {True, False}
    assert tight_rtol(1e-10) == pytest.approx(1e-11) and tight_rtol(1e-13) == pytest.approx(1e-12)


def closed_form_fraction(cfg, a, f, k):
    """Collapse fraction of the closed form (housner-linear with the RBM's inertia)
    over the same ensemble members: an independent model of the rigid block."""
    model = model_from_config(cfg)
    alpha, p = linear_rocking_parameters(model.column)
    flags = []
    for m in members(k):
        exc = dataclasses.replace(cfg.excitation, phase=cfg.excitation.phase + m.phase_rad)
        motion = make_ground_motion(exc, a * (1 + m.amplitude_relative), f)
        out = linear_run(alpha, p, motion, restitution=model.restitution)
        flags.append(out.status == "collapsed")
    return float(np.mean(flags))


def test_rigid_block_fractions_match_the_closed_form(tmp_path):
    """Member 0 is the plain cell; the fractions equal the closed form's over the
    same perturbations. Most cells are robust (0 or 1), but a block that
    collapses late (0.3 g, 1 Hz: at 9.13 s of 10 s) is not: a 1e-6 change of
    phase and amplitude lets it survive, in the closed form too."""
    cfg = slender()
    plain = read_domain(run_sweep(cfg, tmp_path / "plain", jobs=1).folder / "domain.csv")
    ens = run_sweep(cfg, tmp_path / "ens", jobs=2, ensemble=4)
    df = read_domain(ens.folder / "domain.csv")
    np.testing.assert_array_equal(df["collapsed"].to_numpy(), plain["collapsed"].to_numpy())
    expected = [closed_form_fraction(cfg, a, f, 4) for a, f in
                zip(df["amplitude_g"], df["frequency_hz"], strict=True)]  # fmt: skip
    np.testing.assert_array_equal(df["collapse_fraction"].to_numpy(), expected)
    assert 0.0 < min(x for x in expected if x > 0) < 1.0  # one sensitive cell in this grid
    # limits: below the uplift level (alpha g) no member moves; some cells always collapse
    alpha, _ = linear_rocking_parameters(model_from_config(cfg).column)
    below = df["amplitude_g"] < alpha
    assert below.any() and (df.loc[below, "collapse_fraction"] == 0.0).all()
    assert (df["collapse_fraction"] == 1.0).any()
    # the solver check: the step kernel at rtol/100, atol/100 (the closed form ran)
    tight = dataclasses.replace(cfg, solver=dataclasses.replace(
        cfg.solver, method="DOP853", rtol=1e-12, atol=1e-14))  # fmt: skip
    same = [simulate(tight, a, f).status == s for a, f, s in
            zip(df["amplitude_g"], df["frequency_hz"], df["status"], strict=True)]  # fmt: skip
    robust = np.isin(expected, [0.0, 1.0]) & np.array(same)
    np.testing.assert_array_equal(df["robust"], robust.astype(int))
    why = np.where(robust, "none", np.where(np.array(same), "inputs", "solver"))
    why[~np.isin(expected, [0.0, 1.0]) & ~np.array(same)] = "both"
    np.testing.assert_array_equal(df["sensitive_to"], why)
    meta = json.loads((ens.folder / "meta.json").read_text())
    assert meta["ensemble"] == {"members": 4, "rule": RULE}


def test_multidrum_ensemble_is_its_members_and_reproducible(tmp_path):
    """An 8-drum cell near the boundary (chaotic): the row's collapse_fraction and
    robust flag are those of its members run one by one through simulate (with
    member_config), and the sweep gives the same bytes on 1 and 2 workers."""
    cfg = load_config(CONFIGS / "harmonic_multidrum.yaml")
    cfg = dataclasses.replace(cfg, grid=GridConfig(amplitudes_g=(0.4,), frequencies_hz=(3.0,)))
    a = run_sweep(cfg, tmp_path / "a", jobs=1, ensemble=5)
    b = run_sweep(cfg, tmp_path / "b", jobs=2, ensemble=5)
    assert (a.folder / "domain.csv").read_bytes() == (b.folder / "domain.csv").read_bytes()
    row = read_domain(a.folder / "domain.csv").iloc[0]
    flags = []
    for m in members(5):
        member_cfg, amp = member_config(cfg, 0.4, m)
        flags.append(simulate(member_cfg, amp, 3.0).status == "collapsed")
    assert row["collapse_fraction"] == pytest.approx(np.mean(flags))
    # the solver check: the step kernel at rtol/100 and atol/100, and the exact integrator
    checks = [{"method": "DOP853", "rtol": 1e-12, "atol": 1e-14}, {"method": "exact"}]
    same = [simulate(dataclasses.replace(cfg, solver=dataclasses.replace(cfg.solver, **c)),
                     0.4, 3.0).status == "collapsed" for c in checks]  # fmt: skip
    members_agree = len(set(flags)) == 1
    solver_agrees = all(s == flags[0] for s in same)
    assert row["robust"] == int(members_agree and solver_agrees)
    why = ("none", "inputs", "solver", "both")[(not members_agree) + 2 * (not solver_agrees)]
    assert row["sensitive_to"] == why


def test_cli_ensemble_writes_fractions_and_refuses_zero(tmp_path):
    cfg_path = tmp_path / "c.yaml"
    text = (CONFIGS / "spanos_koh_slender.yaml").read_text()
    text = text.split("grid:")[0] + (
        "grid:\n  amplitudes: {start: 0.3, stop: 0.5, step: 0.1}\n"
        "  frequencies: {start: 1.0, stop: 2.0, num: 2}\ncollapse:\n  ratio: 1.0\n"
    )
    cfg_path.write_text(text)
    runner = CliRunner()
    res = runner.invoke(cli, ["sweep", str(cfg_path), "-o", str(tmp_path / "o"),
                              "--ensemble", "3", "-j", "1"])  # fmt: skip
    assert res.exit_code == 0, res.output
    folder = next((tmp_path / "o").iterdir())
    assert "collapse_fraction" in (folder / "domain.csv").read_text().splitlines()[0]
    assert (folder / "domain.png").is_file()
    bad = runner.invoke(cli, ["sweep", str(cfg_path), "-o", str(tmp_path / "p"),
                              "--ensemble", "0"])  # fmt: skip
    assert bad.exit_code == 2 and "ensemble" in bad.output.lower()
    assert "Traceback" not in bad.output
    assert not (tmp_path / "p").exists() or not any((tmp_path / "p").rglob("domain.csv"))
