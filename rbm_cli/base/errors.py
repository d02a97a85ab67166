"""Errors a user can cause. The CLI turns each into one line and a non-zero exit."""


class RbmError(Exception):
    """Base class of user-facing errors (bad input, unwritable output...).

    Its message is one line naming the problem: the argument or key with its range and
    unit, or the file and its line.

    Examples
    --------
    >>> import rbm
    >>> try:
    ...     rbm.run({"name": "b", "column": {"height": 2.0, "base_width": 0.5}}, -0.1, 1.0)
    ... except rbm.RbmError as exc:
    ...     print(exc)
    amplitude_g must be a number in [0, 1000] [g], got -0.1
    """


class ConfigError(RbmError):
    """A configuration file is missing, malformed or out of range.

    The message names the YAML key path and the allowed range, e.g.
    ``column.height must be > 0 [m], got -1``.

    Examples
    --------
    >>> import rbm
    >>> cfg = rbm.load_config({"name": "b", "column": {"height": 2.0, "base_width": 0.5}})
    >>> try:
    ...     rbm.with_value(cfg, "column.height", -1)
    ... except rbm.ConfigError as exc:
    ...     print(exc)
    b with column.height = -1: column.height must be a number > 0 [m], got -1
    """
