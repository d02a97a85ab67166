"""Sweeps: run a grid of amplitude x frequency cells in parallel, in memory or resumably
into a folder.

The sweep knows runs, not physics. Cells are run in chunks by workers
(rbm_cli.study.parallel; each worker assembles the model once per chunk and returns its rows;
nothing accumulates in globals): :func:`run_cells` hands each finished chunk's rows to a
callback. :func:`sweep_rows` is the sweep in memory: cells in, rows out, nothing written.
:func:`run_sweep` is the same with a transactional store around it (rbm_cli.study.store):
the output folder is locked for one sweep, finished chunks are appended to a validated
journal, ``domain.partial.jsonl``, so an interrupted, killed or doubled sweep keeps every
finished cell and leaves no file that looks complete, and ``resume=True`` finishes it
without redoing finished cells. The result is published in one step at the end, in grid
order, so the same config gives the same ``domain.csv`` whatever the number of workers.
"""

from __future__ import annotations

import dataclasses
import io
import json
import numbers
import os
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from rbm_cli.base.errors import RbmError
from rbm_cli.config.grid import MAX_CELLS as GRID_MAX_CELLS
from rbm_cli.config.points import GridPoint
from rbm_cli.config.types import MODELS, Config
from rbm_cli.models.compile_ahead import compile_once, needs_compile
from rbm_cli.models.methods import compiled_codes
from rbm_cli.models.registry import make_runner
from rbm_cli.structures.assembly import model_from_config
from rbm_cli.structures.similarity import rocking_scales
from rbm_cli.study.cells import (
    Cell,
    add_point,
    count_cells,
    grid_cells,
    grid_points,
    has_records,
    key,
    max_drums,
    row_key,
    tasks,
)
from rbm_cli.study.domain import csv_text, parse_domain
from rbm_cli.study.fingerprint import config_hash
from rbm_cli.study.intensities import column_period
from rbm_cli.study.parallel import run_chunks
from rbm_cli.study.robustness import (
    check_config,
    member_config,
    members,
    solver_checks,
    summarise,
)
from rbm_cli.study.schema import ENSEMBLE_COLUMNS, C, domain_columns, point_columns
from rbm_cli.study.simulate import simulate
from rbm_cli.study.store import JOURNAL, SweepStore
from rbm_cli.study.sweep_folder import (
    as_started,
    prepare_folder,
    publish_result,
    status_counts,
    sweep_meta,
)

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.figure import Figure

#: Grids larger than this need force=True (a 10 s cell takes ~0.01-10 s); an ensemble's
#: members count as cells.
MAX_CELLS = 100_000
#: Most runs (cells x ensemble members) a sweep takes, with force too: the grid's limit
#: (rbm_cli.config.grid.MAX_CELLS).
MAX_RUNS = GRID_MAX_CELLS
BACKENDS = ("loky", "threading", "sequential", "dask")
#: Columns an ensemble sweep adds to domain.csv (rbm_cli.study.robustness).
ENSEMBLE_FIELDS = ENSEMBLE_COLUMNS


@dataclass(frozen=True)
class SweepSummary:
    folder: Path
    n_cells: int
    n_run: int
    n_resumed: int
    n_collapsed: int
    n_survived: int
    n_failed: int
    wall_time_s: float
    compile_s: float = 0.0  # compiling (or loading) the kernel, left out of wall_time_s
    compile_what: str = ""  # what compile_s was spent on ("compiling the integrator", ...)
    already_finished: bool = False  # resume on a folder that holds this config's result
    workers: int | None = None  # the cells ran in this process (0), on N workers, or ? (None)


def _run_cell(config: Config, a: float, f: float | None, runner) -> dict:
    try:
        return simulate(config, a, f, runner=runner).row()
    except Exception as exc:  # a sweep goes on past one bad cell
        return {
            C.amplitude_g: a,
            C.frequency_hz: f,
            C.status: "failed",
            C.collapsed: 0,
            C.message: f"{type(exc).__name__}: {' '.join(str(exc).split())}",
        }


def _outcomes(rows: list[dict]) -> list[int | None]:
    """Each run's outcome for the robustness rule: collapsed (1 or 0), None if it failed."""
    return [None if r[C.status] == "failed" else r[C.collapsed] for r in rows]


def run_chunk(config: Config, cells: list[Cell], ensemble: int = 1) -> list[dict]:
    """Run cells of one point's config in this process; a cell that raises is 'failed'.

    Cells are (amplitude_g, frequency_hz, point values) (rbm_cli.study.cells); each row
    gets its point's values and its column's scales. With ensemble K > 1 each cell is
    run K times (rbm_cli.study.robustness.members) and once or twice more by the solver
    check (rbm_cli.study.robustness.solver_checks); its row is member 0's, plus
    collapse_fraction (the fraction of the members that did not fail which collapsed;
    NaN if all failed), robust (1 when all members agree, none failed and the solver
    check agrees: the robustness rule) and sensitive_to (why not: inputs, solver, both;
    none when robust)."""
    runner = make_runner(config)  # the column assembled once for every cell and member
    scales = rocking_scales(config)
    period = column_period(config) if has_records(config) else None
    rows = []
    others = members(ensemble)[1:]
    checks = [check_config(config, s) for s in solver_checks(config)] if ensemble > 1 else []
    for cell in cells:
        a, f, _ = cell
        row = add_point(_run_cell(config, a, f, runner), config, cell, scales, period)
        if ensemble > 1:
            runs = [row] + [_run_cell(*member_config(config, a, m), f, runner) for m in others]
            checked = [_run_cell(c, a, f, runner) for c in checks]
            summary = summarise(_outcomes(runs), _outcomes(checked))
            row.update(zip(ENSEMBLE_FIELDS, summary, strict=True))
        rows.append(row)
    return rows


# --------------------------------------------------------------------------- in memory


def run_cells(config: Config, points: list[GridPoint], cells: list[Cell],
              on_rows: Callable[[list[dict]], None], jobs: int = 1, backend: str = "loky",
              scheduler: str | None = None, ensemble: int = 1,
              progress: Callable[[int, int], None] | None = None, n_done: int = 0,
              n_cells: int | None = None, stop_after: int | None = None,
              placed: dict | None = None) -> None:  # fmt: skip
    """Run cells of a config's grid points in chunks on workers (rbm_cli.study.parallel);
    ``on_rows(rows)`` gets each finished chunk's rows (:func:`run_chunk`), in the order
    the chunks finish.

    Parameters
    ----------
    config : Config  The checked config; points : its grid points (rbm_cli.study.cells)
    cells : list of Cell  The cells to run (amplitude [g], frequency [Hz], point values)
    on_rows : callable(list of dict)  Takes each finished chunk's rows
    jobs, backend, scheduler : As :func:`run_sweep`
    ensemble : int  Runs per cell (:func:`run_chunk`)
    progress : callable(done, total)  Called before the first chunk runs, as chunks finish
        and now and then between; done counts from ``n_done`` (cells finished before)
    n_cells : int  The total progress names (default: n_done + len(cells))
    stop_after : int  Run only this many chunks (tests of interruption)
    placed : dict  Filled with "workers" (rbm_cli.study.parallel.run_chunks)
    """
    n_cells = n_done + len(cells) if n_cells is None else n_cells
    chunks = tasks(config, points, cells, jobs)
    if stop_after is not None:
        chunks = chunks[:stop_after]
    work = [(cfg, c, ensemble) for cfg, c in _probe_first(chunks)]
    if progress:
        progress(n_done, n_cells)
    sizes = [len(c) for _, c, _ in work]  # what a pool pays for (parallel)
    for rows in run_chunks(run_chunk, work, jobs, backend, scheduler, sizes, placed):
        if rows is not None:
            on_rows(rows)
            n_done += len(rows)
        if progress:
            progress(n_done, n_cells)


@dataclass(frozen=True)
class SweepRows:
    """A sweep's rows in memory: domain.csv's rows, in grid order, without a file.

    Attributes
    ----------
    rows : list of dict  One per cell, in grid order (as domain.csv lists them)
    fields : tuple of str  domain.csv's columns
    compile_s : float  Compiling (or loading) the compiled code [s], not in wall_time_s
    wall_time_s : float  Running the cells [s]
    workers : int or None  Worker processes or threads the cells ran on (0: this process)
    """

    rows: list[dict]
    fields: tuple[str, ...]
    compile_s: float = 0.0
    wall_time_s: float = 0.0
    workers: int | None = None

    def csv(self) -> str:
        """domain.csv's text for these rows (what a folder sweep of the config writes)."""
        return csv_text(self.rows, self.fields)

    def frame(self) -> pd.DataFrame:
        """The DataFrame rbm_cli.study.domain.read_domain gives for domain.csv's text: read
        from :meth:`csv` by the same reader, so that the types are those of a stored domain's."""
        return parse_domain(io.StringIO(self.csv()), "the sweep's rows")


def sweep_fields(config: Config, ensemble: int = 1) -> tuple[str, ...]:
    """domain.csv's columns for a sweep of ``config`` with ``ensemble`` runs per cell."""
    return domain_columns(config, ensemble)


def sweep_rows(
    config: Config,
    jobs: int = 1,
    backend: str = "loky",
    scheduler: str | None = None,
    ensemble: int = 1,
    force: bool = False,
    progress: Callable[[int, int], None] | None = None,
    notify: Callable[[str], None] | None = None,
) -> SweepRows:
    """Run the grid of a config in memory: cells in, rows out, nothing written.

    The same cells, chunks and rows as :func:`run_sweep` (which is this with a
    transactional store around it): the rows are those of the domain.csv it writes.

    Parameters
    ----------
    config : Config  Validated config with a non-empty grid
    jobs, backend, scheduler, ensemble, force, progress : As :func:`run_sweep`
    notify : callable(str)  One-line notes (what a compile waits for)

    Returns
    -------
    SweepRows  The rows in grid order, their columns, compile and wall times [s]

    Raises
    ------
    RbmError  Bad arguments (one line), before any cell runs
    """
    _check_request(config, jobs, ensemble, backend, scheduler, force)
    points = _check_points(grid_points(config))
    cells = grid_cells(config, points)
    paths = point_columns(config)
    done: dict = {}

    def keep(rows: list[dict]) -> None:
        for row in rows:
            done[row_key(row, paths)] = row

    placed: dict = {}
    compile_s, _ = warm_up(points, cells, backend, scheduler, notify or (lambda text: None))
    start = time.perf_counter()
    run_cells(config, points, cells, keep, jobs, backend, scheduler, ensemble, progress,
              placed=placed)  # fmt: skip
    wall = time.perf_counter() - start
    return SweepRows([done[key(c)] for c in cells], sweep_fields(config, ensemble), compile_s,
                     wall, placed.get("workers"))  # fmt: skip


# --------------------------------------------------------------------------- in a folder


def _check_request(
    config: Config, jobs: int, ensemble: int, backend: str, scheduler: str | None, force: bool
) -> int:
    """The number of cells, once every argument is checked (before any folder exists)."""
    # counted before the cells are listed: a 10^8-cell grid is refused at once
    n_cells = count_cells(config)
    if config.excitation.type == "record":  # a record has no frequency
        if not n_cells:
            raise RbmError("the config has no grid: give grid.amplitudes (the records' PGA [g])")
    elif not n_cells or not config.grid.frequencies_hz:
        raise RbmError("the config has no grid: give grid.amplitudes and grid.frequencies")
    for name, value in (("jobs", jobs), ("ensemble", ensemble)):
        if not (_is_int(value) and value >= 1):
            raise RbmError(f"--{name} must be a whole number >= 1, got {value!r}")
    # an ensemble's members are runs as cells are: counted against the same limits
    runs = n_cells * int(ensemble)
    cells = f"{n_cells:,} cell{'s' if n_cells != 1 else ''}"
    what = f"the grid has {cells}" if ensemble == 1 else \
        f"the sweep has {cells} x {int(ensemble):,} ensemble members = {runs:,} runs"  # fmt: skip
    if runs > MAX_RUNS:
        raise RbmError(
            f"{what}, more than the {MAX_RUNS:,} a sweep can run: split the grid"
            + (" or lower --ensemble" if ensemble > 1 else "")
        )
    if runs > MAX_CELLS and not force:
        raise RbmError(f"{what} (more than {MAX_CELLS:,}); use --force to run it")
    if not isinstance(backend, str) or backend not in BACKENDS:
        raise RbmError(f"unknown backend {backend!r} (allowed: {', '.join(BACKENDS)})")
    if backend == "dask":
        # lazy: loads joblib only where needed (docs/architecture.md, Start-up)
        from rbm_cli.study.parallel import check_dask_installed, probe_dask

        check_dask_installed()
        if scheduler:
            probe_dask(scheduler)  # an address that is not a Dask scheduler: one line, bounded
    return n_cells


def _is_int(value) -> bool:
    """A whole number: an int or a numpy integer, not a boolean."""
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


def _check_points(points: list[GridPoint]) -> list[GridPoint]:
    """The points, once every point's RBM has finite derived quantities (or one line
    naming the point)."""
    for point in points:
        if MODELS[point.config.model].beam:
            try:
                model_from_config(point.config)
            except RbmError as exc:
                text = f"grid point {point.label}: {exc}" if point.values else str(exc)
                raise type(exc)(text) from None
    return points


def run_sweep(
    config: Config,
    output: str | os.PathLike = "out",
    jobs: int = 2,
    backend: str = "loky",
    scheduler: str | None = None,
    resume: bool = False,
    force: bool = False,
    progress: Callable[[int, int], None] | None = None,
    stop_after: int | None = None,
    ensemble: int = 1,
    notify: Callable[[str], None] | None = None,
    resume_command: str | None = None,
    *,
    figure: Callable[[pd.DataFrame, Config], Figure],
) -> SweepSummary:
    """Run the grid of a config and write OUTPUT/<name>/domain.csv and friends.

    The folder is locked for the sweep (a second sweep into it is refused), finished
    cells go to a validated journal as they finish, and the result is published in one
    step once every file of it is written (rbm_cli.study.store). Nothing finished is deleted:
    an unfinished journal needs resume=True (or force=True, which moves it to
    superseded/); a finished result of the same config is replaced only by a complete
    new one; one of another config needs force=True (moved to superseded/ first).

    Parameters
    ----------
    config : Config  Validated config with a non-empty grid
    output : path  Output root; files go to output/<name>/
    jobs : int  Worker processes (joblib); 1 runs in this process
    backend : str  joblib backend: loky (default), threading, sequential or
        dask (a Dask distributed cluster at `scheduler`)
    resume : bool  Finish an interrupted sweep of the same config, by its journal's
        solver.method; on a finished folder of it, do nothing (summary: already_finished)
    force : bool  Allow grids of more than MAX_CELLS cells; set aside (never delete)
        an unfinished journal, or a finished result of another config, and start again
    progress : callable(done, total)  Called before the first cell runs (after the compile;
        done = the resumed cells), as chunks finish, and now and then between
    stop_after : int  Stop after this many chunks (tests of interruption)
    ensemble : int  Runs per cell (>1 adds the collapse_fraction column; see
        rbm_cli.study.robustness for the perturbations)
    notify : callable(str)  One-line notes (a journal recovered, lines not trusted...)
    resume_command : str  The command that resumes it (state file, messages; default generic)
    figure : callable(DataFrame, Config) -> Figure  Draws domain.png (rbm_cli.api.run_sweep
        passes rbm_cli.report.domain_figure.domain_figure: the sweep does not plot); one
        with a ``from_rows`` method gets the rows (rbm_cli.study.sweep_folder.draw_figure)

    Raises
    ------
    RbmError  Bad arguments, a busy or unusable folder, a full disk (finished cells kept)
    SweepInterrupted  Ctrl-C (a KeyboardInterrupt): finished cells kept, see its message
    """
    n_cells = _check_request(config, jobs, ensemble, backend, scheduler, force)
    points = _check_points(grid_points(config))
    cells = grid_cells(config, points)
    folder = Path(output) / config.name
    digest = config_hash(config, points) + (f"-ensemble{ensemble}" if ensemble > 1 else "")
    fields = sweep_fields(config, ensemble)
    resume_command = resume_command or f"rbm sweep CONFIG.yaml -o {output} --resume"
    note = notify or (lambda text: None)
    with SweepStore(folder) as store:
        done, started = prepare_folder(store, config, points, cells, digest, ensemble, resume,
                                       force, note, resume_command)  # fmt: skip
        if done is None:
            return _finished_summary(folder, n_cells)
        config, points = as_started(config, points, started, note)
        todo = [c for c in cells if key(c) not in done]
        run = _Run(store, config, points, cells, digest, ensemble, resume_command, done, note=note)
        compile_s, wall = run.run(todo, jobs, backend, scheduler, progress, stop_after)
        rows = [done[key(c)] for c in cells]
        counts = status_counts(rows)
        meta = sweep_meta(config, points, digest, len(cells), len(todo), counts, ensemble, folder)
        meta.update(wall_time_s=wall, jobs=jobs, backend=backend, scheduler=scheduler,
                    compile_time_s=compile_s)  # fmt: skip
        try:
            publish_result(store, figure, config, rows, fields, meta,
                           resume_command)  # fmt: skip
        except KeyboardInterrupt:
            raise SweepInterrupted(folder, len(done), n_cells, resume_command) from None
    return _summary(folder, len(cells), len(todo), counts, wall, compile_s, run)


def _summary(folder, n_cells, n_run, counts, wall, compile_s, run=None) -> SweepSummary:
    """The summary of a sweep (run: the _Run that ran its cells, None if none ran)."""
    return SweepSummary(
        folder=folder,
        n_cells=n_cells,
        n_run=n_run,
        n_resumed=n_cells - n_run,
        n_collapsed=int(counts.get("collapsed", 0)),
        n_survived=int(counts.get("survived", 0)),
        n_failed=int(counts.get("failed", 0)),
        wall_time_s=wall,
        compile_s=compile_s,
        compile_what=run.compiled if run else "",
        workers=run.placed.get("workers") if run else None,
    )


@dataclass
class _Run:
    """The cells of one sweep being run into its store (journal rows land in `done`)."""

    store: SweepStore
    config: Config
    points: list
    cells: list
    digest: str
    ensemble: int
    resume_command: str
    done: dict
    placed: dict = dataclasses.field(default_factory=dict)  # where the cells ran (parallel)
    note: Callable[[str], None] = lambda text: None  # what the compile waits for
    compiled: str = ""  # what the compile time was spent on (warm_up)

    def cells_kept(self) -> int:
        """Cells kept after a Ctrl-C, counted from the journal: Ctrl-C may land between a
        chunk's write and its count."""
        read = self.store.read_journal(self.digest, {key(c) for c in self.cells},
                                       max_drums(self.points), self.ensemble,
                                       point_columns(self.config))  # fmt: skip
        return max(len(self.done), len(read.rows))

    def run(self, todo, jobs, backend, scheduler, progress, stop_after) -> tuple[float, float]:
        """Run the cells still to do (:func:`run_cells`), each finished chunk's rows into the
        journal (fsync'ed), then into ``done``; (compile time, wall time) [s]."""
        n_cells = len(self.cells)
        paths = point_columns(self.config)

        def journal(rows: list[dict]) -> None:
            self.store.append(rows, self.digest)
            for row in rows:
                self.done[row_key(row, paths)] = row

        try:
            compile_s, self.compiled = warm_up(self.points, todo, backend, scheduler, self.note)
            start = time.perf_counter()
            try:
                self.store.open_journal()
                run_cells(self.config, self.points, todo, journal, jobs, backend, scheduler,
                          self.ensemble, progress, len(self.done), n_cells, stop_after,
                          self.placed)  # fmt: skip
            except OSError as exc:
                raise RbmError(
                    f"cannot write the journal {self.store.journal}: {exc.strerror or exc}; the"
                    f" {len(self.done)} finished cells are kept: make room, then run"
                    f" {self.resume_command}"
                ) from None
            finally:
                self.store.close_journal()
        except KeyboardInterrupt:
            raise SweepInterrupted(self.store.folder, self.cells_kept(), n_cells,
                                   self.resume_command) from None  # fmt: skip
        if stop_after is not None and len(self.done) < n_cells:
            raise RbmError(
                f"sweep stopped after {stop_after} chunks (journal kept in {self.store.journal})"
            )
        return compile_s, time.perf_counter() - start


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C during a sweep into a folder: the finished cells are kept in the journal.

    Attributes
    ----------
    folder : pathlib.Path  The sweep's folder
    n_kept, n_cells : int  Cells kept [-], cells of the grid (amplitudes [g] x
        frequencies [Hz] x other axes) [-]
    resume_command : str  What finishes it (``rbm.sweep(cfg, output, resume=True)`` does)

    Examples
    --------
    >>> import rbm
    >>> issubclass(rbm.SweepInterrupted, KeyboardInterrupt)  # raised by rbm.sweep(cfg, output=...)
    True
    """

    def __init__(self, folder: Path, n_kept: int, n_cells: int, resume_command: str):
        self.folder, self.n_kept, self.n_cells = folder, n_kept, n_cells
        self.resume_command = resume_command
        super().__init__(
            f"interrupted: {n_kept} of {n_cells} cells are kept in {folder / JOURNAL};"
            f" resume with: {resume_command}"
        )


def _finished_summary(folder: Path, n_cells: int) -> SweepSummary:
    """The summary of a folder that already holds this config's result."""
    counts: dict = {}
    try:
        counts = json.loads((folder / "meta.json").read_text()).get("status_counts", {})
    except (OSError, ValueError, AttributeError):
        pass
    return dataclasses.replace(
        _summary(folder, n_cells, 0, counts, 0.0, 0.0), already_finished=True
    )


def _probe_first(chunks: list) -> list:
    """The chunks, the first cut in pieces of 1, 2, 4... cells: loky's first chunks run
    here until the time they take says whether a pool pays (rbm_cli.study.parallel), and
    small pieces make that known early. Rows do not depend on the cut."""
    if not chunks:
        return chunks
    config, cells = chunks[0]
    pieces, i, n = [], 0, 1
    while i < len(cells):
        pieces.append((config, cells[i : i + n]))
        i, n = i + n, 2 * n
    return pieces + chunks[1:]


def warm_up(points: list[GridPoint], todo: list, backend: str, scheduler: str | None,
            note: Callable[[str], None]) -> tuple[float, str]:  # fmt: skip
    """Compile (or load) the compiled code of the cells once here, if this process runs
    cells (every backend but a Dask scheduler's; loky runs its first chunks here) or if it
    must be compiled (then workers load it from numba's cache instead of each compiling it):
    compile_ahead.compile_once, which waits for a compile another process runs instead of
    compiling a second time, and tells note what it waits for before it waits. Returns its
    time [s], which the sweep's wall time and ETA leave out, and what it was spent on."""
    codes = sorted({code for p in points for code in compiled_codes(p.config)})
    if not (todo and codes):
        return 0.0, ""
    if backend == "dask" and scheduler and all(needs_compile(c) is False for c in codes):
        return 0.0, ""  # no cell runs here, and the workers find it in numba's cache
    spent = [compile_once(code, note) for code in codes]
    return sum(s for s, _ in spent), " and ".join(what for _, what in spent)
