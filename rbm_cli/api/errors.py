"""The errors the library raises: one line each, for a user to read."""

from __future__ import annotations

from rbm_cli.base.errors import ConfigError, RbmError
from rbm_cli.base.files import OutputError

__all__ = ["ConfigError", "OutputError", "RbmError"]
