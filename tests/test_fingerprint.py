"""The config's hash (rbm_cli.study.fingerprint): every setting in it under a schema number,
the method that runs in place of `auto`, and `rbm migrate`, which brings a domain stored by
rbm 0.1 (schema 1) to this version's hash once it has checked that it is the same domain.

tests/data/schema1/spanos_koh_thick_linear is a domain as rbm 0.1.0 stored it (copied
unchanged from its results/): the hash of its meta.json is recomputed here by schema 1's
rule as rbm 0.1 documented it (the SHA-256 of the resolved config as JSON with sorted
keys, solver.max_wall_time left out, solver.stop left out when `figures`, `auto` written
as DOP853), the oracle that it is a schema-1 domain and of the tampered ones below.
"""

from __future__ import annotations

import copy
import hashlib
import json
import shutil

import pytest
from click.testing import CliRunner

from rbm_cli.api import load_config, sweep
from rbm_cli.cli.main import cli
from rbm_cli.study.fingerprint import SCHEMA
from rbm_cli.study.sweep import config_hash

from .paths import CONFIGS, ROOT

NAME = "spanos_koh_thick_linear"
FIXTURE = ROOT / "tests" / "data" / "schema1" / NAME
FILES = ("domain.csv", "boundary.csv", "domain.png")


def schema1_digest(stored: dict) -> str:
    """rbm 0.1's hash of a config as its meta.json stores it (the module's docstring)."""
    form = copy.deepcopy(stored)
    solver = form["solver"]
    solver.pop("max_wall_time", None)
    if solver.get("stop") == "figures":
        del solver["stop"]
    if solver["method"] == "auto":
        solver["method"] = "DOP853"
    return hashlib.sha256(json.dumps(form, sort_keys=True).encode()).hexdigest()[:16]


def _stored(tmp_path):
    folder = tmp_path / "results" / NAME
    shutil.copytree(FIXTURE, folder)
    return folder


def _meta(folder) -> dict:
    return json.loads((folder / "meta.json").read_text())


def _write_meta(folder, meta: dict) -> None:
    (folder / "meta.json").write_text(json.dumps(meta, indent=2))


def _migrate(*folders):
    return CliRunner().invoke(cli, ["migrate", *map(str, folders)])


def test_the_fixture_is_a_schema1_domain():
    meta = _meta(FIXTURE)
    assert "schema" not in meta and meta["versions"]["rbm"] == "0.1.0"
    assert meta["config_hash"] == schema1_digest(meta["config"]) + "-ensemble16"


def test_a_schema1_domain_migrates_to_the_hash_of_its_config(tmp_path):
    folder = _stored(tmp_path)
    before = {name: (folder / name).read_bytes() for name in FILES}
    old = _meta(folder)["config_hash"]
    res = _migrate(folder)
    assert res.exit_code == 0, res.output
    assert len(res.output.strip().splitlines()) == 1 and "schema 1 -> 4" in res.output
    meta = _meta(folder)
    # the hash of the shipped config, as a sweep of it computes it today
    assert meta["config_hash"] == config_hash(load_config(CONFIGS / f"{NAME}.yaml")) + "-ensemble16"
    assert meta["schema"] == SCHEMA == 4 and meta["solver_method"] == "closed-form"
    assert meta["migrated"]["from_schema"] == 1 and meta["migrated"]["from_hash"] == old
    assert {name: (folder / name).read_bytes() for name in FILES} == before  # rows untouched
    text = (folder / "meta.json").read_bytes()
    again = _migrate(folder)
    assert again.exit_code == 0 and "nothing to do" in again.output
    assert (folder / "meta.json").read_bytes() == text


def test_resume_takes_a_schema1_domain_as_finished(tmp_path):
    folder = _stored(tmp_path)
    meta = (folder / "meta.json").read_bytes()
    res = CliRunner().invoke(
        cli,
        [
            "sweep",
            str(CONFIGS / f"{NAME}.yaml"),
            "-o",
            str(folder.parent),
            "--ensemble",
            "16",
            "--resume",
        ],  # fmt: skip
    )
    assert res.exit_code == 0, res.output
    assert "already finished" in res.output
    assert (folder / "meta.json").read_bytes() == meta
    assert sorted(p.name for p in folder.iterdir()) == sorted([*FILES, "meta.json"])


def _budget_row(folder, meta):
    lines = (folder / "domain.csv").read_text().splitlines(keepends=True)
    names = lines[0].rstrip("\n").split(",")
    row = lines[1].rstrip("\n").split(",")
    row[names.index("status")] = "failed"
    row[names.index("message")] = "event budget exceeded (200000 events; raise solver.max_events)"
    lines[1] = ",".join(row) + "\n"
    (folder / "domain.csv").write_text("".join(lines))
    meta["files"]["domain.csv"] = hashlib.sha256((folder / "domain.csv").read_bytes()).hexdigest()


def _changed_config(folder, meta):
    meta["config"]["solver"]["rtol"] = 1e-9


def _changed_file(folder, meta):
    with open(folder / "boundary.csv", "a") as handle:
        handle.write("\n")


def _changed_setting(folder, meta):
    meta["config_written"]["interface"]["restitution"] = 0.8


def _newer(folder, meta):
    meta["schema"] = SCHEMA + 1


@pytest.mark.parametrize(
    "tamper, says",
    [
        (_changed_config, "not the one its hash was taken of"),
        (_changed_file, "its boundary.csv is not the file meta.json names"),
        (_changed_setting, "a setting differs: interface.restitution"),
        (_budget_row, "1 cell(s) ran out of a step or event budget"),
        (_newer, f"stored under schema {SCHEMA + 1}: made by a newer rbm"),
    ],
)
def test_migrate_refuses_a_domain_it_cannot_vouch_for(tmp_path, tamper, says):
    folder = _stored(tmp_path)
    meta = _meta(folder)
    tamper(folder, meta)
    _write_meta(folder, meta)
    text = (folder / "meta.json").read_bytes()
    res = _migrate(folder)
    assert res.exit_code == 2
    assert says in res.output and len(res.output.strip().splitlines()) == 1, res.output
    assert "Traceback" not in res.output
    assert (folder / "meta.json").read_bytes() == text  # left as it was


def test_migrate_refuses_a_monolith_stored_when_auto_was_dop853(tmp_path):
    """A rigid monolith of model rbm stored by rbm 0.1 ran DOP853 (its `auto` then); this
    version's auto runs the rigid block's closed form on it: not the same domain."""
    folder = _stored(tmp_path)
    meta = _meta(folder)
    meta["config_written"]["model"] = "rbm"
    meta["config"]["model"] = "rbm"
    meta["config"]["solver"]["method"] = "DOP853"  # as rbm 0.1 wrote its default
    del meta["solver_method"]  # which rbm 0.1 wrote only where auto ran the closed form
    meta["config_hash"] = schema1_digest(meta["config"]) + "-ensemble16"
    _write_meta(folder, meta)
    res = _migrate(folder)
    assert res.exit_code == 2
    assert "its cells ran with DOP853; this config runs closed-form now" in res.output


def test_migrate_names_every_folder_it_refuses(tmp_path):
    good = _stored(tmp_path)
    res = _migrate(tmp_path / "nowhere", good)
    assert res.exit_code == 2
    assert "nowhere holds no finished domain (no meta.json)" in res.output
    assert _meta(good)["schema"] == SCHEMA  # the others are migrated


BLOCK = {"name": "b", "column": {"height": 2.0, "base_width": 0.5}}


def _hash(**extra):
    return config_hash(load_config({**copy.deepcopy(BLOCK), **extra}))


def test_every_setting_is_in_the_hash_and_a_default_written_is_the_default():
    plain = _hash()
    assert _hash(solver={"stop": "figures", "max_events": "auto"}) == plain
    assert _hash(solver={"max_events": 300_000}) != plain
    assert _hash(solver={"max_wall_time": 60.0}) == plain  # a guard, not a setting
    elastic = {"column": {"drums": 3, "height": 2.0, "base_width": 0.5}}
    stiff = {"stiffness": {"normal": 5e9}}
    undamped = _hash(**elastic, interface=stiff)
    assert _hash(**elastic, interface={**stiff, "damping": 0.0}) == undamped
    assert _hash(**elastic, interface={**stiff, "damping": 0.01}) != undamped


def test_the_hash_holds_the_method_that_runs():
    monolith = _hash()  # rigid, one drum: auto runs the rigid block's closed form
    assert monolith == _hash(solver={"method": "closed-form"})
    assert monolith != _hash(solver={"method": "DOP853"})
    drums = {"column": {"drums": 3, "height": 2.0, "base_width": 0.5},
             "interface": {"stiffness": {"normal": 5e9}}}  # fmt: skip
    assert _hash(**drums) == _hash(**drums, solver={"method": "DOP853"})


def test_a_sweep_stores_the_schema_and_the_method(tmp_path):
    cfg = load_config(
        {
            **BLOCK,
            "grid": {"amplitudes": [0.1, 0.4], "frequencies": [1.0]},
            "excitation": {"type": "harmonic", "duration": 1.0},
        }  # fmt: skip
    )
    sweep(cfg, output=tmp_path)
    meta = _meta(tmp_path / "b")
    assert meta["schema"] == SCHEMA and meta["solver_method"] == "closed-form"
    assert meta["config_hash"] == config_hash(cfg)


# ------------------------------------------------------------ schemas 2 and 3 -> 4

#: A domain stored by rbm 0.2.0 under schema 2 (its meta.json's config is that rbm's
#: resolved form), migrated to schema 3 and then to 4 in results/: made schema-2 or
#: schema-3 again here from the record of its migrations.
EARLIER = ROOT / "results" / NAME
#: The section each schema added to the resolved form (None where a config has none).
ADDED = {3: "uncertain", 4: "frame"}


def earlier_digest(meta: dict, schema: int) -> str:
    """Schema 2's or 3's hash of the config meta.json stores (rbm 0.2.0's resolved form,
    schema 2's): without solver.max_wall_time, the sections added up to the schema as None
    (the domain has none), the method that ran in place of the one written, under its
    number."""
    form = copy.deepcopy(meta["config"])
    form["solver"].pop("max_wall_time", None)
    form["solver"]["method"] = meta["solver_method"]
    for added, section in ADDED.items():
        assert section not in form
        if added <= schema:
            form[section] = None
    form["schema"] = schema
    return hashlib.sha256(json.dumps(form, sort_keys=True).encode()).hexdigest()[:16]


def _earlier(tmp_path, schema):
    folder = tmp_path / "results" / NAME
    shutil.copytree(EARLIER, folder)
    meta = _meta(folder)
    record = meta.pop("migrated")
    while record["from_schema"] != schema:
        record = record["before"]
    meta["schema"], meta["config_hash"] = schema, record["from_hash"]
    _write_meta(folder, meta)
    return folder


@pytest.mark.parametrize("schema", [2, 3])
def test_an_earlier_domain_holds_its_schemas_hash_of_its_config(tmp_path, schema):
    meta = _meta(_earlier(tmp_path, schema))
    assert meta["versions"]["rbm"] == "0.2.0"
    assert meta["config_hash"] == earlier_digest(meta, schema) + "-ensemble16"


@pytest.mark.parametrize("schema", [2, 3])
def test_an_earlier_domain_migrates_to_schema4_with_its_rows_untouched(tmp_path, schema):
    folder = _earlier(tmp_path, schema)
    before = {name: (folder / name).read_bytes() for name in FILES}
    old = _meta(folder)["config_hash"]
    res = _migrate(folder)
    assert res.exit_code == 0, res.output
    assert len(res.output.strip().splitlines()) == 1 and f"schema {schema} -> 4" in res.output
    meta = _meta(folder)
    assert meta["config_hash"] == config_hash(load_config(CONFIGS / f"{NAME}.yaml")) + "-ensemble16"
    assert meta["config_hash"] != old and meta["schema"] == SCHEMA == 4
    assert meta["migrated"]["from_schema"] == schema and meta["migrated"]["from_hash"] == old
    assert {name: (folder / name).read_bytes() for name in FILES} == before


@pytest.mark.parametrize("schema", [2, 3])
def test_resume_takes_an_earlier_domain_as_finished(tmp_path, schema):
    folder = _earlier(tmp_path, schema)
    meta = (folder / "meta.json").read_bytes()
    res = CliRunner().invoke(cli, ["sweep", str(CONFIGS / f"{NAME}.yaml"), "-o",
                                   str(folder.parent), "--ensemble", "16", "--resume"])  # fmt: skip
    assert res.exit_code == 0 and "already finished" in res.output, res.output
    assert (folder / "meta.json").read_bytes() == meta


@pytest.mark.parametrize(
    "tamper, says",
    [
        (_changed_file, "its boundary.csv is not the file meta.json names"),
        (_changed_setting, "not the schema-2 hash of the config it holds"),
    ],
)
def test_an_earlier_domain_that_is_not_its_config_is_refused(tmp_path, tamper, says):
    folder = _earlier(tmp_path, 2)
    meta = _meta(folder)
    tamper(folder, meta)
    _write_meta(folder, meta)
    text = (folder / "meta.json").read_bytes()
    res = _migrate(folder)
    assert res.exit_code == 2 and says in res.output, res.output
    assert len(res.output.strip().splitlines()) == 1
    assert (folder / "meta.json").read_bytes() == text
