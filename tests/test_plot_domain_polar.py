"""The polar picture of a domain over excitation.angle: the radii it computes, what it draws,
read back from the artists, and `rbm plot-domain` writing it.

Expected values: the domain is written here cell by cell from a table of outcomes set by
hand (THRESHOLDS, FAILED, REVIVED), so the lowest collapsed amplitude and the highest
survived one below it at each angle and frequency are read off that table (EXPECTED),
not computed by the code under test.
"""

from __future__ import annotations

import math

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402
import yaml  # noqa: E402
from click.testing import CliRunner  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

import rbm  # noqa: E402
from rbm_cli.cli.main import cli  # noqa: E402
from rbm_cli.config.load import parse_config  # noqa: E402
from rbm_cli.report.domain_figure import domain_figure  # noqa: E402
from rbm_cli.report.plot_polar import (  # noqa: E402
    OPEN_RING,
    is_closed_turn,
    polar_boundary,
)

ANGLES = (0.0, 90.0, 180.0, 270.0)
FREQS = (1.0, 2.0)
AMPS = (0.2, 0.4, 0.6, 0.8, 1.0)
#: The lowest amplitude from which the column collapses [g] at (angle, frequency); None:
#: nothing collapses on the grid (an open angle).
THRESHOLDS = {
    (0.0, 1.0): 0.6, (90.0, 1.0): 0.4, (180.0, 1.0): 0.2, (270.0, 1.0): 0.8,
    (0.0, 2.0): None, (90.0, 2.0): 1.0, (180.0, 2.0): 0.6, (270.0, 2.0): None,
}  # fmt: skip
#: Failed runs (angle, frequency, amplitude): neither collapse nor survival.
FAILED = {(90.0, 1.0, 0.2), (270.0, 1.0, 0.6), (270.0, 2.0, 1.0)}
#: Cells above the threshold that survive anyway (chaotic rocking).
REVIVED = {(180.0, 2.0, 0.8), (180.0, 2.0, 1.0)}
#: (highest survived amplitude below the lowest collapsed one, lowest collapsed amplitude,
#: failed runs) [g], read off the table above; NaN where there is none.
NAN = math.nan
EXPECTED = {
    (0.0, 1.0): (0.4, 0.6, 0), (90.0, 1.0): (NAN, 0.4, 1), (180.0, 1.0): (NAN, 0.2, 0),
    (270.0, 1.0): (0.4, 0.8, 1), (0.0, 2.0): (1.0, NAN, 0), (90.0, 2.0): (0.8, 1.0, 0),
    (180.0, 2.0): (0.4, 0.6, 0), (270.0, 2.0): (0.8, NAN, 1),
}  # fmt: skip

CONFIG = {
    "name": "polar",
    "model": "housner-3d",
    "column": {"height": 4.0, "base_width": 1.0, "top_width": 0.8, "section": "circular",
               "density": 2700},
    "interface": {"stiffness": "rigid", "restitution": 0.9},
    "excitation": {"type": "half-sine", "duration": 3.0},
    "grid": {"amplitudes": {"start": 0.2, "stop": 1.0, "step": 0.2},
             "frequencies": list(FREQS), "excitation.angle": list(ANGLES)},
}  # fmt: skip


def hand_domain() -> pd.DataFrame:
    """domain.csv's rows as a sweep orders them (angle outermost), from the table."""
    rows = []
    for angle in ANGLES:
        for f in FREQS:
            for a in AMPS:
                threshold = THRESHOLDS[(angle, f)]
                collapsed = threshold is not None and a >= threshold - 1e-12
                status = "collapsed" if collapsed else "survived"
                if (angle, f, a) in REVIVED:
                    status = "survived"
                if (angle, f, a) in FAILED:
                    status = "failed"
                row = {"excitation.angle": angle, "amplitude_g": a, "frequency_hz": f}
                rows.append({**row, "status": status, "collapsed": int(status == "collapsed")})
    return pd.DataFrame(rows)


def artists(ax, gid):
    return [a for a in (*ax.lines, *ax.collections) if a.get_gid() == gid]


def points(ax, gid) -> np.ndarray:
    """(theta [deg] in [0, 360), r) of the finite points of the lines with ``gid``."""
    out = [line.get_xydata() for line in ax.lines if line.get_gid() == gid]
    xy = np.concatenate(out) if out else np.empty((0, 2))
    xy = xy[np.isfinite(xy).all(axis=1)]
    return np.column_stack([np.round(np.degrees(xy[:, 0]), 9) % 360.0, xy[:, 1]])


def test_the_radii_are_the_lowest_collapse_and_the_highest_survival_below_it():
    radii = polar_boundary(hand_domain().sample(frac=1.0, random_state=7))
    assert list(radii.columns) == ["frequency_hz", "angle_deg", "survived_g", "collapsed_g",
                                   "n_failed"]  # fmt: skip
    want = [(f, angle, *EXPECTED[(angle, f)]) for f in FREQS for angle in ANGLES]
    got = radii.to_numpy(float)
    np.testing.assert_allclose(got, np.array(want, float), rtol=0, atol=1e-12)


def test_the_angles_close_the_turn_or_span_a_sector():
    assert is_closed_turn(ANGLES) == (True, 0.0, 360.0)
    assert is_closed_turn([0, 120, 240]) == (True, 0.0, 360.0)
    assert is_closed_turn([0, 30, 60, 90]) == (False, 0.0, 90.0)
    assert is_closed_turn([-45, 0, 45]) == (False, -45.0, 45.0)
    assert is_closed_turn([300, 0, 60]) == (False, -60.0, 60.0)
    assert is_closed_turn([0, 180])[0] is False  # two directions are not a turn


def test_the_figure_draws_both_radii_the_open_angles_and_says_what_was_left_out():
    cfg = parse_config(CONFIG)
    fig = domain_figure(hand_domain(), cfg)
    ax = fig.axes[0]
    assert ax.name == "polar"
    title = ax.get_title()
    assert title.startswith("polar, model housner-3d:") and "azimuth" in title
    for k, f in enumerate(FREQS):
        collapse = {(a, EXPECTED[(a, f)][1]) for a in ANGLES
                    if not math.isnan(EXPECTED[(a, f)][1])}  # fmt: skip
        marks = points(ax, f"collapsed-{k}")
        on_grid = {(t, round(r, 12)) for t, r in marks if t in ANGLES and r > 0}
        assert collapse <= on_grid
        # the dashed line passes each grid angle at the survival radius (0 where the
        # column collapsed at the lowest amplitude), and the band spans the two
        dashed = points(ax, f"survived-{k}")
        for angle in ANGLES:
            survived, collapsed, _ = EXPECTED[(angle, f)]
            r = dashed[np.isclose(dashed[:, 0], angle), 1]
            assert r.size and np.allclose(r, 0.0 if math.isnan(survived) else survived)
        assert artists(ax, f"band-{k}")
        opened = points(ax, f"open-{k}")
        want = sorted(a for a in ANGLES if math.isnan(EXPECTED[(a, f)][1]))
        assert sorted(opened[:, 0]) == want
        np.testing.assert_allclose(opened[:, 1], OPEN_RING * max(AMPS))
    assert artists(ax, "open-ring") and artists(ax, "static")
    failed = points(ax, "failed")
    assert sorted(map(tuple, failed)) == sorted((a, amp) for a, _, amp in FAILED)
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "1 Hz" in texts and "2 Hz" in texts
    assert any(t.startswith("failed run, left out") and t.endswith(": 3") for t in texts)
    assert any(t.startswith("open: no collapse up to 1 g") for t in texts)
    assert ax.get_ylim()[1] > OPEN_RING * max(AMPS)


def test_a_sector_of_angles_shows_that_sector_and_no_failure_note():
    df = hand_domain()
    df = df[(df["status"] != "failed") & (df["excitation.angle"] <= 90.0)]
    ax = rbm.plot_domain(df)
    assert ax.name == "polar"
    assert (ax.get_thetamin(), ax.get_thetamax()) == pytest.approx((0.0, 90.0))
    assert not artists(ax, "failed")
    assert not [t for t in ax.get_legend().get_texts() if "failed" in t.get_text()]


def test_the_library_puts_a_polar_axes_in_the_place_of_a_plain_one():
    fig = Figure()
    left, right = fig.subplots(1, 2)
    ax = rbm.plot_domain(hand_domain(), ax=right)
    assert ax.name == "polar" and ax.figure is fig and right not in fig.axes
    assert left in fig.axes
    # asked for panels, the domain is laid out as any other
    panels = rbm.plot_domain(hand_domain(), layout="panels")
    assert isinstance(panels, list) and all(p.name != "polar" for p in panels)


def test_a_domain_without_an_angle_axis_keeps_its_picture():
    df = hand_domain().rename(columns={"excitation.angle": "column.height"})
    fig = domain_figure(df, None, labels=["heights"])
    assert all(ax.name != "polar" for ax in fig.axes)


def test_rbm_plot_domain_writes_the_polar_png(tmp_path):
    folder = tmp_path / "polar"
    folder.mkdir()
    hand_domain().to_csv(folder / "domain.csv", index=False)
    cfg = tmp_path / "polar.yaml"
    cfg.write_text(yaml.safe_dump(CONFIG))
    res = CliRunner().invoke(cli, ["plot-domain", str(folder / "domain.csv"), "--config",
                                   str(cfg)])  # fmt: skip
    assert res.exit_code == 0, res.output
    png = folder / "domain.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000


@pytest.mark.parametrize(
    "change, needle",
    [
        (lambda d: d.assign(**{"excitation.angle": d["excitation.angle"].astype(object)
                               .where(d.index != 5, "north")}),
         "line 7: excitation.angle must be a finite number [deg], got 'north'"),
        (None, "draws one domain: compare domains in panels"),
    ],
)  # fmt: skip
def test_bad_input_is_one_line(tmp_path, change, needle):
    path = tmp_path / "domain.csv"
    df = hand_domain()
    (change(df) if change else df).to_csv(path, index=False)
    args = ["plot-domain", str(path), "-o", str(tmp_path / "x.png")]
    if change is None:
        args += ["--compare", str(path)]
    res = CliRunner().invoke(cli, args)
    assert res.exit_code == 2 and needle in res.output, res.output
    assert "Traceback" not in res.output and len(res.output.strip().splitlines()) == 1
