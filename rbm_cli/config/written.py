"""The config as the user wrote it: a plain copy kept beside the validated one."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np


def plain_copy(data: Any) -> Any:
    """A deep copy of a config mapping as plain JSON types (dict with str keys, list, str,
    int, float, bool, None), so that it can be stored in meta.json and validated again.

    Examples
    --------
    >>> plain_copy({"grid": {"amplitudes": (0.1, np.float64(0.2))}})
    {'grid': {'amplitudes': [0.1, 0.2]}}
    """
    if isinstance(data, Mapping):
        return {str(k): plain_copy(v) for k, v in data.items()}
    if isinstance(data, list | tuple):
        return [plain_copy(v) for v in data]
    if isinstance(data, np.generic):
        return data.item()
    return data
