"""Tests of the YAML config loader (rbm_cli.config.load): values, defaults and error messages.

Every file is written under pytest's tmp_path; nothing touches the working tree.
"""

from __future__ import annotations

import copy
import math
import random
import textwrap

import pytest

from rbm_cli.base.errors import ConfigError
from rbm_cli.config.load import load_config, parse_config
from rbm_cli.config.types import (
    Config,
    GridConfig,
    InitialConfig,
    SolverConfig,
    StiffnessConfig,
)
from rbm_cli.config.yaml_reader import read_yaml

FULL = """\
name: paper_column-8.drums
model: rbm
column:
  height: 5.0
  base_width: 0.96
  top_width: 0.66
  section: rectangular
  depth: 0.9
  density: 2600
  drums: [0.5, 1.0, 1.5, 2.0]
interface:
  stiffness: {rotational: [1e8, 2e8, 3E+8, 4.5e8]}
  xi: 0.8
  restitution: 0.9
  formulation: geometric
excitation:
  type: half-sine
  duration: 12.5
  initial:
    rotations: [0, 0, 0, 1e-3]
    velocities: [0.0, 0, 0, -2.5e-2]
grid:
  amplitudes: [0.1, 0.2, 0.35]
  frequencies: {start: 0.5, stop: 2.0, step: 0.5}
collapse:
  ratio: 0.9
solver:
  method: RK45
  rtol: 1e-8
  atol: 1e-10
  max_steps: 5e5
  max_events: 1000
"""

MINIMAL = """\
name: slender
column:
  height: 4
  base_width: 1
"""


def write(tmp_path, text: str, name: str = "cfg.yaml"):
    path = tmp_path / name
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return path


def minimal() -> dict:
    return {"name": "slender", "column": {"height": 4.0, "base_width": 1.0}}


# ------------------------------------------------------------------------ valid configs


def test_full_config_round_trip(tmp_path):
    cfg = load_config(write(tmp_path, FULL))
    assert isinstance(cfg, Config)
    assert cfg.name == "paper_column-8.drums"
    assert cfg.model == "rbm"
    col = cfg.column
    assert (col.height, col.base_width, col.top_width) == (5.0, 0.96, 0.66)
    assert col.section == "rectangular" and col.depth == 0.9
    assert col.density == 2600.0 and isinstance(col.density, float)
    assert col.drum_heights == (0.5, 1.0, 1.5, 2.0)
    assert col.n_drums == 4
    assert cfg.interface.stiffness == StiffnessConfig("moment", (1e8, 2e8, 3e8, 4.5e8))
    assert cfg.interface.xi == 0.8
    assert cfg.interface.restitution == 0.9
    assert cfg.interface.formulation == "geometric"
    exc = cfg.excitation
    assert (exc.type, exc.duration, exc.phase) == ("half-sine", 12.5, 0.0)
    assert exc.initial == InitialConfig((0.0, 0.0, 0.0, 1e-3), (0.0, 0.0, 0.0, -0.025))
    assert cfg.grid == GridConfig((0.1, 0.2, 0.35), (0.5, 1.0, 1.5, 2.0))
    assert cfg.collapse.ratio == 0.9
    assert cfg.solver == SolverConfig("RK45", 1e-8, 1e-10, 500_000, 1000)
    assert isinstance(cfg.solver.max_steps, int)
    # everything is a plain float in the frozen dataclasses
    assert all(type(x) is float for x in col.drum_heights + cfg.interface.stiffness.values)
    # the same mapping through parse_config gives the same object
    assert parse_config(read_yaml(FULL, "full.yaml")) == cfg


def test_minimal_config_defaults(tmp_path):
    cfg = load_config(write(tmp_path, MINIMAL))
    assert cfg.model == "rbm"
    col = cfg.column
    assert col.top_width == 1.0  # default base_width
    assert col.section == "rectangular" and col.depth is None
    assert col.density == 2700.0
    assert col.drum_heights == (4.0,)
    assert cfg.interface.stiffness == StiffnessConfig("rigid", ())
    assert (cfg.interface.xi, cfg.interface.restitution) == (1.0, 1.0)
    assert cfg.interface.formulation == "relative"
    assert (cfg.excitation.type, cfg.excitation.duration) == ("harmonic", 10.0)
    assert cfg.excitation.initial == InitialConfig((), ())
    assert cfg.grid == GridConfig((), ())
    assert cfg.collapse.ratio == 1.0
    assert cfg.solver == SolverConfig()


@pytest.mark.parametrize(
    ("kind", "duration"), [("harmonic", 10.0), ("half-sine", 20.0), ("free", 10.0)]
)
def test_default_duration_depends_on_type(kind, duration):
    data = minimal()
    data["excitation"] = {"type": kind}
    if kind == "free":
        data["excitation"]["initial"] = {"velocities": [0.1]}
    assert parse_config(data).excitation.duration == duration


@pytest.mark.parametrize("text", ["5e9", "5E9", "5e+9", "5.0e9", "+5e9"])
def test_exponent_without_dot_is_a_float(tmp_path, text):
    """Guards against YAML 1.1 loaders reading 5e9 as the string '5e9'."""
    path = write(tmp_path, MINIMAL + f"interface:\n  stiffness: {{normal: {text}}}\n")
    assert load_config(path).interface.stiffness == StiffnessConfig("normal", (5e9,))


def test_negative_exponent_is_a_float(tmp_path):
    path = write(tmp_path, MINIMAL + "solver:\n  rtol: 1e-6\n  atol: 1e-9\n")
    solver = load_config(path).solver
    assert (solver.rtol, solver.atol) == (1e-6, 1e-9)


def test_single_moment_stiffness():
    data = minimal()
    data["interface"] = {"stiffness": {"rotational": 2.5e8}}
    assert parse_config(data).interface.stiffness == StiffnessConfig("moment", (2.5e8,))


def test_drum_count_gives_equal_drums():
    data = minimal()
    data["column"]["drums"] = 8
    data["interface"] = {"stiffness": {"normal": 5e9}}
    heights = parse_config(data).column.drum_heights
    assert heights == (0.5,) * 8


def test_drum_list_equals_drum_count():
    by_count, by_list = minimal(), minimal()
    by_count["column"]["drums"] = 4
    by_list["column"]["drums"] = [1, 1, 1, 1]
    for data in (by_count, by_list):
        data["interface"] = {"stiffness": {"rotational": 1e9}}
    assert parse_config(by_count).column == parse_config(by_list).column


def test_drum_list_sum_within_tolerance():
    data = minimal()
    data["column"]["drums"] = [4.0 / 3, 4.0 / 3, 4.0 / 3 * (1 + 1e-12)]
    data["interface"] = {"stiffness": {"rotational": 1e9}}
    assert parse_config(data).column.n_drums == 3


def test_housner_restitution_and_circular_section():
    data = minimal()
    data["column"]["section"] = "circular"
    data["interface"] = {"restitution": "housner"}
    cfg = parse_config(data)
    assert cfg.interface.restitution == "housner"
    assert cfg.column.section == "circular" and cfg.column.depth is None


def test_empty_sections_read_as_defaults(tmp_path):
    path = write(tmp_path, MINIMAL + "grid:\nsolver:\ncollapse:\n")
    cfg = load_config(path)
    assert cfg.grid == GridConfig() and cfg.solver == SolverConfig()


# -------------------------------------------------------------------------------- grid


def test_grid_step_includes_stop():
    """Guards against arange dropping stop when (stop - start) / step is 37.999999..."""
    data = minimal()
    data["grid"] = {"amplitudes": {"start": 0.1, "stop": 2.0, "step": 0.05}}
    amps = parse_config(data).grid.amplitudes_g
    assert len(amps) == 39
    assert amps[0] == 0.1 and amps[-1] == 2.0
    assert amps[4] == 0.3  # rounded: not 0.30000000000000004
    assert all(b > a for a, b in zip(amps, amps[1:], strict=False))


def test_grid_step_stops_below_stop_when_not_a_multiple():
    data = minimal()
    data["grid"] = {"frequencies": {"start": 0.5, "stop": 1.2, "step": 0.25}}
    assert parse_config(data).grid.frequencies_hz == (0.5, 0.75, 1.0)


def test_grid_num_includes_both_ends():
    data = minimal()
    data["grid"] = {"frequencies": {"start": 0.25, "stop": 3.0, "num": 56}}
    freqs = parse_config(data).grid.frequencies_hz
    assert len(freqs) == 56
    assert (freqs[0], freqs[1], freqs[-1]) == (0.25, 0.3, 3.0)
    assert all(f == float(f"{f:.12g}") for f in freqs)


def test_grid_step_property():
    """stop = start + k step is always included; values are increasing and rounded.

    Deterministic random cases (not hypothesis, whose cache would land in the working tree).
    """
    rng = random.Random(20240521)
    for _ in range(500):
        start, step = rng.randint(0, 10_000) / 1000, rng.randint(1, 1000) / 1000
        _check_step_grid(start, step, rng.randint(0, 300))


def _check_step_grid(start: float, step: float, count: int) -> None:
    stop = start + count * step
    data = minimal()
    data["grid"] = {"amplitudes": {"start": start, "stop": stop, "step": step}}
    amps = parse_config(data).grid.amplitudes_g
    assert len(amps) == count + 1
    assert amps[0] == float(f"{start:.12g}")
    assert math.isclose(amps[-1], stop, rel_tol=1e-11, abs_tol=1e-12)
    assert all(b > a for a, b in zip(amps, amps[1:], strict=False))
    assert all(
        math.isclose(b - a, step, rel_tol=1e-6) for a, b in zip(amps, amps[1:], strict=False)
    )


def test_grid_single_values_and_single_point_range():
    data = minimal()
    data["grid"] = {"amplitudes": 0, "frequencies": {"start": 1, "stop": 1, "num": 1}}
    assert parse_config(data).grid == GridConfig((0.0,), (1.0,))


def test_grid_start_equal_stop_with_step():
    data = minimal()
    data["grid"] = {"amplitudes": {"start": 0.5, "stop": 0.5, "step": 0.1}}
    assert parse_config(data).grid.amplitudes_g == (0.5,)


# -------------------------------------------------------------------------- bad configs

# (replace these lines of MINIMAL-based YAML, expected fragments of the message)
BAD = [
    ("column:\n  height: -1\n  base_width: 1\n", ["column.height", "> 0 [m]", "got -1"]),
    ("column:\n  height: true\n  base_width: 1\n", ["column.height", "boolean"]),
    ("column:\n  height: '4'\n  base_width: 1\n", ["column.height", "quoted"]),
    ("column:\n  height: .nan\n  base_width: 1\n", ["column.height", "finite"]),
    ("column:\n  height: 4\n  base_width: .inf\n", ["column.base_width", "finite"]),
    ("column:\n  base_width: 1\n", ["column.height is required"]),
    ("column:\n  height: 4\n  base_width: 5\n", ["column.base_width must be <= column.height"]),
    ("column:\n  height: 4\n  base_width: 1\n  top_width: 3.5\n", ["column.top_width", "(0, 3]"]),
    ("column:\n  height: 4\n  base_width: 1\n  top_width: 0\n", ["column.top_width"]),
    (
        "column:\n  height: 4\n  base_width: 1\n  section: circular\n  depth: 1\n",
        ["column.depth", "rectangular"],
    ),
    ("column:\n  height: 4\n  base_width: 1\n  section: square\n", ["column.section", "circular"]),
    ("column:\n  height: 4\n  base_width: 1\n  density: 0\n", ["column.density", "[kg/m^3]"]),
    ("column:\n  height: 4\n  base_width: 1\n  drums: 0\n", ["column.drums", "1..200"]),
    ("column:\n  height: 4\n  base_width: 1\n  drums: 2.5\n", ["column.drums", "integer"]),
    ("column:\n  height: 4\n  base_width: 1\n  drums: 201\n", ["column.drums", "1..200"]),
    ("column:\n  height: 4\n  base_width: 1\n  drums: [1, 1, 0, 2]\n", ["column.drums[2]", "> 0"]),
    ("column:\n  height: 4\n  base_width: 1\n  drums: [1, 1, 1]\n", ["column.drums", "sum to 3"]),
    ("column:\n  height: 4\n  base_width: 1\n  drums: []\n", ["column.drums"]),
    ("column:\n  height: 4\n  base_width: 1\n  colour: grey\n", ["unknown key 'colour' in column"]),
]
BAD_EXTRA = [
    ("colum:\n  height: 4\n", ["unknown key 'colum' at top level", "allowed: name, model"]),
    ("model: bullet\ninterface:\n  friction: 0\n", ["interface.friction must be a number > 0"]),
    (
        "model: housner\ninterface:\n  friction: 0.6\n",
        ["interface.friction applies only to models bullet", "model housner"],
    ),
    ("interface:\n  friction: 200\n", ["interface.friction must be at most 100"]),
    ("solver:\n  time_step: 0.1\n", ["solver.time_step must be a number in", "[s]"]),
    ("model: fem\n", ["model must be one of rbm", "'fem'"]),
    ("interface:\n  stiffness: soft\n", ["interface.stiffness must be rigid"]),
    ("interface:\n  stiffness: {rotational: -5}\n", ["interface.stiffness", "> 0 [N m/rad]"]),
    ("interface:\n  stiffness: {rotational: .inf}\n", ["interface.stiffness", "use rigid"]),
    (
        "interface:\n  stiffness: 5e9\n",
        ["interface.stiffness: a bare number", "{rotational: K_M}", "{normal: k_n}"],
    ),
    (
        "interface:\n  stiffness: {rotational: 1e9, normal: 1e9}\n",
        ["interface.stiffness needs exactly one of rotational and normal"],
    ),
    ("interface:\n  stiffness: {normal: 0}\n", ["interface.stiffness.normal", "[Pa/m]"]),
    ("interface:\n  stiffness: {shear: 1e9}\n", ["unknown key 'shear' in interface.stiffness"]),
    ("interface:\n  stiffness: {}\n", ["interface.stiffness needs exactly one of rotational"]),
    ("interface:\n  stiffness: [1e9, 2e9]\n", ["interface.stiffness: a bare list"]),
    (
        "interface:\n  stiffness: {rotational: [1e9, 2e9]}\n",
        ["interface.stiffness.rotational", "one K_M per interface"],
    ),
    ("interface:\n  xi: 0\n", ["interface.xi", "(0, 1]"]),
    ("interface:\n  xi: 1.5\n", ["interface.xi", "(0, 1]"]),
    ("interface:\n  restitution: 0\n", ["interface.restitution", "(0, 1]"]),
    ("interface:\n  restitution: newton\n", ["interface.restitution", "housner"]),
    ("interface:\n  formulation: rel\n", ["interface.formulation", "relative, absolute"]),
    ("excitation:\n  type: pulse\n", ["excitation.type", "half-sine"]),
    ("excitation:\n  duration: 0\n", ["excitation.duration", "(0, 10000] [s]"]),
    ("excitation:\n  duration: 2e4\n", ["excitation.duration", "(0, 10000] [s]"]),
    ("excitation:\n  phase: .inf\n", ["excitation.phase", "finite"]),
    ("excitation:\n  type: half-sine\n  phase: 1\n", ["excitation.phase", "harmonic"]),
    ("excitation:\n  type: free\n", ["excitation.initial", "at rest"]),
    ("excitation:\n  initial:\n    rotations: [0.1, 0]\n", ["excitation.initial.rotations"]),
    ("excitation:\n  initial:\n    velocities: [x]\n", ["excitation.initial.velocities[0]"]),
    ("excitation:\n  initial:\n    angles: [0.1]\n", ["unknown key 'angles' in excitation.init"]),
    ("initial:\n  rotations: [0.1]\n", ["initial", "excitation"]),
    ("grid:\n  amplitudes: []\n", ["grid.amplitudes", "empty"]),
    ("grid:\n  amplitudes: [0.1, -0.2]\n", ["grid.amplitudes[1]", ">= 0 [g]"]),
    ("grid:\n  frequencies: 0\n", ["grid.frequencies must be a number > 0 [Hz], got 0"]),
    ("grid:\n  frequencies: [1, 2, 1]\n", ["grid.frequencies[2]", "repeats"]),
    ("grid:\n  frequencies: {start: 1, stop: 2, step: 0}\n", ["grid.frequencies.step", "> 0"]),
    (
        "grid:\n  frequencies: {start: 1, stop: 2, step: 0.5, num: 3}\n",
        ["grid.frequencies", "exactly one of step and num"],
    ),
    ("grid:\n  amplitudes: {start: 1, stop: 2}\n", ["grid.amplitudes", "exactly one"]),
    ("grid:\n  amplitudes: {start: 2, stop: 1, num: 3}\n", ["grid.amplitudes.stop", ">= "]),
    ("grid:\n  amplitudes: {stop: 1, num: 3}\n", ["grid.amplitudes.start is required"]),
    ("grid:\n  amplitudes: {start: 0, stop: 1, num: 0}\n", ["grid.amplitudes.num", "1..10000"]),
    ("grid:\n  amplitudes: {start: 0, stop: 1, num: 1}\n", ["grid.amplitudes.num", "start"]),
    ("grid:\n  amplitudes: {start: 0, stop: 1, step: 1e-7}\n", ["grid.amplitudes.step", "at most"]),
    ("grid:\n  frequency: [1]\n", ["unknown key 'frequency' in grid", "frequencies"]),
    ("grid:\n  amplitudes: low\n", ["grid.amplitudes must be a number, a list"]),
    ("collapse:\n  ratio: 1.2\n", ["collapse.ratio", "(0, 1]"]),
    ("solver:\n  method: LSODA\n", ["solver.method", "DOP853"]),
    ("solver:\n  rtol: 1e-14\n", ["solver.rtol", "[1e-13, 0.001]"]),
    ("solver:\n  atol: 0\n", ["solver.atol", "(0, 0.001]"]),
    ("solver:\n  max_steps: 10\n", ["solver.max_steps", "in 1000..1000000000"]),
    ("solver:\n  max_steps: 1e300\n", ["solver.max_steps", "in 1000..1000000000"]),
    ("solver:\n  max_wall_time: 0\n", ["solver.max_wall_time", "(0, 1000000] [s]"]),
    (
        "column:\n  height: 4\n  base_width: 1\n  density: 1e307\n",
        ["column.density", "[1, 100000]"],
    ),
    ("column:\n  height: 1:30\n  base_width: 1\n", ["column.height", "'1:30'", "base-60"]),
    ("column:\n  height: 012\n  base_width: 1\n", ["column.height", "'012'", "decimal"]),
    ("grid:\n  frequencies: 1e200\n", ["grid.frequencies must be in [0.001, 1000] [Hz]"]),
    ("solver:\n  max_events: 99.5\n", ["solver.max_events", "integer"]),
]


def _replace_section(text: str) -> str:
    """MINIMAL with the given column section, or MINIMAL plus extra top-level keys."""
    if text.startswith("column:"):
        return "name: slender\n" + text
    if text.startswith("colum:"):
        return "name: slender\n" + text
    return MINIMAL + text


@pytest.mark.parametrize(("text", "fragments"), BAD + BAD_EXTRA)
def test_bad_config_names_the_key(tmp_path, text, fragments):
    path = write(tmp_path, _replace_section(text))
    with pytest.raises(ConfigError) as info:
        load_config(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(str(path))
    for fragment in fragments:
        assert fragment in message, message


def test_rigid_multidrum_is_refused():
    data = minimal()
    data["column"]["drums"] = 3
    data["interface"] = {"stiffness": "rigid"}
    with pytest.raises(ConfigError, match=r"interface\.stiffness: rigid needs a monolithic"):
        parse_config(data)
    del data["interface"]  # the default stiffness is rigid too
    with pytest.raises(ConfigError, match=r"interface\.stiffness: rigid \(the default\) needs"):
        parse_config(data)


def test_housner_restitution_needs_one_drum():
    data = minimal()
    data["column"]["drums"] = 2
    data["interface"] = {"stiffness": {"rotational": 1e9}, "restitution": "housner"}
    with pytest.raises(ConfigError, match=r"interface\.restitution: housner needs a monolithic"):
        parse_config(data)


@pytest.mark.parametrize(
    ("name", "ok"),
    [
        ("run_1.v2-b", True),
        ("a/b", False),
        ("my run", False),
        ("..", False),
        ("", False),
        ("x" * 101, False),
        (12, False),
        ("ñandú", False),
    ],
)
def test_name_must_be_a_folder_name(name, ok):
    data = minimal()
    data["name"] = name
    if ok:
        assert parse_config(data).name == name
    else:
        with pytest.raises(ConfigError, match=r"^<config>: name must be"):
            parse_config(data)


def test_required_top_level_keys():
    with pytest.raises(ConfigError, match="name is required"):
        parse_config({"column": {"height": 4, "base_width": 1}})
    with pytest.raises(ConfigError, match="column is required"):
        parse_config({"name": "x"})


def test_source_prefixes_messages():
    with pytest.raises(ConfigError, match=r"^study\.yaml: column\.height"):
        parse_config({"name": "x", "column": {"height": 0, "base_width": 1}}, "study.yaml")


# -------------------------------------------------------------------- files and YAML


def test_duplicate_key_is_refused(tmp_path):
    path = write(tmp_path, MINIMAL.replace("  base_width: 1\n", "  base_width: 1\n  height: 5\n"))
    with pytest.raises(ConfigError, match=r"duplicate key 'column\.height' \(line 5\)"):
        load_config(path)


def test_duplicate_top_level_key_is_refused(tmp_path):
    path = write(tmp_path, MINIMAL + "name: other\n")
    with pytest.raises(ConfigError, match="duplicate key 'name'"):
        load_config(path)


def test_missing_file(tmp_path):
    with pytest.raises(ConfigError, match="config file not found"):
        load_config(tmp_path / "nope.yaml")


def test_directory_instead_of_file(tmp_path):
    with pytest.raises(ConfigError, match="is a directory"):
        load_config(tmp_path)


@pytest.mark.parametrize("text", ["", "\n", "# only a comment\n", "---\n"])
def test_empty_file(tmp_path, text):
    with pytest.raises(ConfigError, match="empty"):
        load_config(write(tmp_path, text))


@pytest.mark.parametrize("text", ["- a\n- b\n", "just a string\n", "42\n"])
def test_top_level_must_be_a_mapping(tmp_path, text):
    with pytest.raises(ConfigError, match="top level must be a mapping"):
        load_config(write(tmp_path, text))


@pytest.mark.parametrize(
    ("text", "line"),
    [
        ("name: x\ncolumn:\n  height: 4\n base_width: 1\n", 4),
        ("name: x\ncolumn: {height: 4, base_width: 1\n", 3),
        ("name: x\ncolumn:\n\theight: 4\n", 3),
        ("name: [x\n", 2),
        ("name: x\n---\nname: y\n", 2),
        ("name: !!python/object:os.system x\n", 1),
    ],
)
def test_malformed_yaml_is_one_line(tmp_path, text, line):
    path = write(tmp_path, text)
    with pytest.raises(ConfigError) as info:
        load_config(path)
    message = str(info.value)
    assert message.startswith(f"cannot parse {path}: ")
    assert f"line {line}" in message
    assert "\n" not in message


def test_not_utf8(tmp_path):
    path = tmp_path / "cfg.yaml"
    path.write_bytes(b"name: caf\xe9\n")
    with pytest.raises(ConfigError, match="not UTF-8"):
        load_config(path)


def test_unreadable_file(tmp_path, monkeypatch):
    path = write(tmp_path, MINIMAL)

    def refuse(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(type(path), "open", refuse)
    with pytest.raises(ConfigError, match="cannot read .*permission denied"):
        load_config(path)


def test_os_error_is_a_config_error(tmp_path, monkeypatch):
    path = write(tmp_path, MINIMAL)

    def fail(*args, **kwargs):
        raise OSError(5, "Input/output error")

    monkeypatch.setattr(type(path), "open", fail)
    with pytest.raises(ConfigError, match="cannot read .*Input/output error"):
        load_config(path)


def test_huge_integer_is_a_config_error(tmp_path):
    path = write(tmp_path, MINIMAL + "collapse:\n  ratio: " + "9" * 5000 + "\n")
    with pytest.raises(ConfigError):
        load_config(path)


def test_deep_nesting_is_a_config_error(tmp_path):
    path = write(tmp_path, "name: " + "[" * 5000 + "]" * 5000 + "\n")
    with pytest.raises(ConfigError):
        load_config(path)


def test_parse_config_does_not_mutate_its_input():
    data = minimal()
    data["grid"] = {"amplitudes": [0.1, 0.2]}
    before = copy.deepcopy(data)
    parse_config(data)
    assert data == before


def test_results_are_frozen():
    cfg = parse_config(minimal())
    with pytest.raises(AttributeError):
        cfg.column.height = 2.0  # type: ignore[misc]
    assert math.isclose(sum(cfg.column.drum_heights), cfg.column.height)


@pytest.mark.parametrize("model", ["housner", "housner-linear"])
def test_reference_models_need_a_monolithic_column(model):
    data = {
        "name": "x",
        "model": model,
        "column": {"height": 4.0, "base_width": 1.0, "drums": 2},
        "interface": {"stiffness": {"rotational": 1e9}},
    }
    with pytest.raises(ConfigError, match=f"model '{model}' needs a monolithic column"):
        parse_config(data)
    data["column"]["drums"] = 1
    assert parse_config(data).model == model
