"""A config's fingerprint: the hash a domain is stored, resumed and compared under, and the
migration of a domain stored under an earlier form of it.

The hash (:func:`config_hash`) is taken of the config's resolved form
(rbm_cli.config.types.Config.resolved: every setting, defaults included), under the number
of its form, SCHEMA, which meta.json writes beside it, with two changes: the method that
runs each point of the grid in place of the method as written (``auto`` is the closed form
for one column and DOP853 for another: :func:`methods_that_run`), and without the settings
that never change a finished row (NOT_SETTINGS: solver.max_wall_time, a guard that fails a
run that would not end).

Schema 1 (rbm 0.1 and the domains stored before the schema was written) took the hash of a
form that left out the settings added after the first release where they had their
defaults (SCHEMA1_LEFT_OUT), solver.stop when it was ``figures``, and wrote ``auto`` as
DOP853; its step and event budgets were fixed numbers (SCHEMA1_BUDGETS), where ``auto``
now follows the column and the motion and is never less. A domain stored under it keeps
its rows (those of the rbm that made them; the regression rule compares them with this
version's): :func:`migrate` rewrites its meta.json with today's hash once it has checked
(:func:`schema1_problem`) that

- its meta.json is intact: the stored ``config`` is the config its hash was taken of, and
  its files are those meta.json names (SHA-256);
- the config, read again as this version reads it, has every setting the stored one has,
  and the default of every setting schema 1 left out;
- no cell ran out of a step or event budget (a larger budget would have taken it further);
- the method that ran is the one this version runs (meta.json's ``solver_method``; a domain
  that does not name it is refused where ``auto`` does not run DOP853 now).

Anything else is refused in one line, naming what differs: re-make the domain.

Schemas 2 and 3 took the hash of the same form as today's before the config had the
sections a later schema added (ADDED_BY): schema 3 added ``uncertain``
(rbm_cli.config.uncertain), schema 4 ``frame`` (columns under a beam,
rbm_cli.config.types.FrameConfig); each is None in the resolved form of a config without
it, so adding it changed every config's hash and nothing else. A domain stored under
schema 2 or 3 has none of the sections added after it, so its rows stand: :func:`migrate`
rewrites its meta.json with today's hash once its files are those meta.json names and its
hash is the hash its schema took (:func:`earlier_hash`) of the config read back from it,
as this version reads it.
"""

from __future__ import annotations

import copy
import csv
import dataclasses
import hashlib
import json
from pathlib import Path

from rbm_cli import __version__
from rbm_cli.base.errors import ConfigError, RbmError
from rbm_cli.base.files import json_ready, write_text_atomic
from rbm_cli.config.motions import named
from rbm_cli.config.types import MODELS, ONLY_FOR, STEP_DEFAULT, Config
from rbm_cli.models.methods import resolve_method
from rbm_cli.study.cells import grid_points
from rbm_cli.study.domain import domain_config
from rbm_cli.study.schema import C
from rbm_cli.study.store import JOURNAL

#: The form of the config hash (written as meta.json's ``schema``).
SCHEMA = 4
#: The section of the resolved config each schema added (schema -> section): a config of an
#: earlier schema had none (None in today's form).
ADDED_BY = {3: "uncertain", 4: "frame"}
#: Settings left out of the hash: they fail a run, never change a finished one.
NOT_SETTINGS = (("solver", "max_wall_time"),)
#: Settings schema 1 left out of its hash where they had these (default) values: they came
#: after the first release. Key paths of the resolved config, values as JSON gives them.
SCHEMA1_LEFT_OUT = {
    ("column", "capital"): None,
    ("column", "top_mass"): None,
    ("interface", "friction_limit"): None,
    ("interface", "damping"): 0.0,
    ("grid", "axes"): [],
    ("grid", "records"): [],
    ("dimensions",): 2,
    ("solver", "stop"): "figures",
    ("excitation", "vertical"): None,
    ("excitation", "vertical_sha256"): None,
    ("excitation", "file_y"): None,
    ("excitation", "file_y_sha256"): None,
    ("excitation", "processing"): None,
    ("excitation", "im_periods"): [],
    ("excitation", "angle"): 0.0,
    ("excitation", "y"): None,
    ("excitation", "initial", "rotations_across"): [],
    ("excitation", "initial", "velocities_across"): [],
    ("uncertain",): None,
    ("frame",): None,
}
#: Schema 1's step and event budgets of one run (fixed then; ``auto`` now, never less).
SCHEMA1_BUDGETS = {"max_steps": 2_000_000, "max_events": 200_000}
#: A row that ran out of a budget says so in its message (rbm_cli.models.outcome).
_BUDGET_WORDS = ("step budget exceeded", "event budget exceeded")


def _plain(data):
    """JSON's form of data (tuples as lists), as meta.json holds it."""
    return json.loads(json.dumps(data, default=str))


def _digest(form: dict) -> str:
    return hashlib.sha256(json.dumps(form, sort_keys=True, default=str).encode()).hexdigest()[:16]


def methods_that_run(config: Config, points: list | None = None) -> str:
    """The method(s) the cells of a config run with: solver.method with ``auto`` resolved at
    each point of the grid (rbm_cli.models.methods.resolve_method), e.g. 'closed-form' or
    'closed-form, DOP853' when the points differ; the method as written where it does not
    apply (the sweep refuses it, in one line). The points take the config's solver, unless
    an axis of the grid is over one of its keys. ``points``: the config's grid points
    where the caller has them (rbm_cli.study.cells.grid_points), else expanded here."""
    own = not any(path.startswith("solver.") for path in config.grid.axis_paths)
    try:
        return ", ".join(
            dict.fromkeys(
                resolve_method(
                    dataclasses.replace(p.config, solver=config.solver) if own else p.config
                )  # fmt: skip
                for p in (grid_points(config) if points is None else points)
            )
        )
    except (RbmError, ConfigError):
        return config.solver.method


def hash_form(config: Config, points: list | None = None) -> dict:
    """What a config's hash is taken of: its resolved form with the methods that run
    (:func:`methods_that_run`; ``points`` its grid points, if the caller has them), without
    NOT_SETTINGS, and the SCHEMA."""
    form = config.resolved()
    for section, key in NOT_SETTINGS:
        form[section].pop(key, None)
    form["solver"]["method"] = methods_that_run(config, points)
    form["schema"] = SCHEMA
    return form


def config_hash(config: Config, points: list | None = None) -> str:
    """Fingerprint of everything that changes a domain (:func:`hash_form`), 16 hex digits."""
    return _digest(hash_form(config, points))


def earlier_hash(config: Config, schema: int, points: list | None = None) -> str | None:
    """The hash schema 2 or 3 took of a config (the module's docstring): today's form
    without the sections added after ``schema``, under its number; None for a config that
    has one of them, which that schema could not hold."""
    later = [section for added, section in ADDED_BY.items() if added > schema]
    if any(getattr(config, section) is not None for section in later):
        return None
    form = hash_form(config, points)
    for section in later:
        form.pop(section, None)
    form["schema"] = schema
    return _digest(form)


def _files_problem(folder: Path, meta: dict) -> str | None:
    """Which file of a domain is not the one its meta.json names (SHA-256), or None."""
    for name, sha in (meta.get("files") or {}).items():
        path = folder / name
        if not path.is_file() or hashlib.sha256(path.read_bytes()).hexdigest() != sha:
            return f"its {name} is not the file meta.json names"
    return None


def earlier_problem(folder: Path, meta: dict, config: Config) -> str | None:
    """Why the domain in ``folder``, stored under schema 2 or 3 with this ``meta``, is not
    the domain ``config`` gives today, or None."""
    problem = _files_problem(folder, meta)
    if problem:
        return problem
    schema = meta["schema"]
    stored = str(meta.get("config_hash", ""))[:16]
    if earlier_hash(config, schema) != stored:
        return f"its config hash is not the schema-{schema} hash of the config it holds"
    return None


def schema1_hash(stored: dict) -> str:
    """The schema-1 hash of a config as meta.json stored it (its ``config``): what rbm 0.1
    took it of (the module's docstring)."""
    form = copy.deepcopy(stored)
    solver = form.get("solver", {})
    solver.pop("max_wall_time", None)
    if solver.get("stop") == "figures":
        solver.pop("stop")
    if solver.get("method") == "auto":
        solver["method"] = STEP_DEFAULT
    return _digest(form)


def _setting_difference(stored: dict, current: dict, config: Config) -> str | None:
    """The first setting where a schema-1 config (``stored``) and today's resolved form of
    the same config differ, as 'key: stored value against today's', or None."""
    excitation_type = config.excitation.type
    always_3d = MODELS[config.model].three_d

    def left_out(path, value):
        if path == ("dimensions",) and always_3d:
            return value == 3  # a model in three dimensions: schema 1 wrote none
        return path in SCHEMA1_LEFT_OUT and SCHEMA1_LEFT_OUT[path] == value

    def walk(a, b, path):
        if isinstance(b, dict) and isinstance(a, dict):
            for key in b:
                here = (*path, key)
                if key in a:
                    found = walk(a[key], b[key], here)
                elif here in NOT_SETTINGS or left_out(here, b[key]):
                    found = None
                else:
                    found = f"{'.'.join(here)} (not in the stored config; {b[key]!r} now)"
                if found:
                    return found
            for key in a:
                here = (*path, key)
                of = key.removesuffix("_sha256")
                if key not in b and not (
                    path == ("excitation",) and of in ONLY_FOR
                    and excitation_type not in ONLY_FOR[of]
                ):  # fmt: skip
                    return f"{'.'.join(here)} (stored {a[key]!r}; not a setting now)"
            return None
        if path == ("solver", "method"):
            return None  # the method that ran is compared (schema1_problem)
        if path[:1] == ("solver",) and path[1:] and path[1] in SCHEMA1_BUDGETS and b is None:
            same = a is None or a == SCHEMA1_BUDGETS[path[1]]  # auto then, or the fixed one
            return None if same else f"{'.'.join(path)} (stored {a!r})"
        return None if a == b else f"{'.'.join(path)} (stored {a!r}, {b!r} now)"

    return walk(stored, current, ())


def _budget_rows(domain_csv: Path) -> int:
    """How many rows of a domain.csv ran out of a step or event budget."""
    with open(domain_csv, newline="", encoding="utf-8") as handle:
        return sum(
            1
            for row in csv.DictReader(handle)
            if row.get(C.status) == "failed"
            and any(word in (row.get(C.message) or "") for word in _BUDGET_WORDS)
        )


def schema1_problem(folder: Path, meta: dict, config: Config) -> str | None:
    """Why the domain in ``folder``, stored under schema 1 with this ``meta`` (meta.json),
    is not the domain ``config`` gives today (the module's checks), or None."""
    stored = meta.get("config")
    digest = str(meta.get("config_hash", "")).split("-")[0]
    if not isinstance(stored, dict) or schema1_hash(stored) != digest:
        return "its meta.json's config is not the one its hash was taken of"
    problem = _files_problem(folder, meta)
    if problem:
        return problem
    current = _plain(named(config.resolved()))
    differs = _setting_difference(stored, current, config)
    if differs:
        return f"a setting differs: {differs}"
    ran_out = _budget_rows(folder / "domain.csv")
    if ran_out:
        return f"{ran_out} cell(s) ran out of a step or event budget, which now follows the run"
    now = methods_that_run(config)
    ran = meta.get("solver_method")
    written = stored["solver"].get("method", "auto")
    if ran is None and written != "auto":  # the method as written then, as it runs now
        solver = dataclasses.replace(config.solver, method=written)
        ran = methods_that_run(dataclasses.replace(config, solver=solver))
    if ran is None and now != STEP_DEFAULT:
        return f"meta.json does not say which method ran; auto runs {now} now"
    if ran is not None and ran != now:
        return f"its cells ran with {ran}; this config runs {now} now"
    return None


def read_meta(folder: Path) -> dict:
    """The meta.json of the finished domain in ``folder``, a dict; RbmError in one line
    when there is none or it is not a JSON object."""
    path = folder / "meta.json"
    try:
        meta = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise RbmError(f"{folder} holds no finished domain (no meta.json)") from None
    except (OSError, ValueError) as exc:
        raise RbmError(f"cannot read {path}: {' '.join(str(exc).split())}") from None
    if not isinstance(meta, dict):
        raise RbmError(f"{path} is not a domain's meta.json (not a JSON object)")
    return meta


def same_domain(folder: Path, meta: dict, config: Config, digest: str) -> bool:
    """Whether the finished domain in ``folder`` (its ``meta``) is the one ``config`` gives
    under ``digest`` (its hash, with the ensemble's suffix): the same hash under this
    schema, or a domain of an earlier schema that :func:`migrate` would take."""
    schema = meta.get("schema", 1)
    if schema == SCHEMA:
        return meta.get("config_hash") == digest
    if schema in (2, 3):
        stored = str(meta.get("config_hash", ""))
        return _suffix(stored) == _suffix(digest) and stored[:16] == earlier_hash(config, schema)
    if schema != 1 or _suffix(str(meta.get("config_hash", ""))) != _suffix(digest):
        return False
    try:
        return schema1_problem(folder, meta, config) is None
    except OSError:
        return False


def _suffix(digest: str) -> str:
    return digest[16:]  # '-ensembleK' or ''


def migrate(folder: str | Path) -> str:
    """Rewrite the meta.json of a domain stored under schema 1, 2 or 3 with today's hash and
    schema, once the module's checks hold; its other files are not touched. Returns a
    one-line note; RbmError (one line) when it cannot or need not be done."""
    folder = Path(folder)
    meta = read_meta(folder)
    schema = meta.get("schema", 1)
    if schema == SCHEMA:
        return f"{folder}: already stored under schema {SCHEMA}, nothing to do"
    if schema not in (1, 2, 3):
        raise RbmError(f"{folder} was stored under schema {schema!r}: made by a newer rbm")
    if (folder / JOURNAL).exists() or not (folder / "domain.csv").is_file():
        raise RbmError(f"{folder} holds no finished domain: finish it with the rbm that started it")
    config = domain_config(folder / "domain.csv")
    if config is None:
        raise RbmError(f"{folder}: its meta.json holds no config this rbm can read")
    check = schema1_problem if schema == 1 else earlier_problem
    problem = check(folder, meta, config)
    if problem:
        raise RbmError(f"cannot migrate {folder}: {problem}; re-make it")
    old = meta["config_hash"]
    meta["config_hash"] = config_hash(config) + _suffix(str(old))
    meta["schema"] = SCHEMA
    if schema == 1:
        meta["solver_method"] = methods_that_run(config)
    earlier = meta.get("migrated")
    meta["migrated"] = {"from_schema": schema, "from_hash": old, "rbm": __version__}
    if isinstance(earlier, dict):
        meta["migrated"]["before"] = earlier
    text = json.dumps(json_ready(meta), indent=2, allow_nan=False) + "\n"
    write_text_atomic(folder / "meta.json", text)
    return f"{folder}: schema {schema} -> {SCHEMA}, hash {old} -> {meta['config_hash']}"
