"""Gauss-Legendre quadrature over a step of the compiled engine (the energy account's work
and damping, integrated on the step's dense output)."""

from __future__ import annotations

import numpy as np

#: Gauss-Legendre nodes on [0, 1] and weights (5 points: exact for polynomials of degree 9).
GL_NODES = np.array([0.04691007703066802, 0.23076534494715845, 0.5, 0.7692346550528415,
                     0.9530899229693319])  # fmt: skip
GL_WEIGHTS = np.array([0.11846344252809454, 0.23931433524968324, 0.28444444444444444,
                       0.23931433524968324, 0.11846344252809454])  # fmt: skip
