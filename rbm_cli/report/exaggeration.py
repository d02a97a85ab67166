"""The exaggeration of a drawn column's rotations (shapes.png): a round factor.

The column's outlines are its structure's (rbm_cli.structures.outline);
:func:`rbm_cli.report.plots.plot_shapes` draws them.
"""

from __future__ import annotations

import math

import numpy as np

#: Round exaggeration factors: 1, 2, 5 times a power of ten.
ROUND_STEPS = (1.0, 2.0, 5.0)


def round_factor(target: float) -> float:
    """The largest of 1, 2, 5, 10, 20, 50, ... not above ``target`` (at least 1).

    Parameters
    ----------
    target : float  Wished factor [-]

    Returns
    -------
    float  A round factor in [1, target] (1 if target < 1 or not finite)
    """
    if not np.isfinite(target) or target < 1.0:
        return 1.0
    decade = 10.0 ** math.floor(math.log10(target))
    for step in reversed(ROUND_STEPS):
        if step * decade <= target * (1.0 + 1e-12):
            return step * decade
    return decade  # not reached: step 1 always fits
