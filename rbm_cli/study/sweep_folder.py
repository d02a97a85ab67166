"""The folder of a sweep before and after its cells run (over rbm_cli.study.store).

prepare_folder decides, from what the folder holds, what a new sweep may do with it:
finish the journal (resume), start one, or refuse; it never deletes a finished cell.
as_started keeps a resumed sweep on the method its journal was started with;
publish_result writes the result files and publishes them in one step.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import platform
import sys
from collections import Counter
from collections.abc import Callable
from importlib.metadata import version
from pathlib import Path

import numpy as np

from rbm_cli import __version__
from rbm_cli.base.errors import RbmError
from rbm_cli.base.files import json_ready
from rbm_cli.config.motions import named, storable
from rbm_cli.config.types import Config
from rbm_cli.study.cells import grid_points, key, max_drums
from rbm_cli.study.domain import boundary_table, csv_text, domain_frame
from rbm_cli.study.fingerprint import SCHEMA, hash_form, methods_that_run, same_domain
from rbm_cli.study.provenance import provenance
from rbm_cli.study.robustness import RULE as ROBUSTNESS_RULE
from rbm_cli.study.samples import majority_rows
from rbm_cli.study.schema import C, point_columns
from rbm_cli.study.store import FINALS, JOURNAL, STATE


def prepare_folder(store, config, points, cells, digest, ensemble, resume, force, note, command):
    """(rows, method): the finished rows to keep (resume), {} for a new sweep, None if the
    folder already holds this config's finished result and resume is asked; and on a
    resume the solver.method the journal was started with (None: not recorded). Refuses
    (RbmError) whatever would lose finished work."""
    folder = store.folder
    if store.journal.exists():
        grid = {key(c) for c in cells}
        read = store.read_journal(digest, grid, max_drums(points), ensemble,
                                  point_columns(config))  # fmt: skip
        ours = digest in read.hashes or store.state_hash() == digest
        n = len(read.rows) if ours else read.rejected  # rows of the other config
        if not read.rows and not read.rejected and (ours or not read.hashes):
            # it held no cell: start over
            store.start_journal(digest, len(cells), command, config.solver.method,
                                config.record_files())  # fmt: skip
            return {}, None
        changed = "" if ours else changed_records(read.records, config)
        whose = "of this config" if ours else "of another config"
        if changed:
            whose = f"started before {changed} changed"
        if not resume and not force:
            hint = "add --resume to finish it" if ours else "use another -o folder"
            raise RbmError(
                f"{folder} holds an unfinished sweep {whose} ({n} finished cells): {hint},"
                " or --force to set its journal aside (to superseded/) and start again"
            )
        if not resume or (not ours and read.hashes):
            if resume:
                if changed:
                    raise RbmError(
                        f"{store.journal}: {changed} changed since the sweep was started, so"
                        " its finished cells would mix two records: put the file back, or run"
                        " without --resume and with --force to set the journal aside"
                    )
                raise RbmError(
                    f"{store.journal} was made with a different config: use another -o folder,"
                    " or run without --resume and with --force to set it aside"
                )
            where = store.set_aside([JOURNAL, STATE])
            note(f"the unfinished journal ({n} finished cells) was moved to {where}")
        elif not ours:  # no hash anywhere: nothing in it can be trusted
            where = store.set_aside([JOURNAL, STATE])
            note(f"the journal held no row of this config; it was moved to {where}")
        else:
            if read.rejected:
                note(
                    f"{read.rejected} journal line(s) were not trusted and their cells run"
                    f" again (first: {read.first_problem})"
                )
            if store.state_hash() != digest:
                note("the state file was missing or unreadable: recovered from the journal")
                try:
                    store.write_state(digest, len(cells), command)
                except OSError as exc:
                    raise RbmError(
                        f"cannot write the sweep's state file in {folder}:"
                        f" {exc.strerror or exc}; the journal is kept: make room, then resume"
                    ) from None
            return dict(read.rows), read.solver_method
    else:
        finished = store.finished_hash()
        if finished not in (None, digest) and _same_domain(folder, config, digest):
            finished = digest  # stored under an earlier schema of the hash, the same domain
        if finished == digest and resume:
            return None, None
        if finished is not None and finished != digest:
            if not force:
                act = "nothing to resume" if resume else "it is kept"
                changed = changed_records(_finished_records(folder), config)
                whose = (
                    f"a finished domain made before {changed} changed"
                    if changed
                    else "the finished domain of another config"
                )
                raise RbmError(
                    f"{folder} holds {whose} ({act}): use"
                    " another -o folder, or --force (without --resume) to set it aside"
                    " (to superseded/) and run this config"
                )
            if resume:
                raise RbmError(
                    f"{folder} holds the finished domain of another config: nothing to resume"
                )
            where = store.set_aside(FINALS)
            note(f"the finished domain of another config was moved to {where}")
    store.start_journal(digest, len(cells), command, config.solver.method,
                        config.record_files())  # fmt: skip
    return {}, None


def changed_records(before, config: Config) -> str:
    """The record files of ``config`` whose content differs from ``before`` (a journal's or
    a finished domain's list of [key path, file, SHA-256]), named for a message ('' when
    none is known to differ)."""
    if not isinstance(before, list):
        return ""
    now = {(r[0], r[1]): r[2] for r in config.record_files()}
    names = []
    for entry in before:
        if not (isinstance(entry, list | tuple) and len(entry) == 3):
            continue
        key_path, written, digest = entry
        current = now.get((key_path, written))
        if current is not None and current != digest:
            names.append(f"{written} (SHA-256 {str(digest)[:12]}... then, {current[:12]}... now)")
    if not names:
        return ""
    shown = "; ".join(names[:3]) + (f"; and {len(names) - 3} more" if len(names) > 3 else "")
    return f"the record file {shown}" if len(names) == 1 else f"the record files {shown}"


def _finished_records(folder: Path) -> list | None:
    """The record files of the finished domain in ``folder`` (meta.json's config), or None."""
    try:
        config = json.loads((folder / "meta.json").read_text(encoding="utf-8"))["config"]
    except (OSError, ValueError, KeyError, TypeError):
        return None
    if not isinstance(config, dict):
        return None
    excitation, grid = config.get("excitation"), config.get("grid")
    out = []
    if isinstance(excitation, dict):
        for key in ("file", "vertical"):
            if excitation.get(key) is not None:
                out.append([f"excitation.{key}", excitation[key], excitation.get(f"{key}_sha256")])
    if isinstance(grid, dict) and isinstance(grid.get("records"), list):
        out += grid["records"]
    return out


def as_started(config, points, method: str | None, note) -> tuple:
    """(config, grid points) a resumed sweep runs: with the solver.method its journal was
    started with, where the config now spells the same hash another way (`auto` for
    `DOP853` or back, rbm_cli.study.fingerprint.hash_form). The cells still to do then run by
    the method the journal's cells ran by, and the domain is the one a straight run of
    the journal's config gives."""
    if method is None or method == config.solver.method:
        return config, points
    other = dataclasses.replace(config, solver=dataclasses.replace(config.solver, method=method))
    if hash_form(other) != hash_form(config):
        return config, points
    note(
        f"resumed with solver.method {method}, as its journal was started (the config says"
        f" {config.solver.method}): the same domain as a straight run of the journal's config"
    )
    return other, grid_points(other)


def publish_result(store, figure, config, rows, fields, meta, resume_command) -> None:
    """domain.png (the sweep's ``figure`` of the rows: :func:`draw_figure`), boundary.csv
    (of the samples' majority where the config has uncertain keys: rbm_cli.study.samples),
    domain.csv and meta.json (with the others' SHA-256), published in one step; a failure
    keeps the journal and says how to finish. The CSV files are written from the rows
    (dicts with the columns ``fields``), without pandas."""
    columns, lines = boundary_table(*majority_rows(rows, fields))
    texts = {
        "domain.csv": csv_text(rows, fields),
        "boundary.csv": csv_text(lines, columns),
    }

    def png(path: Path) -> None:
        drawn = draw_figure(figure, rows, fields, config)
        drawn.savefig(path, format="png", dpi=150, bbox_inches="tight")

    def text(name: str) -> Callable[[Path], None]:
        return lambda path: path.write_text(texts[name], encoding="utf-8")

    def meta_json(path: Path) -> None:
        meta["files"] = {
            name: hashlib.sha256((path.parent / name).read_bytes()).hexdigest()
            for name in FINALS
            if name != "meta.json"
        }
        path.write_text(json.dumps(json_ready(meta), indent=2, allow_nan=False) + "\n")

    writers = [("domain.png", png), ("boundary.csv", text("boundary.csv")),
               ("domain.csv", text("domain.csv")), ("meta.json", meta_json)]  # fmt: skip
    kept = f"every finished cell is kept in {store.journal}"
    try:
        store.publish(writers)
    except OSError as exc:
        raise RbmError(
            f"cannot write the result into {store.folder}: {exc.strerror or exc}; {kept}:"
            f" make room, then run {resume_command}"
        ) from None
    except (RbmError, KeyboardInterrupt):
        raise
    except Exception as exc:  # a plot that fails: the result is not published half
        reason = " ".join(str(exc).split())[:200]
        raise RbmError(
            f"cannot draw domain.png ({type(exc).__name__}: {reason}); {kept}, and {resume_command}"
            " publishes it once the cause is fixed"
        ) from None


def status_counts(rows: list[dict]) -> dict[str, int]:
    """meta.json's status_counts: cells per status, the most frequent first (ties in the
    order of their first row), as pandas' value_counts gives them."""
    counts = Counter(row[C.status] for row in rows if row.get(C.status) is not None)
    return dict(sorted(counts.items(), key=lambda item: -item[1]))


def draw_figure(figure, rows: list[dict], fields: tuple[str, ...], config: Config):
    """domain.png's figure (an object with savefig): ``figure.from_rows(rows, fields,
    config)`` where the figure takes the rows (the CLI's figure process, which builds the
    DataFrame in its own process: the sweep's process does not import pandas),
    else ``figure(DataFrame, config)`` with the DataFrame built here, now."""
    from_rows = getattr(figure, "from_rows", None)
    if from_rows is not None:
        return from_rows(rows, fields, config)
    return figure(domain_frame(rows, fields), config)


def _same_domain(folder: Path, config, digest: str) -> bool:
    """Whether the finished domain in ``folder`` is the one ``config`` gives under
    ``digest``, though meta.json holds another hash: stored under an earlier schema of the
    hash (rbm_cli.study.fingerprint.same_domain)."""
    try:
        meta = json.loads((folder / "meta.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(meta, dict) and same_domain(folder, meta, config, digest)


def _version(name: str) -> str:
    """A library's version without importing it here: its ``__version__`` if it is
    imported, else its installed distribution's (the same string; a sweep that ran in
    this process never imports joblib nor pandas, and its figure may be drawn in another
    process, rbm_cli.report.figure_process)."""
    module = sys.modules.get(name)
    if module is not None:
        return module.__version__
    return version(name)


def _versions() -> dict:
    # lazy: scipy loads only where needed (docs/architecture.md, Start-up)
    import scipy

    return {
        "rbm": __version__,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "pandas": _version("pandas"),
        "joblib": _version("joblib"),
        "matplotlib": _version("matplotlib"),
    }


def sweep_meta(
    config: Config, points: list, digest: str, n_cells: int, n_run: int, counts: dict,
    ensemble: int, folder: Path | None = None,
):  # fmt: skip
    """meta.json's record of a sweep (wall time, workers and compile time added after).
    ``config_dir``: the folder the config's relative paths (records) are taken from,
    relative to the result's ``folder``, so that the written config can be read again
    (rbm_cli.study.domain.domain_config) wherever the checkout lives."""
    where = None
    if config.base_dir is not None and folder is not None:
        where = Path(os.path.relpath(config.base_dir, Path(folder).resolve())).as_posix()
    return {
        "name": config.name,
        "config": named(config.resolved()),
        "config_written": storable(config.written),  # a motion given as arrays: its identity
        "config_dir": where,
        "schema": SCHEMA,
        "config_hash": digest,
        "solver_method": methods_that_run(config, points),
        "versions": _versions(),
        "wall_time_s": None,
        "jobs": None,
        "backend": None,
        "scheduler": None,
        "n_cells": n_cells,
        "n_run": n_run,
        "n_resumed": n_cells - n_run,
        "status_counts": counts,
        "ensemble": {"members": ensemble, "rule": ROBUSTNESS_RULE if ensemble > 1 else None},
        # the design of the uncertain keys (rbm_cli.config.uncertain): keys, distributions,
        # seed, samples and the values drawn, a row per sample
        "uncertain": None if config.uncertain is None else config.uncertain.design(),
        "provenance": provenance(),
        "cpu_count": os.cpu_count(),
    }
