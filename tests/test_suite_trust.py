"""Record suites as safe as plain sweeps: every record in the hash by its content, globs and
folders expanded wherever a record is named, scaled records checked, no hang on a special
file, no traceback, and messages a user can act on.

Each test guards against one defect seen on suites and records (its docstring says which),
through the command line (click's CliRunner, or a subprocess where a hang is the point) or
the library (``import rbm``). Files only under tmp_path.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import rbm
from rbm_cli.api import run_sweep
from rbm_cli.base.errors import ConfigError, RbmError
from rbm_cli.cli.main import cli
from rbm_cli.config.load import load_config
from rbm_cli.config.types import G
from rbm_cli.inputs.records import write_csv
from rbm_cli.report.info import own_point_note
from rbm_cli.study.store import JOURNAL

from .paths import CONFIGS

pytestmark = pytest.mark.timeout(120)

#: A rigid block (B/H = 0.25: uplift at 0.25 g), cheap to run.
BLOCK = "column: {height: 2.0, base_width: 0.5}\ninterface: {stiffness: rigid}\n"


def invoke(*args, **kwargs):
    return CliRunner().invoke(cli, [str(a) for a in args], **kwargs)


def one_line_error(res, *needles, code: int = 2) -> str:
    """Exit status ``code``, one line 'Error: ...' holding the needles, no traceback."""
    output = res.output if hasattr(res, "output") else res.stdout + res.stderr
    status = res.exit_code if hasattr(res, "exit_code") else res.returncode
    assert status == code, output
    assert "Traceback" not in output, output
    errors = [line for line in output.splitlines() if line.startswith("Error:")]
    assert len(errors) == 1, output
    for needle in needles:
        assert needle in errors[0], (needle, errors[0])
    return errors[0]


def pulse(path: Path, frequency_hz: float, peak_g: float = 1.0) -> Path:
    """A one-sine pulse record (CSV in g) of the given frequency and peak: one cycle,
    400 samples."""
    t = np.linspace(0.0, 1.0 / frequency_hz, 401)
    a = peak_g * G * np.sin(2.0 * np.pi * frequency_hz * t)
    a[0] = a[-1] = 0.0
    return write_csv(path, (t, a), units="g")


@pytest.fixture
def suite(tmp_path) -> Path:
    """A folder rec/ of three records (r1, r2, r3: one-sine pulses of 1, 2 and 3 Hz) and a
    config suite.yaml sweeping them at four PGAs; its path."""
    (tmp_path / "rec").mkdir()
    for k, f in enumerate((1.0, 2.0, 3.0), start=1):
        pulse(tmp_path / "rec" / f"r{k}.csv", f)
    path = tmp_path / "suite.yaml"
    path.write_text(
        "name: suite\n" + BLOCK + "excitation: {type: record, file: rec, free_time: 2.0}\n"
        "grid: {amplitudes: [0.2, 0.4, 0.8, 1.6]}\n"
    )
    return path


def _domain_rows(folder: Path) -> list[str]:
    return (folder / "domain.csv").read_text().splitlines()


# ------------------------------------------------------------ every record in the hash


def test_a_resume_over_a_changed_record_of_a_suite_is_refused_naming_it(suite, tmp_path):
    """Defect: only the first record of a suite was in the config's hash; after a kill, a
    record copied over rec/r2.csv and --resume ran on, mixing the old record's rows with
    the new one's, with exit 0 and no word. Now the resume is refused in one line that
    names the file, and the journal is kept."""
    out = tmp_path / "out"
    with pytest.raises(RbmError, match="stopped after 1 chunks"):
        run_sweep(load_config(suite), out, jobs=1, stop_after=1)  # a sweep cut short
    journal = out / "suite" / JOURNAL
    kept = journal.read_bytes()
    assert kept.count(b"\n") >= 2  # its header and at least one finished cell
    shutil.copy(tmp_path / "rec" / "r3.csv", tmp_path / "rec" / "r2.csv")
    res = invoke("sweep", suite, "-o", out, "--resume", "--jobs", "1", "--quiet")
    one_line_error(res, "rec/r2.csv", "changed since the sweep was started")
    assert journal.read_bytes() == kept and not (out / "suite" / "domain.csv").exists()


def test_a_finished_suite_whose_record_changed_is_not_already_finished(suite, tmp_path):
    """Defect: on a finished folder, after record 3 changed, --resume said "already
    finished" and a plain re-run overwrote the old domain without moving it to
    superseded/. Now both name the changed file and keep the old domain; --force moves
    it to superseded/ and the new domain is a straight sweep's of the new records."""
    out = tmp_path / "out"
    assert invoke("sweep", suite, "-o", out, "--jobs", "1", "--quiet").exit_code == 0
    folder = out / "suite"
    old = (folder / "domain.csv").read_bytes()
    pulse(tmp_path / "rec" / "r3.csv", 0.5)  # another record under the same name
    for extra in (["--resume"], []):
        res = invoke("sweep", suite, "-o", out, "--jobs", "1", "--quiet", *extra)
        one_line_error(res, "rec/r3.csv", "changed")
        assert (folder / "domain.csv").read_bytes() == old
    res = invoke("sweep", suite, "-o", out, "--jobs", "1", "--quiet", "--force")
    assert res.exit_code == 0, res.output
    (stamp,) = (folder / "superseded").iterdir()
    assert (stamp / "domain.csv").read_bytes() == old
    straight = tmp_path / "straight"
    assert invoke("sweep", suite, "-o", straight, "--jobs", "1", "--quiet").exit_code == 0
    new = (folder / "domain.csv").read_bytes()
    assert new == (straight / "suite" / "domain.csv").read_bytes() and new != old
    changed = [(a, b) for a, b in zip(old.splitlines(), new.splitlines(), strict=True) if a != b]
    assert changed and all(b",r3," in b for a, b in changed)  # only the r3 rows differ


def test_a_vertical_record_axis_is_in_the_hash(tmp_path):
    """Every record a grid names, a vertical one too, is in the hash by its content: a
    changed vertical record of an axis changes the config's hash."""
    from rbm_cli.study.sweep import config_hash

    pulse(tmp_path / "h.csv", 1.0)
    for name in ("v1.csv", "v2.csv"):
        pulse(tmp_path / name, 4.0, 0.2)
    path = tmp_path / "v.yaml"
    path.write_text(
        "name: v\n" + BLOCK + "excitation: {type: record, file: h.csv, vertical: v1.csv}\n"
        "grid: {amplitudes: [0.5], excitation.vertical: [v1.csv, v2.csv]}\n"
    )
    before = config_hash(load_config(path))
    pulse(tmp_path / "v2.csv", 4.0, 0.3)
    assert config_hash(load_config(path)) != before


# ------------------------------------------------------------ globs and folders as axis values


def test_a_glob_or_folder_given_as_an_axis_value_is_expanded(suite, tmp_path):
    """Defect: grid {excitation.file: "rec/*.csv"} ran only the first match, labelled with
    the pattern. A glob, a folder, or a list mixing a file and a glob is expanded as
    excitation.file is: one point per file, in the order written (a pattern's matches
    sorted)."""
    pulse(tmp_path / "extra.csv", 1.5)
    expect = ["extra.csv", "rec/r1.csv", "rec/r2.csv", "rec/r3.csv"]
    for value in ('"rec/*.csv"', "rec", '[extra.csv, "rec/*.csv"]'):
        path = tmp_path / "axis.yaml"
        path.write_text(
            "name: axis\n" + BLOCK + "excitation: {type: record, file: extra.csv}\n"
            f"grid: {{amplitudes: [0.4], excitation.file: {value}}}\n"
        )
        cfg = load_config(path)
        (axis,) = cfg.grid.axes
        files = [p[0] for p in axis.points]
        assert files == (expect if value.startswith("[") else expect[1:]), value
        df = rbm.sweep(cfg)
        assert df["excitation.file"].tolist() == files
        assert df["record"].tolist() == [Path(f).stem for f in files]


def test_a_glob_in_a_linked_axis_is_refused(suite, tmp_path):
    path = tmp_path / "linked.yaml"
    path.write_text(
        "name: linked\n" + BLOCK + "excitation: {type: record, file: rec/r1.csv}\n"
        "grid: {amplitudes: [0.4], linked: [{excitation.file: ['rec/*.csv'],"
        " collapse.ratio: [0.5]}]}\n"
    )
    with pytest.raises(ConfigError, match="a linked axis lists each record file by name"):
        load_config(path)


def test_a_record_named_twice_by_an_axis_is_refused(suite, tmp_path):
    path = tmp_path / "twice.yaml"
    path.write_text(
        "name: twice\n" + BLOCK + "excitation: {type: record, file: rec/r1.csv}\n"
        "grid: {amplitudes: [0.4], excitation.file: [rec/r2.csv, 'rec/*.csv']}\n"
    )
    res = invoke("sweep", path, "-o", tmp_path / "out")
    one_line_error(res, "'rec/r2.csv' is named twice")
    assert not (tmp_path / "out").exists()


# ------------------------------------------------------------ scaled records checked


def _record_config(tmp_path, name: str, rows: str, scale: str) -> Path:
    (tmp_path / name).write_text("time_s,acceleration_g\n" + rows)
    path = tmp_path / f"{Path(name).stem}.yaml"
    path.write_text(
        f"name: r\n{BLOCK}excitation: {{type: record, file: {name}, scale: {scale}}}\n"
        "grid: {amplitudes: [1.0]}\n"
    )
    return path


def test_a_record_beyond_any_ground_motion_is_refused(tmp_path):
    """Defect: a CSV '0,0 / 0.01,1e306 / 0.02,0' with scale: factor and -a 1 'survived'
    with 0 uplifts (its arithmetic overflowed); 1.5e308 g passed loading, then printed two
    RuntimeWarnings and a message without the file. Now the record is refused when the
    config is loaded, in one line naming the file."""
    for value in ("1e306", "1.5e308"):
        path = _record_config(tmp_path, "big.csv", f"0,0\n0.01,{value}\n0.02,0\n", "factor")
        res = subprocess.run(
            [sys.executable, "-m", "rbm_cli", "run", str(path), "-a", "1", "-o",
             str(tmp_path / "out")],
            capture_output=True, text=True, timeout=60,
        )  # fmt: skip
        one_line_error(res, "big.csv", "more than 1000 g")
        assert "RuntimeWarning" not in res.stderr
        assert not (tmp_path / "out").exists()


def test_a_pga_too_small_to_scale_is_refused(tmp_path):
    """Defect: a record whose PGA is subnormal (1e-310 g) 'survived' at 5 g: the scale
    factor 5 / 1e-310 overflowed. Now a PGA below 1e-6 g is refused with scale: pga."""
    path = _record_config(tmp_path, "tiny.csv", "0,0\n0.01,1e-310\n0.02,0\n", "pga")
    res = invoke("run", path, "-a", "5", "-o", tmp_path / "out")
    one_line_error(res, "tiny.csv", "too small to be scaled")
    # a plain factor on the same record is a real (if tiny) motion: it runs and survives
    factor = _record_config(tmp_path, "tiny.csv", "0,0\n0.01,1e-310\n0.02,0\n", "factor")
    assert rbm.run(factor, amplitude_g=5.0).status == "survived"


def test_a_scaled_record_beyond_1000_g_is_refused(tmp_path):
    """The scaled record is checked before a run: a factor that lifts its peak above
    1000 g is one line naming the file (a sweep records such a cell as failed, with it)."""
    path = _record_config(tmp_path, "large.csv", "0,0\n0.01,500\n0.02,0\n", "factor")
    res = invoke("run", path, "-a", "3", "-o", tmp_path / "out")
    one_line_error(res, "large.csv", "1500 g", "at most 1000 g")
    assert rbm.run(path, amplitude_g=1.0).status in ("survived", "collapsed")


# ------------------------------------------------------------ the library's arguments


def test_the_library_refuses_booleans_and_nan(tmp_path):
    """Defect: rbm.run(cfg, amplitude_g=True) ran at 1 g (the config refuses booleans);
    output_dt=True and rbm.sweep(..., jobs=nan) were accepted."""
    cfg = rbm.load_config({"name": "b", "column": {"height": 2.0, "base_width": 0.5},
                           "grid": {"amplitudes": [0.1], "frequencies": [1.0]}})  # fmt: skip
    with pytest.raises(RbmError, match="amplitude_g must be a number"):
        rbm.run(cfg, amplitude_g=True, frequency_hz=1.0)
    with pytest.raises(RbmError, match="frequency_hz must be a number"):
        rbm.run(cfg, amplitude_g=0.1, frequency_hz=np.True_)
    with pytest.raises(RbmError, match="output_dt must be a number > 0"):
        rbm.run(cfg, amplitude_g=0.1, frequency_hz=1.0, output_dt=True)
    for jobs in (math.nan, True, 1.5, 0):
        with pytest.raises(RbmError, match="--jobs must be a whole number >= 1"):
            rbm.sweep(cfg, tmp_path / "out", jobs=jobs)
    assert not (tmp_path / "out").exists()


def test_the_library_takes_numpy_numbers_and_0d_arrays():
    """Defect: height: np.array(2.0) raised a TypeError; numpy numbers were shown as
    np.float64(0.05) in messages."""
    cfg = rbm.load_config({"name": "b", "column": {"height": np.array(2.0),
                                                   "base_width": np.float32(0.5)}})  # fmt: skip
    assert (cfg.column.height, cfg.column.base_width) == (2.0, 0.5)
    assert rbm.run(cfg, amplitude_g=np.array(0.1), frequency_hz=np.int64(1)).status == "survived"
    for call in (
        lambda: rbm.with_values(cfg, {"column.height": np.float64(-0.05)}),
        lambda: rbm.run(cfg, amplitude_g=np.float64(-0.05), frequency_hz=1.0),
    ):
        with pytest.raises(RbmError) as info:
            call()
        assert "np." not in str(info.value) and "-0.05" in str(info.value)


def test_a_deep_or_cyclic_mapping_is_refused_in_one_line():
    """Defect: a dict nested 10^5 deep, or one that holds itself, raised RecursionError."""
    deep: dict = {}
    node = deep
    for _ in range(100_000):
        node["a"] = {}
        node = node["a"]
    with pytest.raises(ConfigError, match="more than 32 levels deep"):
        rbm.load_config({"name": "b", "column": {"height": 2.0, "base_width": 0.5}, "x": deep})
    cyclic: dict = {"name": "b", "column": {"height": 2.0, "base_width": 0.5}}
    cyclic["column"]["drums"] = [cyclic]
    with pytest.raises(ConfigError, match="holds itself"):
        rbm.load_config(cyclic)
    cfg = rbm.load_config({"name": "b", "column": {"height": 2.0, "base_width": 0.5}})
    with pytest.raises(ConfigError, match="holds itself"):
        rbm.with_values(cfg, {"column.drums": cyclic["column"]["drums"]})


def test_the_library_bounds_the_history(tmp_path):
    """Defect: rbm.run(..., output_dt=1e-12) ran out of memory: the command line's --dt
    guard was not in the library."""
    cfg = rbm.load_config({"name": "b", "column": {"height": 2.0, "base_width": 0.5}})
    with pytest.raises(RbmError, match="samples over 10 s"):
        rbm.run(cfg, amplitude_g=0.1, frequency_hz=1.0, output_dt=1e-12)
    path = tmp_path / "b.yaml"
    path.write_text("name: b\n" + BLOCK)
    one_line_error(invoke("run", path, "-a", 0.1, "-f", 1, "--dt", "1e-12"), "use a larger --dt")


# ------------------------------------------------------------ special files: no hang


def test_a_fifo_or_a_device_named_as_a_record_does_not_hang(tmp_path):
    """Defect: a FIFO named x.AT2 blocked config loading forever; a symlink to /dev/zero
    read without limit, then a MemoryError traceback. Only regular files are read."""
    os.mkfifo(tmp_path / "x.AT2")
    (tmp_path / "zero.AT2").symlink_to("/dev/zero")
    for name in ("x.AT2", "zero.AT2"):
        path = tmp_path / f"{name}.yaml"
        path.write_text(f"name: f\n{BLOCK}excitation: {{type: record, file: {name}}}\n")
        start = time.monotonic()
        res = subprocess.run(
            [sys.executable, "-m", "rbm_cli", "run", str(path), "-a", "0.5"],
            capture_output=True, text=True, timeout=30,
        )  # fmt: skip
        one_line_error(res, name, "not a regular file")
        assert time.monotonic() - start < 30


def test_a_huge_grid_is_refused_at_once(tmp_path):
    """Defect: a grid of 10^12 cells (three axes of 10,000) took 4-5 minutes to be refused
    (each point re-validated the record); --force on a 10^8-cell grid ran out of memory.
    Cells are counted before any point is built: refused in one line, at once."""
    pulse(tmp_path / "r.csv", 1.0)
    path = tmp_path / "huge.yaml"
    path.write_text(
        "name: huge\n" + BLOCK + "excitation: {type: record, file: r.csv}\n"
        "grid: {amplitudes: {start: 0.001, stop: 1, num: 10000},"
        " frequencies: {start: 1, stop: 10, num: 10000},"
        " column.height: {start: 1, stop: 3, num: 10000}}\n"
    )
    start = time.perf_counter()
    with pytest.raises(ConfigError, match="1,000,000,000,000 cells"):
        load_config(path)
    assert time.perf_counter() - start < 1.0
    path.write_text(
        "name: huge\n" + BLOCK + "excitation: {type: harmonic}\n"
        "grid: {amplitudes: {start: 0.001, stop: 1, num: 10000},"
        " frequencies: {start: 1, stop: 10, num: 10000}}\n"
    )
    res = invoke("sweep", path, "-o", tmp_path / "out", "--force")
    one_line_error(res, "100,000,000 cells", "a sweep can hold")
    assert not (tmp_path / "out").exists()


# ------------------------------------------------------------ tracebacks become one line


def test_a_folder_named_like_a_record_inside_a_suite_is_not_a_record(suite, tmp_path):
    """Defect: a folder named x.AT2 inside a suite folder raised IndexError. It is not a
    record: the suite is the folder's record files; a folder holding no record file is
    refused in one line."""
    (tmp_path / "rec" / "x.AT2").mkdir()
    cfg = load_config(suite)
    assert [p[0] for p in cfg.grid.axes[0].points] == [f"rec/r{k}.csv" for k in (1, 2, 3)]
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "y.AT2").mkdir()
    suite.write_text(suite.read_text().replace("file: rec,", "file: empty,"))
    one_line_error(invoke("sweep", suite, "-o", tmp_path / "out"), "holds no .AT2 or .csv")


def test_a_file_name_too_long_is_one_line(tmp_path):
    """Defect: a 5,000-character file name (ENAMETOOLONG) ended in a traceback."""
    path = tmp_path / "long.yaml"
    path.write_text(f"name: l\n{BLOCK}excitation: {{type: record, file: {'a' * 5000}.csv}}\n")
    one_line_error(invoke("run", path, "-a", 0.5), "File name too long")
    one_line_error(invoke("sweep", tmp_path / f"{'b' * 5000}.yaml"), "File name too long")


def test_a_full_disk_when_the_journal_starts_is_one_line(tmp_path):
    """Defect: ENOSPC while the journal was started (the store's small-file write) ended in
    a traceback. A file-size limit of 10 bytes makes that first write fail (EFBIG, as a
    full disk fails it with ENOSPC): one line, nothing run, no journal left."""
    import resource

    path = tmp_path / "b.yaml"
    path.write_text("name: b\n" + BLOCK + "grid: {amplitudes: [0.1], frequencies: [1]}\n")

    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (10, 10))

    res = subprocess.run(
        [sys.executable, "-m", "rbm_cli", "sweep", str(path), "-o", str(tmp_path / "out"),
         "--jobs", "1", "--quiet"],
        capture_output=True, text=True, timeout=60, preexec_fn=limit,
    )  # fmt: skip
    one_line_error(res, "cannot start the sweep's journal", "nothing was run")
    folder = tmp_path / "out" / "b"
    assert not (folder / JOURNAL).exists() and not (folder / "domain.partial.json").exists()
    assert [p.name for p in folder.iterdir() if not p.name.startswith(".sweep.lock")] == []


# ------------------------------------------------------------ messages a user can act on


def test_record_messages_name_the_problem(tmp_path):
    """Defects: a UTF-16 record's message quoted NUL bytes; `vertical: <folder>` said
    "unknown record format ''"; a record file name with a carriage return made a
    domain.csv that no command could read."""
    write_csv(tmp_path / "ok.csv", (np.array([0.0, 0.01, 0.02]), np.array([0.0, 0.3, 0.0]) * G))
    (tmp_path / "u16.csv").write_text("time_s,acc_g\n0,0\n0.01,0.1\n", encoding="utf-16")
    (tmp_path / "folder").mkdir()
    shutil.copy(tmp_path / "ok.csv", tmp_path / "cr\r.csv")
    cases = [
        ("file: u16.csv", ["u16.csv", "not UTF-8 text"]),
        ("file: ok.csv, vertical: folder", ["excitation.vertical", "is a folder"]),
        ('file: "cr\\r.csv"', ["control characters"]),
        ('file: "*.csv"', ["control characters"]),  # the glob finds cr\r.csv
    ]
    for excitation, needles in cases:
        path = tmp_path / "c.yaml"
        path.write_text(f"name: c\n{BLOCK}excitation: {{type: record, {excitation}}}\n"
                        "grid: {amplitudes: [0.5]}\n")  # fmt: skip
        error = one_line_error(invoke("sweep", path, "-o", tmp_path / "out"), *needles)
        assert "\\x00" not in error and "\x00" not in error
    assert not (tmp_path / "out").exists()


def test_grid_keys_that_cannot_vary_say_so(tmp_path):
    """Defect: grid.model: [rbm, housner] said "unknown key 'model' in grid" though the
    README said any scalar key can be an axis; a whole section gave the same message."""
    path = tmp_path / "m.yaml"
    for key, needle in (("model: [rbm, housner]", "model cannot vary over a grid"),
                        ("column: [1]", "the whole column section cannot vary")):  # fmt: skip
        path.write_text(f"name: m\n{BLOCK}grid: {{amplitudes: [0.1], frequencies: [1], {key}}}\n")
        one_line_error(invoke("sweep", path, "-o", tmp_path / "out"), needle)


def test_bench_output_must_name_a_folder():
    """Defect: rbm bench -o '' was accepted (and would write into the current folder)."""
    one_line_error(invoke("bench", "--quick", "-o", ""), "--output must name a folder")


def test_run_on_a_suite_says_which_record_it_ran(suite, tmp_path):
    """Defect: rbm run on a suite (or a config with axes) silently ran the first record."""
    res = CliRunner().invoke(cli, ["run", str(suite), "-a", "0.4", "-o", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    assert "this run is the config's own point (excitation.file = rec/r1.csv)" in res.output
    summary = json.loads((tmp_path / "o/suite/run_A0.4/summary.json").read_text())
    assert summary["config"]["excitation"]["file"] == "rec/r1.csv"


def test_a_run_on_a_suite_of_pairs_names_the_pair_it_ran():
    """Defect: on a suite of pairs the note named the first x record and "excitation.file_y
    = its default", though the run takes the first pair's y record."""
    cfg = load_config(CONFIGS / "suite_pairs.yaml")
    note = own_point_note(cfg)
    assert cfg.excitation.file_y == "records/synthetic/rdk_02.AT2"  # what the run takes
    assert "excitation.file = records/synthetic/rdk_01.AT2" in note
    assert "excitation.file_y = records/synthetic/rdk_02.AT2" in note


# ------------------------------------------------------------ a backend that cannot run


def test_a_missing_dask_is_refused_before_the_journal(tmp_path, monkeypatch):
    """Defect: --backend dask without the dask extra printed '0/144 cells', failed, and
    left a journal whose resume command repeated the failing backend. The backend is
    checked before the folder is touched (dask hidden from the import system here)."""
    monkeypatch.setitem(sys.modules, "dask", None)
    monkeypatch.setitem(sys.modules, "distributed", None)
    path = tmp_path / "b.yaml"
    path.write_text("name: b\n" + BLOCK + "grid: {amplitudes: [0.1], frequencies: [1]}\n")
    res = invoke("sweep", path, "-o", tmp_path / "out", "--backend", "dask")
    one_line_error(res, "pip install 'rbm[dask]'")
    assert not (tmp_path / "out").exists()


# ------------------------------------------------------------ the store's own leftovers


def test_temporary_files_a_kill_left_are_removed_by_the_next_sweep(tmp_path):
    """Defect (found by the suite fault injection): a kill between the write of the state
    file's (or the journal header's) temporary copy and its rename left
    .domain.partial.json.<random>.tmp in the folder for good. The next sweep, holding the
    folder's lock, removes those and nothing else."""
    path = tmp_path / "b.yaml"
    path.write_text("name: b\n" + BLOCK + "grid: {amplitudes: [0.1], frequencies: [1]}\n")
    folder = tmp_path / "out" / "b"
    folder.mkdir(parents=True)
    stale = [folder / ".domain.partial.json.1p2w9_lr.tmp", folder / ".domain.partial.jsonl.x.tmp"]
    mine = [folder / ".notes.tmp", folder / "domain.partial.json.tmp", folder / "keep.tmp"]
    for item in stale + mine:
        item.write_text("{}")
    assert invoke("sweep", path, "-o", tmp_path / "out", "--jobs", "1", "--quiet").exit_code == 0
    assert [p.exists() for p in stale] == [False, False]
    assert all(p.exists() for p in mine)
