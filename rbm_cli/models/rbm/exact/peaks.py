"""Peaks of the compiled exact integrator, refined at the end of the run (numba).

Refining the peaks of every interval whose upper bound of |z| exceeds the running maximum
as the run goes (rbm_cli.models.rbm.exact.search.refine_peaks) would spend most of its work
on maxima that a later peak exceeds anyway. Such an interval is only noted (its start point,
length, law pieces, segment and upper bounds); at the end of the run the notes are taken
in decreasing order of their excess over the maxima and refined by the same procedure
while some row may still exceed its maximum. The maxima are the same (the refinement is
exact either way); only the work differs. When the notes are full, those no longer above
the maxima are dropped, and if none is, the largest is refined at once.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from rbm_cli.base.jit import jit
from rbm_cli.models.rbm.exact.bounds import track_upper
from rbm_cli.models.rbm.exact.piece import eval_point, make_piece, set_point
from rbm_cli.models.rbm.exact.search import bounds_of, refine_peaks

#: Notes kept at most.
NOTES = 2048

#: Noted intervals: start time t, length h, modal state (q, v) at the start, law pieces
#: (k, side), segment index, upper bounds of the tracked rows; count in count[0].
Notes = namedtuple("Notes", "t h q v k side seg up count")


@jit
def new_notes(n, m, cap):
    """Room for cap notes of a column of n drums (modes) and m joints."""
    return Notes(np.zeros(cap), np.zeros(cap), np.zeros((cap, n)), np.zeros((cap, n)),
                 np.zeros((cap, m), dtype=np.int64), np.zeros((cap, m), dtype=np.int64),
                 np.zeros(cap, dtype=np.int64), np.zeros((cap, m + 1)),
                 np.zeros(1, dtype=np.int64))  # fmt: skip


@jit
def _excess(notes, i, maxima):
    """How far note i's upper bounds exceed the maxima (<= 0: nothing to refine)."""
    out = -np.inf
    for r in range(maxima.size):
        out = max(out, notes.up[i, r] - maxima[r])
    return out


@jit
def _compact(notes, maxima):
    """Drop the notes whose upper bounds no longer exceed the maxima."""
    j = 0
    for i in range(notes.count[0]):
        if _excess(notes, i, maxima) > 0.0:
            if j != i:
                notes.t[j], notes.h[j], notes.seg[j] = notes.t[i], notes.h[i], notes.seg[i]
                notes.q[j], notes.v[j], notes.k[j] = notes.q[i], notes.v[i], notes.k[i]
                notes.side[j], notes.up[j] = notes.side[i], notes.up[i]
            j += 1
    notes.count[0] = j


@jit(borrow=True)
def may_exceed(pc, pts, maxima, mb, fb, fresh, up):
    """Raise the maxima to the values at points 0 and 1; up gets the upper bounds of the
    tracked quantities between them. Returns whether one may exceed its maximum there."""
    n, m, of, nf = pc.n, pc.m, 1 + 2 * pc.n, pc.nf
    for i in range(m + 1):
        maxima[i] = max(maxima[i], abs(pts[0, of + m + i]), abs(pts[1, of + m + i]))
    fast = bounds_of(pc, pts, 0, 1, mb, fb) if not fresh else _any_fast(mb, n)
    h = pts[1, 0] - pts[0, 0]
    above = False
    for i in range(m + 1):
        kk = m + i
        up[i] = track_upper(kk, pts[0, of + kk], pts[1, of + kk], pts[0, of + nf + kk],
                            pts[1, of + nf + kk], fb, fast, h)  # fmt: skip
        above = above or not up[i] <= maxima[i]
    return above


@jit
def note_interval(pc, pts, maxima, mb, fb, notes, side, k, seg, wk):
    """Note the interval between points 0 and 1, where a peak may exceed the maxima
    (:func:`may_exceed` said so and left the upper bounds in wk.up). Returns the
    evaluations spent (refinement when the notes are full)."""
    n = pc.n
    h = pts[1, 0] - pts[0, 0]
    up = wk.up
    if notes.count[0] == notes.t.size:
        _compact(notes, maxima)
    if notes.count[0] == notes.t.size:  # still full: refine this one now
        return refine_peaks(pc, pts, maxima, mb, fb, wk.refs, wk.free, wk.st_ab, wk.st_rows,
                            True)  # fmt: skip
    j = notes.count[0]
    notes.t[j], notes.h[j], notes.seg[j] = pts[0, 0], h, seg
    notes.q[j], notes.v[j] = pts[0, 1 : 1 + n], pts[0, 1 + n : 1 + 2 * n]
    notes.k[j], notes.side[j], notes.up[j] = k, side, up
    notes.count[0] = j + 1
    return 0


@jit(borrow=True)
def _any_fast(mb, n):
    for j in range(n):
        if mb[3, j] != 0.0:
            return True
    return False


@jit
def settle_peaks(mdl, cache, notes, seg_fc, maxima, wk):
    """Refine the noted intervals that may still exceed the maxima, largest excess first.
    Returns the evaluations."""
    count = notes.count[0]
    if count == 0:
        return 0
    excess = np.empty(count)
    for i in range(count):
        excess[i] = _excess(notes, i, maxima)
    evals = 0
    none = np.zeros(notes.k.shape[1], dtype=np.bool_)  # one per joint
    for i in np.argsort(-excess):
        if not _excess(notes, i, maxima) > 0.0:
            continue
        pc = make_piece(mdl, cache, notes.side[i], notes.k[i], none, none, seg_fc[notes.seg[i]])
        set_point(pc, wk.pts, 0, notes.t[i], notes.q[i].copy(), notes.v[i].copy())
        eval_point(pc, wk.pts, 0, notes.h[i], 1)
        evals += 1 + refine_peaks(pc, wk.pts, maxima, wk.mb, wk.fb, wk.refs, wk.free, wk.st_ab,
                                  wk.st_rows, False)  # fmt: skip
    notes.count[0] = 0
    return evals
