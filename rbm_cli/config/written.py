"""The config as the user wrote it: a plain copy kept beside the validated one."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from rbm_cli.base.errors import ConfigError

#: Deepest nesting a config mapping may have (a config is 4 levels deep; lists of lists
#: of a grid add a few): deeper is not a config, and would exhaust Python's recursion.
MAX_DEPTH = 32


def plain_copy(data: Any) -> Any:
    """A deep copy of a config mapping as plain JSON types (dict with str keys, list, str,
    int, float, bool, None), so that it can be stored in meta.json and validated again.
    numpy numbers become the numbers they are, numpy arrays lists (a 0-d array its one
    number).

    Raises
    ------
    ConfigError  A mapping or list nested deeper than :data:`MAX_DEPTH` levels, or one
        that holds itself (a cycle), in one line.

    Examples
    --------
    >>> plain_copy({"grid": {"amplitudes": (0.1, np.float64(0.2))}})
    {'grid': {'amplitudes': [0.1, 0.2]}}
    >>> plain_copy({"column": {"height": np.array(2.0)}})
    {'column': {'height': 2.0}}
    """
    return _copy(data, 0, set())


def _copy(data: Any, depth: int, open_ids: set[int]) -> Any:
    if isinstance(data, np.ndarray):
        data = data.tolist()  # plain numbers, nested lists (a 0-d array: its number)
    if isinstance(data, np.generic):
        return data.item()
    if not isinstance(data, Mapping | list | tuple):
        return data
    if depth >= MAX_DEPTH:
        raise ConfigError(f"the config nests mappings or lists more than {MAX_DEPTH} levels deep")
    if id(data) in open_ids:
        raise ConfigError("the config holds itself (a mapping or list inside itself)")
    open_ids.add(id(data))
    try:
        if isinstance(data, Mapping):
            return {str(k): _copy(v, depth + 1, open_ids) for k, v in data.items()}
        return [_copy(v, depth + 1, open_ids) for v in data]
    finally:
        open_ids.discard(id(data))
