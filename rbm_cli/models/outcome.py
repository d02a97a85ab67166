"""The raw outcome of one run, the one type every model's runner returns.

study.simulate adds the cell (amplitude, frequency) and the wall time and turns it into a
rbm_cli.study.result.RunResult, the row of a domain.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from rbm_cli.models.history import History

#: A joint's lean is wobbling (Outcome.turns counts its direction's turning) while it is at
#: least this fraction of the joint's collapse limit [-]: nearer closure the direction of a
#: small rotation, which turns round at every pass near zero, says nothing of a rolling
#: column [assumption; the contact engine's reading of its joints uses the same fraction].
WOBBLE_LEVEL = 0.1


class EnergyAccount(NamedTuple):
    """The energy account of a run [J], relative to the ground (Model.energy: kinetic, the
    joints' potential and, for `geometric`, gravity's): at the start and at the end, the work
    the ground did, and the energy the joints' damping and the impacts took."""

    initial: float
    final: float
    ground_work: float
    damping: float
    impacts: float

    @property
    def residual(self) -> float:
        """final - initial - (ground_work - damping - impacts) [J]: zero for an exact
        balance (the integration's error otherwise; the `absolute` formulation's joint
        moments are not conservative, so its balance does not close)."""
        return self.final - self.initial - (self.ground_work - self.damping - self.impacts)

    def as_dict(self) -> dict:
        """JSON-ready, the residual included [J]."""
        return {"initial_J": self.initial, "final_J": self.final,
                "ground_work_J": self.ground_work, "damping_J": self.damping,
                "impacts_J": self.impacts, "residual_J": self.residual}  # fmt: skip


def budget_message(kind: str, budget: int) -> str:
    """The message of a run that used up its step or event budget (kind: 'step' or
    'event'): which budget, its size and how to raise it."""
    return (
        f"{kind} budget exceeded ({budget:,} {kind}s; raise solver.max_{kind}s, by default"
        " auto: it scales with the motion's duration and the joints)"
    )


@dataclass
class Outcome:
    """Raw outcome of an integration (simulate() turns it into a RunResult)."""

    status: str = "survived"
    message: str = ""
    t_end: float = 0.0
    t_collapse: float = math.nan
    collapse_interface: int | None = None
    max_ratio: np.ndarray | None = None
    max_top: float = 0.0
    friction: np.ndarray | None = None
    #: the instantaneous peak of |T_i / N_i| per interface [-] (friction: the demand held
    #: for the run's duration, models.rbm.pieces; the same without one)
    friction_peak: np.ndarray | None = None
    #: where the friction demand first exceeded the run's friction limit: (t [s], interface
    #: from 1); None: it did not, or no limit was given
    slip: tuple[float, int] | None = None
    n_uplifts: int = 0
    n_impacts: int = 0
    n_steps: int = 0
    n_rhs: int = 0
    n_events: int = 0
    samples: list = field(default_factory=list)  # (t, theta, rate) when recording
    history: History | None = None  # the sampled history, made by the runner when recording
    method: str = ""  # the method that ran (solver.method, `auto` resolved), set by the runner
    energy: EnergyAccount | None = None  # a recorded run's energy account, where kept
    #: a model in three dimensions: where its lean pointed at collapse [rad from x], and
    #: the angle its lean's direction swept while it leant by WOBBLE_LEVEL of its collapse
    #: limit or more (a wobble), in turns [-] (the largest over the joints)
    azimuth: float = math.nan
    turns: float = math.nan
    #: the contact engine's residual state where a run that survived ended (the motion
    #: and its free time over, or at rest after the pulse): the largest |slip| of a joint
    #: [m], the top's offset in plan from its start [m] and the largest |relative
    #: rotation| of a joint over its alpha_i [-]; nan for the other models, and for a
    #: run that collapsed or failed
    residual_slip: float = math.nan
    residual_top: float = math.nan
    residual_tilt: float = math.nan
    top_plan: np.ndarray | None = None  # a recorded 3D run: the top in plan per sample [m]
    across: np.ndarray | None = None  # ... and the rotations seen across the motion's plane

    def carry_plan(self) -> Outcome:
        """A recorded run of a model in three dimensions: its history takes the top's path
        in plan and the rotations seen across the motion's plane (kept beside the samples
        by the run). Returns the outcome itself."""
        if self.history is not None and self.top_plan is not None:
            self.history = dataclasses.replace(self.history, top_plan=self.top_plan,
                                               rotations_across=self.across)  # fmt: skip
        return self

    def stop(self, status: str, message: str, t: float) -> Outcome:
        """End the run at time t with a status and a reason."""
        self.status, self.t_end = status, t
        self.message = message if status != "failed" else f"{message} at t={t:.6g} s"
        return self

    def collapse(self, t: float, interface: int) -> Outcome:
        """The run collapsed at t [s] at an interface (numbered from 1)."""
        self.status, self.t_collapse, self.collapse_interface = "collapsed", t, interface
        self.message = f"interface {interface} reached its collapse limit"
        return self

    def stopped_early(self, outcome_only: bool = False) -> Outcome:
        """The run stopped early in free motion below the collapse barrier: at a peak, every
        figure final; with ``outcome_only`` (solver.stop: outcome) where its survival became
        certain, at t_end [s], the peaks those up to then."""
        if outcome_only:
            self.message = (
                f"free motion below every joint's collapse barrier: stopped at {self.t_end:.6g} s"
                " (solver.stop: outcome), the peaks are those up to then"
            )
        else:
            self.message = "free motion below the collapse barrier: stopped early"
        return self

    def out_of_steps(self, solver, t: float) -> Outcome:
        """The run ended 'failed' at t [s]: more steps than solver.max_steps."""
        return self.stop("failed", budget_message("step", solver.max_steps), t)

    def out_of_events(self, solver, t: float) -> Outcome:
        """The run ended 'failed' at t [s]: more events than solver.max_events."""
        return self.stop("failed", budget_message("event", solver.max_events), t)

    def out_of_time(self, solver, t: float) -> Outcome:
        """The run ended 'failed' at t [s]: past its wall-clock budget."""
        budget = f"{solver.max_wall_time:g} s, solver.max_wall_time"
        return self.stop("failed", f"wall-clock budget exceeded ({budget})", t)

    def past_budget(self, solver, deadline: float, t: float) -> Outcome | None:
        """The run ended 'failed' at t [s] if its steps exceed solver.max_steps or the
        monotonic clock is past deadline [s] (solver.max_wall_time); else None."""
        if self.n_steps > solver.max_steps:
            return self.out_of_steps(solver, t)
        if time.monotonic() > deadline:
            return self.out_of_time(solver, t)
        return None

    def past_events(self, solver, t: float) -> Outcome | None:
        """The run ended 'failed' at t [s] if its events exceed solver.max_events; else
        None."""
        if self.n_events > solver.max_events:
            return self.out_of_events(solver, t)
        return None

    def lifted_off(self, t_lift: float | None) -> Outcome:
        """A run that reached t_lift [s], where g + a_v(t) <= 0 (the ground's upward
        acceleration reaches -g: the column leaves the ground), ends there as 'failed'
        unless it collapsed before; None: nothing to do."""
        if t_lift is not None and self.status == "survived":
            self.stop("failed", "g + a_v(t) <= 0: the ground drops faster than gravity and"
                      " the column leaves it (excitation.vertical)", t_lift)  # fmt: skip
        return self


def sample_buffer(t_end: float, output_dt: float, record: bool, n: int) -> np.ndarray:
    """The rows (t [s], theta [n] [rad], rate [n] [rad/s]) a compiled run fills every
    output_dt [s] up to t_end [s]; none unless record."""
    rows = int(math.floor(t_end / output_dt + 1e-9)) + 2 if record else 0
    return np.zeros((rows, 1 + 2 * n))


def sample_rows(samples: np.ndarray, count: int, n: int) -> list:
    """Outcome.samples from the first count rows of a sample_buffer."""
    return [(float(r[0]), r[1 : 1 + n].copy(), r[1 + n :].copy()) for r in samples[:count]]
