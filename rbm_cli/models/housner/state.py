"""The moving parts of a run of Housner's block (`housner`, rbm_cli.models.housner.runner): the
recorder of the time history and the moving state of a run (time, side, rest, peak
rotation, outcome), with the rest phase and the end of the run."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.models.outcome import Outcome


class Recorder:
    """Time-history samples (t, [theta], [rate]) every output_dt [s], at k * output_dt."""

    def __init__(self, output_dt: float, samples: list | None):
        self.dt = output_dt
        self.samples = samples
        self.k = 0

    def times(self, t_stop: float) -> np.ndarray:
        """The sample times not yet emitted up to t_stop [s] (consumed)."""
        if self.samples is None:
            return np.zeros(0)
        k_last = math.floor((t_stop + 1e-12) / self.dt)
        ts = self.dt * np.arange(self.k, k_last + 1)
        self.k = max(self.k, k_last + 1)
        return ts

    def emit(self, ts, theta, rate) -> None:
        for t, th, v in zip(
            ts, np.broadcast_to(theta, ts.shape), np.broadcast_to(rate, ts.shape), strict=True
        ):
            self.samples.append((float(t), np.array([float(th)]), np.array([float(v)])))

    def rest(self, t_stop: float) -> None:
        ts = self.times(t_stop)
        self.emit(ts, 0.0, 0.0)


@dataclass
class BlockRun:
    """The moving state of one run of a rocking block.

    Attributes
    ----------
    alpha : float  Slenderness [rad]
    limit : float  Collapse rotation c alpha [rad]
    out : Outcome  Filled as the run goes
    rec : Recorder  Time-history samples (none kept unless recording)
    note : callable  Takes (t [s], kind) for every uplift, impact, rest and collapse
    top : callable  Top displacement [m] at a peak rotation [rad]
    t : float  Current time [s]
    side : int  Side s = +-1 the block rocks on
    at_rest : bool  Resting on its base (no motion)
    peak : float  Largest |theta| so far [rad]
    """

    alpha: float
    limit: float
    out: Outcome
    rec: Recorder
    note: Callable[[tuple], None]
    top: Callable[[float], float]
    t: float = 0.0
    side: int = 1
    at_rest: bool = False
    peak: float = 0.0

    @staticmethod
    def parts(record: bool, output_dt: float, events: list | None) -> dict:
        """A fresh outcome (friction not computed: NaN), its recorder and the event note,
        as keyword arguments of the constructor."""
        out = Outcome()
        out.friction = np.array([math.nan])
        rec = Recorder(output_dt, out.samples if record else None)
        note = events.append if events is not None else (lambda item: None)
        return dict(out=out, rec=rec, note=note)

    def finish(self, status: str = "survived", message: str = "") -> Outcome:
        """End the run at the current time: the counts, the peak ratio and top displacement."""
        out = self.out
        out.n_events = out.n_uplifts + out.n_impacts
        out.max_ratio = np.array([self.peak / self.alpha])
        out.max_top = self.top(self.peak)
        out.status, out.message, out.t_end = status, message, self.t
        return out

    def collapsed_at_start(self) -> Outcome | None:
        """The collapsed outcome if the initial rotation is already beyond the limit."""
        if self.peak >= self.limit:
            self.out.t_collapse, self.out.collapse_interface = 0.0, 1
            return self.finish("collapsed", "initial rotation beyond the collapse limit")
        return None

    def wait(self, motion: GroundMotion, seg_end: float, level: float, forced: bool) -> str:
        """At rest: wait (recording zeros) until |a_g| exceeds level [m/s^2], then lift on
        the side turning away from a_g. Returns what ended the rest: 'uplift', 'segment'
        (the segment ended first) or 'end' (no ground motion from here on)."""
        kind, t_stop = motion.rest_end(self.t, seg_end, level, forced)
        self.rec.rest(t_stop - (1e-15 if kind == "uplift" else 0.0))
        self.t = t_stop
        if kind in ("end", "segment"):
            return kind
        self.side = motion.uplift_side(self.t)
        self.at_rest = False
        self.out.n_uplifts += 1
        self.note((self.t, "uplift"))
        return kind
