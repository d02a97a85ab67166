"""The boundary of an ensemble domain is the majority's (a cell counts as collapsed where
collapse_fraction >= 0.5; a cell whose members all failed counts as neither side), with
member 0's own boundary kept beside it: boundary.csv's member0_* columns and a second line
in domain.png and `rbm plot-domain`, the legend saying which is which. A domain without an
ensemble keeps its boundary.csv as it was."""

from __future__ import annotations

import csv
import hashlib
import io
import json
import math

import matplotlib

matplotlib.use("Agg")

import pandas as pd  # noqa: E402
import pytest  # noqa: E402
import yaml  # noqa: E402
from click.testing import CliRunner  # noqa: E402

import rbm  # noqa: E402
import rbm_cli.base.files  # noqa: E402
from rbm_cli.api import run_sweep  # noqa: E402
from rbm_cli.cli.main import cli  # noqa: E402
from rbm_cli.config.load import load_config  # noqa: E402
from rbm_cli.report.domain_figure import domain_figure  # noqa: E402
from rbm_cli.study.domain import boundary, boundary_table, csv_text  # noqa: E402

from .paths import CONFIGS, RESULTS  # noqa: E402

NAN = math.nan
#: Members of the hand-made ensemble (fractions in sixteenths).
K = 16
#: Cells by hand: frequency [Hz] -> (amplitude [g], member 0's status, collapse fraction).
CELLS = {
    # member 0 survives everywhere, but 15 of 16 members collapse from 0.3 g
    1.0: [(0.1, "survived", 0.0), (0.2, "survived", 0.0), (0.3, "survived", 15 / K),
          (0.4, "survived", 15 / K), (0.5, "survived", 15 / K)],
    # member 0 collapses from 0.2 g where 1 of 16 members does; 8 of 16 (a tie) at 0.4 g
    2.0: [(0.1, "survived", 0.0), (0.2, "collapsed", 1 / K), (0.3, "collapsed", 2 / K),
          (0.4, "collapsed", 8 / K), (0.5, "collapsed", 1.0)],
    # at 0.2 g every member failed (no fraction); at 0.3 g member 0 failed and all the
    # others collapsed
    3.0: [(0.1, "survived", 0.0), (0.2, "failed", NAN), (0.3, "failed", 1.0),
          (0.4, "collapsed", 1.0), (0.5, "collapsed", 1.0)],
}  # fmt: skip
#: What the rule says of CELLS, line by line: (lowest unsafe, highest safe) [g] of the
#: majority and of member 0. At 3 Hz the cell without a fraction is on neither side: the
#: highest safe amplitude below 0.3 g is 0.1 g, not 0.2 g.
MAJORITY = [(0.3, 0.2), (0.4, 0.3), (0.3, 0.1)]
MEMBER0 = [(NAN, 0.5), (0.2, 0.1), (0.4, 0.1)]


def hand_rows() -> list[dict]:
    return [
        {"amplitude_g": a, "frequency_hz": f, "status": s, "collapsed": int(s == "collapsed"),
         "collapse_fraction": x, "robust": int(x in (0.0, 1.0) and s != "failed")}
        for f, cells in CELLS.items() for a, s, x in cells
    ]  # fmt: skip


def pairs(df: pd.DataFrame, low: str, high: str) -> list[float]:
    """The (low, high) pairs of a boundary's lines, flattened."""
    return [v for pair in zip(df[low], df[high], strict=True) for v in pair]


def flat(expected: list[tuple[float, float]]) -> list[float]:
    return [v for pair in expected for v in pair]


def line(ax, gid: str):
    (found,) = [ln for ln in ax.get_lines() if ln.get_gid() == gid]
    return found


def test_the_boundary_of_an_ensemble_is_where_the_majority_collapses():
    """Defect: the boundary of an ensemble domain was member 0's: where member 0
    survived but 15 of 16 members collapsed there was no boundary, and where 1 of 16
    collapsed it was drawn there. Rows made by hand: the boundary's own columns are the
    majority's, member 0's are beside them."""
    df = pd.DataFrame(hand_rows())
    bnd = boundary(df)
    assert list(bnd.columns) == ["frequency_hz", "lowest_unsafe_g", "highest_safe_g",
                                 "member0_lowest_unsafe_g", "member0_highest_safe_g"]  # fmt: skip
    assert list(bnd["frequency_hz"]) == [1.0, 2.0, 3.0]
    low_high = pairs(bnd, "lowest_unsafe_g", "highest_safe_g")
    assert low_high == pytest.approx(flat(MAJORITY), nan_ok=True)
    low_high = pairs(bnd, "member0_lowest_unsafe_g", "member0_highest_safe_g")
    assert low_high == pytest.approx(flat(MEMBER0), nan_ok=True)
    # the sweep's writer (plain Python, from the rows) gives the same table
    columns, lines = boundary_table(hand_rows(), tuple(df.columns))
    assert csv_text(lines, columns) == csv_text(bnd.to_dict("records"), tuple(bnd.columns))


def test_plot_domain_draws_the_majority_and_member_0_with_a_legend(tmp_path, monkeypatch):
    """Defect: `rbm plot-domain` (and rbm.plot_domain) drew member 0's boundary of an
    ensemble domain as its boundary. Now the line 'boundary' is the majority's and
    'boundary-member0' member 0's, and the legend names both."""
    path = tmp_path / "domain.csv"
    path.write_text(csv_text(hand_rows(), tuple(hand_rows()[0])), encoding="utf-8")
    drawn = []
    monkeypatch.setattr(
        rbm_cli.base.files, "save_figure_atomic", lambda fig, path: drawn.append(fig)
    )
    res = CliRunner().invoke(cli, ["plot-domain", str(path), "-o", str(tmp_path / "d.png")])
    assert res.exit_code == 0, res.output
    (fig,) = drawn
    api_ax = rbm.plot_domain(rbm.read_domain(path))
    for ax in (fig.axes[0], api_ax):
        majority, member0 = line(ax, "boundary"), line(ax, "boundary-member0")
        assert list(majority.get_xdata()) == list(member0.get_xdata()) == [1.0, 2.0, 3.0]
        assert list(majority.get_ydata()) == pytest.approx([m[0] for m in MAJORITY])
        assert list(member0.get_ydata()) == pytest.approx([m[0] for m in MEMBER0], nan_ok=True)
        texts = [t.get_text() for t in ax.get_legend().get_texts()]
        assert majority.get_label() in texts and member0.get_label() in texts
        assert "majority" in majority.get_label() and "0.5" in majority.get_label()
        assert "member 0" in member0.get_label()
        assert majority.get_linestyle() != member0.get_linestyle()


def slender_grid(tmp_path):
    """The slender Spanos-Koh block (rigid, 10 s harmonic) on 18 cells."""
    data = yaml.safe_load((CONFIGS / "spanos_koh_slender.yaml").read_text())
    data["name"] = "slender"
    data["grid"] = {"amplitudes": [0.2, 0.25, 0.3, 0.35, 0.5, 0.8], "frequencies": [0.5, 1.0, 2.0]}
    path = tmp_path / "slender.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def by_hand(domain: list[dict]) -> dict[str, tuple[str, str]]:
    """{frequency: (lowest, highest)} of the majority, computed here from domain.csv's
    text: the lowest amplitude whose fraction is >= 0.5, the highest below it whose
    fraction is < 0.5 (empty: none)."""
    out = {}
    for f in dict.fromkeys(r["frequency_hz"] for r in domain):
        cells = [(float(r["amplitude_g"]), r["collapse_fraction"]) for r in domain
                 if r["frequency_hz"] == f and r["collapse_fraction"] != ""]  # fmt: skip
        low = min((a for a, x in cells if float(x) >= 0.5), default=None)
        high = max((a for a, x in cells if float(x) < 0.5 and (low is None or a < low)),
                   default=None)  # fmt: skip
        out[f] = tuple("" if v is None else f"{v:.12g}" for v in (low, high))
    return out


def read_rows(path) -> list[dict]:
    return list(csv.DictReader(io.StringIO(path.read_text(encoding="utf-8"))))


def test_an_ensemble_sweep_writes_both_boundaries(tmp_path, monkeypatch):
    """Defect: `rbm sweep --ensemble 16` wrote member 0's boundary as the domain's.
    boundary.csv now has the majority's (as computed here from domain.csv) and member 0's
    (the plain sweep's boundary, byte for byte); they agree on every line whose cells
    are all robust. A plain sweep's boundary.csv has its three columns as before.
    `rbm plot-domain` and the sweep's domain.png draw the majority's line and member 0's."""
    config = slender_grid(tmp_path)
    runner = CliRunner()
    for out, extra in (("ens", ["--ensemble", "16"]), ("plain", [])):
        res = runner.invoke(cli, ["sweep", str(config), "-o", str(tmp_path / out), "-j", "1",
                                  "-q", *extra])  # fmt: skip
        assert res.exit_code == 0, res.output
    plain_text = (tmp_path / "plain" / "slender" / "boundary.csv").read_text()
    assert plain_text.splitlines()[0] == "frequency_hz,lowest_unsafe_g,highest_safe_g"
    folder = tmp_path / "ens" / "slender"
    lines = read_rows(folder / "boundary.csv")
    assert list(lines[0]) == ["frequency_hz", "lowest_unsafe_g", "highest_safe_g",
                              "member0_lowest_unsafe_g", "member0_highest_safe_g"]  # fmt: skip
    member0 = "frequency_hz,lowest_unsafe_g,highest_safe_g\n" + "".join(
        f"{r['frequency_hz']},{r['member0_lowest_unsafe_g']},{r['member0_highest_safe_g']}\n"
        for r in lines
    )
    assert member0 == plain_text
    domain = read_rows(folder / "domain.csv")
    majority = by_hand(domain)
    assert {r["frequency_hz"]: (r["lowest_unsafe_g"], r["highest_safe_g"]) for r in lines} == (
        majority
    )
    robust_lines = 0
    for r in lines:
        cells = [d for d in domain if d["frequency_hz"] == r["frequency_hz"]]
        if all(d["robust"] == "1" for d in cells):
            robust_lines += 1
            assert (r["lowest_unsafe_g"], r["highest_safe_g"]) == (
                r["member0_lowest_unsafe_g"], r["member0_highest_safe_g"])  # fmt: skip
    assert robust_lines >= 1

    drawn = []
    monkeypatch.setattr(
        rbm_cli.base.files, "save_figure_atomic", lambda fig, path: drawn.append(fig)
    )
    res = runner.invoke(cli, ["plot-domain", str(folder / "domain.csv")])
    assert res.exit_code == 0, res.output

    def capture(df, cfg):  # the sweep's domain.png, kept to be read
        drawn.append(domain_figure(df, cfg))
        return drawn[-1]

    run_sweep(load_config(config), tmp_path / "again", jobs=1, ensemble=16, figure=capture)
    want_majority = [float(r["lowest_unsafe_g"]) if r["lowest_unsafe_g"] else NAN for r in lines]
    want_member0 = [float(r["member0_lowest_unsafe_g"]) if r["member0_lowest_unsafe_g"] else NAN
                    for r in lines]  # fmt: skip
    assert len(drawn) == 2
    same = want_member0 == pytest.approx(want_majority, nan_ok=True)
    for fig in drawn:
        ax = fig.axes[0]
        assert list(line(ax, "boundary").get_ydata()) == pytest.approx(want_majority, nan_ok=True)
        texts = [t.get_text() for t in ax.get_legend().get_texts()]
        assert any("majority" in t for t in texts)
        if same:  # one line, listed once: member 0's would lie under it, unseen
            assert not [ln for ln in ax.get_lines() if ln.get_gid() == "boundary-member0"]
            assert not any("member 0's boundary" in t for t in texts)
        else:
            assert list(line(ax, "boundary-member0").get_ydata()) == pytest.approx(
                want_member0, nan_ok=True
            )
            assert any("member 0's boundary" in t for t in texts)


def stored_ensembles() -> list[str]:
    return sorted(p.parent.name for p in RESULTS.glob("*/domain.csv")
                  if "collapse_fraction" in p.read_text().split("\n", 1)[0])  # fmt: skip


@pytest.mark.parametrize("name", stored_ensembles())
def test_stored_boundaries_are_their_ensembles(name):
    """Defect: the stored ensemble domains' boundary.csv held member 0's boundary as
    the domain's. Each stored boundary.csv is the boundary of its domain.csv (majority and
    member 0), and meta.json's checksums match the files beside it."""
    folder = RESULTS / name
    df = pd.read_csv(folder / "domain.csv")
    columns, lines = boundary_table(df.to_dict("records"), tuple(df.columns))
    assert "member0_lowest_unsafe_g" in columns
    assert (folder / "boundary.csv").read_text(encoding="utf-8") == csv_text(lines, columns)
    files = json.loads((folder / "meta.json").read_text()).get("files", {})
    for file, digest in files.items():
        assert hashlib.sha256((folder / file).read_bytes()).hexdigest() == digest, file


@pytest.mark.parametrize("bad", ["abc", "1.5", "-0.25", "inf"])
def test_a_collapse_fraction_out_of_range_is_one_line(tmp_path, bad):
    """Defect: the boundary of an ensemble is drawn from collapse_fraction, but a domain.csv
    whose collapse_fraction was text gave a ValueError traceback in `rbm plot-domain`, and
    one outside [0, 1] was drawn as if it were a fraction. Both are refused in one line
    naming the line and the value; an empty one (every member failed) is accepted."""
    rows = hand_rows()
    rows[7]["collapse_fraction"] = bad
    path = tmp_path / "domain.csv"
    path.write_text(csv_text(rows, tuple(rows[0])), encoding="utf-8")
    for command in (["plot-domain", str(path), "-o", str(tmp_path / "d.png")],
                    ["compare", str(path), str(path)]):  # fmt: skip
        res = CliRunner().invoke(cli, command)
        assert res.exit_code == 2, res.output
        assert "Traceback" not in res.output and len(res.output.strip().splitlines()) == 1
        assert "line 9" in res.output and "collapse_fraction" in res.output
        assert repr(bad) in res.output
    assert not (tmp_path / "d.png").exists()
    rows[7]["collapse_fraction"] = None  # written empty
    path.write_text(csv_text(rows, tuple(rows[0])), encoding="utf-8")
    assert CliRunner().invoke(cli, ["compare", str(path), str(path)]).exit_code == 0
