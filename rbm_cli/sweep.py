"""Sweeps: run a grid of amplitude x frequency cells in parallel, resumably.

The sweep knows runs, not physics. Cells are run in chunks by joblib workers
(each worker assembles the model once per chunk and returns its rows; nothing
accumulates in globals). Finished chunks are appended to a journal,
``domain.partial.jsonl`` (one JSON row a line), so an interrupted sweep leaves no file that looks
complete and ``resume=True`` finishes it without redoing finished cells. The
final files are written atomically at the end, in grid order, so the same
config gives the same ``domain.csv`` whatever the number of workers.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import platform
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

import joblib
import numpy as np
import pandas as pd

from . import __version__
from .config_types import Config
from .domain import boundary, cell_key, csv_text
from .errors import RbmError
from .provenance import provenance
from .result import CSV_FIELDS
from .robustness import RULE as ROBUSTNESS_RULE
from .robustness import Member, member_config, members, summarise

JOURNAL = "domain.partial.jsonl"
STATE = "domain.partial.json"
#: Grids larger than this need force=True (a 10 s cell takes ~0.01-10 s).
MAX_CELLS = 100_000
BACKENDS = ("loky", "threading", "sequential", "dask")
#: Columns an ensemble sweep adds to domain.csv (rbm_cli.robustness).
ENSEMBLE_FIELDS = ("collapse_fraction", "robust")

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


def grid_cells(config: Config) -> list[tuple[float, float]]:
    """The cells of a config's grid, frequency-major: [(amplitude_g, frequency_hz), ...]."""
    return [(a, f) for f in config.grid.frequencies_hz for a in config.grid.amplitudes_g]


def config_hash(config: Config) -> str:
    """Fingerprint of everything that changes a domain (the resolved config)."""
    text = json.dumps(dataclasses.asdict(config), sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def ensemble_member(config: Config, a: float, member: Member) -> tuple[Config, float]:
    """(config, amplitude [g]) of an ensemble member (rbm_cli.robustness.members)
    of the cell at amplitude a [g]."""
    return member_config(config, a, member)


def _run_cell(config: Config, a: float, f: float, model) -> dict:
    from .simulate import simulate

    try:
        return simulate(config, a, f, model=model).row()
    except Exception as exc:  # a sweep goes on past one bad cell
        return {
            "amplitude_g": a,
            "frequency_hz": f,
            "status": "failed",
            "collapsed": 0,
            "message": f"{type(exc).__name__}: {' '.join(str(exc).split())}",
        }


def run_chunk(config: Config, cells: list[tuple[float, float]], ensemble: int = 1) -> list[dict]:
    """Run cells of one config in this process; a cell that raises is 'failed'.

    With ensemble K > 1 each cell is run K times (rbm_cli.robustness.members) and
    its row is member 0's, plus collapse_fraction (the fraction of the members
    that did not fail which collapsed; NaN if all failed) and robust (1 when all
    members agree and none failed: the robustness rule)."""
    from .simulate import model_from_config

    model = model_from_config(config) if config.model == "rbm" else None
    rows = []
    others = members(ensemble)[1:]
    for a, f in cells:
        row = _run_cell(config, a, f, model)
        if ensemble > 1:
            runs = [row] + [_run_cell(*ensemble_member(config, a, m), f, model) for m in others]
            flags = [r["collapsed"] for r in runs if r["status"] != "failed"]
            fraction, robust = summarise(flags, len(runs) - len(flags))
            row["collapse_fraction"], row["robust"] = fraction, robust
        rows.append(row)
    return rows


def _chunks(cells: list, jobs: int) -> list[list]:
    size = int(np.clip(len(cells) // max(1, 16 * jobs), 1, 32))
    return [cells[i : i + size] for i in range(0, len(cells), size)]


def _read_journal(folder: Path, digest: str) -> dict[tuple[str, str], dict]:
    """Finished rows of an interrupted sweep of the same config, keyed by cell."""
    journal, state = folder / JOURNAL, folder / STATE
    if not journal.is_file() or not state.is_file():
        return {}
    try:
        saved = json.loads(state.read_text())
    except (OSError, ValueError):
        return {}
    if saved.get("config_hash") != digest:
        raise RbmError(
            f"{journal} was made with a different config; delete it or run without --resume"
        )
    done = {}
    for line in journal.read_text().splitlines():
        try:
            row = json.loads(line)
        except ValueError:
            continue  # a line cut by the interruption
        if isinstance(row, dict) and {"amplitude_g", "frequency_hz"} <= row.keys():
            done[cell_key(row["amplitude_g"], row["frequency_hz"])] = row
    return done


def _versions() -> dict:
    import matplotlib
    import scipy

    return {
        "rbm": __version__,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "pandas": pd.__version__,
        "joblib": joblib.__version__,
        "matplotlib": matplotlib.__version__,
    }


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
) -> SweepSummary:
    """Run the grid of a config and write OUTPUT/<name>/domain.csv and friends.

    Parameters
    ----------
    config : Config  Validated config with a non-empty grid
    output : path  Output root; files go to output/<name>/
    jobs : int  Worker processes (joblib); 1 runs in this process
    backend : str  joblib backend: loky (default), threading, sequential or
        dask (a Dask distributed cluster at `scheduler`)
    resume : bool  Finish an interrupted sweep of the same config
    force : bool  Allow grids of more than MAX_CELLS cells
    progress : callable(done, total)  Called as chunks finish
    stop_after : int  Stop after this many chunks (tests of interruption)
    ensemble : int  Runs per cell (>1 adds the collapse_fraction column; see
        rbm_cli.robustness for the perturbations)
    """
    # counted before the cells are listed: a 10^8-cell grid is refused at once
    n_cells = len(config.grid.amplitudes_g) * len(config.grid.frequencies_hz)
    if not n_cells:
        raise RbmError("the config has no grid: give grid.amplitudes and grid.frequencies")
    if n_cells > MAX_CELLS and not force:
        raise RbmError(
            f"the grid has {n_cells:,} cells (more than {MAX_CELLS:,}); use --force to run it"
        )
    cells = grid_cells(config)
    if jobs < 1:
        raise RbmError(f"--jobs must be >= 1, got {jobs}")
    if ensemble < 1:
        raise RbmError(f"--ensemble must be >= 1, got {ensemble}")
    if backend not in BACKENDS:
        raise RbmError(f"unknown backend {backend!r} (allowed: {', '.join(BACKENDS)})")
    folder = Path(output) / config.name
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / ".write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as exc:
        raise RbmError(f"cannot write to output folder {folder}: {exc.strerror or exc}") from None

    digest = config_hash(config) + (f"-ensemble{ensemble}" if ensemble > 1 else "")
    fields = CSV_FIELDS + (ENSEMBLE_FIELDS if ensemble > 1 else ())
    done = _read_journal(folder, digest) if resume else {}
    finals = ("domain.csv", "boundary.csv", "meta.json", "domain.png")
    for name in finals:  # a new or resumed sweep: no stale result may look complete
        (folder / name).unlink(missing_ok=True)
    journal = folder / JOURNAL
    if not done:
        journal.write_text("")
        (folder / STATE).write_text(json.dumps({"config_hash": digest}))
    todo = [c for c in cells if cell_key(*c) not in done]
    if todo and config.model == "rbm" and config.solver.implementation == "compiled":
        from .kernel import warm_up

        warm_up()  # compile (or load) once here, so the workers load it from numba's cache

    start = time.perf_counter()
    chunks = _chunks(todo, jobs)
    if stop_after is not None:
        chunks = chunks[:stop_after]
    n_done = len(cells) - len(todo)
    if progress:
        progress(n_done, len(cells))
    with journal.open("a") as fh:
        for rows in _parallel(config, chunks, jobs, backend, scheduler, ensemble):
            for row in rows:
                fh.write(json.dumps(row) + "\n")
                done[cell_key(row["amplitude_g"], row["frequency_hz"])] = row
            fh.flush()
            n_done += len(rows)
            if progress:
                progress(n_done, len(cells))
    if stop_after is not None and len(done) < len(cells):
        raise RbmError(f"sweep stopped after {stop_after} chunks (journal kept in {journal})")
    wall = time.perf_counter() - start

    # the complete domain, in grid order, written atomically
    from .output import save_figure_atomic, write_json_atomic, write_text_atomic

    rows = [done[cell_key(*c)] for c in cells]
    write_text_atomic(folder / "domain.csv", csv_text(rows, fields))
    df = pd.DataFrame(rows, columns=list(fields))
    bnd = boundary(df)
    write_text_atomic(
        folder / "boundary.csv",
        csv_text(bnd.to_dict("records"), tuple(bnd.columns)),
    )
    counts = df["status"].value_counts().to_dict()
    meta = {
        "name": config.name,
        "config": dataclasses.asdict(config),
        "config_hash": digest,
        "versions": _versions(),
        "wall_time_s": wall,
        "jobs": jobs,
        "backend": backend,
        "scheduler": scheduler,
        "n_cells": len(cells),
        "n_run": len(todo),
        "n_resumed": len(cells) - len(todo),
        "status_counts": counts,
        "ensemble": {"members": ensemble, "rule": ROBUSTNESS_RULE if ensemble > 1 else None},
        "provenance": provenance(),
        "cpu_count": os.cpu_count(),
    }
    write_json_atomic(folder / "meta.json", meta)
    fig = domain_figure(df, config)
    save_figure_atomic(fig, folder / "domain.png")
    import matplotlib.pyplot as plt

    plt.close(fig)  # pyplot holds every figure it made until closed
    journal.unlink(missing_ok=True)
    (folder / STATE).unlink(missing_ok=True)
    return SweepSummary(
        folder=folder,
        n_cells=len(cells),
        n_run=len(todo),
        n_resumed=len(cells) - len(todo),
        n_collapsed=int(counts.get("collapsed", 0)),
        n_survived=int(counts.get("survived", 0)),
        n_failed=int(counts.get("failed", 0)),
        wall_time_s=wall,
    )


def _parallel(config, chunks, jobs, backend, scheduler, ensemble=1) -> Iterable[list[dict]]:
    """Yield the rows of each chunk as it finishes."""
    if not chunks:
        return
    if jobs == 1 and backend in ("loky", "sequential"):
        for chunk in chunks:
            yield run_chunk(config, chunk, ensemble)
        return
    if backend == "dask":
        try:
            from dask.distributed import Client
        except ImportError:
            raise RbmError(
                "--backend dask needs dask's distributed scheduler: pip install 'rbm[dask]'"
            ) from None
        try:
            client = Client(scheduler, timeout=10) if scheduler else Client(processes=False)
        except (OSError, TimeoutError, ValueError) as exc:
            raise RbmError(f"cannot reach the Dask scheduler {scheduler}: {exc}") from None
        try:
            with joblib.parallel_config(backend="dask"):
                par = joblib.Parallel(n_jobs=jobs, return_as="generator_unordered")
                yield from par(joblib.delayed(run_chunk)(config, c, ensemble) for c in chunks)
        finally:
            client.close()
        return
    par = joblib.Parallel(n_jobs=jobs, backend=backend, return_as="generator_unordered")
    yield from par(joblib.delayed(run_chunk)(config, c, ensemble) for c in chunks)


def domain_figure(df: pd.DataFrame, config: Config, compare=(), labels=None):
    """The domain PNG's figure (the CLI and run_sweep save it)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .column import build_column
    from .plot_domain import plot_domain

    column = build_column(config.column, config.interface)
    level, level_label = column.static_multiplier, "static multiplier"
    if config.model == "bullet":  # the engine's true solids: its own uplift level
        from .bullet import engine_uplift_g

        level, level_label = engine_uplift_g(config), "engine uplift level"
    fig, ax = plt.subplots(figsize=(9.5, 5))
    plot_domain(
        df,
        ax=ax,
        compare=compare,
        labels=labels,
        column=column,
        excitation_type=config.excitation.type,
        static_multiplier=level,
        static_label=level_label,
    )
    ax.set_title(f"{config.name}: safe (o) / unsafe (x) domain")
    fig.tight_layout()
    return fig
