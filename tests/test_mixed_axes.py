"""Axes whose values mix names and numbers (`interface.restitution: [0.9, housner, 0.5]`) or
are names only (a suite's `excitation.file`): the sweep publishes domain.csv, boundary.csv
and domain.png, boundary.csv's lines in grid order (each such axis's values as written),
and `rbm plot-domain` and `rbm compare` read the result. Each point's boundary is checked
against a sweep of that point alone, a config without the axis."""

from __future__ import annotations

import csv
import io

import matplotlib

matplotlib.use("Agg")

import pytest  # noqa: E402
import yaml  # noqa: E402
from click.testing import CliRunner  # noqa: E402

import rbm_cli.base.files  # noqa: E402
from rbm_cli.api import run_sweep  # noqa: E402
from rbm_cli.base.errors import RbmError  # noqa: E402
from rbm_cli.cli.main import cli  # noqa: E402
from rbm_cli.config.load import load_config  # noqa: E402

from .record_files import half_sine_csv  # noqa: E402

#: A rigid block 2 m x 0.5 m (uplift at 0.25 g) under 3 s of harmonic motion: at 2 Hz it
#: collapses from 1 g with Housner's restitution, from 2 g with 0.9 or 0.5.
BLOCK = {
    "name": "mixed",
    "column": {"height": 2.0, "base_width": 0.5, "depth": 0.5, "drums": 1},
    "interface": {"stiffness": "rigid", "restitution": 1.0},
    "excitation": {"type": "harmonic", "duration": 3.0},
    "grid": {"amplitudes": [0.2, 0.5, 1.0, 2.0], "frequencies": [1.0, 2.0]},
}
#: The axis as written: a name between two numbers, in no sorted order.
WRITTEN = [0.9, "housner", 0.5]


def invoke(*args):
    return CliRunner().invoke(cli, [str(a) for a in args])


def write_config(path, data):
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def with_axis(values, name="mixed"):
    return {**BLOCK, "name": name, "grid": {**BLOCK["grid"], "interface.restitution": values}}


def read_rows(path) -> list[dict]:
    return list(csv.DictReader(io.StringIO(path.read_text(encoding="utf-8"))))


def sweep_cli(config_path, out, *extra):
    res = invoke("sweep", config_path, "-o", out, "--jobs", "1", "--quiet", *extra)
    assert res.exit_code == 0, res.output
    assert "Traceback" not in res.output
    return res


def alone(tmp_path, value) -> list[tuple[str, str, str]]:
    """(frequency, lowest unsafe, highest safe) of each boundary line of the block swept
    with ``interface.restitution: value`` and no axis."""
    data = {**BLOCK, "name": "alone", "interface": {**BLOCK["interface"], "restitution": value}}
    out = tmp_path / f"alone-{value}"
    sweep_cli(write_config(tmp_path / f"alone-{value}.yaml", data), out)
    rows = read_rows(out / "alone" / "boundary.csv")
    return [(r["frequency_hz"], r["lowest_unsafe_g"], r["highest_safe_g"]) for r in rows]


def test_an_axis_mixing_a_name_and_numbers_publishes_its_domain(tmp_path, monkeypatch):
    """Defect: a grid axis holding both `housner` and numbers (allowed for
    interface.restitution) made the sweep fail with a TypeError while writing
    boundary.csv, after every cell had run; nothing was published. Now the four files are
    published; boundary.csv has one line per point and frequency, the points in the order
    the axis is written, each the boundary of that point swept alone; `rbm plot-domain`
    draws a panel per point in that order and `rbm compare` reads the domain."""
    config = write_config(tmp_path / "mixed.yaml", with_axis(WRITTEN))
    sweep_cli(config, tmp_path / "out")
    folder = tmp_path / "out" / "mixed"
    for name in ("domain.csv", "boundary.csv", "domain.png", "meta.json"):
        assert (folder / name).is_file(), name
    assert (folder / "domain.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not list(folder.glob("domain.partial*")), "the journal stays after publishing"

    domain = read_rows(folder / "domain.csv")
    assert len(domain) == 3 * 2 * 4
    assert [r["interface.restitution"] for r in domain[::8]] == ["0.9", "housner", "0.5"]
    lines = read_rows(folder / "boundary.csv")
    assert list(lines[0]) == ["interface.restitution", "frequency_hz", "lowest_unsafe_g",
                              "highest_safe_g"]  # fmt: skip
    points = [r["interface.restitution"] for r in lines]
    assert points == ["0.9", "0.9", "housner", "housner", "0.5", "0.5"]
    by_point = {}
    for r in lines:
        by_point.setdefault(r["interface.restitution"], []).append(
            (r["frequency_hz"], r["lowest_unsafe_g"], r["highest_safe_g"])
        )
    for value in WRITTEN:
        assert by_point[str(value)] == alone(tmp_path, value), value
    # the points do not all share one boundary: the check above can tell them apart
    assert len({tuple(v) for v in by_point.values()}) > 1

    drawn = []
    monkeypatch.setattr(
        rbm_cli.base.files, "save_figure_atomic", lambda fig, path: drawn.append(fig)
    )
    res = invoke("plot-domain", folder / "domain.csv", "-o", tmp_path / "fig.png")
    assert res.exit_code == 0, res.output
    (fig,) = drawn
    panels = [ax for ax in fig.axes if ax.get_title()]
    titles = [ax.get_title() for ax in panels]
    assert titles == [f"interface.restitution = {v}" for v in WRITTEN]
    for ax, value in zip(panels, WRITTEN, strict=True):
        (line,) = [ln for ln in ax.get_lines() if ln.get_gid() == "boundary"]
        want = [float(low) if low else float("nan") for _, low, _ in by_point[str(value)]]
        assert list(line.get_ydata()) == pytest.approx(want, nan_ok=True)


def test_rbm_compare_reads_mixed_axes_written_in_another_order(tmp_path):
    """Defect: a domain over an axis mixing a name and numbers could not be published,
    so it could not be compared. Two sweeps of the same points, the axis written in two
    orders, are the same domain: compare matches every cell and lists the boundary lines
    in the first domain's grid order."""
    for name, values in (("a", WRITTEN), ("b", ["housner", 0.5, 0.9])):
        sweep_cli(write_config(tmp_path / f"{name}.yaml", with_axis(values, name)),
                  tmp_path / "out")  # fmt: skip
    res = invoke("compare", tmp_path / "out" / "a" / "domain.csv",
                 tmp_path / "out" / "b" / "domain.csv")  # fmt: skip
    assert res.exit_code == 0, res.output
    assert "24 in common, 0 differ" in res.output
    assert "only in A: 0, only in B: 0" in res.output
    lines = res.output.splitlines()
    header = next(k for k, line in enumerate(lines) if "frequency [Hz]" in line)
    table = [line.split() for line in lines[header + 1 :]]
    assert [(row[0], row[1]) for row in table] == [
        ("0.9", "1"), ("0.9", "2"), ("housner", "1"), ("housner", "2"), ("0.5", "1"),
        ("0.5", "2"),
    ]  # fmt: skip
    assert all(row[-1] == "+0" for row in table)


def test_resume_publishes_a_mixed_axis_as_a_straight_run(tmp_path):
    """Defect: the sweep's journal kept the cells of such a grid but every `--resume`
    failed with the same TypeError. A sweep stopped after its first chunk, then resumed
    through the CLI, publishes the same bytes as a straight run."""
    data = with_axis(WRITTEN)
    config = write_config(tmp_path / "mixed.yaml", data)
    with pytest.raises(RbmError, match="stopped after"):
        run_sweep(load_config(config), tmp_path / "cut", jobs=1, stop_after=1)
    assert (tmp_path / "cut" / "mixed" / "domain.partial.jsonl").is_file()
    res = sweep_cli(config, tmp_path / "cut", "--resume")
    assert "resumed" in res.output
    sweep_cli(config, tmp_path / "whole")
    for name in ("domain.csv", "boundary.csv"):
        cut = (tmp_path / "cut" / "mixed" / name).read_bytes()
        assert cut == (tmp_path / "whole" / "mixed" / name).read_bytes(), name


def test_a_suite_keeps_its_records_in_the_order_written(tmp_path):
    """Defect: boundary.csv sorted a suite's records by file name, not in the grid's
    order. A suite written [b_slow, a_fast] has its boundary lines in that order, each
    the boundary of its record swept alone."""
    half_sine_csv(tmp_path / "b_slow.csv", 1.0)
    half_sine_csv(tmp_path / "a_fast.csv", 4.0)
    base = {**BLOCK, "name": "suite", "grid": {"amplitudes": [0.2, 0.4, 0.6, 1.0, 2.0]}}

    def swept(name, files):
        exc = {"type": "record", "file": files, "units": "g", "scale": "factor",
               "free_time": 2.0}  # fmt: skip
        sweep_cli(write_config(tmp_path / f"{name}.yaml", {**base, "name": name,
                                                            "excitation": exc}),
                  tmp_path / "out")  # fmt: skip
        return read_rows(tmp_path / "out" / name / "boundary.csv")

    suite = swept("suite", ["b_slow.csv", "a_fast.csv"])
    assert [r["excitation.file"] for r in suite] == ["b_slow.csv", "a_fast.csv"]
    for row, name in zip(suite, ("b_slow", "a_fast"), strict=True):
        (one,) = swept(name, f"{name}.csv")
        assert (row["frequency_hz"], row["lowest_unsafe_g"], row["highest_safe_g"]) == (
            one["frequency_hz"], one["lowest_unsafe_g"], one["highest_safe_g"])  # fmt: skip
    assert suite[0]["lowest_unsafe_g"] != suite[1]["lowest_unsafe_g"]
