"""Uncertain keys for the library and ``rbm sensitivity``: the design of a config or of a
stored domain (rbm_cli.config.uncertain), and which key moves a domain's outcome most
(rbm_cli.study.sensitivity), with its tornado figure and files."""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rbm_cli.api.configs import as_config
from rbm_cli.base.errors import RbmError
from rbm_cli.base.files import save_figure_atomic, write_text_atomic
from rbm_cli.config.types import Config
from rbm_cli.report.sensitivity_figure import tornado_figure
from rbm_cli.study.domain import csv_text, read_domain
from rbm_cli.study.fingerprint import read_meta

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["read_design", "sensitivity", "write_sensitivity"]


def _stored_design(path: Path) -> dict | None:
    return read_meta(path if path.is_dir() else path.parent).get("uncertain")


def read_design(source: Config | str | os.PathLike | Mapping[str, Any]) -> pd.DataFrame | None:
    """The design of a config's uncertain keys: a row per sample, the columns of domain.csv
    (``sample``, ``uncertain.<key>``: the value each key takes in that sample, in the key's
    unit in the config: ``column.height`` [m], ``interface.stiffness.normal`` [Pa/m],
    ``interface.restitution`` [-]); ``.attrs["uncertain"]`` holds the keys' distributions,
    the seed and the number of samples. None for a config without an uncertain section.

    Parameters
    ----------
    source : Config, mapping, path  A config (a Config, a mapping or a YAML file), or a
        stored domain (its folder, its domain.csv or its meta.json), whose meta.json holds
        the design it was swept with

    Examples
    --------
    >>> import rbm
    >>> cfg = {"name": "b", "model": "housner", "column": {"height": 2.0, "base_width": 0.5},
    ...        "uncertain": {"samples": 4, "seed": 1,
    ...                      "keys": {"interface.restitution": {"uniform": [0.8, 0.9]}}}}
    >>> design = rbm.read_design(cfg)
    >>> list(design.columns), len(design)
    (['sample', 'uncertain.interface.restitution'], 4)
    """
    # lazy: pandas loads only where needed (docs/architecture.md, Start-up)
    import pandas as pd

    path = Path(source) if isinstance(source, str | os.PathLike) else None
    if path is not None and (path.is_dir() or path.suffix in (".csv", ".json")):
        design = _stored_design(path)
    else:
        config = as_config(source)
        design = None if config.uncertain is None else config.uncertain.design()
    if design is None:
        return None
    columns = design["columns"]
    frame = pd.DataFrame([[k, *v] for k, v in enumerate(design["values"])], columns=columns).astype(
        {columns[0]: "int64"}
    )
    frame.attrs["uncertain"] = {k: design[k] for k in ("samples", "seed", "keys", "method")}
    return frame


def sensitivity(domain: str | os.PathLike | pd.DataFrame) -> pd.DataFrame:
    """Which uncertain key moves a domain's outcome most: per key and outcome (the peak
    rotation ratio, collapsed), Spearman's rank correlation and the partial rank
    correlation coefficient (PRCC, the intensity and the grid's other inputs cleared), each
    in [-1, 1] [-], with their p-values [-] (rbm_cli.study.sensitivity). ``domain``: a
    domain.csv or its table (amplitudes [g], frequencies [Hz]).

    Examples
    --------
    >>> import rbm
    >>> rbm.sensitivity("out/block/domain.csv")  # doctest: +SKIP
    """
    # lazy: pandas and scipy.stats load only where needed (docs/architecture.md, Start-up)
    from rbm_cli.study.sensitivity import sensitivity as measure

    df = domain if not isinstance(domain, str | os.PathLike) else read_domain(domain)
    return measure(df)


def write_sensitivity(domain: str | os.PathLike, output: str | os.PathLike | None = None):
    """sensitivity.csv and the tornado figure sensitivity.png of a stored domain, in
    ``output`` (default: the domain's folder); returns (table, [paths])."""
    domain = Path(domain)
    table = sensitivity(domain)
    folder = Path(output) if output is not None else domain.parent
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise RbmError(f"cannot create {folder}: {exc.strerror or exc}") from None
    rows = table.to_dict("records")
    csv_path = folder / "sensitivity.csv"
    png_path = folder / "sensitivity.png"
    title = f"{domain.parent.name}: sensitivity to the uncertain keys"
    try:
        save_figure_atomic(tornado_figure(table, title), png_path)
        write_text_atomic(csv_path, csv_text(rows, tuple(table.columns)))
    except OSError as exc:
        raise RbmError(f"cannot write into {folder}: {exc.strerror or exc}") from None
    return table, [csv_path, png_path]
