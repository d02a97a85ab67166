"""Grid axes over any config key: parsing, refusals, sweeps, resume, compare.

Expected values come from the config itself (a point must equal the config written by hand
with that value), from closed forms (the RBM's p and alpha of a rectangular block) and from
the similarity law of rocking (rbm_cli.structures.similarity), never from the axis code.
"""

from __future__ import annotations

import dataclasses
import json
import math

import pandas as pd
import pytest

from rbm_cli.api import run_sweep
from rbm_cli.base.errors import ConfigError, RbmError
from rbm_cli.config.load import parse_config
from rbm_cli.config.types import G
from rbm_cli.study.cells import grid_cells, grid_points
from rbm_cli.study.domain import compare, read_domain
from rbm_cli.study.simulate import simulate
from rbm_cli.study.sweep import JOURNAL, config_hash

BLOCK = {
    "name": "axes",
    "column": {"height": 2.0, "base_width": 0.5, "drums": 1},
    "interface": {"stiffness": "rigid", "restitution": 1.0},
    "excitation": {"type": "half-sine", "duration": 6.0},
}


def config(grid: dict, **top):
    return parse_config({**BLOCK, **top, "grid": {"amplitudes": [0.3, 0.6], **grid}})


# ---------------------------------------------------------------------- parsing


def test_axis_points_are_the_configs_written_by_hand():
    cfg = config(
        {"frequencies": [1.0], "column.height": [1.0, 3.0], "interface.restitution": [0.8, 1.0]}
    )
    points = grid_points(cfg)
    assert [p.values for p in points] == [
        (("column.height", 1.0), ("interface.restitution", 0.8)),
        (("column.height", 1.0), ("interface.restitution", 1.0)),
        (("column.height", 3.0), ("interface.restitution", 0.8)),
        (("column.height", 3.0), ("interface.restitution", 1.0)),
    ]
    by_hand = parse_config(
        {**BLOCK, "column": {**BLOCK["column"], "height": 3.0},
         "interface": {**BLOCK["interface"], "restitution": 0.8}}
    )  # fmt: skip
    point = points[2].config
    assert point == dataclasses.replace(by_hand, grid=point.grid)
    assert (point.grid.amplitudes_g, point.grid.frequencies_hz, point.grid.axes) == (
        (0.3, 0.6),
        (1.0,),
        (),
    )
    assert len(grid_cells(cfg)) == 4 * 1 * 2


def test_linked_size_and_slenderness_axes():
    linked = config({"frequencies": [1.0], "linked": [
        {"column.height": [1.0, 4.0], "column.base_width": [0.25, 1.0]}]})  # fmt: skip
    cols = [p.config.column for p in grid_points(linked)]
    assert [(c.height, c.base_width) for c in cols] == [(1.0, 0.25), (4.0, 1.0)]

    tapered = {**BLOCK, "column": {"height": 2.0, "base_width": 0.5, "top_width": 0.4,
                                   "depth": 0.3, "drums": [0.5, 1.5]},
               "interface": {"stiffness": {"normal": 5e9}}}  # fmt: skip
    size = parse_config({**tapered, "grid": {"amplitudes": [0.1], "frequencies": [1.0],
                                             "column.size": [4.0]}})  # fmt: skip
    c = grid_points(size)[0].config.column
    assert (c.height, c.base_width, c.top_width, c.depth) == (4.0, 1.0, 0.8, 0.6)
    assert c.drum_heights == (1.0, 3.0)  # every length scaled by 2: a similar column

    slender = parse_config({**tapered, "grid": {"amplitudes": [0.1], "frequencies": [1.0],
                                                "column.slenderness": [8.0]}})  # fmt: skip
    c = grid_points(slender)[0].config.column
    assert c.height == 2.0 and c.base_width == pytest.approx(0.25)
    assert c.top_width == pytest.approx(0.2) and c.depth == pytest.approx(0.15)  # taper kept


def test_log_spacing_and_stiffness_axis_over_a_rigid_interface():
    cfg = config({"frequencies": [1.0], "column.size": {"start": 1, "stop": 100, "num": 3,
                                                        "spacing": "log"}})  # fmt: skip
    assert cfg.grid.axes[0].points == ((1.0,), (10.0,), (100.0,))
    stiff = config({"frequencies": [1.0], "interface.stiffness.normal": [5e8, 5e9]})
    kinds = [p.config.interface.stiffness for p in grid_points(stiff)]
    assert [(k.kind, k.values) for k in kinds] == [("normal", (5e8,)), ("normal", (5e9,))]


@pytest.mark.parametrize(
    ("grid", "fragments"),
    [
        (
            {"column.height": [1.0, -2.0]},
            ["grid point column.height = -2", "column.height must be"],
        ),
        ({"column.heigth": [1.0]}, ["grid point column.heigth = 1", "unknown key 'heigth'"]),
        ({"column.drums": [1, 0]}, ["grid point column.drums = 0", "column.drums must be"]),
        ({"interface.restitution": [0.5, 1.5]}, ["interface.restitution = 1.5"]),
        ({"name": ["a"]}, ["grid.name: name cannot vary over a grid"]),
        ({"grid.amplitudes": [1]}, ["grid.amplitudes cannot vary"]),
        ({"column.height": [1.0, 1.0]}, ["grid.column.height[1] repeats 1"]),
        ({"column.height": []}, ["grid.column.height must be"]),
        ({"column.size": [1.0], "column.height": [2.0]}, ["column.size and column.height"]),
        ({"column.slenderness": [0.0]}, ["column.slenderness must be a number > 0"]),
        (
            {"linked": [{"column.height": [1, 2], "column.base_width": [0.1]}]},
            ["linked axes must have as many values", "column.height: 2"],
        ),
        ({"linked": [{"column.height": [1, 2]}]}, ["grid.linked[0] must map two or more"]),
        (
            {"column.height": {"start": 1, "stop": 2, "step": 0.5, "spacing": "log"}},
            ["log needs num"],
        ),
        (
            {
                "column.height": [1.0],
                "linked": [{"column.height": [1, 2], "column.base_width": [0.1, 0.2]}],
            },
            ["the axis column.height is given twice"],
        ),
    ],
)
def test_a_bad_axis_is_refused_in_one_line(grid, fragments):
    with pytest.raises(ConfigError) as info:
        config({"frequencies": [1.0], **grid})
    message = str(info.value)
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, message


def test_a_plain_grid_hashes_as_before_the_axes_existed():
    """The stored results were made before grids had axes: their hashes must still hold
    (meta.json's config_hash of the stored study = the hash of its shipped config)."""
    from rbm_cli.config.load import load_config

    from .paths import CONFIGS, RESULTS

    meta = json.loads((RESULTS / "spanos_koh_slender" / "meta.json").read_text())
    digest = config_hash(load_config(CONFIGS / "spanos_koh_slender.yaml"))
    assert meta["config_hash"].startswith(digest)
    with_axis = config({"frequencies": [1.0], "column.height": [2.0]})
    assert config_hash(with_axis) != config_hash(config({"frequencies": [1.0]}))


# ---------------------------------------------------------------------- sweeps


def rbm_p_alpha(height: float, width: float) -> tuple[float, float]:
    """The RBM's rigid rectangular monolith as the linear model (closed form, alpha = B/H):
    tan alpha = B / H, p^2 = 6 g H / (4 H^2 + B^2)."""
    return math.atan(width / height), math.sqrt(6.0 * G * height / (4 * height**2 + width**2))


def test_sweep_rows_carry_the_point_and_the_scales(tmp_path):
    cfg = config({"frequencies": [1.0, 2.0], "column.size": [1.0, 4.0]})
    df = read_domain(run_sweep(cfg, tmp_path, jobs=1).folder / "domain.csv")
    assert list(df.columns[:3]) == ["column.size", "amplitude_g", "frequency_hz"]
    assert len(df) == 2 * 2 * 2
    for _, row in df.iterrows():
        size = row["column.size"]
        alpha, p = rbm_p_alpha(size, size / 4.0)
        assert row["alpha_rad"] == pytest.approx(alpha, rel=1e-12)
        assert row["p_rad_s"] == pytest.approx(p, rel=1e-12)
        assert row["a_over_g_alpha"] == pytest.approx(row["amplitude_g"] / math.tan(alpha))
        assert row["omega_over_p"] == pytest.approx(2 * math.pi * row["frequency_hz"] / p)
        by_hand = parse_config({**BLOCK, "column": {"height": size, "base_width": size / 4.0}})
        one = simulate(by_hand, row["amplitude_g"], row["frequency_hz"])
        assert (one.status, one.n_impacts) == (row["status"], row["n_impacts"])
    bnd = pd.read_csv(tmp_path / "axes" / "boundary.csv")
    assert list(bnd.columns) == ["column.size", "frequency_hz", "lowest_unsafe_g", "highest_safe_g"]
    assert len(bnd) == 4


def test_similar_blocks_rock_alike_in_time_units_of_p():
    """The similarity law: a block 4x larger at the same omega/p and A/(g tan alpha) has
    the same outcome, and its collapse time scales as 1/p."""
    small = parse_config({**BLOCK, "column": {"height": 1.0, "base_width": 0.25}})
    large = parse_config({**BLOCK, "column": {"height": 4.0, "base_width": 1.0}})
    (_, p1), (_, p4) = rbm_p_alpha(1.0, 0.25), rbm_p_alpha(4.0, 1.0)
    for a, f in ((0.5, 1.0), (0.45, 1.5), (0.8, 2.0)):
        r1, r4 = simulate(small, a, f), simulate(large, a, f * p4 / p1)
        assert r1.status == r4.status
        if r1.status == "collapsed":
            assert r4.t_collapse_s == pytest.approx(r1.t_collapse_s * p1 / p4, rel=1e-6)


def test_resume_ensemble_and_compare_on_axes(tmp_path):
    cfg = config({"frequencies": [1.0, 2.0], "interface.restitution": [0.9, 1.0]})
    whole = read_domain(run_sweep(cfg, tmp_path / "whole", jobs=1).folder / "domain.csv")
    with pytest.raises(RbmError, match="stopped after"):
        run_sweep(cfg, tmp_path / "cut", jobs=1, stop_after=1)
    assert (tmp_path / "cut" / "axes" / JOURNAL).exists()
    summary = run_sweep(cfg, tmp_path / "cut", jobs=2, resume=True)
    assert summary.n_resumed > 0 and summary.n_run > 0
    resumed = read_domain(summary.folder / "domain.csv")
    pd.testing.assert_frame_equal(resumed, whole)
    result = compare(whole, resumed)
    assert (result.n_common, result.n_differ, result.only_a) == (len(whole), 0, 0)
    assert list(result.shifts.columns[:2]) == ["interface.restitution", "frequency_hz"]

    other = whole.copy()
    i = other.index[(other["interface.restitution"] == 0.9) & (other["amplitude_g"] == 0.6)][0]
    other.loc[i, "collapsed"] = 1 - other.loc[i, "collapsed"]
    assert compare(whole, other).n_differ == 1  # cells matched on the axis value too

    ens = read_domain(run_sweep(cfg, tmp_path / "ens", jobs=2, ensemble=3).folder / "domain.csv")
    assert {"collapse_fraction", "robust"} <= set(ens.columns)
    assert (ens["collapsed"].to_numpy() == whole["collapsed"].to_numpy()).all()


def test_a_journal_row_of_another_point_is_not_trusted(tmp_path):
    cfg = config({"frequencies": [1.0], "column.height": [1.0, 2.0]})
    with pytest.raises(RbmError):
        run_sweep(cfg, tmp_path, jobs=1, stop_after=1)
    journal = tmp_path / "axes" / JOURNAL
    lines = journal.read_text().splitlines()
    row = json.loads(lines[1])
    row["column.height"] = 7.0  # not a point of the grid
    journal.write_text("\n".join([*lines, json.dumps(row)]) + "\n")
    notes: list[str] = []
    run_sweep(cfg, tmp_path, jobs=1, resume=True, notify=notes.append)
    assert any("not in the config's grid" in n for n in notes), notes


@pytest.mark.slow
def test_dask_sweeps_axes_as_the_local_workers_do(tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    cfg = config({"frequencies": [1.0], "column.slenderness": [3.0, 5.0]})
    ref = run_sweep(cfg, tmp_path / "ref", jobs=1)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, host="127.0.0.1", dashboard_address=None
    ) as cluster:
        got = run_sweep(
            cfg, tmp_path / "dask", jobs=2, backend="dask", scheduler=cluster.scheduler_address
        )
    assert (got.folder / "domain.csv").read_bytes() == (ref.folder / "domain.csv").read_bytes()


def test_rbm_compare_prints_the_point_of_each_boundary_line(tmp_path):
    from click.testing import CliRunner

    from rbm_cli.cli.main import cli

    cfg = config({"frequencies": [1.0], "interface.restitution": [0.9, 1.0]})
    csv = run_sweep(cfg, tmp_path, jobs=1).folder / "domain.csv"
    res = CliRunner().invoke(cli, ["compare", str(csv), str(csv)])
    assert res.exit_code == 0, res.output
    lines = res.output.splitlines()
    header = next(line for line in lines if "frequency [Hz]" in line)
    assert header.split()[0] == "interface.restitution"
    assert [line.split()[0] for line in lines[lines.index(header) + 1 :]] == ["0.9", "1.0"]
