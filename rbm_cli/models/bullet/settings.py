"""Engine settings of a `model: bullet` run, from its config.

Its own module so that the run (:mod:`rbm_cli.models.bullet.run`) and the impact
measurement (:mod:`rbm_cli.models.bullet.impact`) both read them without
importing each other.
"""

from __future__ import annotations

from dataclasses import dataclass

from rbm_cli.base.errors import RbmError
from rbm_cli.config.types import Config

#: Bullet caps a contact's friction coefficient at this (btManifoldResult's MAX_FRICTION).
MAX_FRICTION = 10.0


@dataclass(frozen=True)
class EngineSettings:
    """Bullet settings of a run (the scoping values of the contact engine's study, docs/engine.md).

    time_step : float  Fixed engine step [s]
    solver_iterations : int  Sequential-impulse iterations per step
    erp : float  Error reduction parameter of contacts and friction [-]
    friction : float  Coulomb friction coefficient, drum-drum and drum-ground [-]
    """

    time_step: float = 1e-4
    solver_iterations: int = 100
    erp: float = 0.2
    friction: float = 1.0


def settings_from_config(config: Config) -> EngineSettings:
    """The engine settings of a config: its ``solver.time_step`` [s] and
    ``interface.friction`` [-], the rest at their scoped values.

    Raises
    ------
    RbmError  interface.friction above MAX_FRICTION (the engine would cap it quietly).
    """
    friction = config.interface.friction
    if friction > MAX_FRICTION:
        raise RbmError(
            f"interface.friction must be <= {MAX_FRICTION:g} for model bullet (the engine caps"
            f" a contact's friction there), got {friction:g}"
        )
    return EngineSettings(time_step=config.solver.time_step, friction=friction)
