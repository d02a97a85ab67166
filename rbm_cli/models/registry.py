"""The registry: a config's `model` name -> its runner class (the contract in
:mod:`rbm_cli.models.contract`).

The table itself is :data:`rbm_cli.config.types.MODELS`, so that the config validates a
model name against the same line that names its runner. Runner modules are imported only
when a config asks for them: a sweep of the RBM never imports PyBullet or scipy's
integrators.
"""

from __future__ import annotations

import importlib

from rbm_cli.config.types import MODELS, Config
from rbm_cli.models.contract import Runner


def runner_class(name: str) -> type:
    """The runner class registered under a model name (KeyError if none)."""
    module, _, cls = MODELS[name].runner.partition(":")
    return getattr(importlib.import_module(module), cls)


def make_runner(config: Config) -> Runner:
    """The runner of a config's model, built for its column."""
    return runner_class(config.model)(config)


def model_names() -> tuple[str, ...]:
    """Every registered model name."""
    return tuple(MODELS)
