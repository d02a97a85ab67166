"""The model error of a domain against a reference model's domain of the same cells.

The RBM's rigid monolith is a small-rotation law (alpha := B/H, the linearised rocking
equation); `housner` is the exact large-rotation block of the true geometry. Where the two
domains differ, the side matters to a user who reads a domain as a safety statement:

- **unconservative**: the model survives where the reference collapses (the model says
  safe and the column falls);
- **conservative**: the model collapses where the reference survives.

Per frequency, the model's boundary (lowest collapsed amplitude) above the reference's is
unconservative there, below it conservative.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pandas as pd

from rbm_cli.study.domain import cell_key, compare

#: The sides of a differing cell, from the model's point of view.
UNCONSERVATIVE = "unconservative"
CONSERVATIVE = "conservative"

_CELL_COLUMNS = ["amplitude_g", "frequency_hz", "side", "robust"]


@dataclass(frozen=True)
class ModelError:
    """Where a model's domain differs from a reference domain, and on which side.

    Attributes
    ----------
    n_common : int  Cells in both domains where neither run failed
    cells : pandas.DataFrame  The differing cells: amplitude_g [g], frequency_hz [Hz],
        side ('unconservative': the model survived, the reference collapsed;
        'conservative': the reverse), robust (True when both domains are ensembles and
        the cell is robust in both, False when it is sensitive in either, NA without
        ensembles); sorted by frequency, then amplitude
    shifts : pandas.DataFrame  Per frequency: frequency_hz, boundary_model_g,
        boundary_reference_g, shift_g (model minus reference [g]; > 0: the model's
        boundary is higher, unconservative at that frequency). A boundary that leaves
        the grid is one grid step above it (rbm_cli.study.domain.compare)
    n_failed : int  Common cells left out because a run failed in either domain
    """

    n_common: int
    cells: pd.DataFrame
    shifts: pd.DataFrame
    n_failed: int

    @property
    def fraction(self) -> float:
        """Differing cells over common cells [-]."""
        return len(self.cells) / self.n_common if self.n_common else math.nan

    def count(self, side: str) -> int:
        """Number of differing cells on one side ('unconservative' or 'conservative')."""
        return int((self.cells["side"] == side).sum())

    def summary(self) -> str:
        """One line: the fraction, the two sides, and the largest shift each way [g]."""
        up = self.shifts["shift_g"].max() if len(self.shifts) else 0.0
        down = self.shifts["shift_g"].min() if len(self.shifts) else 0.0
        return (
            f"{len(self.cells)} of {self.n_common} cells differ ({100 * self.fraction:.2f} %):"
            f" {self.count(UNCONSERVATIVE)} unconservative (model survives, reference"
            f" collapses), {self.count(CONSERVATIVE)} conservative; boundary shift"
            f" {max(up, 0.0):+.2f} g at most upwards, {min(down, 0.0):+.2f} g downwards"
        )


def _rows(df: pd.DataFrame) -> dict:
    robust = df["robust"] if "robust" in df.columns else [None] * len(df)
    cols = (df["amplitude_g"], df["frequency_hz"], df["status"], robust)
    return {cell_key(a, f): (float(a), float(f), s, r) for a, f, s, r in zip(*cols, strict=True)}


def model_error(model: pd.DataFrame, reference: pd.DataFrame) -> ModelError:
    """Compare a model's domain with a reference domain cell by cell, by side.

    Parameters
    ----------
    model : pandas.DataFrame  Domain of the model judged (e.g. the RBM), as read by
        rbm_cli.study.domain.read_domain: amplitude_g [g], frequency_hz [Hz], status,
        collapsed; optionally robust (ensemble domains)
    reference : pandas.DataFrame  Domain of the reference model (e.g. `housner`) on the
        same cells

    Returns
    -------
    ModelError  The differing cells with their side and the boundary shifts.

    Examples
    --------
    >>> import pandas as pd
    >>> rbm = pd.DataFrame({"amplitude_g": [0.5, 1.0], "frequency_hz": [1.0, 1.0],
    ...                     "status": ["survived", "survived"], "collapsed": [0, 0]})
    >>> exact = rbm.assign(status=["survived", "collapsed"], collapsed=[0, 1])
    >>> model_error(rbm, exact).cells["side"].tolist()
    ['unconservative']
    """
    a, b = _rows(model), _rows(reference)
    common = a.keys() & b.keys()
    n_failed = 0
    cells = []
    for key in common:
        amp, freq, s_model, r_model = a[key]
        s_ref, r_ref = b[key][2], b[key][3]
        if "failed" in (s_model, s_ref):
            n_failed += 1
            continue
        if s_model == s_ref:
            continue
        side = UNCONSERVATIVE if s_model == "survived" else CONSERVATIVE
        robust = pd.NA if r_model is None or r_ref is None else bool(r_model and r_ref)
        cells.append((amp, freq, side, robust))
    table = pd.DataFrame(cells, columns=_CELL_COLUMNS)
    table = table.sort_values(["frequency_hz", "amplitude_g"], ignore_index=True)
    shifts = compare(model, reference).shifts.rename(
        columns={"boundary_a_g": "boundary_model_g", "boundary_b_g": "boundary_reference_g"}
    )
    shifts["shift_g"] = 0.0 - shifts["shift_g"]  # model minus reference, no -0.0
    return ModelError(
        n_common=len(common) - n_failed, cells=table, shifts=shifts, n_failed=n_failed
    )
