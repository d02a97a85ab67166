"""What the two single-block reference models share as runners: the true block of the
config's monolithic column (rbm_cli.structures.block), or the block a frame of such columns
under a beam rocks as (rbm_cli.structures.frame), its restitution, its initial state and
its history. Each model says only how it integrates one run (`_integrate`)."""

from __future__ import annotations

import numpy as np

from rbm_cli.config.types import Config, SolverConfig
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.models.contract import DEFAULT_OUTPUT_DT
from rbm_cli.models.history import history_from_samples
from rbm_cli.models.outcome import Outcome
from rbm_cli.structures.block import block_geometry, block_initial
from rbm_cli.structures.frame import frame_block, frame_restitution
from rbm_cli.structures.restitution import block_restitution, resolve


class BlockRunner:
    """A single rigid block (rbm_cli.models.contract.Runner); subclasses give `_integrate`.

    Attributes
    ----------
    geometry : BlockGeometry  The true block of the column, or of a frame of such columns
        under a beam the equivalent block (rbm_cli.structures.frame.frame_block)
    restitution : float  e [-] (Housner's, of the true block or the frame, for 'housner')
    initial : (float, float)  theta0 [rad], rate0 [rad/s]
    """

    n_interfaces = 1

    def __init__(self, config: Config) -> None:
        self.config = config
        column, frame = block_geometry(config.column), config.frame
        self.geometry = column if frame is None else frame_block(column, frame)
        self.restitution = resolve(
            config.interface.restitution,
            lambda: (
                block_restitution(column) if frame is None else frame_restitution(column, frame)
            ),
        )
        self.initial = block_initial(config)
        self.node_map = np.array([[0.0], [config.column.height]])

    def _integrate(self, motion: GroundMotion, solver: SolverConfig, **options) -> Outcome:
        raise NotImplementedError

    def run(
        self,
        motion: GroundMotion,
        solver: SolverConfig,
        *,
        record: bool = False,
        output_dt: float = DEFAULT_OUTPUT_DT,
        early_stop: bool = True,
    ) -> Outcome:
        """One run (rbm_cli.models.contract.Runner.run)."""
        t_lift = motion.lift_off  # a vertical record dropping faster than gravity
        if t_lift is not None:
            motion = motion.until(t_lift)
        out = self._integrate(
            motion, solver, record=record, output_dt=output_dt, early_stop=early_stop
        ).lifted_off(t_lift)
        if record:
            out.history = history_from_samples(self.node_map, motion, out.samples)
        return out
