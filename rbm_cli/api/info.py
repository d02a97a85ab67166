"""What ``rbm info`` and ``rbm run`` tell of a config: its derived figures
(rbm_cli.report.info.describe) as text or JSON, and which grid point a run is."""

from __future__ import annotations

import json

from rbm_cli.base.files import json_ready
from rbm_cli.config.types import Config
from rbm_cli.report.info import describe, format_info, own_point_note

__all__ = ["describe", "format_info", "info_json", "own_point_note"]


def info_json(config: Config) -> str:
    """``rbm info --json``'s text: :func:`describe`'s figures as indented JSON."""
    return json.dumps(json_ready(describe(config)), indent=2)
