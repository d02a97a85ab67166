"""The one contract every model keeps: a Runner.

A runner is built once per column (``Runner(config)``: the column's equations assembled,
its derived quantities checked, its restitution resolved) and then run once per ground
motion. Everything that may change from one run of the column to the next comes with the
run: the ground motion (amplitude, frequency, phase, duration) and the solver settings (an
ensemble member may tighten the tolerance). Every runner returns the same type,
:class:`rbm_cli.models.outcome.Outcome`, with the sampled history when asked to record.

Adding a model is one module with a class that keeps this contract plus one line in
:data:`rbm_cli.config.types.MODELS` (the registry: model name -> runner class), which the
config validates against and :func:`rbm_cli.models.registry.make_runner` resolves.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

from rbm_cli.config.types import Config, SolverConfig
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.models.outcome import Outcome

#: Sampling interval of a recorded history when the caller gives none [s].
DEFAULT_OUTPUT_DT = 0.002


@runtime_checkable
class Runner(Protocol):
    """A model of one column, built once per config and run once per ground motion.

    Attributes
    ----------
    config : Config  The validated config the runner was built from
    n_interfaces : int  Interfaces (joints) the outcome's per-interface arrays cover
    """

    config: Config
    n_interfaces: int

    def __init__(self, config: Config) -> None: ...

    def run(
        self,
        motion: GroundMotion,
        solver: SolverConfig,
        *,
        record: bool = False,
        output_dt: float = DEFAULT_OUTPUT_DT,
        early_stop: bool = True,
    ) -> Outcome:
        """One run under a ground motion.

        Parameters
        ----------
        motion : GroundMotion  a_g(t) [m/s^2] and the simulated time [s]
        solver : SolverConfig  Tolerances, budgets and implementation of this run
        record : bool  Keep the history, sampled every output_dt [s] (Outcome.history)
        output_dt : float  Sampling interval of the history [s]
        early_stop : bool  Stop once the outcome cannot change (free motion below the
            lowest collapse barrier, a block at rest after its pulse)

        Returns
        -------
        Outcome  Why the run stopped and its summary figures.
        """
        ...
