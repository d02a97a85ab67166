"""Configs for the library: load one (a file or a dict), change values by key path, check
a cell's amplitude [g] and frequency [Hz] and a history's sampling interval [s]."""

from __future__ import annotations

import copy
import os
import re
from collections.abc import Mapping
from typing import Any

import numpy as np

from rbm_cli.base.errors import ConfigError, RbmError
from rbm_cli.config.load import check_cell as check_amplitude_frequency
from rbm_cli.config.load import finite_number, parse_config, shown
from rbm_cli.config.load import load_config as _load_file
from rbm_cli.config.types import Config
from rbm_cli.config.validate import describe, fmt
from rbm_cli.config.written import plain_copy

__all__ = [
    "MAX_HISTORY_SAMPLES",
    "Config",
    "as_config",
    "check_cell",
    "check_config",
    "check_flag",
    "check_options",
    "check_output_dt",
    "load_config",
    "parse_config",
    "with_value",
    "with_values",
]

#: One key of a key path.
_KEY = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


# --------------------------------------------------------------------------- configs


def load_config(source: str | os.PathLike | Mapping[str, Any]) -> Config:
    """A validated config from a YAML file or from a mapping (a dict).

    Parameters
    ----------
    source : str, path-like or mapping  A YAML file or the mapping it holds (numbers may be
        numpy numbers, lists numpy arrays); lengths [m], stiffnesses [N m/rad] or [Pa/m],
        grid amplitudes [g] and frequencies [Hz] (the configuration reference,
        docs/reference/config.md)

    Returns
    -------
    Config  Frozen, in SI (the grid in g and Hz); ``Config.written`` keeps the mapping

    Raises
    ------
    ConfigError  One line naming the key path (``<dict>: column.height must be ...``)

    Examples
    --------
    >>> import rbm
    >>> cfg = rbm.load_config({"name": "block", "column": {"height": 2.0, "base_width": 0.5}})
    >>> cfg.column.height, cfg.model
    (2.0, 'rbm')
    >>> cfg = rbm.load_config("configs/spanos_koh_slender.yaml")  # doctest: +SKIP
    """
    if isinstance(source, Mapping):
        return parse_config(source, "<dict>")
    if isinstance(source, str | os.PathLike):
        return _load_file(source)
    raise ConfigError(f"a config is a YAML file's path or a mapping, got {type(source).__name__}")


def as_config(config: Config | str | os.PathLike | Mapping[str, Any]) -> Config:
    """``config`` itself, or loaded (:func:`load_config`) from a path or a mapping."""
    return config if isinstance(config, Config) else load_config(config)


def check_config(config: Any, where: str) -> Config:
    """``config``, checked to be a Config (a ConfigError naming ``where`` otherwise)."""
    if not isinstance(config, Config):
        raise ConfigError(
            f"{where}: config must be a Config (from rbm.load_config), got {type(config).__name__}"
        )
    return config


def check_flag(value: Any, name: str) -> bool:
    """``value``, checked to be True or False (a numpy boolean too): a string such as "no"
    or a number is not taken for one (RbmError naming ``name``)."""
    if not isinstance(value, bool | np.bool_):
        raise RbmError(f"{name} must be True or False, got {shown(value)}")
    return bool(value)


def with_values(config: Config, changes: Mapping[str, Any]) -> Config:
    """The config with values changed at dotted key paths, validated again: the changes are
    made on the mapping the user wrote (``config.written``), validated as a file is.

    Parameters
    ----------
    config : Config  A config from :func:`load_config`; it is not changed
    changes : mapping  {key path: value}, paths as error messages name them, in the config's
        units: ``column.height`` [m], ``interface.stiffness.normal`` [Pa/m], ``column.drums``
        (a list is given whole). Missing sections are made; a value on the way that is not
        a mapping (``stiffness: rigid``) is replaced by one

    Returns
    -------
    Config  The new config

    Raises
    ------
    ConfigError  A config that is not a Config, changes that are not a mapping, a
        malformed path, or a bad value (one line naming its key path)

    Examples
    --------
    >>> import rbm
    >>> cfg = rbm.load_config({"name": "block", "column": {"height": 2.0, "base_width": 0.5}})
    >>> taller = rbm.with_values(cfg, {"column.height": 4.0, "interface.restitution": 0.9})
    >>> taller.column.height, taller.interface.restitution, cfg.column.height
    (4.0, 0.9, 2.0)
    """
    check_config(config, "with_values")
    if config.written is None:
        raise ConfigError(f"config {config.name} keeps no written mapping: use rbm.load_config")
    if not isinstance(changes, Mapping):
        raise ConfigError(f"changes must be a mapping {{key path: value}}, got {describe(changes)}")
    written = copy.deepcopy(config.written)
    told = ", ".join(f"{path} = {shown(value)}" for path, value in changes.items())
    source = f"{config.name} with {told}" if told else config.name
    try:
        for path, value in changes.items():
            _set(written, path, plain_copy(value))
    except ConfigError as exc:
        raise ConfigError(f"{source}: {exc}") from None
    return parse_config(written, source, base_dir=config.base_dir)


def with_value(config: Config, path: str, value: Any) -> Config:
    """The config with one value changed at a dotted key path, validated again.

    ``with_value(cfg, path, value)`` is ``with_values(cfg, {path: value})`` (which see).

    Parameters
    ----------
    config : Config  A config from :func:`load_config`; it is not changed
    path : str  A dotted key path (``column.height`` [m], ``interface.restitution`` [-])
    value : any  The new value, in the config's units

    Returns
    -------
    Config  The new config

    Raises
    ------
    ConfigError  A config that is not a Config, a path that is not a string, a malformed
        path, or a bad value (one line naming its key path)

    Examples
    --------
    >>> import rbm
    >>> cfg = rbm.load_config({"name": "block", "column": {"height": 2.0, "base_width": 0.5}})
    >>> rbm.with_value(cfg, "column.height", 6.0).column.height
    6.0
    >>> rbm.with_value(cfg, "column.height", -1.0)
    Traceback (most recent call last):
    ...
    rbm_cli.base.errors.ConfigError: block with column.height = -1: column.height must be a number > 0 [m], got -1
    """  # noqa: E501
    check_config(config, "with_value")
    if not isinstance(path, str):
        raise ConfigError(
            f"{config.name}: with_value takes one key path (a string such as"
            f" 'column.height'), got {type(path).__name__}; several changes:"
            " rbm.with_values(config, {path: value, ...})"
        )
    return with_values(config, {path: value})


def _set(data: dict, path: str, value: Any) -> None:
    """Set ``value`` at a dotted key path in the nested mapping ``data``."""
    keys = path.split(".") if isinstance(path, str) else []
    if not keys or not all(_KEY.fullmatch(key) for key in keys):
        raise ConfigError(f"{path!r} is not a key path (keys joined by dots: column.height)")
    node = data
    for key in keys[:-1]:
        if not isinstance(node.get(key), dict):
            node[key] = {}
        node = node[key]
    node[keys[-1]] = value


# --------------------------------------------------------------------------- cells


#: Most samples a run's history may have (duration / output_dt).
MAX_HISTORY_SAMPLES = 10_000_000


def check_cell(config: Config, amplitude_g: Any, frequency_hz: Any) -> tuple[float, float | None]:
    """(amplitude [g], frequency [Hz] or None) of one cell of ``config``, checked: numbers
    (not booleans) in the grid's ranges; a record has no frequency, ``free`` neither
    (both 0) (rbm_cli.config.load.check_cell).

    Raises
    ------
    RbmError  One line naming the argument, its range and the value given
    """
    return check_amplitude_frequency(config.excitation.type, amplitude_g, frequency_hz)


def check_output_dt(config: Config, output_dt: Any) -> float | None:
    """The history's sampling interval [s], checked: None (the default), or a number > 0
    that gives at most :data:`MAX_HISTORY_SAMPLES` samples over the run.

    Raises
    ------
    RbmError  One line naming the problem
    """
    if output_dt is None:
        return None
    if not (finite_number(output_dt) and output_dt > 0.0):
        raise RbmError(f"output_dt must be a number > 0 [s], got {shown(output_dt)}")
    samples = config.excitation.duration / float(output_dt)
    if samples > MAX_HISTORY_SAMPLES:
        raise RbmError(
            f"output_dt {fmt(float(output_dt))} s gives {samples:.3g} samples over"
            f" {fmt(config.excitation.duration)} s (at most {MAX_HISTORY_SAMPLES:,}):"
            " use a larger output_dt"
        )
    return float(output_dt)


def check_options(config: Config, amplitude: float | None, frequency: float | None):
    """(amplitude [g], frequency [Hz] or None) from the command line's --amplitude and
    --frequency for ``config``'s excitation, checked (rbm_cli.config.load.check_cell: the
    messages name the options).

    Raises
    ------
    RbmError  One line naming the option, its range and the value given
    """
    return check_amplitude_frequency(config.excitation.type, amplitude, frequency, options=True)
