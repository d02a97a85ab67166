"""YAML -> validated, typed config (SI units inside). Imports only rbm_cli.base."""

from rbm_cli.config.load import load_config, parse_config
from rbm_cli.config.types import Config

__all__ = ["Config", "load_config", "parse_config"]
