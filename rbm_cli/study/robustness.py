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

Otherwise the cell is **sensitive**: reported, not scored, by the regression
(tests/test_regression.py, `rbm compare`) and by `rbm bench --quick`. The rule
is deterministic: the same config gives the same ensemble, byte for byte.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from rbm_cli.config.types import Config

#: Ensemble size the rule needs for a cell to be called robust.
MEMBERS = 16
#: Range of the perturbations (relative amplitude; phase in rad).
SMALLEST, LARGEST = 1e-12, 1e-6
#: The solver's tightest rtol (config validation range).
MIN_RTOL = 1e-13
#: What meta.json records of the rule.
RULE = (
    f"robust: all {MEMBERS} or more ensemble members agree and none fails; member j >= 1 "
    f"shifts phase and scales amplitude by eps_j log-spaced {SMALLEST:g}..{LARGEST:g} "
    "(all four sign pairs); odd members at rtol, even members at rtol/10"
)


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


def summarise(flags: list[int], n_failed: int) -> tuple[float, int]:
    """(collapse_fraction, robust) of a cell from its members' collapsed flags
    (members that did not fail) and the count of members that failed."""
    fraction = sum(flags) / len(flags) if flags else math.nan
    robust = int(n_failed == 0 and bool(flags) and fraction in (0.0, 1.0))
    return fraction, robust


__all__ = ["MEMBERS", "RULE", "Member", "member_config", "members", "summarise", "tight_rtol"]
