"""The drum-count study: the tapered column in 1, 2, 4, 8 and 16 drums.

configs/drum_count.yaml sweeps the drum count as a grid axis (column.drums). Two of its points
are columns the project already stores, each from a config written by hand and swept on its
own: 1 drum is results/harmonic_monolithic, 8 drums results/harmonic_multidrum (their grids
hold this study's). The same column must give the same outcome on every cell that both
ensembles call robust: this checks that a point of the axis is the column the hand-written
config describes, through two independent sweeps. tests/test_regression.py re-makes the study.
"""

from __future__ import annotations

import pytest

from rbm_cli.config.load import load_config
from rbm_cli.study.cells import grid_points
from rbm_cli.study.domain import cell_key, read_domain

from .paths import CONFIGS, RESULTS


@pytest.fixture(scope="module")
def study():
    return read_domain(RESULTS / "drum_count" / "domain.csv")


def test_the_axis_is_the_drum_count(study):
    cfg = load_config(CONFIGS / "drum_count.yaml")
    counts = [p.config.column.n_drums for p in grid_points(cfg)]
    assert counts == [1, 2, 4, 8, 16]
    assert sorted(study["column.drums"].unique()) == counts
    for point in grid_points(cfg):
        heights = point.config.column.drum_heights
        assert sum(heights) == pytest.approx(5.0) and len(set(heights)) == 1


@pytest.mark.parametrize(
    ("drums", "stored"), [(1, "harmonic_monolithic"), (8, "harmonic_multidrum")]
)
def test_a_point_equals_the_column_swept_on_its_own(study, drums, stored):
    other = read_domain(RESULTS / stored / "domain.csv")
    mine = study[study["column.drums"] == drums]

    def table(df):
        cols = (df["amplitude_g"], df["frequency_hz"], df["collapsed"], df["robust"])
        return {cell_key(a, f): (c, r) for a, f, c, r in zip(*cols, strict=True)}

    a, b = table(mine), table(other)
    common = a.keys() & b.keys()
    assert len(common) == len(mine)  # the stored study's grid holds this one
    robust = [k for k in common if a[k][1] == 1 and b[k][1] == 1]
    assert len(robust) >= 0.8 * len(common)
    differ = [k for k in robust if a[k][0] != b[k][0]]
    assert not differ, differ[:5]
