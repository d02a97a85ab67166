"""tools/validation_measures.py: the measurements of the validation report, against closed
forms and hand-made cases."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pandas as pd
import pytest

from rbm_cli.config.load import load_config
from rbm_cli.config.types import GridConfig
from rbm_cli.structures.closed_forms import linear_rocking_parameters
from rbm_cli.structures.column import build_column
from rbm_cli.study.domain import read_domain

from .paths import CONFIGS, RESULTS, tool_script

_MEASURES = tool_script("validation_measures")
differing_cells = _MEASURES.differing_cells
linear_domain = _MEASURES.linear_domain
period_from_crossings = _MEASURES.period_from_crossings
zero_crossings = _MEASURES.zero_crossings


def test_crossing_of_a_sampled_cubic_is_its_root():
    """A cubic is its own cubic Hermite: the crossing is the polynomial's root."""
    root = 0.3137

    def theta(t):
        return (t - root) * (t * t + 1.0)

    def rate(t):
        return (t * t + 1.0) + 2.0 * t * (t - root)

    t = np.array([0.0, 0.5, 1.0])
    np.testing.assert_allclose(zero_crossings(t, theta(t), rate(t)), [root], atol=1e-14)
    # the other direction of crossing too
    np.testing.assert_allclose(zero_crossings(t, -theta(t), -rate(t)), [root], atol=1e-14)


def test_crossings_and_period_of_a_sampled_sine():
    """theta = sin(w t) sampled every 10 ms: zeros at k pi / w to the Hermite error
    (~dt^4), period 2 pi / w."""
    w = 2.0
    t = np.arange(0.0, 10.0, 0.01)
    got = zero_crossings(t, np.sin(w * t), w * np.cos(w * t))
    k = np.arange(1, len(got) + 1)
    assert len(got) == int(10.0 * w / math.pi)
    np.testing.assert_allclose(got, k * math.pi / w, atol=1e-9)
    assert period_from_crossings(got) == pytest.approx(2 * math.pi / w, rel=1e-9)


def test_no_crossing_without_a_strict_sign_change():
    t = np.array([0.0, 1.0, 2.0, 3.0])
    assert len(zero_crossings(t, [1.0, 0.0, -1.0, -2.0], [-1.0, -1.0, -1.0, -1.0])) == 0
    assert len(zero_crossings(t, [1.0, 2.0, 1.0, 0.5], [1.0, 0.0, -1.0, -0.5])) == 0
    assert math.isnan(period_from_crossings([1.0]))
    assert math.isnan(period_from_crossings([]))


def test_linear_domain_is_the_rbm_domain_on_a_sub_grid():
    """The closed form over a sub-grid of the slender study (every 4th frequency, 5th
    amplitude) gives the stored RBM domain's flags there (a second model), and
    nothing moves below the uplift level alpha g."""
    cfg = load_config(CONFIGS / "spanos_koh_slender.yaml")
    g = cfg.grid
    cfg = dataclasses.replace(
        cfg, grid=GridConfig(g.amplitudes_g[::5], g.frequencies_hz[::4] + (0.1,))
    )
    alpha, p = linear_rocking_parameters(build_column(cfg.column, cfg.interface))
    lin = linear_domain(cfg, alpha, p, 1.0)
    assert list(lin.columns) == ["amplitude_g", "frequency_hz", "status", "collapsed"]
    assert len(lin) == len(cfg.grid.amplitudes_g) * len(cfg.grid.frequencies_hz)
    assert set(lin.status) == {"collapsed", "survived"}
    np.testing.assert_array_equal(lin.collapsed, (lin.status == "collapsed").astype(int))
    below = lin[lin.amplitude_g < alpha]
    assert len(below) > 0 and (below.status == "survived").all()
    rbm = read_domain(RESULTS / "spanos_koh_slender" / "domain.csv")
    merged = lin.merge(rbm, on=["amplitude_g", "frequency_hz"], suffixes=("", "_rbm"))
    assert len(merged) == len(lin) - len(cfg.grid.amplitudes_g)  # 0.1 Hz is not stored
    np.testing.assert_array_equal(merged.collapsed, merged.collapsed_rbm)


def _domain(flags: dict) -> pd.DataFrame:
    rows = [{"amplitude_g": a, "frequency_hz": f, "collapsed": c} for (a, f), c in flags.items()]
    return pd.DataFrame(rows)


def test_differing_cells_by_hand():
    """Two 4 x 3 domains. At 1 Hz the boundary moved one cell down: that cell has a
    neighbour of the other flag (next to the boundary). At 2 Hz one isolated cell
    collapses in b only: in b its neighbours differ from it (near). At 3 Hz every cell
    differs (a survives all, b collapses all): no neighbour of another flag in either
    domain, so none is near."""
    amps = (0.1, 0.2, 0.3, 0.4)
    a = {(x, 1.0): int(x >= 0.3) for x in amps}
    a |= {(x, 2.0): 0 for x in amps} | {(x, 3.0): 0 for x in amps}
    b = dict(a) | {(0.2, 1.0): 1, (0.3, 2.0): 1} | {(x, 3.0): 1 for x in amps}
    got = differing_cells(_domain(a), _domain(b))
    expected = [(0.2, 1.0, True), (0.3, 2.0, True)] + [(x, 3.0, False) for x in amps]
    assert [(c["amplitude_g"], c["frequency_hz"], c["near"]) for c in got] == expected
    assert all((c["a"], c["b"]) == (0, 1) for c in got)
    assert differing_cells(_domain(a), _domain(a)) == []
