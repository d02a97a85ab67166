"""The step kernel's event rows read over their nonzero columns (step.events.row_spans).

A joint's argument reads the drums beside it, so each row of a column's event rows costs
the same for any number of drums. Left-out zeros change no sum that starts from 0.0: the
rows, their interpolants' coefficients and constant terms are the same, to the bit, as
over whole rows (numpy's nonzero entries and whole-row sums are the references)."""

from __future__ import annotations

import numpy as np
import pytest

import rbm
from rbm_cli.models.rbm.step.events import row_base, row_coef, row_spans, surfaces
from rbm_cli.structures.arrays import column_arrays
from rbm_cli.study.simulate import model_from_config


def _spans(gx, gc):
    spans = np.empty((4, gx.shape[0]), dtype=np.int64)
    row_spans(gx, gc, spans)
    return spans


def _column(drums, formulation="relative", frame=None):
    cfg = {
        "name": "spans",
        "model": "rbm",
        "column": {
            "height": 5.0,
            "base_width": 0.96,
            "top_width": 0.66,
            "density": 2700,
            "drums": drums,
        },  # fmt: skip
        "interface": {"stiffness": {"normal": 5e9}, "formulation": formulation},
        "excitation": {"type": "harmonic"},
    }
    if frame:
        cfg["frame"] = frame
    return column_arrays(model_from_config(rbm.load_config(cfg)))


def test_spans_hold_every_nonzero_entry():
    """Random rows with leading, trailing and inner zeros and rows of zeros: each span is
    numpy's first and last nonzero column (+ 1), (0, 0) for a row of zeros."""
    rng = np.random.default_rng(3)
    for _ in range(50):
        m, n = rng.integers(1, 9), rng.integers(1, 12)
        gx = rng.normal(size=(m, n)) * (rng.random((m, n)) < 0.4)
        gc = rng.normal(size=(m, n)) * (rng.random((m, n)) < 0.4)
        spans = _spans(gx, gc)
        for b, rows in enumerate((gx, gc)):
            for i in range(m):
                nz = np.flatnonzero(rows[i])
                want = (nz[0], nz[-1] + 1) if nz.size else (0, 0)
                assert (spans[2 * b, i], spans[2 * b + 1, i]) == want


@pytest.mark.parametrize("drums", [4, 8, 16])
def test_a_columns_rows_read_two_drums_whatever_its_height(drums):
    """`relative`: a joint's argument and collapse ratio read the two drums beside it (the
    ground joint one), at every drum count."""
    col = _column(drums)
    spans = _spans(col.gx, col.gc)
    assert (spans[1] - spans[0]).max() == 2 and (spans[3] - spans[2]).max() == 2
    assert spans[1, 0] - spans[0, 0] == 1


@pytest.mark.parametrize(
    "drums, formulation, frame",
    [
        (16, "relative", None),
        (4, "geometric", None),
        (4, "absolute", None),
        (3, "relative", {"columns": 2, "beam_mass": 1e4}),
        (3, "geometric", {"columns": 3, "beam_mass": 1e4}),
    ],
)
def test_rows_over_their_spans_are_whole_rows_to_the_bit(drums, formulation, frame):
    """The event distances, rates and second derivatives (surfaces), a row's interpolant
    coefficients and its constant term over the spans are the same functions' over whole
    rows, bit for bit, and numpy's products, on random states (columns and frames, the
    three formulations)."""
    col = _column(drums, formulation, frame)
    gx, gc = col.gx, col.gc
    m, n = gx.shape
    spans = _spans(gx, gc)
    whole = np.array([[0] * m, [n] * m, [0] * m, [n] * m], dtype=np.int64)
    rng = np.random.default_rng(11)
    none, ground = np.empty(0), np.zeros(8)
    for _ in range(20):
        y = rng.normal(size=2 * n) * 10.0 ** rng.uniform(-6, 0)
        acc = rng.normal(size=n)
        h0 = rng.normal(size=4 * m)
        got = [np.empty(4 * m) for _ in range(6)]
        surfaces(gx, gc, col.same, spans, y, acc, h0, *got[:3], 0.0, ground, none, none)
        surfaces(gx, gc, col.same, whole, y, acc, h0, *got[3:], 0.0, ground, none, none)
        for a, b in zip(got[:3], got[3:], strict=True):
            assert np.array_equal(a, b)
        for d, v, offset in ((got[0], y[:n], h0[:m]), (got[1], y[n:], 0.0), (got[2], acc, 0.0)):
            assert np.allclose(d[:m], gx @ v + offset, rtol=1e-13, atol=1e-300)
        F = rng.normal(size=(7, 2 * n))
        for b, rows in enumerate((gx, gc)):
            for i in range(m):
                lo, hi = spans[2 * b, i], spans[2 * b + 1, i]
                for rate in (False, True):
                    c1, c2 = np.empty(7), np.empty(7)
                    row_coef(2, F, rows, i, lo, hi, n, rate, c1)
                    row_coef(2, F, rows, i, 0, n, n, rate, c2)
                    assert np.array_equal(c1, c2)
                    for sign in (1.0, -1.0):
                        start = 0.0 if rate else h0[i]
                        assert row_base(y, rows, i, sign, start, lo, hi, n, rate) == row_base(
                            y, rows, i, sign, start, 0, n, n, rate
                        )
