"""`housner-linear` (the linear reference block): the config's monolithic column as Spanos and Koh's
piecewise-linear rocking block of the true geometry, run in closed form
(rbm_cli.models.block.closed_form).

The linearised rocking equation of a rigid block on a rigid ground,

    theta'' = p^2 (theta - alpha sgn(theta)) - p^2 a_g(t) / g,

is linear on each side of theta = 0, so between two events it is solved exactly; nothing
is integrated numerically.

References
----------
.. [1] P. D. Spanos and A.-S. Koh (1984). Rocking of rigid blocks due to
   harmonic shaking. Journal of Engineering Mechanics 110(11), 1627-1642.
"""

from __future__ import annotations

from rbm_cli.config.types import SolverConfig
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.models.block.base import BlockRunner
from rbm_cli.models.block.closed_form import linear_block, run_closed_form
from rbm_cli.models.outcome import Outcome


class HousnerLinearRunner(BlockRunner):
    """`housner-linear` (rbm_cli.models.contract.Runner): the block's closed form, compiled
    with `solver.implementation: compiled` (the default) or run uncompiled with `python`;
    a vertical record's gam = (g + a_v) / g taken per piece (rbm_cli.models.block.run). Its
    method is `closed-form` whatever solver.method says (as before `auto` existed, when the
    solver was unused), so configs that name a method still run."""

    def _integrate(self, motion: GroundMotion, solver: SolverConfig, **options) -> Outcome:
        geometry = self.geometry
        block = linear_block(geometry.slenderness, geometry.frequency_parameter,
                             self.restitution, self.config.collapse.ratio,
                             self.config.column.height)  # fmt: skip
        motion = motion.sampled()  # a pulse with no closed form as a record; else itself
        out = run_closed_form(block, motion, *self.initial, solver, **options)
        out.method = "closed-form"
        return out
