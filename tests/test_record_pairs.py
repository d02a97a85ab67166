"""Suites of record pairs written directly: ``excitation.file_y`` as a list, folder or glob
beside ``excitation.file``'s, or ``excitation.file`` as a list of ``{x, y}``. Each is the
linked grid axis over ``excitation.file`` and ``excitation.file_y`` (the same config, hash,
runs and rows); bad forms are refused in one line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from rbm_cli.base.errors import ConfigError
from rbm_cli.cli.main import cli
from rbm_cli.config import parse_config
from rbm_cli.study.sweep import config_hash

RECORDS = Path(__file__).resolve().parents[1] / "configs" / "records" / "synthetic"
COLUMN = {"height": 4.0, "base_width": 1.0, "top_width": 0.8, "section": "circular",
          "density": 2700}  # fmt: skip
PAIRS = [("rdk_01.AT2", "rdk_02.AT2"), ("rdk_03.AT2", "rdk_04.AT2")]
LINKED = {"linked": [{"excitation.file": [x for x, _ in PAIRS],
                      "excitation.file_y": [y for _, y in PAIRS]}]}  # fmt: skip
AS_PAIRS = {"file": [{"x": x, "y": y} for x, y in PAIRS]}


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """rdk_01..04 side by side, the x records also in x/ and the y records in y/, and a
    record sampled otherwise (short.csv)."""
    root = tmp_path_factory.mktemp("pairs")
    for sub in ("", "x", "y"):
        (root / sub).mkdir(exist_ok=True)
    for x, y in PAIRS:
        for name, sub in ((x, "x"), (y, "y")):
            data = (RECORDS / name).read_bytes()
            (root / name).write_bytes(data)
            (root / sub / name).write_bytes(data)
    np.savetxt(root / "short.csv", np.c_[np.arange(10) * 0.01, np.full(10, 0.1)],
               delimiter=",", header="time_s,acc_g", comments="")  # fmt: skip
    return root


def raw(model: str = "housner-3d", grid: dict | None = None, **excitation) -> dict:
    return {
        "name": "pairs", "model": model, "column": dict(COLUMN),
        "interface": {"stiffness": "rigid", "restitution": 0.9},
        "excitation": {"type": "record", "units": "g", "free_time": 1.0, **excitation},
        "grid": {"amplitudes": [0.2, 0.5], **(grid or {})},
    }  # fmt: skip


def linked(folder):
    return parse_config(raw(file=PAIRS[0][0], file_y=PAIRS[0][1], grid=LINKED), base_dir=folder)


@pytest.mark.parametrize(
    "excitation",
    [
        AS_PAIRS,
        {"file": [x for x, _ in PAIRS], "file_y": [y for _, y in PAIRS]},
        {"file": "rdk_0[13].AT2", "file_y": "rdk_0[24].AT2"},
        {"file": "rdk_0[13].AT2", "file_y": [y for _, y in PAIRS]},
    ],
    ids=["pairs", "lists", "globs", "glob-and-list"],
)
def test_each_form_is_the_linked_axis(folder, excitation):
    """The config of each form equals the linked axis's, hash included: one axis linking
    excitation.file and excitation.file_y, the excitation set to the first pair."""
    cfg, ref = parse_config(raw(**excitation), base_dir=folder), linked(folder)
    assert cfg == ref and config_hash(cfg) == config_hash(ref)
    (axis,) = cfg.grid.axes
    assert axis.paths == ("excitation.file", "excitation.file_y") and list(axis.points) == PAIRS
    assert (cfg.excitation.file, cfg.excitation.file_y) == PAIRS[0]


def test_parallel_folders_pair_in_sorted_order(folder):
    """Two folders: the k-th file of each (sorted) is a pair."""
    cfg = parse_config(raw(file="x", file_y="y"), base_dir=folder)
    (axis,) = cfg.grid.axes
    assert list(axis.points) == [(f"x/{x}", f"y/{y}") for x, y in PAIRS]


@pytest.mark.slow
def test_a_sweep_of_pairs_gives_the_linked_axis_rows(folder):
    """Two pairs x two amplitudes: the rows of the pairs {x, y} and of the parallel globs
    are those of the linked axis, every column; each pair is named as its x record."""
    import rbm

    ref = rbm.sweep(linked(folder))
    assert ref["record"].tolist() == ["rdk_01", "rdk_01", "rdk_03", "rdk_03"]
    assert list(zip(ref["excitation.file"], ref["excitation.file_y"], strict=True)) == [
        PAIRS[0], PAIRS[0], PAIRS[1], PAIRS[1]]  # fmt: skip
    assert "collapsed" in set(ref.status) and ref.max_rotation_ratio.max() > 0.0
    for excitation in (AS_PAIRS, {"file": "rdk_0[13].AT2", "file_y": "rdk_0[24].AT2"}):
        df = rbm.sweep(parse_config(raw(**excitation), base_dir=folder))
        pd.testing.assert_frame_equal(df, ref)


def test_a_file_suite_without_file_y_is_unchanged(folder):
    """No file_y: the suite is the axis over excitation.file alone, as before."""
    cfg = parse_config(raw(file="rdk_0[13].AT2"), base_dir=folder)
    (axis,) = cfg.grid.axes
    assert axis.paths == ("excitation.file",) and cfg.excitation.file_y is None


def refusal(folder, message: str, model: str = "housner-3d", grid=None, **excitation) -> str:
    with pytest.raises(ConfigError) as err:
        parse_config(raw(model, grid, **excitation), base_dir=folder)
    text = str(err.value)
    assert "\n" not in text and message in text, text
    return text


@pytest.mark.parametrize(
    ("excitation", "message"),
    [
        ({"file": "rdk_0[1-3].AT2", "file_y": "rdk_0[24].AT2"},
         "excitation.file names 3 records and excitation.file_y 2 records"),
        ({"file": [x for x, _ in PAIRS], "file_y": "rdk_02.AT2"},
         "excitation.file names 2 records and excitation.file_y 1 record"),
        ({"file": "rdk_01.AT2", "file_y": [y for _, y in PAIRS]},
         "excitation.file names 1 record and excitation.file_y 2 records"),
        ({**AS_PAIRS, "file_y": "rdk_02.AT2"},
         "excitation.file lists pairs {x, y} and excitation.file_y is given too"),
        ({"file": [{"x": "rdk_01.AT2", "y": "rdk_02.AT2", "z": "rdk_03.AT2"}]},
         "unknown key 'z' in excitation.file[0] (allowed: x, y)"),
        ({"file": [{"x": "rdk_01.AT2"}]}, "excitation.file[0].y is required"),
        ({"file": [{"x": "rdk_01.AT2", "y": "rdk_02.AT2"}, "rdk_03.AT2"]},
         "excitation.file[1] must be a pair {x: FILE, y: FILE}"),
        ({"file": {"x": "rdk_01.AT2", "y": "rdk_02.AT2"}},
         "excitation.file: a pair {x: FILE, y: FILE} goes in a list"),
        ({"file": [{"x": "rdk_01.AT2", "y": 3}]},
         "excitation.file[0].y must be a record file's path, got 3"),
        ({"file": [{"x": "x", "y": "rdk_02.AT2"}]},
         "excitation.file[0].x: 'x' is a folder or a pattern"),
        ({"file": [{"x": "rdk_01.AT2", "y": "rdk_02.AT2"}, {"x": "rdk_01.AT2", "y": "rdk_04.AT2"}]},
         "excitation.file[1].x: 'rdk_01.AT2' is named twice (at excitation.file[0].x too)"),
        ({"file": [{"x": "rdk_01.AT2", "y": "rdk_01.AT2"}]},
         "excitation.file[0].y: 'rdk_01.AT2' is the pair's x record too"),
        ({"file": [x for x, _ in PAIRS], "file_y": 3},
         "excitation.file_y must be a record file, a list of them, a folder or a glob"),
    ],
)  # fmt: skip
def test_a_bad_suite_of_pairs_is_refused_in_one_line(folder, excitation, message):
    refusal(folder, message, **excitation)


def test_an_axis_beside_a_suite_of_pairs_is_refused(folder):
    for grid in ({"excitation.file_y": ["rdk_04.AT2"]}, LINKED):
        refusal(folder, "excitation.file names a suite of pairs and the grid has an axis over",
                grid=grid, **AS_PAIRS)  # fmt: skip


def test_a_planar_model_refuses_pairs(folder):
    for excitation in (AS_PAIRS, {"file": "rdk_0[13].AT2", "file_y": "rdk_0[24].AT2"}):
        refusal(folder, "excitation.file_y is a second horizontal component", "housner",
                **excitation)  # fmt: skip


def test_every_pair_is_checked_for_its_sampling_and_named(folder):
    """A y record sampled otherwise than its x, in the first pair or a later one: one line
    naming both files of that pair."""
    for pairs in ([("rdk_01.AT2", "short.csv"), PAIRS[1]], [PAIRS[0], ("rdk_03.AT2", "short.csv")]):
        text = refusal(folder, "must be sampled as excitation.file",
                       file=[{"x": x, "y": y} for x, y in pairs])  # fmt: skip
        bad = next(x for x, y in pairs if y == "short.csv")
        assert bad in text and "short.csv" in text
    text = refusal(folder, "must be sampled as excitation.file", file="rdk_0[13].AT2",
                   file_y=["rdk_02.AT2", "short.csv"])  # fmt: skip
    assert "grid point excitation.file = 'rdk_03.AT2', excitation.file_y = 'short.csv'" in text


def test_the_command_line_refuses_in_one_line(folder, tmp_path):
    path = tmp_path / "counts.yaml"
    path.write_text(
        "name: counts\nmodel: housner-3d\n"
        "column: {height: 4.0, base_width: 1.0, top_width: 0.8, section: circular}\n"
        f"excitation: {{type: record, file: '{folder}/rdk_0[1-3].AT2',"
        f" file_y: '{folder}/rdk_0[24].AT2'}}\n"
        "grid: {amplitudes: [0.2]}\n"
    )
    res = CliRunner().invoke(cli, ["sweep", str(path), "-o", str(tmp_path / "out")])
    lines = [line for line in res.output.splitlines() if line.strip()]
    assert res.exit_code == 2 and "Traceback" not in res.output, res.output
    assert len(lines) == 1 and lines[0].startswith("Error:"), res.output
    assert "excitation.file names 3 records and excitation.file_y 2 records" in lines[0]
    assert not (tmp_path / "out").exists()
