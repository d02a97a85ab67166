"""The schema of domain.csv (rbm_cli.study.schema) and the registry of intensity measures
(rbm_cli.study.intensities): what `rbm sweep` writes is what the schema and the docs' table
of columns say, and a new measure is one registry entry.

The expected values are not the code's output: a measure defined in the test as twice the
PGA must come out as twice the domain's pga_g, which is the cell's amplitude for records
scaled to their PGA; and a lognormal fragility fitted by maximum likelihood on an intensity
twice the amplitude has twice the median and the same dispersion (the MLE is equivariant
under a change of scale of x).
"""

from __future__ import annotations

import io
import json
import os
import re
import shutil
import subprocess
import sys
import tokenize
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from click.testing import CliRunner

from rbm_cli.cli.main import cli
from rbm_cli.config.types import G
from rbm_cli.study import intensities, schema
from rbm_cli.study.domain import read_domain
from rbm_cli.study.intensities import IntensityMeasure, measure_of

from .paths import CONFIGS, ROOT, docs_extension

RECORDS = [CONFIGS / "records" / "synthetic" / f"rdk_0{k}.AT2" for k in (1, 2, 3)]


def _suite_config(tmp_path: Path, name: str = "suite", **excitation) -> Path:
    """A small record suite on Housner's linear block (3 records x 6 PGAs)."""
    cfg = {
        "name": name,
        "model": "housner-linear",
        "column": {"height": 2.0, "base_width": 0.5, "drums": 1},
        "excitation": {
            "type": "record",
            "file": [str(r) for r in RECORDS],
            "units": "g",
            "scale": "pga",
            "free_time": 2.0,
            **excitation,
        },  # fmt: skip
        "grid": {"amplitudes": {"start": 0.1, "stop": 0.6, "step": 0.1}},
    }
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(cfg))
    return path


def _sweep(tmp_path: Path, config: Path, *extra) -> Path:
    res = CliRunner().invoke(cli, ["sweep", str(config), "-o", str(tmp_path / "out"),
                                   "--jobs", "1", "--backend", "sequential", "--quiet",
                                   *extra])  # fmt: skip
    assert res.exit_code == 0, res.output
    return tmp_path / "out" / config.stem / "domain.csv"


def _reference():
    return docs_extension("rbm_reference")


def _check_dtypes(df: pd.DataFrame, text: str) -> None:
    """Each column's values are of the schema's dtype, as domain.csv's text holds them."""
    raw = pd.read_csv(io.StringIO(text), dtype=str, keep_default_na=False)
    for name in df.columns:
        if "." in name:  # an axis over a config key: the config's, not the schema's
            continue
        entry = schema.column(name)
        assert entry is not None, f"{name} is written but not in the schema"
        values = [v for v in raw[name] if v != ""]
        if entry.dtype == "float":
            [float(v) for v in values]
        elif entry.dtype == "int":
            assert all(v.lstrip("-").isdigit() for v in values), name
        elif entry.dtype == "0/1":
            assert set(values) <= {"0", "1"}, name


def test_written_columns_are_the_schemas_and_the_docs(tmp_path):
    """domain.csv's header, for an ensemble of a record suite with a spectral period, is the
    schema's columns in its order, each value of its dtype; the docs' table lists each
    column in the same order."""
    config = _suite_config(tmp_path, im_periods=[0.5])
    path = _sweep(tmp_path, config, "--ensemble", "2")
    text = path.read_text()
    header = text.splitlines()[0].split(",")
    assert header[:2] == ["excitation.file", "record"]  # the axis, then the record's name
    for must in ("amplitude_g", "pga_g", "sa_0p5s_g", "arias_m_s", "collapse_fraction",
                 "sensitive_to"):  # fmt: skip
        assert must in header
    assert "slides" not in header and "wobble_turns" not in header  # not this model's
    _check_dtypes(read_domain(path), text)
    # the docs' table: every written column (a period's Sa as its pattern), in order
    table = _reference().domain_columns_rst()
    rows = [line.split("``")[1] for line in table.splitlines() if line.startswith("   * - ``")]
    documented = [measure_of(h).column if measure_of(h) else h for h in header[1:]]
    assert [r for r in rows if r in documented] == documented
    assert rows[0] == "<path>"


@pytest.mark.may_skip(reason="sphinx and myst-parser come with the docs extra")
def test_outputs_page_shows_the_generated_table(tmp_path):
    """Defect: the page's table of columns showed as the literal text `.. list-table::` and
    a nested bullet list (the directive's reStructuredText was parsed as Markdown). The page,
    built alone by Sphinx with MyST and the site's directives, has the columns in a table."""
    pytest.importorskip("sphinx")
    pytest.importorskip("myst_parser")
    src = tmp_path / "src"
    src.mkdir()
    shutil.copy(ROOT / "docs" / "reference" / "outputs.md", src / "index.md")
    (src / "conf.py").write_text(
        f"import sys\nsys.path.insert(0, {str(ROOT / 'docs' / '_ext')!r})\n"
        "extensions = ['myst_parser', 'rbm_reference']\n"
        "myst_enable_extensions = ['dollarmath', 'amsmath', 'colon_fence', 'deflist']\n"
    )
    res = subprocess.run(
        [sys.executable, "-m", "sphinx", "-q", "-b", "html", str(src), str(tmp_path / "out")],
        capture_output=True, text=True, timeout=300, env={**os.environ, "MPLBACKEND": "Agg"},
    )  # fmt: skip
    assert res.returncode == 0, res.stderr
    html = (tmp_path / "out" / "index.html").read_text()
    assert "list-table::" not in html
    tables = re.findall(r"<table.*?</table>", html, re.S)
    for name in ("pga_over_g_tan_alpha", "t_collapse_s", "a_over_g_alpha", "sensitive_to"):
        assert any(name in t for t in tables), name


def test_a_new_measure_is_one_registry_entry(tmp_path, monkeypatch):
    """A measure added to the registry alone (here twice the PGA, in g) is written in
    domain.csv after the others, offered by `rbm fragility --intensity` and its help, typed
    when read, listed in the docs' table and fitted."""
    twice = IntensityMeasure("twice_pga_g", "twice the PGA", "g",
                             lambda t, a, period_s=None: 2.0 * float(np.max(np.abs(a))),
                             express=lambda value, column: value / G)  # fmt: skip
    monkeypatch.setattr(intensities, "MEASURES", intensities.MEASURES + (twice,))
    path = _sweep(tmp_path, _suite_config(tmp_path))
    df = read_domain(path)
    header = list(df.columns)
    assert header.index("twice_pga_g") == header.index("pgv_p_over_g_tan_alpha") + 1
    assert df["twice_pga_g"].dtype == np.float64
    np.testing.assert_allclose(df["twice_pga_g"], 2.0 * df["amplitude_g"], rtol=1e-12)
    assert "``twice_pga_g``" in _reference().domain_columns_rst()

    runner = CliRunner()
    helped = " ".join(runner.invoke(cli, ["fragility", "--help"]).output.split())
    assert "twice_pga_g" in helped
    fits = {}
    for intensity in (None, "twice_pga_g"):
        out = tmp_path / f"frag_{intensity}"
        args = ["fragility", str(path), "-o", str(out), "--resamples", "0"]
        res = runner.invoke(cli, args + (["--intensity", intensity] if intensity else []))
        assert res.exit_code == 0, res.output
        fits[intensity] = json.loads((out / "fragility.json").read_text())
    plain, doubled = fits[None], fits["twice_pga_g"]
    assert doubled["intensity_column"] == "twice_pga_g" and doubled["intensity_unit"] == "g"
    assert doubled["fitted"] and plain["fitted"]
    assert doubled["median_g"] == pytest.approx(2.0 * plain["median_g"], rel=1e-6)
    assert doubled["beta"] == pytest.approx(plain["beta"], rel=1e-6)


def test_a_measure_that_does_not_grow_with_the_scale_is_not_an_intensity(tmp_path):
    """The registry's scaling decides what a fragility may be fitted on: D5-95 and the
    column's period stay the same when the record is scaled, so --intensity refuses them."""
    for name in ("d5_95_s", "t1_s"):
        res = CliRunner().invoke(cli, ["fragility", str(tmp_path / "x.csv"), "--intensity",
                                       name])  # fmt: skip
        lines = [line for line in res.output.splitlines() if line.strip()]
        assert res.exit_code == 2 and len(lines) == 1 and "--intensity" in lines[0], res.output
        assert "Traceback" not in res.output


def test_figure_labels_are_the_schemas():
    from rbm_cli.report.domain_view import AMPLITUDE_LABEL, DIMENSIONLESS_LABELS
    from rbm_cli.report.fragility_run import intensity_label
    from rbm_cli.report.plot_domain import FRACTION_LABEL

    assert AMPLITUDE_LABEL == "amplitude [g]"
    assert DIMENSIONLESS_LABELS == (r"$\omega / p$ [-]", r"$A / (g \tan\alpha)$ [-]")
    assert FRACTION_LABEL.endswith("[-]") and "ensemble" in FRACTION_LABEL
    assert intensity_label("pgv_m_s") == "intensity: peak ground velocity PGV [m/s]"
    assert intensity_label("sa_0p5s_g") == "intensity: Sa(0.5 s, 5 %) [g]"
    assert intensity_label("arias_m_s").endswith("[m/s]")


#: String literals equal to a column's name that are not the column: the config keys of a
#: pulse (inputs/pulses.py) and of the synthetic records' model (inputs/rdk_model.py,
#: inputs/synthetic.py), an argument's name (structures/closed_forms.py), the fields of the
#: run loop's record (numerics/loop.py: RunEnd) and a line of `rbm run`'s text (cli/run.py).
#: Below study/, a module cannot read the schema.
NOT_COLUMNS = {"rbm_cli/inputs/pulses.py", "rbm_cli/inputs/rdk_model.py",
               "rbm_cli/inputs/synthetic.py", "rbm_cli/structures/closed_forms.py",
               "rbm_cli/numerics/loop.py", "rbm_cli/cli/run.py"}  # fmt: skip
#: Modules that name columns the schema reads from them: the uncertain keys' design names
#: its sample's columns (``sample``, ``uncertain.<key>``), as the grid names its axes'.
NAMES_COLUMNS = {"rbm_cli/config/uncertain.py"}
#: Names that are also words of another meaning (a status, an excitation's type): not
#: checked here.
WORDS = {"record", "status", "collapsed", "message", "robust"}


def test_column_names_are_typed_only_in_the_schema_and_the_registry():
    """No module of rbm_cli but the schema and the registry writes a column's name as a
    string: the others read it from the schema (schema.C) or the registry."""
    names = {c.name for c in schema.columns()} - WORDS
    found = []
    for path in sorted((ROOT / "rbm_cli").rglob("*.py")):
        rel = path.relative_to(ROOT).as_posix()
        if rel in NOT_COLUMNS | NAMES_COLUMNS | {
            "rbm_cli/study/schema.py",
            "rbm_cli/study/intensities.py",
        }:
            continue
        for tok in tokenize.generate_tokens(io.StringIO(path.read_text()).readline):
            if tok.type != tokenize.STRING:
                continue
            if tok.string[1:-1] in names and tok.string[0] == tok.string[-1] == '"':
                found.append(f"{rel}:{tok.start[0]}: {tok.string}")
            elif tok.string.startswith(("f", "rf", "fr")):  # a name inside an f-string
                for name in re.findall(r"\[['\"](\w+)['\"]\]", tok.string):
                    if name in names:
                        found.append(f"{rel}:{tok.start[0]}: {name} in an f-string")
    assert not found, "\n".join(found)
