"""Sliding demand of model rbm against a friction coefficient, and the domain figure's marks.

Independent reasons: a rigid block at rest on the ground carries T = m a_g on N = m g, so
under a harmonic A sin(omega t) below its uplift level (A < g B / H) its friction demand
max |T / N| is A / g exactly and first exceeds mu < A / g at t = asin(mu g / A) / omega;
above the uplift level the demand is at least the uplift level B / H (it equals it at
uplift). Hence on a grid with mu below B / H a cell slides exactly where A / g > mu.
The figures are read back from their artists (gids, point counts, legend texts) and
checked against the domain's own columns and the column's static multiplier computed
from its geometry (tan alpha = B / H of a rectangular monolith).
"""

from __future__ import annotations

import dataclasses
import io
import json
import math

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402
from click.testing import CliRunner  # noqa: E402

import rbm  # noqa: E402
from rbm_cli.base.errors import ConfigError  # noqa: E402
from rbm_cli.cli.main import cli  # noqa: E402
from rbm_cli.report.domain_figure import domain_figure  # noqa: E402
from rbm_cli.report.plot_domain import (  # noqa: E402
    SLIDES_LABEL,
    UPPER_JOINT_LABEL,
    plot_domain,
)
from rbm_cli.study.domain import domain_config, parse_domain, read_domain  # noqa: E402
from rbm_cli.study.regression import check  # noqa: E402
from rbm_cli.study.simulate import simulate  # noqa: E402
from rbm_cli.study.sweep import config_hash, sweep_fields, sweep_rows  # noqa: E402

from .paths import CONFIGS, RESULTS  # noqa: E402

H, B = 2.0, 0.5  # a rigid monolith, uplift level B / H = 0.25 g
FREQ = 1.3  # Hz
METHODS = ("closed-form", "exact", "DOP853", "RK45", "RK23")


def block(friction=None, method="auto", grid=None, duration=3.0):
    raw = {
        "name": "slide_block",
        "column": {"height": H, "base_width": B},
        "excitation": {"type": "harmonic", "duration": duration},
        "solver": {"method": method},
    }
    if friction is not None:
        raw["interface"] = {"friction": friction}
    if grid is not None:
        raw["grid"] = grid
    return rbm.load_config(raw)


@pytest.mark.parametrize("method", METHODS)
def test_block_at_rest_has_demand_a_over_g_and_slips_at_the_closed_form_time(method):
    mu = 0.12
    errors = []
    for a in (0.05, 0.15, 0.2, 0.24):
        r = simulate(block(mu, method), a, FREQ)
        assert r.method == method and r.n_uplifts == 0 and r.status == "survived"
        errors.append(abs(r.friction_demand[0] - a))
        if a > mu:  # a_g = a g sin(omega t) first reaches mu g at asin(mu / a) / omega
            t_slip, where = r.slip
            assert where == 1
            assert t_slip == pytest.approx(math.asin(mu / a) / (2 * math.pi * FREQ), abs=1e-9)
            assert r.slides == 1
        else:
            assert r.slip is None and r.slides == 0
    assert max(errors) < 1e-6, errors


@pytest.mark.parametrize("method", METHODS)
def test_a_rocking_block_demands_at_least_its_uplift_level(method):
    r = simulate(block(None, method), 0.5, FREQ)
    assert r.n_uplifts >= 1 and r.friction_limit is None and r.slip is None
    assert r.friction_demand[0] >= B / H - 1e-9
    assert "slides" not in r.row() and math.isfinite(r.row()["friction_demand"])


def test_slides_exactly_where_a_over_g_exceeds_mu_on_a_grid():
    mu = 0.125  # below the uplift level 0.25: every cell above it demands more
    grid = {"amplitudes": {"start": 0.05, "stop": 0.6, "step": 0.05},
            "frequencies": {"start": 0.5, "stop": 3.0, "num": 6}}  # fmt: skip
    rows = sweep_rows(block(mu, grid=grid))
    assert "slides" in rows.fields
    assert rows.fields.index("slides") == rows.fields.index("friction_demand") + 1
    df = rows.frame()
    assert len(df) == 72 and (df["status"] != "failed").all()
    np.testing.assert_array_equal(df["slides"], (df["amplitude_g"] > mu).astype(int))
    below = df["amplitude_g"] < B / H
    np.testing.assert_allclose(df.loc[below, "friction_demand"], df.loc[below, "amplitude_g"],
                               rtol=0, atol=1e-9)  # fmt: skip
    assert (df.loc[~below, "friction_demand"] >= B / H - 1e-9).all()


def test_no_friction_no_slides_column_and_stored_hashes_unchanged():
    cfg = rbm.load_config(CONFIGS / "spanos_koh_slender.yaml")
    assert cfg.interface.friction_limit is None
    fields = sweep_fields(cfg)
    assert "friction_demand" in fields and "slides" not in fields
    meta = json.loads((RESULTS / "spanos_koh_slender" / "meta.json").read_text())
    assert config_hash(cfg) == meta["config_hash"].split("-")[0]
    checked = rbm.load_config({**cfg.written, "interface": {**cfg.written["interface"],
                                                             "friction": 0.6}})  # fmt: skip
    assert checked.interface.friction_limit == 0.6 and config_hash(checked) != config_hash(cfg)


def test_interface_friction_is_refused_where_no_demand_is_computed():
    for model in ("housner", "housner-linear"):
        with pytest.raises(ConfigError, match="interface.friction applies only to models"):
            rbm.load_config({"name": "x", "model": model,
                             "column": {"height": H, "base_width": B},
                             "interface": {"friction": 0.5}})  # fmt: skip


def test_stored_domains_without_the_column_pass_the_regression_rule():
    """A domain stored before friction_demand existed lacks it; a re-made one has it: the
    rule compares the cells it keeps (here the stored rows without the column stand for the
    older domain, the plain rows with it for a re-made one)."""
    made = read_domain(RESULTS / "spanos_koh_slender" / "domain.csv")
    assert "friction_demand" in made.columns
    older = made.drop(columns=["friction_demand"])
    fresh = made.drop(columns=["robust", "collapse_fraction", "sensitive_to"])
    assert check(older, fresh).ok
    flipped = fresh.assign(collapsed=1 - fresh["collapsed"])  # the rule can fail here
    assert not check(older, flipped).ok


def test_models_that_compute_no_demand_leave_the_column_empty():
    cfg = rbm.load_config({"name": "x", "model": "housner-linear",
                           "column": {"height": H, "base_width": B}})  # fmt: skip
    row = simulate(cfg, 0.5, FREQ).row()
    assert math.isnan(row["friction_demand"]) and "slides" not in row


def test_a_bullet_domain_keeps_no_demand_and_no_slides():
    """The engine's contacts slide: their |T/N| (capped by Coulomb) is no demand."""
    cfg = rbm.load_config({"name": "x", "model": "bullet", "column": {"height": H,
                           "base_width": B}, "interface": {"friction": 0.4}})  # fmt: skip
    assert cfg.interface.friction == 0.4 and cfg.interface.friction_limit is None
    assert "slides" not in sweep_fields(cfg)
    engine = dataclasses.replace(simulate(block(), 0.1, FREQ), model="bullet")
    assert engine.max_friction_demand == pytest.approx(0.1)
    assert math.isnan(engine.row()["friction_demand"]) and engine.slides is None


def test_run_summary_says_where_the_demand_first_exceeded_mu(tmp_path):
    cfg_path = tmp_path / "block.yaml"
    cfg_path.write_text(
        f"name: block\ncolumn: {{height: {H}, base_width: {B}}}\n"
        "interface: {friction: 0.1}\nexcitation: {type: harmonic, duration: 1.0}\n"
    )
    res = CliRunner().invoke(cli, ["run", str(cfg_path), "-a", "0.2", "-f", str(FREQ), "-o",
                                   str(tmp_path / "out")])  # fmt: skip
    assert res.exit_code == 0, res.output
    t_want = math.asin(0.1 / 0.2) / (2 * math.pi * FREQ)
    line = next(ln for ln in res.output.splitlines() if ln.startswith("slides:"))
    assert f"first at t = {t_want:.6g} s, interface 1" in line
    summary = json.loads(next((tmp_path / "out").rglob("summary.json")).read_text())
    assert summary["slip_interface"] == 1 and summary["slides"] == 1
    assert summary["t_slip_s"] == pytest.approx(t_want, abs=1e-9)
    result = rbm.run(rbm.load_config(cfg_path), amplitude_g=0.2, frequency_hz=FREQ,
                     record=False).result  # fmt: skip
    assert result["friction_limit"] == 0.1 and result.slip[1] == 1
    assert result.slip[0] == pytest.approx(t_want, abs=1e-9)


# ---- the domain figure


def _gid(ax, gid):
    return [a for a in ax.lines if a.get_gid() == gid]


def _legend(ax):
    return [t.get_text() for t in ax.get_legend().get_texts()]


def test_cells_are_marked_by_mechanism_and_slides():
    rows = []
    for f in (1.0, 2.0):
        for a, status, where, slides in ((0.1, "survived", None, 0), (0.3, "survived", None, 1),
                                         (0.5, "collapsed", 1, 1), (0.7, "collapsed", 3, 1),
                                         (0.9, "collapsed", 2, 1)):  # fmt: skip
            rows.append(dict(amplitude_g=a, frequency_hz=f, status=status,
                             collapse_interface=where, slides=slides))  # fmt: skip
    df = pd.DataFrame(rows)
    ax = plot_domain(df)
    (upper,) = _gid(ax, "upper-joint")
    assert len(upper.get_xdata()) == 4 and set(upper.get_ydata()) == {0.7, 0.9}
    assert upper.get_marker() != _gid(ax, "unsafe")[0].get_marker()
    (slides,) = _gid(ax, "slides")
    assert len(slides.get_xdata()) == int(df["slides"].sum()) == 8
    assert {UPPER_JOINT_LABEL, SLIDES_LABEL} <= set(_legend(ax))
    assert "cross alone" in UPPER_JOINT_LABEL  # a collapse at the base is the plain cross:
    assert sum(t == "unsafe (collapsed)" or "base joint" in t for t in _legend(ax)) == 1  # once
    # a domain without the columns draws none of these marks
    plain = plot_domain(df.drop(columns=["collapse_interface", "slides"]))
    assert not any(_gid(plain, g) for g in ("upper-joint", "slides", "base-joint"))
    assert UPPER_JOINT_LABEL not in _legend(plain)


def test_stored_multidrum_figure_states_its_column_and_upper_joint_collapses():
    csv = RESULTS / "harmonic_multidrum" / "domain.csv"
    df, cfg = read_domain(csv), domain_config(csv)
    (ax, *_) = domain_figure(df, cfg).axes
    note = ax.get_title().split("\n")[1]
    assert note == ("column: H = 5 m, B = 0.96 m (top 0.66 m), drums = 8, k_n = 5e+09 Pa/m,"
                    " e = 1, model rbm")  # fmt: skip
    upper = df[(df["status"] == "collapsed") & (df["collapse_interface"] > 1)]
    assert len(_gid(ax, "upper-joint")[0].get_xdata()) == len(upper) > 0


def test_overlay_over_drums_labels_each_static_multiplier():
    csv = RESULTS / "drum_count" / "domain.csv"
    df, cfg = read_domain(csv), domain_config(csv)
    (ax,) = domain_figure(df, cfg, layout="overlay").axes
    texts = _legend(ax)
    for k, drums in enumerate(sorted(df["column.drums"].unique())):
        # the static multiplier the sweep wrote beside each drum count's cells
        level = df.loc[df["column.drums"] == drums, "static_multiplier"].iloc[0]
        label = _gid(ax, f"boundary-{k}")[0].get_label()
        assert label == f"column.drums = {drums}, static multiplier {level:.3g} g"
        assert label in texts


def test_sweep_png_marks_the_cells_that_slide(tmp_path):
    mu = 0.125
    grid = {"amplitudes": {"start": 0.05, "stop": 0.3, "step": 0.05},
            "frequencies": {"start": 1.0, "stop": 2.0, "num": 2}}  # fmt: skip
    cfg = block(mu, grid=grid)
    df = parse_domain(io.StringIO(sweep_rows(cfg).csv()), "rows")
    (ax, *_) = domain_figure(df, cfg).axes
    (slides,) = _gid(ax, "slides")
    want = df[df["amplitude_g"] > mu]
    assert sorted(zip(slides.get_xdata(), slides.get_ydata(), strict=True)) == sorted(
        zip(want["frequency_hz"], want["amplitude_g"], strict=True)
    )
    assert "interface.friction = 0.125" in ax.get_title()
