"""The Python API (`import rbm`, rbm_cli.api): configs from dicts, changed values, one cell,
a sweep, plots on a given axes, and the notebook-style example of docs/.

The block is rigid and monolithic, H = 2 m, B = 0.5 m: the RBM's rigid monolith starts to
rock when |a_g| > g B/H = 0.25 g (alpha = B/H), so at 0.1 g nothing moves. At 2.5 g
(ten times B/H) and 0.5 Hz it overturns: p = sqrt(3 g / (4 R)) = 2.67 rad/s for R = 1.03 m,
so w/p = 1.18, and the first half-cycle of the sine is a half-sine pulse of 10 alpha, far
above Housner's threshold sqrt(1 + (w/p)^2) alpha = 1.55 alpha for such a pulse.
"""

from __future__ import annotations

import ast
import doctest
import math
import re
import runpy

import numpy as np
import pandas as pd
import pytest
import yaml
from matplotlib.figure import Figure

import rbm
import rbm_cli.api
from tests.paths import ROOT

G = 9.81  # [m/s^2], as the library
H, B = 2.0, 0.5  # [m]
UPLIFT_G = B / H  # [g]
EXAMPLE = ROOT / "docs" / "examples" / "api_example.py"


def block(**extra) -> dict:
    return {
        "name": "api_block",
        "column": {"height": H, "base_width": B},
        "interface": {"stiffness": "rigid", "restitution": 0.9},
        "excitation": {"type": "harmonic", "duration": 4.0},
        **extra,
    }


# --------------------------------------------------------------------------- configs


def test_a_dict_with_numbers_loads_as_the_yaml_text_does(tmp_path):
    """A dict holding real numbers (a float 5e9, numpy numbers and arrays, as a notebook
    makes them) gives the config its YAML text gives, read by the project's YAML 1.2 reader."""
    text = (
        "name: multi\n"
        "column: {height: 4.0, base_width: 1.0, drums: 2}\n"
        "interface: {stiffness: {normal: 5e9}}\n"
        "grid: {amplitudes: [0.1, 0.2], frequencies: [1.0]}\n"
    )
    (tmp_path / "multi.yaml").write_text(text)
    from_file = rbm.load_config(tmp_path / "multi.yaml")
    as_dict = {
        "name": "multi",
        "column": {"height": np.float64(4.0), "base_width": 1.0, "drums": np.int64(2)},
        "interface": {"stiffness": {"normal": 5e9}},
        "grid": {"amplitudes": np.array([0.1, 0.2]), "frequencies": [np.float32(1.0)]},
    }
    from_dict = rbm.load_config(as_dict)
    assert from_dict == from_file
    assert from_dict.interface.stiffness.kind == "normal"
    assert from_dict.interface.stiffness.values == (5e9,)
    # the plain parser takes numpy numbers too, and keeps the mapping as plain data
    plain = rbm_cli.api.parse_config({**as_dict, "grid": {"amplitudes": [np.float64(0.1)]}})
    assert type(plain.written["column"]["drums"]) is int
    assert plain.column.n_drums == 2


def test_a_string_5e9_is_refused_as_a_quoted_one_is(tmp_path):
    """PyYAML's yaml.safe_load (YAML 1.1) reads 5e9 as the string '5e9'; a string stays
    refused, as the quoted "5e9" of a YAML file is, with one line saying how to write it."""
    text = "name: x\ncolumn: {height: 4, base_width: 1}\ninterface: {stiffness: {normal: 5e9}}\n"
    data = yaml.safe_load(text)
    assert data["interface"]["stiffness"]["normal"] == "5e9"  # the premise
    with pytest.raises(rbm.ConfigError) as from_dict:
        rbm.load_config(data)
    (tmp_path / "q.yaml").write_text(text.replace("5e9", '"5e9"'))
    with pytest.raises(rbm.ConfigError) as from_file:
        rbm.load_config(tmp_path / "q.yaml")
    for message in (str(from_dict.value), str(from_file.value)):
        assert "\n" not in message
        assert "interface.stiffness.normal" in message and "'5e9'" in message
        assert "5.0e9" in message  # the way to write it


def test_with_value_changes_a_copy_and_validates_it():
    cfg = rbm.load_config(block())
    taller = rbm.with_value(cfg, "column.height", 6.0)
    assert taller.column.height == 6.0 and taller.column.base_width == B
    assert cfg.column.height == H  # the original is untouched
    multi = rbm.with_values(cfg, {"column.drums": 3, "interface.stiffness.normal": 5e9})
    assert multi.column.drum_heights == pytest.approx((H / 3,) * 3)
    assert multi.interface.stiffness.values == (5e9,)
    assert cfg.interface.stiffness.kind == "rigid"
    with pytest.raises(rbm.ConfigError) as bad:
        rbm.with_value(cfg, "column.height", -1.0)
    message = str(bad.value)
    assert "\n" not in message and "column.height must be a number > 0 [m]" in message
    with pytest.raises(rbm.ConfigError, match="unknown key 'heigth' in column"):
        rbm.with_value(cfg, "column.heigth", 3.0)
    with pytest.raises(rbm.ConfigError, match="is not a key path"):
        rbm.with_value(cfg, "column..height", 3.0)


def test_with_value_keeps_a_config_files_folder_for_its_relative_paths(tmp_path, monkeypatch):
    """A record named relative to its config file stays the same file when a value of the
    config changes from another current directory (a notebook's)."""
    monkeypatch.chdir(tmp_path)
    cfg = rbm.load_config(ROOT / "configs" / "ci" / "suite_multidrum_ci.yaml")
    tighter = rbm.with_value(cfg, "solver.rtol", 1e-11)
    assert tighter.excitation.file_path == cfg.excitation.file_path
    assert tighter.grid.records == cfg.grid.records
    other = rbm.with_value(cfg, "excitation.file", ["../records/synthetic/rdk_02.AT2"])
    assert other.excitation.file_path == str(ROOT / "configs" / "records" / "synthetic"
                                             / "rdk_02.AT2")  # fmt: skip


# --------------------------------------------------------------------------- one cell


def test_run_below_the_uplift_level_nothing_moves_far_above_it_collapses():
    cfg = rbm.load_config(block())
    calm = rbm.run(cfg, amplitude_g=0.4 * UPLIFT_G, frequency_hz=1.0)
    assert calm.status == "survived"
    assert math.isnan(calm.t_collapse_s)
    assert calm.result.n_uplifts == 0
    assert np.all(calm.history["theta1_rad"].to_numpy() == 0.0)
    assert calm.history["t_s"].iloc[-1] == pytest.approx(cfg.excitation.duration)
    rough = rbm.run(cfg, amplitude_g=10 * UPLIFT_G, frequency_hz=0.5)
    assert rough.status == "collapsed" and rough.result.collapse_interface == 1
    assert type(rough.result["collapse_interface"]) is int
    # Housner's pulse threshold is passed within the first half-cycle (1 s)
    assert 0.0 < rough.t_collapse_s < 1.0 / 0.5
    assert rough.history["t_s"].iloc[-1] == pytest.approx(rough.t_collapse_s, abs=0.01)


def test_the_history_frame_holds_the_ground_motion_at_its_times():
    cfg = rbm.load_config(block())
    amplitude, frequency = 0.1, 1.5
    cell = rbm.run(cfg, amplitude_g=amplitude, frequency_hz=frequency, output_dt=0.01)
    h = cell.history
    assert list(h.columns) == ["t_s", "ag_m_s2", "ug_m", "u1_m", "u2_m", "theta1_rad"]
    t = h["t_s"].to_numpy()
    assert t[0] == 0.0 and np.allclose(np.diff(t), 0.01)
    w = 2 * math.pi * frequency
    expected = amplitude * G * np.sin(w * t)
    np.testing.assert_allclose(h["ag_m_s2"].to_numpy(), expected, rtol=0, atol=1e-9)
    # the steady harmonic ground displacement u_g = -a_g / w^2 (History's documented form)
    np.testing.assert_allclose(h["ug_m"].to_numpy(), -expected / w**2, rtol=0, atol=1e-12)
    assert rbm.run(cfg, 0.1, 1.5, record=False).history is None


def test_run_refuses_a_missing_or_bad_amplitude_in_one_line():
    cfg = rbm.load_config(block())
    for args, words in (
        ((None, 1.0), "amplitude_g [g] is required"),
        ((0.1, None), "frequency_hz [Hz] is required"),
        ((-0.1, 1.0), "amplitude_g must be a number in [0, 1000] [g]"),
        ((0.1, math.inf), "frequency_hz must be a number in [0.001, 1000] [Hz]"),
    ):
        with pytest.raises(rbm.RbmError) as bad:
            rbm.run(cfg, *args)
        assert words in str(bad.value) and "\n" not in str(bad.value)


# --------------------------------------------------------------------------- sweeps


def test_sweep_returns_the_rows_of_the_domain_csv_it_wrote(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    amplitudes, frequencies = [0.4 * UPLIFT_G, 10 * UPLIFT_G], [0.5, 1.0]
    cfg = rbm.load_config(block(grid={"amplitudes": amplitudes, "frequencies": frequencies}))
    df = rbm.sweep(cfg, output=tmp_path / "out", jobs=1)
    written = pd.read_csv(tmp_path / "out" / "api_block" / "domain.csv")
    pd.testing.assert_frame_equal(df, written, check_dtype=False)
    assert df.attrs["folder"] == str(tmp_path / "out" / "api_block")
    # the grid's cells, frequency-major, and the outcomes the uplift level decides
    cells = [(a, f) for f in frequencies for a in amplitudes]
    assert list(zip(df["amplitude_g"], df["frequency_hz"], strict=True)) == cells
    assert df["status"].tolist() == ["survived", "collapsed"] * 2
    # without an output folder: the same rows, and nothing left on disk
    before = sorted(p.name for p in tmp_path.iterdir())
    in_memory = rbm.sweep(cfg)
    pd.testing.assert_frame_equal(in_memory, df)
    assert in_memory.attrs["folder"] is None
    assert sorted(p.name for p in tmp_path.iterdir()) == before


# --------------------------------------------------------------------------- plots


def test_plot_domain_draws_the_cells_on_the_given_axes():
    df = pd.DataFrame(
        {
            "amplitude_g": [0.1, 2.5, 0.1, 2.5],
            "frequency_hz": [0.5, 0.5, 1.0, 1.0],
            "status": ["survived", "collapsed", "survived", "collapsed"],
        }
    )
    ax = Figure().subplots()
    assert rbm.plot_domain(df, ax=ax, config=block()) is ax
    drawn = {a.get_gid(): a for a in ax.collections + ax.lines if a.get_gid()}
    unsafe = drawn["unsafe"]
    points = unsafe.get_offsets() if hasattr(unsafe, "get_offsets") else unsafe.get_xydata()
    assert sorted(map(tuple, np.asarray(points))) == [(0.5, 2.5), (1.0, 2.5)]
    # the config's uplift level, B/H [g]
    assert np.allclose(drawn["static"].get_ydata(), UPLIFT_G)
    # without a config: no level, and a new axes when none is given
    bare = rbm.plot_domain(df)
    assert bare is not ax and "static" not in [a.get_gid() for a in bare.lines]


def test_plot_history_draws_the_run_on_the_given_axes():
    cell = rbm.run(rbm.load_config(block()), amplitude_g=10 * UPLIFT_G, frequency_hz=0.5)
    ax = Figure().subplots()
    assert rbm.plot_history(cell, ax=ax) is ax
    t = cell.history["t_s"].to_numpy()
    assert any(np.array_equal(line.get_xdata(), t) for line in ax.lines)
    with pytest.raises(rbm.RbmError, match="record=True"):
        rbm.plot_history(rbm.run(block(), 0.1, 1.0, record=False))


# --------------------------------------------------------------------------- the surface


def test_rbm_is_a_thin_face_of_rbm_cli_api():
    """`rbm` imports only rbm_cli.api, and every name it exports is documented with units
    and an Examples section (functions) or its attributes (the result class)."""
    tree = ast.parse((ROOT / "rbm" / "__init__.py").read_text())
    imported = {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
    imported |= {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    assert imported == {"rbm_cli.api"}
    assert rbm.__version__ == rbm_cli.__version__
    for name in rbm.__all__:
        assert getattr(rbm, name) is getattr(rbm_cli.api, name)
    for name in rbm.__all__:
        if name == "__version__":
            continue
        doc = getattr(rbm, name).__doc__ or ""
        assert ">>> import" in doc and "rbm" in doc.split(">>> import", 1)[1], name
        assert re.search(r"\[(g|Hz|s|m|-|kg|N m|rad/s|m/s\^2)\]", doc), name  # units
    for name in ("run", "sweep", "plot_domain"):
        assert "[g]" in rbm.__dict__[name].__doc__ and "[Hz]" in rbm.__dict__[name].__doc__
    for name in ("load_config", "with_value", "with_values", "run", "sweep", "info",
                 "motion_from_arrays", "fragility", "compare"):  # fmt: skip
        doc = getattr(rbm, name).__doc__
        assert all(part in doc for part in ("Parameters", "Returns", "Examples")), name


def public_docstrings() -> list:
    """Every public name of rbm with a docstring of its own (the classes' and the
    functions'), and the package itself: the objects whose examples run."""
    return [rbm] + [getattr(rbm, name) for name in rbm.__all__ if name != "__version__"]


def test_the_docstring_examples_run(tmp_path, monkeypatch):
    """The examples of every public name run (doctest), and leave no files."""
    monkeypatch.chdir(tmp_path)
    finder = doctest.DocTestFinder(recurse=False)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    ran = set()
    for obj in public_docstrings():
        for test in finder.find(obj, getattr(obj, "__name__", "rbm"), globs={"rbm": rbm}):
            if test.examples:
                ran.add(test.name)
                runner.run(test)
    expected = {"rbm"} | {n for n in rbm.__all__ if n != "__version__"}
    assert expected <= ran, sorted(expected - ran)  # every name has an example
    assert runner.failures == 0 and runner.tries > 20
    for module in (rbm_cli.api.configs, rbm_cli.api.cells, rbm_cli.api.sweeps):
        result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
        assert result.failed == 0 and result.attempted > 0, module.__name__
    assert list(tmp_path.iterdir()) == []  # the examples leave no files


def test_the_notebook_example_runs_and_shows_the_size_effect(tmp_path, monkeypatch, capsys):
    """docs/examples/api_example.py runs; of two blocks of equal slenderness the larger
    needs at least as large an amplitude to collapse at every frequency (Housner 1963)."""
    monkeypatch.chdir(tmp_path)
    names = runpy.run_path(str(EXAMPLE), run_name="__main__")
    assert (tmp_path / "out" / "api_example" / "api_example.png").stat().st_size > 0
    first = names["boundaries"].fillna(math.inf)
    assert (first["H = 4 m"] >= first["H = 2 m"]).all()
    assert np.isfinite(first["H = 2 m"]).any()  # the small block does collapse somewhere
    assert names["cell"].status == "collapsed"
    assert "wrote out" in capsys.readouterr().out
