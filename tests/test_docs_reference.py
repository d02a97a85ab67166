"""The site's reference pages (docs/_ext/rbm_reference.py) are generated from the code: every
option of every command and every key the config loader accepts appears in them, with the
default the code has, and the generated text is valid reStructuredText."""

from __future__ import annotations

import dataclasses

import click
import pytest

from .paths import docs_extension


@pytest.fixture(scope="module")
def ref():
    return docs_extension("rbm_reference")


def _parses_cleanly(text: str) -> None:
    """docutils reads the text without a warning (list-tables, literal blocks, escapes)."""
    from docutils.core import publish_doctree
    from docutils.utils import Reporter

    messages = []
    doctree = publish_doctree(
        text,
        settings_overrides={"report_level": Reporter.WARNING_LEVEL, "halt_level": 5,
                            "warning_stream": False},
    )  # fmt: skip
    for node in doctree.findall():
        if node.tagname == "system_message" and node["level"] >= Reporter.WARNING_LEVEL:
            messages.append(node.astext())
    assert not messages, messages


def test_every_command_and_option_is_in_the_cli_reference(ref):
    from rbm_cli.cli.main import cli

    text = ref.cli_rst()
    ctx = click.Context(cli, info_name="rbm")
    names = cli.list_commands(ctx)
    assert {"run", "sweep", "info", "plot-domain", "compare", "fragility", "bench"} <= set(names)
    for name in names:
        cmd = cli.get_command(ctx, name)
        assert f"\nrbm {name}\n" in text, name
        for param in cmd.params:
            if isinstance(param, click.Argument):
                assert param.make_metavar(click.Context(cmd)) in text, (name, param.name)
                continue
            for flag in [*param.opts, *param.secondary_opts]:
                assert f"``{flag}" in text, (name, flag)
            if param.help:
                assert ref.esc(param.help)[:40] in text, (name, param.name)


def test_every_config_key_is_in_the_config_reference(ref):
    from rbm_cli.config.excitation import EXCITATION_KEYS, INITIAL_KEYS
    from rbm_cli.config.grid import EXCITATION_AXES, LINKED, VIRTUAL_PATHS
    from rbm_cli.config.interface import INTERFACE_KEYS, STIFFNESS_KEYS
    from rbm_cli.config.load import COLLAPSE_KEYS, COLUMN_KEYS, FRAME_KEYS, SOLVER_KEYS, TOP_KEYS

    text = ref.config_rst()
    expected = {"name", "model"}
    for section, keys in (("column", COLUMN_KEYS), ("interface", INTERFACE_KEYS),
                          ("excitation", EXCITATION_KEYS), ("collapse", COLLAPSE_KEYS),
                          ("solver", SOLVER_KEYS), ("frame", FRAME_KEYS)):  # fmt: skip
        expected |= {f"{section}.{k}" for k in keys}
    expected |= {f"interface.stiffness.{k}" for k in STIFFNESS_KEYS}
    expected |= {f"excitation.initial.{k}" for k in INITIAL_KEYS}
    expected |= {f"grid.{k}" for k in (*EXCITATION_AXES, LINKED, *VIRTUAL_PATHS)}
    expected |= {"uncertain.samples", "uncertain.seed", "uncertain.keys.<key path>"}
    assert set(TOP_KEYS) <= {k.split(".")[0] for k in expected} | {"grid"}
    for key in sorted(expected):
        assert f"``{key}``" in text, key


def test_the_config_reference_states_the_codes_defaults(ref):
    from rbm_cli.config import types as t

    text = ref.config_rst()
    rows = {}
    for block in text.split("   * - ")[1:]:
        cells = [c.strip() for c in block.split("\n     - ")]
        rows[cells[0].strip("`")] = cells
    for prefix, cls in (("solver", t.SolverConfig), ("interface", t.InterfaceConfig),
                        ("collapse", t.CollapseConfig), ("column", t.ColumnConfig)):  # fmt: skip
        for f in dataclasses.fields(cls):
            key = f"{prefix}.{f.name}"
            if key not in rows or f.default in (dataclasses.MISSING, None, ()):
                continue
            if isinstance(f.default, float):
                assert rows[key][2] == f"``{f.default:g}``", key
            elif isinstance(f.default, str):
                assert rows[key][2] == f"``{f.default}``", key
    assert rows["solver.method"][2] == "``auto``"
    assert rows["column.density"][2] == "``2700``"


def test_a_key_without_a_description_stops_the_build(ref, monkeypatch):
    monkeypatch.delitem(ref.KEY_DOCS, "column.density")
    with pytest.raises(ValueError, match="column.density"):
        ref.config_rst()


@pytest.mark.may_skip(reason="docutils comes with the docs extra (pip install -e '.[docs]')")
def test_the_generated_reference_is_valid_restructuredtext(ref):
    pytest.importorskip("docutils")
    _parses_cleanly(ref.cli_rst())
    _parses_cleanly(ref.config_rst())
