"""The sweep in memory (rbm_cli.study.sweep.sweep_rows, ``rbm.sweep(cfg)`` without an output
folder): it writes nothing anywhere, and its rows are those of the domain.csv a folder sweep
of the same config publishes, on a rigid block and on a 2-drum column."""

from __future__ import annotations

import os
import tempfile

import pandas as pd
import pytest

import rbm
from rbm_cli.api import run_sweep
from rbm_cli.study.domain import read_domain
from rbm_cli.study.sweep import sweep_rows

GRID = {"amplitudes": [0.15, 0.3, 0.6], "frequencies": [1.0, 2.5]}
CONFIGS = {
    "rigid": {"column": {"height": 2.0, "base_width": 0.5}, "interface": {"stiffness": "rigid"}},
    "twodrum": {
        "column": {"height": 5.0, "base_width": 0.96, "top_width": 0.66, "drums": 2},
        "interface": {"stiffness": {"normal": 5e9}},
    },
}


def config(name: str):
    return rbm.load_config(
        {
            "name": name,
            **CONFIGS[name],
            "excitation": {"type": "harmonic", "duration": 2.0},
            "grid": GRID,
        }  # fmt: skip
    )


def files_under(root) -> list[str]:
    return sorted(os.path.join(d, f) for d, _, fs in os.walk(root) for f in fs + [""])


@pytest.mark.parametrize("name", sorted(CONFIGS))
def test_the_sweep_in_memory_gives_the_folder_sweeps_rows(name, tmp_path):
    """Byte for byte the domain.csv a folder sweep writes, and the DataFrame read_domain
    reads from it (values, columns, types)."""
    cfg = config(name)
    summary = run_sweep(cfg, tmp_path / "out", jobs=1)
    stored = (summary.folder / "domain.csv").read_text(encoding="utf-8")
    rows = sweep_rows(cfg)
    assert len(rows.rows) == 6 and rows.csv() == stored
    pd.testing.assert_frame_equal(rbm.sweep(cfg), read_domain(summary.folder / "domain.csv"))


def test_rbm_sweep_without_an_output_folder_writes_nothing(tmp_path, monkeypatch):
    """No temporary folder is asked for, nothing is created in the working folder (read
    only) nor in the temporary one, and the rows come back all the same."""

    def refused(*args, **kwargs):
        raise AssertionError("a temporary file or folder was asked for")

    for name in ("mkdtemp", "mkstemp", "TemporaryDirectory", "NamedTemporaryFile"):
        monkeypatch.setattr(tempfile, name, refused)
    work = tmp_path / "work"
    work.mkdir()
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    monkeypatch.setenv("TMPDIR", str(scratch))
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    monkeypatch.chdir(work)
    work.chmod(0o555)
    try:
        before = files_under(tmp_path)
        df = rbm.sweep(config("rigid"))
        after = files_under(tmp_path)
    finally:
        work.chmod(0o755)
    assert after == before
    assert len(df) == 6 and df.attrs["folder"] is None
    assert set(df["status"]) == {"collapsed", "survived"}


def test_options_of_a_folder_sweep_need_a_folder():
    with pytest.raises(rbm.RbmError, match="resume: needs an output folder"):
        rbm.sweep(config("rigid"), resume=True)
