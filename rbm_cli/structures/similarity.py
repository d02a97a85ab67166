"""The scales of a rocking column that make a domain dimensionless.

Every rocking model here obeys one similarity law: with the slenderness alpha [rad] (the
uplift level is g tan alpha) and the frequency parameter p [rad/s], a ground motion of
amplitude A and circular frequency omega acts on the column only through
A / (g tan alpha) and omega / p (and the restitution, a function of the shape). So two
geometrically similar columns (same alpha) of different size (different p) under
excitations of equal A / (g tan alpha) and omega / p rock alike, in time units 1 / p:
Housner's size effect is that p falls as the size grows, so at one frequency the larger
column sits at a larger omega / p and needs a larger amplitude to overturn.

The scales are those of the column taken as one rigid body (its drums glued), the
column's own first scales however many drums it has:

- ``rbm``: the RBM's rigid monolith (rbm_cli.structures.closed_forms.linear_rocking_parameters:
  tan alpha = theta_u,1, p^2 = m g (H / 2) / (I_G + m H^2 / 4)); with a capital, the shaft
  and the capital as one rigid stack: tan alpha = theta_u,1, p^2 = N_1 zbar_1 / (1^T M 1)
  (rbm_cli.structures.equations.Model.rocking_p); under a frame's beam, the RBM's rigid
  monolithic frame (rbm_cli.structures.frame): its lifting level and Model.rocking_p;
- ``housner``, ``housner-linear``, ``bullet`` (true geometry, rigid blocks): the block's
  tan alpha = b / z_c and p^2 = m g R / I_O (rbm_cli.structures.block.block_geometry); for
  a frame of such columns under a beam, the block it rocks as: its columns' alpha and
  p_hat (rbm_cli.structures.frame), since the frame obeys the same law with p_hat.

The static multiplier is the uniform horizontal acceleration [g] that starts the column
rocking: min over the interfaces of theta_u,i for the RBM (the weakest stack), tan alpha
for a rigid block.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from rbm_cli.config.types import MODELS, Config, InterfaceConfig, StiffnessConfig
from rbm_cli.structures.assembly import model_from_config
from rbm_cli.structures.block import block_geometry
from rbm_cli.structures.closed_forms import linear_rocking_parameters
from rbm_cli.structures.column import build_column
from rbm_cli.structures.equations import build_model
from rbm_cli.structures.frame import frame_block, frame_column


@dataclass(frozen=True)
class RockingScales:
    """alpha [rad], p [rad/s] and the static multiplier [g] of a config's column."""

    alpha: float
    p: float
    static_multiplier: float

    def dimensionless(self, amplitude_g: float, frequency_hz: float | None) -> tuple[float, float]:
        """(A / (g tan alpha), omega / p) of an excitation of amplitude A [g] and frequency
        f [Hz] (omega = 2 pi f); omega / p is NaN without a frequency (a record)."""
        if frequency_hz is None or not math.isfinite(frequency_hz):
            ratio = math.nan
        else:
            ratio = 2.0 * math.pi * frequency_hz / self.p
        return amplitude_g / math.tan(self.alpha), ratio


def rocking_scales(config: Config) -> RockingScales:
    """The scales of a config's column (module docstring); the model decides which."""
    rigid = InterfaceConfig(stiffness=StiffnessConfig("rigid", ()))
    column = build_column(config.column, rigid)
    glued = dataclasses.replace(config.column, drum_heights=(config.column.height,))
    if MODELS[config.model].beam and config.frame is not None:
        # the RBM's rigid monolithic frame (structures.frame): its lifting level and p
        frame = model_from_config(dataclasses.replace(config, column=glued, interface=rigid))
        static = frame_column(column, config.frame, rigid).static_multiplier
        return RockingScales(math.atan(frame.column.static_multiplier), frame.rocking_p, static)
    if MODELS[config.model].beam and config.column.capital is not None:
        # shaft and capital glued into one rigid stack: its base's theta_u and its p
        p = build_model(build_column(glued, rigid)).rocking_p
        tan_alpha = float(column.rotation_capacity[0])
        return RockingScales(math.atan(tan_alpha), p, column.static_multiplier)
    if MODELS[config.model].beam:
        tan_alpha, p = linear_rocking_parameters(build_column(glued, rigid))
        return RockingScales(math.atan(tan_alpha), p, column.static_multiplier)
    block = block_geometry(glued)
    if config.frame is not None:
        block = frame_block(block, config.frame)
    tan_alpha = math.tan(block.slenderness)
    static = tan_alpha if config.column.n_drums == 1 else min(tan_alpha, column.static_multiplier)
    return RockingScales(block.slenderness, block.frequency_parameter, static)


__all__ = ["RockingScales", "rocking_scales"]
