"""CLI tests of run and info, help texts and bad input (click's CliRunner, tmp_path only)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest
from click.testing import CliRunner

from rbm_cli.cli.main import cli

from .paths import CONFIGS

GOOD = """\
name: block
column: {height: 4.0, base_width: 1.0, depth: 1.0}
interface: {stiffness: rigid}
excitation: {type: harmonic, duration: 10.0}
"""


def invoke(*args):
    return CliRunner().invoke(cli, [str(a) for a in args])


def write(tmp_path, text, name="cfg.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize("command", sorted(cli.commands))
def test_every_command_has_help_with_an_example(command):
    res = invoke(command, "--help")
    assert res.exit_code == 0 and "Example" in res.output


def test_run_writes_history_plots_and_summary(tmp_path):
    res = invoke("run", CONFIGS / "spanos_koh_slender.yaml", "-a", 0.5, "-f", 1, "-o", tmp_path)
    assert res.exit_code == 0, res.output
    folder = tmp_path / "spanos_koh_slender" / "run_A0.5_f1"
    for name in ("history.csv", "history.png", "shapes.png", "summary.json"):
        assert (folder / name).is_file(), name
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["status"] == "collapsed" and summary["collapsed"] == 1
    assert summary["collapse_interface"] == 1
    assert summary["max_friction_demand"] > 0
    header = (folder / "history.csv").read_text().splitlines()[0]
    assert header.startswith("t_s,") and "theta1_rad" in header
    assert "collapsed" in res.output and "friction demand" in res.output


def test_run_multidrum_reports_friction_per_interface(tmp_path):
    cfg = write(
        tmp_path,
        GOOD.replace("{stiffness: rigid}", "{stiffness: {normal: 1e8}}").replace(
            "depth: 1.0}", "depth: 1.0, drums: 3}"
        ),
    )
    res = invoke("run", cfg, "-a", 0.2, "-f", 2, "-o", tmp_path)
    assert res.exit_code == 0, res.output
    summary = json.loads((tmp_path / "block" / "run_A0.2_f2" / "summary.json").read_text())
    assert len(summary["friction_demand"]) == 3


def test_info_prints_capacities(tmp_path):
    res = invoke("info", CONFIGS / "harmonic_multidrum.yaml")
    assert res.exit_code == 0
    assert "static multiplier" in res.output and "theta_u,i" in res.output
    res = invoke("info", CONFIGS / "spanos_koh_slender.yaml", "--json")
    data = json.loads(res.output)
    assert data["static_multiplier_g"] == pytest.approx(0.25)
    assert data["uplift_acceleration_g"] == pytest.approx(0.25)


BAD_CONFIGS = [
    ("malformed YAML", "name: x\ncolumn: {height: 4\n", "cannot parse"),
    ("unknown key", GOOD + "colour: red\n", "unknown key 'colour'"),
    ("wrong type", GOOD.replace("height: 4.0", "height: tall"), "column.height"),
    ("negative height", GOOD.replace("height: 4.0", "height: -4.0"), "column.height"),
    (
        "xi out of range",
        GOOD.replace("{stiffness: rigid}", "{stiffness: rigid, xi: 1.5}"),
        "interface.xi",
    ),
    (
        "drums not summing",
        GOOD.replace("depth: 1.0}", "depth: 1.0, drums: [1.0, 1.0]}"),
        "column.drums",
    ),
    (
        "rigid multi-drum",
        GOOD.replace("depth: 1.0}", "depth: 1.0, drums: 3}"),
        "rigid needs a monolithic column",
    ),
    ("zero duration", GOOD.replace("duration: 10.0", "duration: 0"), "excitation.duration"),
    (
        "negative restitution",
        GOOD.replace("{stiffness: rigid}", "{restitution: -0.5}"),
        "interface.restitution",
    ),
    (
        "unknown formulation",
        GOOD.replace("{stiffness: rigid}", "{formulation: wrong}"),
        "interface.formulation",
    ),
    (
        "top wider than allowed",
        GOOD.replace("base_width: 1.0", "base_width: 1.0, top_width: 9"),
        "column.top_width",
    ),
    ("empty file", "", "empty"),
]


@pytest.mark.parametrize("label,text,needle", BAD_CONFIGS, ids=[b[0] for b in BAD_CONFIGS])
def test_bad_config_is_one_line_nonzero_no_traceback(tmp_path, label, text, needle):
    cfg = write(tmp_path, text)
    out = tmp_path / "out"
    res = invoke("run", cfg, "-a", 0.5, "-f", 1, "-o", out)
    assert res.exit_code == 2, res.output
    assert needle in res.output
    lines = [line for line in res.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error:")
    assert "Traceback" not in res.output
    assert not out.exists()  # no partial output


@pytest.mark.parametrize(
    "args,needle",
    [
        (["-a", "0.5", "-f", "0"], "--frequency must be"),
        (["-a", "0.5", "-f", "-2"], "--frequency must be"),
        (["-a", "-0.5", "-f", "1"], "--amplitude must be"),
        (["-f", "1"], "--amplitude [g] is required"),
    ],
)
def test_bad_excitation_options(tmp_path, args, needle):
    cfg = write(tmp_path, GOOD)
    res = invoke("run", cfg, *args, "-o", tmp_path / "out")
    assert res.exit_code == 2 and needle in res.output
    assert not (tmp_path / "out").exists()


def test_missing_config_and_directory(tmp_path):
    res = invoke("run", tmp_path / "nope.yaml", "-a", 1, "-f", 1)
    assert res.exit_code == 2 and "nope.yaml" in res.output and "Traceback" not in res.output
    res = invoke("info", tmp_path)
    assert res.exit_code == 2 and "Traceback" not in res.output


def test_unwritable_output(tmp_path):
    cfg = write(tmp_path, GOOD)
    blocker = tmp_path / "file"
    blocker.write_text("x")
    res = invoke("run", cfg, "-a", 0.5, "-f", 1, "-o", blocker)
    assert res.exit_code == 2 and "Traceback" not in res.output


SHIPPED = sorted(CONFIGS.glob("*.yaml")) + sorted(CONFIGS.glob("*/*.yaml"))


@pytest.mark.parametrize("config", SHIPPED, ids=[p.stem for p in SHIPPED])
def test_info_on_every_shipped_config(config):
    res = invoke("info", config)
    assert res.exit_code == 0, res.output
    assert "static multiplier" in res.output and "Traceback" not in res.output


def one_line_error(res):
    lines = [line for line in res.output.splitlines() if line.strip()]
    return len(lines) == 1 and lines[0].startswith("Error:") and "Traceback" not in res.output


def test_directory_as_config_is_one_line(tmp_path):
    folder = tmp_path / "configs.yaml"
    folder.mkdir()
    for command in (["info"], ["run", "-a", 0.5, "-f", 1, "-o", tmp_path / "out"]):
        res = invoke(command[0], folder, *command[1:])
        assert res.exit_code == 2 and one_line_error(res) and "configs.yaml" in res.output
    assert not (tmp_path / "out").exists()


def test_unwritable_output_is_one_line_and_named(tmp_path):
    """Guards the output check done before the simulation: nothing is created."""
    cfg = write(tmp_path, GOOD)
    blocker = tmp_path / "file"
    blocker.write_text("x")
    res = invoke("run", cfg, "-a", 0.5, "-f", 1, "-o", blocker / "deeper")
    assert res.exit_code == 2 and one_line_error(res) and str(blocker) in res.output
    assert blocker.read_text() == "x"


@pytest.mark.parametrize(
    "args",
    [["-a", "abc", "-f", "1"], ["-a", "0.5", "-f", "1", "--bogus"], []],
    ids=["non-numeric amplitude", "unknown option", "missing config"],
)
def test_usage_errors_are_one_line(tmp_path, args):
    cfg = [write(tmp_path, GOOD)] if args else []
    res = invoke("run", *cfg, *args, "-o", tmp_path / "out")
    assert res.exit_code == 2 and one_line_error(res), res.output
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("cold", [True, False])
def test_run_says_when_it_compiles_the_kernel(tmp_path, monkeypatch, cold):
    """A first run compiles the kernel (15-20 s of silence otherwise): one note on
    stderr then, none when numba's cache is there. A rigid monolith runs the block's
    closed form by default (seconds to compile, no kernel): no note either way."""
    import rbm_cli.models.rbm.step as kernel

    monkeypatch.setattr(kernel, "needs_compile", lambda: cold)
    res = invoke("run", CONFIGS / "harmonic_monolithic.yaml", "-a", 0.5, "-f", 1, "-o", tmp_path)
    assert res.exit_code == 0, res.output
    assert ("compiling the integrator" in res.stderr) == cold
    res = invoke("run", CONFIGS / "spanos_koh_slender.yaml", "-a", 0.5, "-f", 1, "-o", tmp_path)
    assert res.exit_code == 0, res.output
    assert "compiling" not in res.stderr and "method:" in res.output


def test_needs_compile_sees_the_cache(tmp_path):
    """needs_compile reads numba's cache index of the kernel: False after a compiled run in
    this process (the on-disk cache exists), True in a process whose cache folder is empty.
    Guards against a check that cannot fail: it once answered False on any error, and it
    answers None when numba's cache internals are no longer the ones it reads."""
    from rbm_cli.models.rbm.step import needs_compile, warm_up

    warm_up()
    assert needs_compile() is False
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba-cache"))
    code = "from rbm_cli.models.rbm.step import needs_compile; print(needs_compile())"
    res = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         timeout=300)  # fmt: skip
    assert res.returncode == 0, res.stderr[-2000:]
    assert res.stdout.strip() == "True"


def test_info_gives_the_engine_its_own_uplift_level(tmp_path):
    """For `model: bullet` the engine's true rectangular block uplifts at b/h g (statics,
    friction 1 > b/h), not at the RBM's level; a low friction caps it (sliding first)."""
    block = "name: b\nmodel: bullet\ncolumn: {height: 4, base_width: 1, depth: 1}\n"
    res = invoke("info", write(tmp_path, block), "--json")
    assert res.exit_code == 0, res.output
    assert json.loads(res.output)["engine_uplift_g"] == pytest.approx(0.25, rel=1e-12)
    low = block + "interface: {friction: 0.1}\n"
    res = invoke("info", write(tmp_path, low, "low.yaml"))
    assert res.exit_code == 0, res.output
    assert "engine uplift:" in res.output and "0.1 g" in res.output
    assert "engine uplift" not in invoke("info", CONFIGS / "harmonic_monolithic.yaml").output
