"""The parts of a run of Housner's rigid block (rbm_cli.models.housner.housner_run): the
block's constants, the equation and event distances on one side, the run's state and the
record of one step, with the peak rotation found inside a step."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from scipy.optimize import brentq

from rbm_cli.config.types import SolverConfig
from rbm_cli.models.housner.state import BlockRun
from rbm_cli.models.outcome import Outcome


@dataclass(frozen=True)
class HousnerBlock:
    """The block's constants and the run's thresholds and settings."""

    alpha: float  # slenderness [rad]
    p: float  # frequency parameter [rad/s]
    e_rest: float  # restitution [-]
    limit: float  # collapse rotation c alpha [rad]
    barrier: float  # energy at min(c, 1) alpha [rad^2/s^2]
    rest_rate: float  # post-impact rate below which the block rests [rad/s]
    eps: float  # offset of the impact surface [rad]
    level: float  # uplift level g tan(alpha) [m/s^2]
    atol: np.ndarray  # absolute tolerances of theta [rad] and rate [rad/s]
    ground: Callable[[float], float]  # a_g(t) / g [-] of the forced segments, t [s]
    gravity: Callable[[float], float] | None  # (g + a_v(t)) / g [-] (None: no vertical)
    solver: SolverConfig
    record: bool


@dataclass(frozen=True)
class HousnerSide:
    """Housner's equation on side s (forced or free) and its event distances, >= 0 inside:
    impact (s theta + eps), collapse (limit - s theta)."""

    blk: HousnerBlock
    s: int
    forced: bool
    out: Outcome

    def rhs(self, tt, yy):
        """(theta', theta'') at (tt [s], yy), counted in the outcome's n_rhs."""
        self.out.n_rhs += 1
        blk, s = self.blk, self.s
        alpha, p = blk.alpha, blk.p
        arg = alpha * s - yy[0]
        a = blk.ground(tt) if self.forced else 0.0
        if blk.gravity is None or not self.forced:
            return np.array([yy[1], -p * p * (math.sin(arg) + a * math.cos(arg))])
        # g -> g + a_v: p^2 and the weight's moment scale with it, a_g / g does not
        gam = blk.gravity(tt)
        return np.array([yy[1], -p * p * (gam * math.sin(arg) + a * math.cos(arg))])

    def dist(self, yy):
        """Event distances (impact, collapse) at the state(s) yy [rad]."""
        s = self.s
        return np.array([s * yy[0] + self.blk.eps, self.blk.limit - s * yy[0]])

    def ddist(self, yy):
        """Rates of the event distances at the state(s) yy [rad/s]."""
        s = self.s
        return np.array([s * yy[1], -s * yy[1]])


@dataclass
class HousnerRun(BlockRun):
    """BlockRun with the state y = (theta [rad], rate [rad/s])."""

    y: np.ndarray = field(default_factory=lambda: np.zeros(2))


class HousnerStep(NamedTuple):
    """One step taken, cut at its first event (kind 'impact' or 'collapse', else None)."""

    t_old: float
    y_old: np.ndarray
    t_new: float
    y_new: np.ndarray
    kind: str | None
    dense: object  # the step's dense output, if it was made


def peak_in_step(run: HousnerRun, s: int, integ, step: HousnerStep):
    """The time of a peak (the rate turning inward) inside the step, or None, and the
    step's dense output (made if needed); the run's peak rotation updated."""
    t_old, y_old, t_new, y_new = step.t_old, step.y_old, step.t_new, step.y_new
    dense = step.dense
    t_pk = None
    if s * y_old[1] > 0.0 >= s * y_new[1]:
        dense = integ.dense_output() if dense is None else dense
        if s * dense(t_new)[1] < 0.0:
            t_pk = brentq(lambda x, d=dense: d(x)[1], t_old, t_new, xtol=1e-15)
        else:
            t_pk = t_new
        run.peak = max(run.peak, abs(float(dense(t_pk)[0])))
    run.peak = max(run.peak, abs(float(y_new[0])) if step.kind != "impact" else 0.0)
    return t_pk, dense
