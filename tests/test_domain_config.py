"""A stored domain keeps the config as the user wrote it (meta.json's config_written), and
`rbm plot-domain` draws it with that config.

Guards a past defect: plot-domain rebuilt a YAML config from meta.json's derived
values and lost fields, so a bullet domain swept with friction 0.1 was re-drawn at the
default friction 1.0 (its uplift level min(tan alpha, friction) at 0.25 g instead of 0.1 g)
and solver settings were lost.
"""

from __future__ import annotations

import json
import os

import pandas as pd
import pytest
from click.testing import CliRunner

import rbm_cli.base.files
from rbm_cli.api import run_sweep
from rbm_cli.cli.main import cli
from rbm_cli.config import parse_config
from rbm_cli.study.domain import domain_config

BULLET = {
    "name": "slippery",
    "model": "bullet",
    "column": {"height": 4.0, "base_width": 1.0, "density": 2700},
    "interface": {"friction": 0.1},
    "excitation": {"type": "harmonic", "duration": 2.0},
    "grid": {"amplitudes": [0.05, 0.3], "frequencies": [1.0]},
    "solver": {"time_step": 2e-4},
}

RIGID = {
    "name": "rigid_small",
    "column": {"height": 4.0, "base_width": 1.0},
    "interface": {"stiffness": "rigid", "restitution": 0.8},
    "excitation": {"type": "harmonic", "duration": 3.0, "phase": 0.25},
    "grid": {"amplitudes": {"start": 0.2, "stop": 0.6, "step": 0.2}, "frequencies": [1.0, 2.0]},
    "solver": {"rtol": 1e-8, "method": "RK45"},
}


def stored_domain(folder, written: dict):
    """A domain folder as a sweep leaves it, with a few rows and its meta.json."""
    folder.mkdir(parents=True)
    df = pd.DataFrame(
        {
            "amplitude_g": [0.05, 0.3],
            "frequency_hz": [1.0, 1.0],
            "status": ["survived", "collapsed"],
            "collapsed": [0, 1],
        }
    )
    df.to_csv(folder / "domain.csv", index=False)
    cfg = parse_config(written)
    meta = {"name": cfg.name, "config": cfg.resolved(), "config_written": cfg.written}
    (folder / "meta.json").write_text(json.dumps(meta))
    return folder / "domain.csv"


def test_a_swept_domain_keeps_the_config_as_written(tmp_path):
    cfg = parse_config(RIGID)
    run_sweep(cfg, tmp_path, jobs=1)
    back = domain_config(tmp_path / "rigid_small" / "domain.csv")
    assert back == cfg  # every resolved setting, solver and phase included
    assert back.written == RIGID
    assert back.solver.rtol == 1e-8 and back.solver.method == "RK45"


def test_plot_domain_of_a_bullet_domain_uses_its_friction(tmp_path, monkeypatch):
    csv = stored_domain(tmp_path / "slippery", BULLET)
    cfg = domain_config(csv)
    assert cfg.interface.friction == 0.1 and cfg.solver.time_step == 2e-4
    drawn = []
    monkeypatch.setattr(
        rbm_cli.base.files, "save_figure_atomic", lambda fig, path: drawn.append(fig)
    )
    res = CliRunner().invoke(cli, ["plot-domain", str(csv)])
    assert res.exit_code == 0, res.output
    (fig,) = drawn
    (line,) = [ln for ln in fig.axes[0].get_lines() if ln.get_gid() == "static"]
    # the engine's uplift level is min(tan alpha, friction) = min(0.25, 0.1) in g
    assert line.get_ydata()[0] == pytest.approx(0.1, rel=1e-12)
    assert line.get_label().startswith("engine uplift level")


def test_a_stored_config_that_no_longer_validates_is_one_line(tmp_path):
    csv = stored_domain(tmp_path / "slippery", BULLET)
    meta = json.loads((csv.parent / "meta.json").read_text())
    meta["config_written"]["interface"]["friction"] = -1.0
    (csv.parent / "meta.json").write_text(json.dumps(meta))
    res = CliRunner().invoke(cli, ["plot-domain", str(csv)])
    assert res.exit_code == 2
    assert "interface.friction" in res.output and len(res.output.strip().splitlines()) == 1


def test_every_stored_result_keeps_its_config_as_written():
    """results/: each meta.json holds config_written, and it validates to the config whose
    hash the domain was stored under."""
    from pathlib import Path

    from rbm_cli.study.sweep import config_hash

    metas = sorted((Path(__file__).resolve().parents[1] / "results").rglob("meta.json"))
    assert metas
    root = Path(__file__).resolve().parents[1]
    for path in metas:
        meta = json.loads(path.read_text())
        # the config's folder, relative to the domain's, inside this checkout (a domain made
        # elsewhere and copied in names a folder that only its maker's machine has)
        if "config_dir" in meta:
            inside = os.path.normpath(path.parent.relative_to(root) / meta["config_dir"])
            assert inside.split(os.sep)[0] == "configs", (path, meta["config_dir"])
            assert (root / inside).is_dir(), (path, inside)
        cfg = domain_config(path.with_name("domain.csv"))
        assert cfg is not None, path
        assert config_hash(cfg) == meta["config_hash"].split("-")[0], path
