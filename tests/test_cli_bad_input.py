"""Bad input through the command line: every case a user can get wrong.

Each case goes through the CLI (click's CliRunner, files in tmp_path only) and must end
in one line ``Error: ...`` that names the problem, exit status 2, no traceback, and no
output left behind that looks complete (no output folder for a sweep or a run, no image
for plot-domain). Config validation is also unit-tested in tests/test_config.py; here
the point is the whole path from the command line.
"""

from __future__ import annotations

import os
import time

import pandas as pd
import pytest
from click.testing import CliRunner

from rbm_cli.cli.main import cli

from .paths import RESULTS

GOOD = """\
name: small
column: {height: 4.0, base_width: 1.0, depth: 1.0}
interface: {stiffness: rigid}
excitation: {type: harmonic, duration: 1.0}
grid:
  amplitudes: [0.2, 0.3]
  frequencies: [0.5, 2.0]
"""
COLUMN = "column: {height: 4.0, base_width: 1.0, depth: 1.0}"
STORED = RESULTS / "spanos_koh_slender" / "domain.csv"
AS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0
ROOT_REASON = (
    "running as root: chmod does not stop root from reading or writing; the same code "
    "path is covered by the *_permission_error tests, which raise PermissionError"
)


def invoke(*args):
    return CliRunner().invoke(cli, [str(a) for a in args])


def assert_one_line_error(res, *needles):
    """Exit status 2, a single line starting with 'Error:', containing every needle."""
    lines = [line for line in res.output.splitlines() if line.strip()]
    assert res.exit_code == 2, res.output
    assert len(lines) == 1 and lines[0].startswith("Error:"), res.output
    assert "Traceback" not in res.output
    assert res.exception is None or isinstance(res.exception, SystemExit), res.exception
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])


def column(**changes) -> str:
    """GOOD with column keys changed (None deletes a key)."""
    keys = {"height": 4.0, "base_width": 1.0, "depth": 1.0}
    keys.update(changes)
    body = ", ".join(f"{k}: {v}" for k, v in keys.items() if v is not None)
    return GOOD.replace(COLUMN, "column: {" + body + "}")


def grid(amplitudes="[0.2, 0.3]", frequencies="[0.5, 2.0]") -> str:
    text = GOOD.split("grid:")[0] + "grid:\n"
    if amplitudes is not None:
        text += f"  amplitudes: {amplitudes}\n"
    if frequencies is not None:
        text += f"  frequencies: {frequencies}\n"
    return text


# (label, YAML text or bytes, fragments of the one-line message)
CONFIG_CASES = [
    # malformed YAML
    ("unclosed brace", "name: x\ncolumn: {height: 4\n", ["cannot parse", "line 3"]),
    ("tab indentation", "name: x\ncolumn:\n\theight: 4\n", ["cannot parse", "'\\t'"]),
    ("bad indentation", "name: x\ncolumn:\n  height: 4\n base_width: 1\n", ["cannot parse"]),
    ("not UTF-8", bytes(range(256)), ["not UTF-8"]),
    ("top level a list", "- a\n- b\n", ["top level must be a mapping"]),
    ("duplicate key", GOOD + "name: other\n", ["duplicate key 'name'"]),
    ("empty file", "", ["the config is empty"]),
    ("comments only", "# nothing here\n", ["the config is empty"]),
    # wrong types
    ("height as text", column(height="tall"), ["column.height must be a number > 0 [m]", "'tall'"]),
    ("height as a list", column(height="[4]"), ["column.height", "got a list"]),
    ("quoted number", column(height="'4'"), ["column.height", "quoted"]),
    ("boolean size", column(base_width="true"), ["column.base_width", "boolean"]),
    ("drum count 2.5", column(drums=2.5), ["column.drums must be an integer in 1..200"]),
    ("name a number", GOOD.replace("name: small", "name: 5"), ["name must be a string"]),
    ("column a list", GOOD.replace(COLUMN, "column: [4, 1]"), ["column must be a mapping"]),
    (
        "stiffness a word",
        GOOD.replace("stiffness: rigid", "stiffness: soft"),
        ["interface.stiffness must be rigid"],
    ),
    # unknown keys
    ("unknown top-level key", GOOD + "colour: red\n", ["unknown key 'colour' at top level"]),
    ("unknown column key", column(colour="grey"), ["unknown key 'colour' in column", "allowed:"]),
    (
        "unknown excitation key",
        GOOD.replace("duration: 1.0}", "duration: 1.0, pga: 1}"),
        ["unknown key 'pga' in excitation"],
    ),
    ("unknown grid key", GOOD + "  steps: 3\n", ["unknown key 'steps' in grid"]),
    # negative or zero sizes
    ("zero height", column(height=0), ["column.height must be a number > 0 [m], got 0"]),
    ("negative height", column(height=-4), ["column.height must be a number > 0 [m], got -4"]),
    ("zero base width", column(base_width=0), ["column.base_width must be a number > 0 [m]"]),
    ("negative base width", column(base_width=-1), ["column.base_width", "> 0 [m]", "got -1"]),
    ("zero depth", column(depth=0), ["column.depth must be a number > 0 [m], got 0"]),
    ("negative depth", column(depth=-1), ["column.depth must be a number > 0 [m], got -1"]),
    ("zero density", column(density=0), ["column.density must be a number > 0 [kg/m^3]"]),
    ("negative density", column(density=-2700), ["column.density", "got -2700"]),
    ("zero top width", column(top_width=0), ["column.top_width must be a number in (0, 3] [m]"]),
    ("negative top width", column(top_width=-1), ["column.top_width", "got -1"]),
    ("zero drum height", column(drums="[4.0, 0]"), ["column.drums[1] must be a number > 0"]),
    ("negative drum height", column(drums="[5.0, -1.0]"), ["column.drums[1]", "got -1"]),
    ("zero drum count", column(drums=0), ["column.drums must be an integer in 1..200"]),
    ("negative drum count", column(drums=-3), ["column.drums", "got -3"]),
    # sizes whose masses overflow or underflow (tracebacks before the height range)
    ("height 1e100", column(height="1e100"), ["column.height must be in [0.001, 1000] [m]"]),
    (
        "height 1e-100",
        column(height="1e-100", base_width="1e-101", depth="1e-101"),
        ["column.height must be in [0.001, 1000] [m]", "got 1e-100"],
    ),
    # widths beyond what the model accepts: the message says what is allowed
    (
        "top width 9 x base",
        column(top_width=9),
        ["column.top_width must be a number in (0, 3] [m]", "at most 3 x column.base_width"],
    ),
    (
        "top width above the height",
        column(base_width=1.8, top_width=4.5),
        ["column.top_width must be a number in (0, 4] [m]", "at most column.height"],
    ),
    (
        "base wider than tall",
        column(base_width=5),
        ["column.base_width must be <= column.height (4 m), got 5"],
    ),
    # drum heights that do not sum to the height
    ("drums sum below", column(drums="[1.0, 1.0]"), ["column.drums heights sum to 2 m", "4 m"]),
    ("drums sum above", column(drums="[3.0, 3.0]"), ["column.drums heights sum to 6 m"]),
    # zero or negative frequencies, bad amplitudes
    ("zero frequency", grid(frequencies="[0]"), ["grid.frequencies[0] must be a number > 0 [Hz]"]),
    ("negative frequency", grid(frequencies="[0.5, -2]"), ["grid.frequencies[1]", "got -2"]),
    ("negative frequency scalar", grid(frequencies="-3"), ["grid.frequencies must be", "> 0"]),
    (
        "frequency range from 0",
        grid(frequencies="{start: 0, stop: 2, num: 5}"),
        ["grid.frequencies.start must be a number > 0 [Hz], got 0"],
    ),
    (
        "frequency range from -1",
        grid(frequencies="{start: -1, stop: 2, step: 0.5}"),
        ["grid.frequencies.start", "got -1"],
    ),
    ("NaN frequency", grid(frequencies="[.nan]"), ["grid.frequencies[0] must be a finite number"]),
    ("negative amplitude", grid(amplitudes="[-0.2]"), ["grid.amplitudes[0]", ">= 0 [g]"]),
    ("infinite amplitude", grid(amplitudes="[.inf]"), ["grid.amplitudes[0]", "finite"]),
    # empty grids written as empty lists
    ("empty amplitude list", grid(amplitudes="[]"), ["grid.amplitudes must not be an empty list"]),
    (
        "empty frequency list",
        grid(frequencies="[]"),
        ["grid.frequencies must not be an empty list"],
    ),
    ("amplitudes null", grid(amplitudes=""), ["grid.amplitudes must be", "got nothing"]),
]


def _write(tmp_path, text) -> str:
    path = tmp_path / "bad.yaml"
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text)
    return path


@pytest.mark.parametrize("command", ["sweep", "run"])
@pytest.mark.parametrize(
    ("label", "text", "needles"), CONFIG_CASES, ids=[c[0] for c in CONFIG_CASES]
)
def test_bad_config_through_the_cli(tmp_path, command, label, text, needles):
    path = _write(tmp_path, text)
    out = tmp_path / "out"
    if command == "sweep":
        res = invoke("sweep", path, "-o", out, "--quiet", "--jobs", "1")
    else:
        res = invoke("run", path, "-a", 0.5, "-f", 1, "-o", out)
    assert_one_line_error(res, *needles)
    assert not out.exists()  # nothing written, not even a folder


EMPTY_GRIDS = [
    ("grid: {}", GOOD.split("grid:")[0] + "grid: {}\n"),
    ("grid: null", GOOD.split("grid:")[0] + "grid:\n"),
    ("no frequencies", grid(frequencies=None)),
    ("no amplitudes", grid(amplitudes=None)),
    ("no grid at all", GOOD.split("grid:")[0]),
]


@pytest.mark.parametrize(("label", "text"), EMPTY_GRIDS, ids=[c[0] for c in EMPTY_GRIDS])
def test_sweep_of_an_empty_grid(tmp_path, label, text):
    out = tmp_path / "out"
    res = invoke("sweep", _write(tmp_path, text), "-o", out, "--quiet")
    assert_one_line_error(res, "the config has no grid", "grid.amplitudes and grid.frequencies")
    assert not out.exists()


@pytest.mark.parametrize(
    ("amplitudes", "frequencies", "needles"),
    [
        (
            "{start: 0.01, stop: 10.0, num: 10000}",
            "{start: 0.1, stop: 20.0, num: 20}",
            ("the grid has 200,000 cells", "more than 100,000", "--force"),
        ),
        (
            "{start: 0.01, stop: 10.0, num: 10000}",
            "{start: 0.1, stop: 20.0, num: 200}",
            ("10,000 x 200 = 2,000,000 cells", "more than the 1,000,000 a sweep can hold"),
        ),
        (
            "{start: 0.01, stop: 10.0, num: 10000}",
            "{start: 0.1, stop: 20.0, num: 10000}",
            ("10,000 x 10,000 = 100,000,000 cells", "more than the 1,000,000 a sweep can hold"),
        ),
    ],
)
def test_millions_of_cells_refused_at_once(tmp_path, amplitudes, frequencies, needles):
    """Guards the count made before the cells are listed: 10^8 cells took 37 s (and
    gigabytes) to be refused when the list was built first. Above 100,000 cells a sweep
    needs --force; above 1,000,000 a grid is refused even with it."""
    out = tmp_path / "out"
    start = time.perf_counter()
    res = invoke("sweep", _write(tmp_path, grid(amplitudes, frequencies)), "-o", out, "--quiet")
    assert time.perf_counter() - start < 10.0
    assert_one_line_error(res, *needles)
    assert not out.exists()


def test_grid_step_giving_too_many_values(tmp_path):
    text = grid(amplitudes="{start: 0.0, stop: 10.0, step: 0.0001}")
    res = invoke("sweep", _write(tmp_path, text), "-o", tmp_path / "out")
    assert_one_line_error(res, "grid.amplitudes.step gives", "at most 10000")


# ----------------------------------------------------------------- missing, unreadable files


def _commands_reading(config, csv):
    """Every command, reading the given config or domain CSV."""
    return {
        "info": ["info", config],
        "run": ["run", config, "-a", 0.5, "-f", 1],
        "sweep": ["sweep", config, "--quiet"],
        "plot-domain": ["plot-domain", csv],
        "plot-domain --compare": ["plot-domain", STORED, "--compare", csv],
        "plot-domain --config": ["plot-domain", STORED, "--config", config],
        "compare A": ["compare", csv, STORED],
        "compare B": ["compare", STORED, csv],
    }


COMMANDS = list(_commands_reading("C", "D"))


@pytest.mark.parametrize("which", COMMANDS)
def test_missing_file(tmp_path, which, monkeypatch):
    monkeypatch.chdir(tmp_path)  # default output folders land in tmp_path
    args = _commands_reading(tmp_path / "nope.yaml", tmp_path / "nope.csv")[which]
    if args[0] == "plot-domain":
        args = [*args, "-o", tmp_path / "p.png"]
    res = invoke(*args)
    assert_one_line_error(res, "not found", "nope.")
    assert sorted(p.name for p in tmp_path.iterdir()) == []


@pytest.mark.parametrize("which", COMMANDS)
def test_directory_instead_of_a_file(tmp_path, which, monkeypatch):
    folder = tmp_path / "thing.yaml"
    folder.mkdir()
    monkeypatch.chdir(tmp_path)
    args = _commands_reading(folder, folder)[which]
    if args[0] == "plot-domain":
        args = [*args, "-o", tmp_path / "p.png"]
    res = invoke(*args)
    assert_one_line_error(res, "thing.yaml")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["thing.yaml"]


def _unreadable_copies(tmp_path):
    config = tmp_path / "locked.yaml"
    config.write_text(GOOD)
    csv = tmp_path / "locked.csv"
    csv.write_text(STORED.read_text())
    return config, csv


@pytest.mark.skipif(AS_ROOT, reason=ROOT_REASON)
@pytest.mark.may_skip(reason=ROOT_REASON)
@pytest.mark.parametrize("which", COMMANDS)
def test_unreadable_file_chmod(tmp_path, which, monkeypatch):
    config, csv = _unreadable_copies(tmp_path)
    config.chmod(0)
    csv.chmod(0)
    monkeypatch.chdir(tmp_path)
    args = _commands_reading(config, csv)[which]
    if args[0] == "plot-domain":
        args = [*args, "-o", tmp_path / "p.png"]
    try:
        res = invoke(*args)
    finally:
        config.chmod(0o644)
        csv.chmod(0o644)
    assert_one_line_error(res, "cannot read", "ermission denied", "locked.")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["locked.csv", "locked.yaml"]


@pytest.mark.parametrize("which", COMMANDS)
def test_unreadable_file_permission_error(tmp_path, which, monkeypatch):
    """What chmod 000 does for a normal user, simulated: opening the file raises
    PermissionError (the config through Path.open, the CSV through pandas)."""
    config, csv = _unreadable_copies(tmp_path)
    real_open, real_read_csv = type(config).open, pd.read_csv

    def refuse_open(self, *args, **kwargs):
        if self.name.startswith("locked"):
            raise PermissionError(13, "Permission denied")
        return real_open(self, *args, **kwargs)

    def refuse_csv(path, *args, **kwargs):
        if str(path).endswith("locked.csv"):
            raise PermissionError(13, "Permission denied")
        return real_read_csv(path, *args, **kwargs)

    monkeypatch.setattr(type(config), "open", refuse_open)
    monkeypatch.setattr(pd, "read_csv", refuse_csv)
    monkeypatch.chdir(tmp_path)
    args = _commands_reading(config, csv)[which]
    if args[0] == "plot-domain":
        args = [*args, "-o", tmp_path / "p.png"]
    res = invoke(*args)
    assert_one_line_error(res, "cannot read", "ermission denied", "locked.")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["locked.csv", "locked.yaml"]


# ----------------------------------------------------------------- unwritable output


@pytest.fixture
def good(tmp_path):
    path = tmp_path / "good.yaml"
    path.write_text(GOOD)
    return path


@pytest.fixture
def blocker(tmp_path):
    """A plain file where a folder is expected."""
    path = tmp_path / "blocker"
    path.write_text("x")
    return path


@pytest.mark.parametrize("deeper", [False, True], ids=["file", "under a file"])
def test_sweep_into_a_file(good, blocker, deeper):
    target = blocker / "deeper" if deeper else blocker
    res = invoke("sweep", good, "-o", target, "--quiet")
    assert_one_line_error(res, "cannot write to output folder", str(blocker))
    assert blocker.read_text() == "x"


@pytest.mark.parametrize("deeper", [False, True], ids=["file", "under a file"])
def test_run_into_a_file(good, blocker, deeper):
    target = blocker / "deeper" if deeper else blocker
    res = invoke("run", good, "-a", 0.5, "-f", 1, "-o", target)
    assert_one_line_error(res, "cannot create output folder", str(blocker))
    assert blocker.read_text() == "x"


@pytest.mark.skipif(AS_ROOT, reason=ROOT_REASON)
@pytest.mark.may_skip(reason=ROOT_REASON)
@pytest.mark.parametrize("command", ["sweep", "run"])
def test_read_only_output_folder(good, tmp_path, command):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    try:
        if command == "sweep":
            res = invoke("sweep", good, "-o", locked, "--quiet")
        else:
            res = invoke("run", good, "-a", 0.5, "-f", 1, "-o", locked)
        left = list(locked.iterdir())
    finally:
        locked.chmod(0o755)
    assert_one_line_error(res, str(locked))
    assert left == []


@pytest.mark.parametrize(
    ("target", "needle"),
    [
        ("blocker/x.png", "cannot write"),
        ("no_such_folder/x.png", "No such file or directory"),
        (".", "cannot write"),
        ("x.xyz", "unknown image type '.xyz' (allowed: "),
        ("", "--output must name an image file"),
    ],
    ids=["under a file", "missing folder", "a folder", "unknown suffix", "empty name"],
)
def test_plot_domain_unwritable_output(tmp_path, blocker, target, needle, monkeypatch):
    monkeypatch.chdir(tmp_path)
    before = sorted(p.name for p in tmp_path.iterdir())
    res = invoke("plot-domain", STORED, "-o", target)
    assert_one_line_error(res, needle)
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    assert blocker.read_text() == "x"


# ----------------------------------------------------------------- bad domain CSVs

HEADER = "amplitude_g,frequency_hz,status\n"
BAD_CSVS = [
    ("empty file", "", ["cannot read", "as a domain CSV"]),
    ("header only", HEADER, ["has no rows"]),
    ("no status column", "amplitude_g,frequency_hz\n0.1,1\n", ["missing column(s) status"]),
    (
        "no frequency column",
        "amplitude_g,status\n0.1,survived\n",
        ["missing column(s) frequency_hz"],
    ),
    (
        "not a CSV",
        "hello world\nfoo\n",
        ["missing column(s) amplitude_g, frequency_hz, status"],
    ),
    ("binary", bytes(range(256)) * 4, ["cannot read", "as a domain CSV"]),
    ("unterminated quote", HEADER + '"0.1,1,survived\n', ["cannot read", "EOF inside string"]),
    (
        "unknown status",
        HEADER + "0.1,1,maybe\n0.2,1,collapsed\n",
        ["line 2: status must be one of collapsed, survived, failed, got 'maybe'"],
    ),
    (
        "amplitude text",
        HEADER + "0.1,1,survived\nabc,1,survived\n",
        ["line 3: amplitude_g must be a finite number >= 0 [g], got 'abc'"],
    ),
    ("empty amplitude", HEADER + ",1,survived\n", ["line 2: amplitude_g", "an empty field"]),
    ("negative amplitude", HEADER + "-0.1,1,survived\n", ["line 2: amplitude_g", ">= 0"]),
    ("infinite amplitude", HEADER + "inf,1,survived\n", ["line 2: amplitude_g", "finite"]),
    (
        "frequency text",
        HEADER + "0.1,xyz,survived\n",
        ["line 2: frequency_hz must be a finite number > 0 [Hz], got 'xyz'"],
    ),
    ("zero frequency", HEADER + "0.1,0,survived\n", ["line 2: frequency_hz", "> 0 [Hz]"]),
    ("negative frequency", HEADER + "0.1,-1,survived\n", ["line 2: frequency_hz", "got '-1"]),
    (
        "row longer than the header",
        HEADER + "0.1,1,survived,extra,more\n",
        ["some rows have more fields than its header (3)"],
    ),
    ("row shorter than the header", HEADER + "0.1,1,survived\n0.2\n", ["line 3: frequency_hz"]),
    (
        "a cell twice",
        HEADER + "0.1,1,survived\n0.1,1.0,collapsed\n",
        ["line 3 repeats the cell of line 2 (amplitude 0.1 g, frequency 1 Hz)"],
    ),
]


def _write_csv(folder, content):
    folder.mkdir()
    path = folder / "domain.csv"
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content)
    return path


@pytest.mark.parametrize(("label", "content", "needles"), BAD_CSVS, ids=[c[0] for c in BAD_CSVS])
def test_plot_domain_bad_csv(tmp_path, label, content, needles):
    path = _write_csv(tmp_path / "d", content)
    res = invoke("plot-domain", path)
    assert_one_line_error(res, str(path), *needles)
    assert sorted(p.name for p in path.parent.iterdir()) == ["domain.csv"]  # no domain.png
    res = invoke("plot-domain", STORED, "--compare", path, "-o", tmp_path / "p.png")
    assert_one_line_error(res, str(path), *needles)
    assert not (tmp_path / "p.png").exists()


@pytest.mark.parametrize(("label", "content", "needles"), BAD_CSVS, ids=[c[0] for c in BAD_CSVS])
@pytest.mark.parametrize("side", ["A", "B"])
def test_compare_bad_csv(tmp_path, label, content, needles, side):
    path = _write_csv(tmp_path / "d", content)
    args = (path, STORED) if side == "A" else (STORED, path)
    res = invoke("compare", *args, "--max-cells", 0.01)
    assert_one_line_error(res, str(path), *needles)


def test_compare_domains_without_a_common_cell(tmp_path):
    other = _write_csv(tmp_path / "d", HEADER + "0.123,7.77,survived\n")
    res = invoke("compare", STORED, other)
    assert_one_line_error(res, "the two domains have no cell in common")


@pytest.mark.parametrize(
    ("option", "value"), [("--max-cells", "-0.1"), ("--max-cells", "nan"), ("--max-shift", "-1")]
)
def test_compare_bad_limits(option, value):
    res = invoke("compare", STORED, STORED, option, value)
    assert_one_line_error(res, f"{option} must be >= 0")


def test_stored_domains_still_read():
    """The value checks accept every stored domain (guards against a check too strict)."""
    for path in sorted(RESULTS.glob("*/domain.csv")):
        res = invoke("compare", path, path, "--max-cells", 0, "--max-shift", 0)
        assert res.exit_code == 0, (path, res.output)
