"""Errors a user can cause. The CLI turns each into one line and a non-zero exit."""


class RbmError(Exception):
    """Base class of user-facing errors (bad input, unwritable output...)."""


class ConfigError(RbmError):
    """A configuration file is missing, malformed or out of range.

    The message names the YAML key path and the allowed range, e.g.
    ``column.height must be > 0 [m], got -1``.
    """
