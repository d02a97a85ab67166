"""`rbm bench`: the quick benchmark against the stored references (CI), and the
error bookkeeping on hand-made frames (so the scoring itself can fail)."""

from __future__ import annotations

import pandas as pd
import pytest
from click.testing import CliRunner

from rbm_cli.cli.main import cli
from rbm_cli.study.bench import PEAK_TARGET, check_targets, errors


def frame(rows):
    df = pd.DataFrame(rows, columns=["amplitude_g", "frequency_hz", "collapsed",
                                     "t_collapse_s", "max_rotation_ratio"])  # fmt: skip
    df["status"] = ["collapsed" if c else "survived" for c in df["collapsed"]]
    return df


def reference(rows, converged, peak_converged):
    ref = frame(rows)
    ref["converged"] = converged
    ref["peak_converged"] = peak_converged
    return ref


def test_errors_count_only_converged_cells_and_well_conditioned_peaks():
    ref = reference(
        [(0.1, 1.0, 0, None, 0.5), (0.2, 1.0, 1, 2.0, 1.0), (0.3, 1.0, 1, 1.0, 1.0),
         (0.1, 2.0, 0, None, 0.2), (0.2, 2.0, 0, None, 0.4)],
        converged=[1, 1, 1, 1, 0], peak_converged=[1, 0, 0, 0, 0],
    )  # fmt: skip
    run = frame([(0.1, 1.0, 0, None, 0.5005), (0.2, 1.0, 0, None, 0.9), (0.3, 1.0, 1, 1.1, 1.0),
                 (0.1, 2.0, 0, None, 0.3), (0.2, 2.0, 1, 3.0, 1.0)])  # fmt: skip
    e = errors(run, ref)
    assert e["n_converged"] == 4 and e["n_sensitive"] == 1
    assert e["cells_differ"] == 1  # (0.2, 1.0); the sensitive (0.2, 2.0) is not scored
    assert e["n_peak"] == 1 and abs(e["peak_err_max"] - 1e-3) < 1e-12  # (0.1, 2.0) not scored
    assert e["n_tcol"] == 1 and abs(e["tcol_err_max"] - 0.1) < 1e-12
    assert abs(e["boundary_err_g"] - 0.1) < 1e-12  # 1 Hz boundary 0.2 -> 0.3 g


def test_targets_fail_when_the_default_misses_them():
    good = {"problem": "slender", "default": 1, "fraction_differ": 0.0, "cells_differ": 0,
            "n_converged": 1600, "n_peak": 10, "peak_err_max": 1e-6}  # fmt: skip
    assert check_targets(pd.DataFrame([good])) == []
    many = dict(good, fraction_differ=0.01, cells_differ=16)
    assert "cells differ" in check_targets(pd.DataFrame([many]))[0]
    peak = dict(good, peak_err_max=2 * PEAK_TARGET)
    assert "peak rotation" in check_targets(pd.DataFrame([peak]))[0]
    other = dict(many, default=0)  # only the default method is held to the targets
    assert check_targets(pd.DataFrame([other])) == []


@pytest.mark.slow  # the four problems by every method against their references
def test_quick_bench_meets_the_accuracy_targets(tmp_path):
    res = CliRunner().invoke(cli, ["bench", "--quick", "-o", str(tmp_path)])
    assert res.exit_code == 0, res.output
    table = pd.read_csv(tmp_path / "bench.csv")
    assert set(table["problem"]) == {"slender", "tapered", "multidrum", "halfsine"}
    default = table[table["default"] == 1]
    assert len(default) == 4 and (default["n_converged"] > 0).all()
    assert (table["implementation"] == "baseline").sum() == 4
    # both methods on every problem: the exact integrator agrees with the references
    exact = table[table["method"] == "exact"]
    assert len(exact) == 4 and (exact["n_converged"] > 0).all()
    assert (exact["cells_differ"] == 0).all() and (exact["n_failed"] == 0).all()
    assert (exact["peak_err_max"].fillna(0.0) < PEAK_TARGET).all()
    assert (tmp_path / "bench.png").stat().st_size > 0


def test_quick_bench_without_references_is_a_one_line_error(tmp_path):
    res = CliRunner().invoke(cli, ["bench", "--quick", "-o", str(tmp_path / "o"),
                                   "--references", str(tmp_path / "none")])  # fmt: skip
    assert res.exit_code == 2
    assert res.output.strip().startswith("Error:") and "reference" in res.output
    assert len(res.output.strip().splitlines()) == 1


def test_reference_flags_follow_tolerance_nudge_and_event_counts(monkeypatch):
    """make_reference on hand-made runs (rtol 1e-10, 1e-11, 1e-12, then the 1e-9
    amplitude nudge at 1e-12, then the 15 other members of the robustness rule): a
    cell is converged only if its outcome is the same in all four and it is robust
    (every member agrees); a peak is scored only if it is converged, 1e-11, 1e-12
    and the nudge agree to 1e-6, and those three count the same uplifts and impacts."""
    import rbm_cli.study.bench as bench
    from rbm_cli.study.bench_runs import _row

    cells = [(0.1, 1.0), (0.2, 1.0), (0.3, 1.0), (0.4, 1.0), (0.5, 1.0), (0.6, 1.0)]
    # per cell: (collapsed, peak, uplifts) at 1e-10, 1e-11, 1e-12 and nudged
    plan = {
        (0.1, 1.0): [(0, 0.5, 3), (0, 0.5, 3), (0, 0.5, 3), (0, 0.5, 3)],  # all agree
        (0.2, 1.0): [(0, 0.5, 3), (0, 0.5, 3), (0, 0.5, 3), (1, 1.0, 3)],  # nudge flips
        (0.3, 1.0): [(1, 0.5, 3), (0, 0.5, 3), (0, 0.5, 3), (0, 0.5, 3)],  # 1e-10 flips
        (0.4, 1.0): [(0, 0.5, 3), (0, 0.5, 5), (0, 0.5, 3), (0, 0.5, 3)],  # events part
        (0.5, 1.0): [(0, 0.5, 3), (0, 0.5, 3), (0, 0.5, 3), (0, 0.501, 3)],  # peak moves
        (0.6, 1.0): [(0, 0.5, 3)] * 4,  # all agree; one member of the rule flips (below)
    }
    flipping_member = 9  # call 4 + 9: the rule's member 10
    calls = []

    def fake_run_cells(kind, cfg, run_cells, jobs, budget_s=120.0):
        k = len(calls)
        calls.append(kind)
        rows = []
        for a, f in run_cells:
            if k >= 4:  # a member of the robustness rule: as at 1e-12, but one flips
                c, p, u = plan[(round(a, 4), f)][2]
                c = 1 - c if (k - 4 == flipping_member and round(a, 4) == 0.6) else c
            else:
                c, p, u = plan[(round(a, 6), f)][k]
            row = _row(a, f, "collapsed" if c else "survived", float("nan"), p, 0.0)
            rows.append(dict(row, n_uplifts=u, n_impacts=u))
        return pd.DataFrame(rows), 0.0

    monkeypatch.setattr(bench, "bench_cells", lambda cfg: cells)
    monkeypatch.setattr(bench, "_with_solver", lambda cfg, *a: cfg)
    monkeypatch.setattr(bench, "run_cells", fake_run_cells)
    monkeypatch.setattr(bench, "member_config", lambda cfg, a, m: (cfg, a))
    problem = next(p for p in bench.PROBLEMS if p.name == "multidrum")
    ref = bench.make_reference(problem, None, 1)
    assert calls == ["rbm"] * (4 + 15)
    assert ref["robust"].tolist() == [1, 1, 1, 1, 1, 0]
    assert ref["converged"].tolist() == [1, 0, 0, 1, 1, 0]
    assert ref["peak_converged"].tolist() == [1, 0, 0, 0, 0, 0]
