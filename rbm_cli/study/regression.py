"""The regression rule: does a re-made domain agree with a stored one?

A stored domain made as an ensemble (`rbm sweep --ensemble 16`) records per cell
whether its outcome is robust (rbm_cli.study.robustness). A re-made domain agrees
with it when:

1. it has every cell of the stored grid (and no other);
2. every robust cell has the same outcome (0 may differ);
3. if the re-made domain is an ensemble too, its count of sensitive cells is
   at most sensitive_bound(stored count): a change that makes the model
   noisier fails even where no robust cell moved.

Sensitive cells are reported (how many, how many differ) and not scored.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import pandas as pd

from rbm_cli.base.errors import RbmError
from rbm_cli.study.domain import keys_of
from rbm_cli.study.schema import C

#: The bound on the re-made count of sensitive cells: the stored count plus
#: max(SLACK_CELLS, SLACK_FRACTION x the stored count). Measured: re-drawing
#: the ensemble's perturbations (another sign pattern, eps x 1.7) moved the
#: 8-drum study's count by up to a few cells (docs/reproducibility.md).
SLACK_CELLS = 3
SLACK_FRACTION = 0.25


def sensitive_bound(n_stored: int) -> int:
    """The largest count of sensitive cells a re-made ensemble may have."""
    return n_stored + max(SLACK_CELLS, math.ceil(SLACK_FRACTION * n_stored))


@dataclass(frozen=True)
class RegressionCheck:
    """The regression rule applied to a stored and a re-made domain."""

    n_cells: int
    n_robust: int
    n_sensitive: int  # stored
    robust_differ: int
    sensitive_differ: int  # reported, not scored
    missing: int  # stored cells the re-made domain lacks
    extra: int  # re-made cells not in the stored grid
    fresh_sensitive: int | None  # None unless the re-made domain is an ensemble
    bound: int
    differing: list = field(
        default_factory=list
    )  # robust cells that differ: (a [g], f [Hz], *point)

    @property
    def ok(self) -> bool:
        noisy = self.fresh_sensitive is not None and self.fresh_sensitive > self.bound
        return self.missing == 0 and self.extra == 0 and self.robust_differ == 0 and not noisy

    def summary(self) -> str:
        """One line: what agrees, what is reported, what fails."""
        text = (
            f"robust cells: {self.robust_differ} of {self.n_robust} differ; sensitive cells "
            f"(stored): {self.n_sensitive}, {self.sensitive_differ} differ (not scored)"
        )
        if self.fresh_sensitive is not None:
            text += f"; sensitive now: {self.fresh_sensitive} (bound {self.bound})"
        if self.missing or self.extra:
            text += f"; cells missing: {self.missing}, not in the stored grid: {self.extra}"
        if self.differing:
            cells = ", ".join(
                f"{c[0]:g} g at {c[1]:g} Hz" + "".join(f" ({v})" for v in c[2:])
                for c in self.differing[:5]
            )
            text += f" [{cells}{', ...' if len(self.differing) > 5 else ''}]"
        return text


def _flags(df: pd.DataFrame, column: str) -> dict:
    return dict(zip(keys_of(df), df[column], strict=True))


def check(stored: pd.DataFrame, fresh: pd.DataFrame) -> RegressionCheck:
    """Apply the regression rule; `stored` must carry the `robust` column."""
    if C.robust not in stored.columns:
        raise RbmError(
            "the stored domain records no robustness (no 'robust' column): "
            "make it with rbm sweep --ensemble 16"
        )
    robust = _flags(stored, C.robust)
    old, new = _flags(stored, C.collapsed), _flags(fresh, C.collapsed)
    common = old.keys() & new.keys()
    robust_differ = sorted(
        (float(k[0]), float(k[1] or "nan"), *k[2:])
        for k in common
        if int(robust[k]) == 1 and old[k] != new[k]
    )
    sensitive_differ = sum(1 for k in common if int(robust[k]) != 1 and old[k] != new[k])
    n_sensitive = sum(1 for v in robust.values() if int(v) != 1)
    fresh_sensitive = None
    if C.robust in fresh.columns:
        fresh_sensitive = int((fresh[C.robust].astype(int) != 1).sum())
    return RegressionCheck(
        n_cells=len(old),
        n_robust=len(old) - n_sensitive,
        n_sensitive=n_sensitive,
        robust_differ=len(robust_differ),
        sensitive_differ=sensitive_differ,
        missing=len(old.keys() - new.keys()),
        extra=len(new.keys() - old.keys()),
        fresh_sensitive=fresh_sensitive,
        bound=sensitive_bound(n_sensitive),
        differing=robust_differ,
    )


__all__ = ["RegressionCheck", "check", "sensitive_bound"]
