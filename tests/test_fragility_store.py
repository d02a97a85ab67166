"""`rbm fragility` publishes its five files as one set: a kill -9, a Ctrl-C or a SIGTERM
while they are moved into place leaves the folder with the old set or the new one, never
a mix; what a killed run leaves behind is removed by the next run; two runs into one
folder do not mix (the second is refused in one line).

The faults are put exactly between two moves: `rbm fragility` runs in a process of its
own (a session of its own, as a shell starts it) whose ``os.replace`` is wrapped so that,
after the second of the set's files has been moved onto its name, the command's process
group gets the signal (or the mover waits for the test). Expected sets: the bytes of two
uninterrupted runs, one per domain, in folders of the same name.
"""

from __future__ import annotations

import fcntl
import os
import random
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from rbm_cli.cli.main import cli

from .test_fragility_cli import suite, write_domain

FILES = ("fragility.png", "ida.png", "fragility.csv", "fragility_curve.csv", "fragility.json")

#: `python -c RUNNER MODE AFTER MARKER rbm-args...`: `rbm rbm-args` whose os.replace, after
#: the AFTER-th move onto one of FILES, writes MARKER (the mover's pid) and then: sends
#: SIGKILL / SIGINT / SIGTERM to the command's process group (kill, int, term), or waits
#: until MARKER.go exists (pause), or sleeps a random 0-60 ms after every move (slow).
RUNNER = """\
import os, random, signal, sys, time
from pathlib import Path

mode, after, marker = sys.argv[1], int(sys.argv[2]), Path(sys.argv[3])
command = os.getpid()
names = set(sys.argv[4].split(","))
real = os.replace
moved = []

def replace(src, dst, *args, **kwargs):
    real(src, dst, *args, **kwargs)
    if os.path.basename(os.fspath(dst)) not in names:
        return
    moved.append(dst)
    if mode == "slow":
        time.sleep(random.uniform(0.0, 0.06))
    if len(moved) != after:
        return
    marker.write_text(str(os.getpid()))
    if mode == "pause":
        end = time.monotonic() + 60
        while not marker.with_suffix(".go").exists() and time.monotonic() < end:
            time.sleep(0.02)
    elif mode in ("kill", "int", "term"):
        sig = {"kill": signal.SIGKILL, "int": signal.SIGINT, "term": signal.SIGTERM}[mode]
        os.killpg(os.getpgid(command), sig)

os.replace = replace
sys.argv = ["rbm", *sys.argv[5:]]
from rbm_cli.cli.main import main
main()
"""


def start(domain: Path, marker: Path, mode: str = "none", after: int = 2, *args):
    """`rbm fragility DOMAIN --resamples 20 ARGS` in a session of its own, faults as RUNNER."""
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
    command = [sys.executable, "-c", RUNNER, mode, str(after), str(marker), ",".join(FILES),
               "fragility", str(domain), "--resamples", "20", *map(str, args)]  # fmt: skip
    return subprocess.Popen(command, env=env, start_new_session=True, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)  # fmt: skip


def the_set(folder: Path) -> dict[str, bytes]:
    return {name: (folder / name).read_bytes() for name in FILES if (folder / name).exists()}


def hidden(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


def wait_unlocked(folder: Path, timeout: float = 20.0) -> None:
    """Wait until no process holds the folder's fragility lock (as a second run would
    find it), so that whatever was still moving the files has ended."""
    path = folder / ".fragility.lock"
    end = time.monotonic() + timeout
    while True:
        try:
            fd = os.open(path, os.O_RDONLY)
        except FileNotFoundError:
            return
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return
        except BlockingIOError:
            assert time.monotonic() < end, "the fragility lock is still held"
            time.sleep(0.02)
        finally:
            os.close(fd)


@pytest.fixture(scope="module")
def sets(tmp_path_factory):
    """Two domains (20 records; capacities from two seeds) and the bytes of the fragility
    set of each, from runs that were not interrupted, in folders named `suite`."""
    root = tmp_path_factory.mktemp("sets")
    domains, expected = {}, {}
    for key, seed in (("old", 1), ("new", 2)):
        df, _ = suite(seed=seed, n_records=20)
        path = write_domain(root / key / "suite", df)
        res = CliRunner().invoke(cli, ["fragility", path, "--resamples", "20"])
        assert res.exit_code == 0, res.output
        domains[key] = Path(path).read_bytes()
        expected[key] = the_set(root / key / "suite")
    for name in FILES:  # every file differs, so a mix shows in any of them
        assert expected["old"][name] != expected["new"][name], name
    return domains, expected


def folder_with_old_set(tmp_path: Path, sets) -> Path:
    """A folder `suite` holding the old domain's set, and the new domain in domain.csv."""
    domains, expected = sets
    folder = tmp_path / "suite"
    folder.mkdir()
    for name, data in expected["old"].items():
        (folder / name).write_bytes(data)
    (folder / "domain.csv").write_bytes(domains["new"])
    return folder


def whole(folder: Path, expected) -> str:
    """'old' or 'new': which whole set the folder holds (the test fails on a mix)."""
    found = the_set(folder)
    for key in ("old", "new"):
        if found == expected[key]:
            return key
    mix = {name: [k for k in ("old", "new") if expected[k][name] == data]
           for name, data in found.items()}  # fmt: skip
    raise AssertionError(f"the folder holds a mix of two fragility sets: {mix}")


def test_kill_between_two_moves_leaves_one_whole_set(tmp_path, sets):
    """A kill -9 of `rbm fragility`'s process group after two of the five files were moved
    into place once left the new figures beside the old fit's fragility.csv and .json, and
    the staging files forever. Now the folder holds one whole set, and the next run leaves
    no hidden file behind."""
    folder = folder_with_old_set(tmp_path, sets)
    marker = tmp_path / "moved"
    proc = start(folder / "domain.csv", marker, "kill", 2)
    proc.communicate(timeout=120)
    assert proc.returncode == -signal.SIGKILL and marker.exists()  # killed between moves
    wait_unlocked(folder)
    assert whole(folder, sets[1]) == "new"  # the moves were finished, out of its reach
    res = CliRunner().invoke(cli, ["fragility", str(folder / "domain.csv"), "--resamples", "20"])
    assert res.exit_code == 0, res.output
    assert whole(folder, sets[1]) == "new" and hidden(folder) == []


@pytest.mark.parametrize("mode", ["int", "term"])
def test_signal_during_the_moves_waits_for_the_whole_set(tmp_path, sets, mode):
    """Ctrl-C (SIGINT to the process group, as a terminal sends it) or SIGTERM between two
    moves once stopped the publication half done. Now it is held back until the set is
    whole, then acts: Ctrl-C ends the command in one line, exit 130, nothing left behind."""
    folder = folder_with_old_set(tmp_path, sets)
    marker = tmp_path / "moved"
    proc = start(folder / "domain.csv", marker, mode, 2)
    out, err = proc.communicate(timeout=120)
    assert marker.exists()
    wait_unlocked(folder)
    assert whole(folder, sets[1]) == "new"
    if mode == "int":
        assert proc.returncode == 130, err
        lines = [line for line in err.splitlines() if line.strip()]
        assert len(lines) == 1 and lines[0].startswith("Error: interrupted (Ctrl-C)"), err
        assert hidden(folder) == []
    else:
        assert proc.returncode == -signal.SIGTERM, err


def test_leftovers_of_killed_runs_are_removed_by_the_next_run(tmp_path, sets):
    """Staging folders and `.fragility*.tmp` / `.ida.png.*.tmp` files of killed runs were
    never removed. The next run removes them, and nothing else: a sweep's staging folder
    and the user's own hidden files stay."""
    folder = folder_with_old_set(tmp_path, sets)
    staging = folder / ".fragility.publish.4242.k2j3h4"
    staging.mkdir()
    (staging / "fragility.png").write_bytes(b"half a png")
    strays = [".fragility.csv.abc123.tmp", ".fragility.json.q1w2e3.tmp", ".ida.png.zz.tmp",
              ".fragility_curve.csv.x.tmp", ".fragility.png.y.tmp"]  # fmt: skip
    for name in strays:
        (folder / name).write_text("left by a kill")
    (folder / ".fragility.lock").write_text("4242\n")  # its holder is gone
    sweep_staging = folder / ".publish.4243.abcdef"  # a sweep's: not ours to remove
    sweep_staging.mkdir()
    (folder / ".notes.tmp").write_text("mine")
    res = CliRunner().invoke(cli, ["fragility", str(folder / "domain.csv"), "--resamples", "20"])
    assert res.exit_code == 0, res.output
    assert hidden(folder) == [".notes.tmp", ".publish.4243.abcdef"]
    assert whole(folder, sets[1]) == "new"


def test_two_runs_into_one_folder_do_not_mix(tmp_path, sets):
    """A second `rbm fragility` into a folder whose set is being moved into place once
    wrote its own files among the first one's. It is refused in one line (exit 2) naming
    the folder, and the first run's set is published whole."""
    folder = folder_with_old_set(tmp_path, sets)
    marker = tmp_path / "moved"
    proc = start(folder / "domain.csv", marker, "pause", 1)
    try:
        end = time.monotonic() + 120
        while not marker.exists():
            assert proc.poll() is None and time.monotonic() < end, proc.communicate()
            time.sleep(0.02)
        other = tmp_path / "other.csv"  # another domain, same output folder
        other.write_bytes(sets[0]["old"])
        res = CliRunner().invoke(cli, ["fragility", str(other), "-o", str(folder)])
        lines = [line for line in res.output.splitlines() if line.strip()]
        assert res.exit_code == 2 and len(lines) == 1, res.output
        assert "is being written by another rbm fragility" in lines[0], lines[0]
    finally:
        marker.with_suffix(".go").touch()
        out, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    assert whole(folder, sets[1]) == "new" and hidden(folder) == []


@pytest.mark.slow
def test_random_kills_leave_no_mix_and_no_leftovers(tmp_path, sets):
    """A small fault-injection campaign: moves slowed (0-60 ms each) so that kills land
    among them, kill -9 of the process group at random times around the publication;
    after each, the folder holds a whole set (old or new), and the next run leaves no
    hidden file."""
    rng = random.Random(25)
    seen = {"old": 0, "new": 0}
    for trial in range(4):
        (tmp_path / str(trial)).mkdir()
        folder = folder_with_old_set(tmp_path / str(trial), sets)
        marker = tmp_path / f"moved{trial}"
        proc = start(folder / "domain.csv", marker, "slow", 1)
        while not marker.exists() and proc.poll() is None:
            time.sleep(0.005)
        time.sleep(rng.uniform(0.0, 0.2))
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:  # it had ended: counted like the others
            pass
        proc.communicate(timeout=60)
        wait_unlocked(folder)
        seen[whole(folder, sets[1])] += 1
        res = CliRunner().invoke(cli, ["fragility", str(folder / "domain.csv"),
                                       "--resamples", "20"])  # fmt: skip
        assert res.exit_code == 0 and hidden(folder) == [], res.output
        shutil.rmtree(folder)
    assert seen["old"] == 0  # the first move had been made: only the new set can be whole


def test_with_threads_running_the_set_is_moved_without_a_fork(tmp_path, sets, monkeypatch):
    """A program with Python threads running (a notebook, a server) is not forked (fork
    copies one thread): the moves are made in its own process, signals held, and the set
    is published whole all the same."""
    folder = folder_with_old_set(tmp_path, sets)
    forks = []
    monkeypatch.setattr(os, "fork", lambda: forks.append(1) or pytest.fail("forked"))
    stop = threading.Event()
    worker = threading.Thread(target=stop.wait)
    worker.start()
    try:
        res = CliRunner().invoke(cli, ["fragility", str(folder / "domain.csv"),
                                       "--resamples", "20"])  # fmt: skip
    finally:
        stop.set()
        worker.join()
    assert res.exit_code == 0, res.output
    assert forks == [] and whole(folder, sets[1]) == "new" and hidden(folder) == []
