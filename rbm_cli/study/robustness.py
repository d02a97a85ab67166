"""The robustness rule: when is a cell's outcome a fact, not an accident of rounding?

A rocking column can be chaotic: near the boundary of its domain a change in the
last bit of the state (another CPU's rounding, another compiler, another event
order) grows into a different outcome. rbm's arithmetic is the same bit for bit
on every x86-64 machine (rbm_cli.base.detmath), but a stored domain must also hold
against changes that are not bits of the machine: another platform, another
numba, a change of the code that moves the state by 1e-13 rad.

A cell is **robust** when an ensemble of MEMBERS runs of it agrees (all collapse
or all survive, none fails):

- member 0 is the cell itself (its row is the domain's row);
- member j >= 1 shifts the excitation's phase by s_j eps_j [rad] and scales its
  amplitude by 1 + s'_j eps_j, with eps_j log-spaced from 1e-12 (the size of
  machine rounding in the state) to 1e-6, and the signs (s_j, s'_j) running
  through all four combinations;
- odd members run at the config's rtol, even members at a tighter one (rtol/10,
  or 10 rtol if rtol/10 is below the solver's range), so more than one tolerance
  must agree.

and the same cell passes the **solver check**: re-run unperturbed with
another way of computing it (:func:`solver_checks`), each run gives the member
0's outcome (and none fails):

- the same method at tolerances 100 times tighter (rtol/100 and atol/100; 100 rtol
  where rtol/100 is below the solver's range), for every model with tolerances;
- and, for the Rigid Beam Model, the other exact method where one applies: the exact
  integrator (``solver.method: exact``) beside the step kernel on an elastic column;
  the step kernel (at rtol/100) where the rigid block's closed form or the exact
  integrator ran;
- the contact engine (model ``bullet``, no tolerance) at half its time step;
- ``housner-linear`` is its closed form only (no tolerance, no other method): its
  check is empty.

One or two extra runs a cell, against the MEMBERS - 1 of the ensemble.

Otherwise the cell is **sensitive**, and ``sensitive_to`` says why: ``inputs`` (the
members disagree, or one failed), ``solver`` (the solver check disagrees, or a check
run failed) or ``both``; ``none`` for a robust cell. Sensitive cells are reported,
not scored, by the regression (tests/test_regression.py, `rbm compare`) and by `rbm
bench --quick`. The rule is deterministic: the same config gives the same ensemble,
byte for byte.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from rbm_cli.config.load import TIME_STEP_RANGE
from rbm_cli.config.types import Config, SolverConfig
from rbm_cli.models.methods import METHODS, resolve

#: Ensemble size the rule needs for a cell to be called robust.
MEMBERS = 16
#: Range of the perturbations (relative amplitude; phase in rad).
SMALLEST, LARGEST = 1e-12, 1e-6
#: The solver's tightest rtol (config validation range).
MIN_RTOL = 1e-13
#: The solver check divides the tolerances by this.
TIGHTER = 100.0
#: What meta.json records of the rule.
RULE = (
    f"robust: all {MEMBERS} or more ensemble members agree and none fails; member j >= 1 "
    f"shifts phase and scales amplitude by eps_j log-spaced {SMALLEST:g}..{LARGEST:g} "
    "(all four sign pairs); odd members at rtol, even members at rtol/10; and the solver "
    f"check agrees: the cell at rtol/{TIGHTER:g} and atol/{TIGHTER:g}, and with the "
    "other exact method where one applies (rbm: exact beside the step kernel, the step "
    "kernel beside the closed form or exact; bullet: half the time step)"
)
#: The values of domain.csv's ``sensitive_to``: why a cell is not robust.
SENSITIVE_TO = ("none", "inputs", "solver", "both")


@dataclass(frozen=True)
class Member:
    """One ensemble member's perturbation of a cell."""

    phase_rad: float  # added to the excitation's phase [rad]
    amplitude_relative: float  # the amplitude is multiplied by 1 + this
    tight: bool  # run at the rule's second tolerance (tight_rtol)


def members(k: int) -> list[Member]:
    """The k members of an ensemble (member 0 unperturbed), as the rule says."""
    out = [Member(0.0, 0.0, False)]
    for j in range(1, k):
        frac = (j - 1) / (k - 2) if k > 2 else 1.0
        eps = SMALLEST * (LARGEST / SMALLEST) ** frac
        s_phase = 1.0 if (j // 2) % 2 == 0 else -1.0
        s_amp = 1.0 if (j // 4) % 2 == 0 else -1.0
        out.append(Member(s_phase * eps, s_amp * eps, j % 2 == 0))
    return out


def tight_rtol(rtol: float) -> float:
    """The second tolerance of the rule for a config's rtol."""
    return rtol / 10.0 if rtol / 10.0 >= MIN_RTOL else rtol * 10.0


def member_config(config: Config, a: float, member: Member) -> tuple[Config, float]:
    """(config, amplitude [g]) of an ensemble member of the cell at amplitude a [g]."""
    exc = dataclasses.replace(config.excitation, phase=config.excitation.phase + member.phase_rad)
    cfg = dataclasses.replace(config, excitation=exc)
    if member.tight:
        rtol = tight_rtol(config.solver.rtol)
        cfg = dataclasses.replace(cfg, solver=dataclasses.replace(config.solver, rtol=rtol))
    return cfg, a * (1.0 + member.amplitude_relative)


def tighter(solver: SolverConfig) -> SolverConfig:
    """The solver check's tolerances: rtol/TIGHTER and atol/TIGHTER (TIGHTER rtol where
    rtol/TIGHTER is below the solver's range: the two must agree either way)."""
    rtol = solver.rtol / TIGHTER
    rtol = rtol if rtol >= MIN_RTOL else solver.rtol * TIGHTER
    return dataclasses.replace(solver, rtol=rtol, atol=solver.atol / TIGHTER)


def solver_checks(config: Config) -> tuple[SolverConfig, ...]:
    """The solvers of a cell's solver check (see the module): each re-runs the
    unperturbed cell, and each must give its outcome."""
    solver = config.solver
    method = resolve(config).name
    if config.model == "housner-linear":
        return ()
    if config.model == "bullet":
        step = max(solver.time_step / 2.0, TIME_STEP_RANGE[0])
        return (dataclasses.replace(solver, time_step=step),)
    if config.model != "rbm":
        return (tighter(dataclasses.replace(solver, method=method)),)
    if method in ("closed-form", "exact"):
        return (tighter(dataclasses.replace(solver, method="DOP853")),)
    pair = "DOP853" if method == "exact-first" else method
    checks = (tighter(dataclasses.replace(solver, method=pair)),)
    if METHODS["exact"].why_not(config, None) is None:
        checks += (dataclasses.replace(solver, method="exact"),)
    return checks


def check_config(config: Config, solver: SolverConfig) -> Config:
    """The config of a solver check's run (:func:`solver_checks`)."""
    return dataclasses.replace(config, solver=solver)


def summarise(outcomes: list[int | None], checks: list[int | None] = ()) -> tuple[float, int, str]:
    """(collapse_fraction, robust, sensitive_to) of a cell from its members' outcomes
    (member 0 first) and its solver check's: 1 collapsed, 0 survived, None failed.

    The members agree when none failed and all collapsed or all survived; the solver
    check agrees when each of its runs has member 0's outcome (a run that failed where
    member 0 did not, or the other way round, disagrees)."""
    flags = [o for o in outcomes if o is not None]
    fraction = sum(flags) / len(flags) if flags else math.nan
    inputs = not (len(flags) == len(outcomes) and bool(flags) and fraction in (0.0, 1.0))
    reference = outcomes[0] if outcomes else None
    solver = any(c != reference for c in checks)
    why = SENSITIVE_TO[int(inputs) + 2 * int(solver)]
    return fraction, int(not (inputs or solver)), why


__all__ = [
    "MEMBERS",
    "RULE",
    "SENSITIVE_TO",
    "Member",
    "check_config",
    "member_config",
    "members",
    "solver_checks",
    "summarise",
    "tight_rtol",
    "tighter",
]
