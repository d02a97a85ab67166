"""tools/constants.py, the measurement of the numerical constants (docs/stability.md,
"Numerical constants"): its edits still find their constants in today's code, a copy
carries an edit and nothing else, its comparison counts what moved, and the table lists
every constant it measures. (The measurement itself compiles every integrator anew for each
variant, tens of minutes: it is run by hand.)"""

from __future__ import annotations

import importlib.util
import re
import sys

import pandas as pd
import pytest

from tests.paths import ROOT


@pytest.fixture(scope="module")
def tool():
    spec = importlib.util.spec_from_file_location("constants_tool", ROOT / "tools" / "constants.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)
    yield module
    sys.modules.pop(spec.name, None)


def test_every_edit_finds_its_constant_once(tool):
    """A variant whose text is not in the code once would measure the unchanged code (or
    change something else): each edit's text is in its file exactly once, and each variant
    runs on grids whose config and stored domain exist."""
    for name, variant in tool.VARIANTS.items():
        for rel, old, new in variant.edits:
            assert (ROOT / rel).read_text().count(old) == 1, (name, rel, old)
            assert old != new, (name, rel)
        assert variant.grids, name
        for grid in variant.grids:
            spec = tool.grid_spec(grid)  # a grid of the tool, or a stored study's
            if isinstance(spec.config, str):
                assert (ROOT / spec.config).is_file(), (name, grid)
            if spec.stored is not None:
                assert (ROOT / spec.stored).is_file(), (name, grid)


def test_a_copy_carries_its_edit_and_nothing_else(tool, tmp_path):
    edits = tool.VARIANTS["EVENT_EPS"].edits
    src = tool.make_copy(edits, tmp_path / "a")
    events = (src / "rbm_cli" / "base" / "events.py").read_text()
    assert "EVENT_EPS = 1e-14" in events and "EVENT_EPS = 1e-12" not in events
    for rel in ("rbm_cli/models/rbm/pieces.py", "rbm_cli/structures/arrays.py", "rbm/__init__.py"):
        assert (src / rel).read_text() == (ROOT / rel).read_text()
    assert not list(src.rglob("__pycache__"))  # nothing compiled comes along
    # an edit whose text is not in the code stops the variant, naming the file
    with pytest.raises(ValueError, match=r"rbm_cli/base/events\.py: .* found 0 times"):
        tool.make_copy((("rbm_cli/base/events.py", "EVENT_EPS = 2e-12", "x"),), tmp_path / "b")


def _domain(rows):
    cols = ["amplitude_g", "frequency_hz", "status", "collapsed", "t_collapse_s",
            "collapse_interface", "max_rotation_ratio", "max_top_displacement_m", "n_uplifts",
            "n_impacts", "n_steps"]  # fmt: skip
    return pd.DataFrame(rows, columns=cols)


def test_the_comparison_counts_what_moved(tool, tmp_path):
    """Five cells, built so that each kind of change shows once: a robust cell whose status
    flips, a collapse 1e-6 later at another interface, a peak 1e-3 higher with one impact
    more, an unchanged cell, and a chaotic cell (stored robust 0) that flips apart."""
    base = _domain([
        (0.1, 1.0, "survived", 0, None, None, 0.5, 0.1, 3, 4, 100),
        (0.2, 1.0, "collapsed", 1, 2.0, 1, 1.0, 0.3, 1, 0, 100),
        (0.3, 1.0, "survived", 0, None, None, 0.2, 0.05, 2, 10, 100),
        (0.4, 1.0, "survived", 0, None, None, 0.3, 0.07, 1, 1, 100),
        (0.5, 1.0, "survived", 0, None, None, 0.9, 0.2, 5, 5, 100),
    ])  # fmt: skip
    var = _domain([
        (0.1, 1.0, "collapsed", 1, 3.0, 2, 1.0, 0.3, 3, 4, 90),
        (0.2, 1.0, "collapsed", 1, 2.0 * (1 + 1e-6), 2, 1.0, 0.3, 1, 0, 90),
        (0.3, 1.0, "survived", 0, None, None, 0.2 * (1 + 1e-3), 0.05, 2, 11, 90),
        (0.4, 1.0, "survived", 0, None, None, 0.3, 0.07, 1, 1, 90),  # steps are not answers
        (0.5, 1.0, "collapsed", 1, 4.0, 1, 1.0, 0.4, 5, 5, 90),
    ])  # fmt: skip
    stored = pd.DataFrame({"amplitude_g": [0.1, 0.2, 0.3, 0.4, 0.5],
                           "frequency_hz": [1.0] * 5, "robust": [1, 1, 1, 1, 0]})  # fmt: skip
    for name, df in (("base", base), ("var", var), ("stored", stored)):
        df.to_csv(tmp_path / f"{name}.csv", index=False)
    res = tool.compare(tmp_path / "base.csv", tmp_path / "var.csv", str(tmp_path / "stored.csv"))
    robust, chaotic = res["robust"], res["chaotic"]
    assert robust["cells"] == 4 and robust["identical"] == 1
    assert robust["outcomes_differ"] == 1 and robust["which"][0]["amplitude_g"] == 0.1
    assert robust["collapsed"] == 1 and robust["interface_differs"] == 1
    assert robust["t_collapse_rel"] == pytest.approx(1e-6, rel=1e-6)
    assert robust["survived"] == 2
    assert robust["max_rotation_ratio_rel"] == pytest.approx(1e-3, rel=1e-9)
    assert robust["max_top_displacement_m_rel"] == 0.0
    assert robust["counts_differ"] == 1 and robust["counts_rel"] == pytest.approx(0.1)
    assert chaotic["cells"] == 1 and chaotic["outcomes_differ"] == 1


def test_the_comparison_refuses_grids_that_are_not_the_same(tool, tmp_path):
    row = (0.1, 1.0, "survived", 0, None, None, 0.5, 0.1, 3, 4, 100)
    _domain([row]).to_csv(tmp_path / "a.csv", index=False)
    _domain([row, (0.2, *row[1:])]).to_csv(tmp_path / "b.csv", index=False)
    with pytest.raises(RuntimeError, match="the grids differ"):
        tool.compare(tmp_path / "a.csv", tmp_path / "b.csv", None)


def test_the_table_lists_every_constant_measured(tool):
    """docs/stability.md's table has a row for every constant the tool measures, and the
    rows other parts of the program own (the 3D models' pinned lean, the budgets)."""
    text = (ROOT / "docs" / "stability.md").read_text()
    section = text[text.index("## Numerical constants") :]
    rows = [line for line in section.splitlines() if line.startswith("| ")]
    names = set()
    for variant in tool.VARIANTS.values():
        names.update(c for c in variant.constants if not c.startswith("("))
    for name in sorted(names) + ["UPRIGHT_LEAN", "max_steps", "max_events"]:
        short = re.sub(r"^(step|block|exact|housner|housner-3d|rbm-3d) ", "", name)
        assert any(f"`{short}`" in row for row in rows), name


# ------------------------------------------------------------------ the rest of a rigid block
RECORD_BLOCK = {
    "name": "record_block",
    "model": "rbm",
    "column": {"height": 4.0, "base_width": 1.0, "section": "rectangular", "depth": 1.0,
               "density": 2700, "drums": 1},
    "interface": {"stiffness": "rigid", "restitution": "housner"},
    "excitation": {"type": "record", "units": "g", "scale": "pga", "free_time": 5.0},
}  # fmt: skip


def _with_rest_rate(monkeypatch, rate):
    """REST_RATE set to rate wherever a model reads it (the module that defines it and the
    two that take it at import)."""
    import rbm_cli.models.block.closed_form as closed_form
    import rbm_cli.models.housner.runner as housner
    import rbm_cli.structures.arrays as arrays

    for module in (arrays, closed_form, housner):
        monkeypatch.setattr(module, "REST_RATE", rate)


@pytest.mark.parametrize("model", ["rbm", "housner"])
@pytest.mark.parametrize(
    ("record", "pga_g"),
    [("rdk_14", 0.3), ("rdk_01", 0.5), ("rdk_07", 0.8)],
)
def test_a_rigid_block_s_rest_does_not_move_its_answer(monkeypatch, model, record, pga_g):
    """A rigid block (H/B 4, Housner's e 0.91) under a record and 5 s of free motion: the
    answer at the rest rate (sqrt(200 EVENT_EPS) p theta_u) is the answer at 1e-5, 1/100
    of the former 1e-3, and at ten times the rate: the same outcome, the same uplifts, the
    same peak to 1e-9. Under rdk_14 at 0.3 g the former 1e-3 put the block to rest while
    the ground would still rock it (3 uplifts instead of 2, a peak 8 % low)."""
    import rbm
    import rbm_cli.structures.arrays as arrays

    path = str(ROOT / "configs" / "records" / "synthetic" / f"{record}.AT2")
    excitation = {**RECORD_BLOCK["excitation"], "file": path}
    cfg = rbm.load_config({**RECORD_BLOCK, "model": model, "excitation": excitation})
    rate = arrays.REST_RATE
    runs = {}
    for name, value in (("default", rate), ("1e-5", 1e-5), ("x10", 10.0 * rate)):
        _with_rest_rate(monkeypatch, value)
        runs[name] = rbm.run(cfg, amplitude_g=pga_g).result
    ref = runs["default"]
    assert ref["status"] in ("survived", "collapsed") and ref["n_uplifts"] >= 1
    for name in ("1e-5", "x10"):
        got = runs[name]
        assert (got["status"], got["n_uplifts"]) == (ref["status"], ref["n_uplifts"]), name
        assert got["max_rotation_ratio"] == pytest.approx(ref["max_rotation_ratio"], rel=1e-9)
