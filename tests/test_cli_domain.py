"""CLI tests of sweep, plot-domain and compare (click's CliRunner, tmp_path only)."""

from __future__ import annotations

import shutil

import pytest
from click.testing import CliRunner

from rbm_cli.cli.main import cli

from .paths import CONFIGS, RESULTS

SMALL = """\
name: small
column: {height: 4.0, base_width: 1.0, depth: 1.0}
interface: {stiffness: rigid}
excitation: {type: harmonic, duration: 10.0}
grid:
  amplitudes: [0.2, 0.3, 0.5, 1.0]
  frequencies: [0.5, 2.0]
"""


def invoke(*args):
    return CliRunner().invoke(cli, [str(a) for a in args])


@pytest.fixture
def small(tmp_path):
    path = tmp_path / "small.yaml"
    path.write_text(SMALL)
    return path


def test_sweep_writes_the_four_files(small, tmp_path):
    res = invoke("sweep", small, "-o", tmp_path / "out", "--jobs", "1", "--quiet")
    assert res.exit_code == 0, res.output
    folder = tmp_path / "out" / "small"
    for name in ("domain.csv", "boundary.csv", "meta.json", "domain.png"):
        assert (folder / name).is_file()
    lines = (folder / "domain.csv").read_text().splitlines()
    assert lines[0].startswith("amplitude_g,frequency_hz,status,collapsed,t_collapse_s")
    assert len(lines) == 1 + 8
    assert "8 cells" in res.output


@pytest.mark.parametrize(
    "args,needle",
    [
        (["--jobs", "0"], "--jobs must be a whole number >= 1"),
        (["--scheduler", "tcp://127.0.0.1:1"], "--scheduler needs --backend dask"),
    ],
)
def test_sweep_bad_options(small, tmp_path, args, needle):
    res = invoke("sweep", small, "-o", tmp_path, *args)
    assert res.exit_code == 2 and needle in res.output
    assert "Traceback" not in res.output


def test_sweep_without_grid_is_an_error(tmp_path):
    path = tmp_path / "nogrid.yaml"
    path.write_text(SMALL.split("grid:")[0])
    res = invoke("sweep", path, "-o", tmp_path)
    assert res.exit_code == 2 and "no grid" in res.output
    assert not (tmp_path / "small" / "domain.csv").exists()


def test_sweep_into_a_file_is_an_error(small, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    res = invoke("sweep", small, "-o", blocker)
    assert res.exit_code == 2 and "cannot write" in res.output


def test_compare_exit_status_follows_the_limits(tmp_path):
    """The limits alone (plain domains: no robustness record, so no regression rule;
    tests/test_reproducibility.py covers the rule)."""
    import pandas as pd

    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    for name, path in (("spanos_koh_slender", a), ("spanos_koh_thick", b)):
        df = pd.read_csv(RESULTS / name / "domain.csv")
        df.drop(columns=["collapse_fraction", "robust"]).to_csv(path, index=False)
    same = invoke("compare", a, a, "--max-cells", "0", "--max-shift", "0")
    assert same.exit_code == 0 and "0 differ" in same.output
    diff = invoke("compare", a, b, "--max-cells", "0.01", "--max-shift", "0.05")
    assert diff.exit_code == 1 and "FAIL" in diff.output
    loose = invoke("compare", a, b, "--max-cells", "1", "--max-shift", "10")
    assert loose.exit_code == 0


def test_compare_missing_file_and_bad_columns(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("x,y\n1,2\n")
    a = RESULTS / "spanos_koh_slender" / "domain.csv"
    res = invoke("compare", a, tmp_path / "missing.csv")
    assert res.exit_code == 2 and "not found" in res.output
    res = invoke("compare", a, bad)
    assert res.exit_code == 2 and "missing column" in res.output
    assert "Traceback" not in res.output


def test_plot_domain_with_compare_and_config_from_meta(tmp_path):
    src = RESULTS / "housner_halfsine"
    shutil.copytree(src, tmp_path / "housner_halfsine")
    out = tmp_path / "plot.png"
    res = invoke(
        "plot-domain",
        tmp_path / "housner_halfsine" / "domain.csv",
        "-o",
        out,
        "--compare",
        RESULTS / "spanos_koh_slender" / "domain.csv",
    )
    assert res.exit_code == 0, res.output
    assert out.stat().st_size > 10_000


def test_plot_domain_bad_csv(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("amplitude_g,frequency_hz\n0.1,1\n")
    res = invoke("plot-domain", bad)
    assert res.exit_code == 2 and "missing column(s) status" in res.output
    assert not (tmp_path / "domain.png").exists()


def test_shipped_configs_validate():
    for path in sorted(CONFIGS.glob("**/*.yaml")):
        res = invoke("info", path)
        assert res.exit_code == 0, (path, res.output)


def test_huge_grid_is_refused_without_force(tmp_path):
    """A 200,000-cell grid (more than MAX_CELLS) needs --force; nothing is written."""
    path = tmp_path / "huge.yaml"
    path.write_text(
        SMALL.replace("[0.2, 0.3, 0.5, 1.0]", "{start: 0.01, stop: 10.0, num: 1000}").replace(
            "[0.5, 2.0]", "{start: 0.1, stop: 20.0, num: 200}"
        )
    )
    res = invoke("sweep", path, "-o", tmp_path / "out", "--quiet")
    assert res.exit_code == 2 and "200,000 cells" in res.output and "--force" in res.output
    assert not (tmp_path / "out").exists()
