"""What ``rbm info`` and ``rbm run`` tell of a config: its derived figures
(rbm_cli.report.info.describe) as text or JSON, and which grid point a run is."""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from rbm_cli.api.configs import as_config
from rbm_cli.base.errors import RbmError
from rbm_cli.base.files import json_ready
from rbm_cli.config.types import Config
from rbm_cli.report.info import describe, format_info, own_point_note

__all__ = ["describe", "format_info", "info", "info_json", "own_point_note"]


def info_json(config: Config) -> str:
    """``rbm info --json``'s text: :func:`describe`'s figures as indented JSON."""
    return json.dumps(json_ready(describe(config)), indent=2)


if TYPE_CHECKING:
    import pandas as pd


def info(
    config: Config | str | os.PathLike | Mapping[str, Any] | Sequence[Config],
) -> dict | pd.DataFrame:
    """What ``rbm info`` prints of a config, as data: the figures its text is made from.

    Parameters
    ----------
    config : Config, path or mapping, or a list of them  The column(s)

    Returns
    -------
    dict or pandas.DataFrame  For one config a dict, units in the key names: name,
        n_drums (the capital included), capital_height_m, capital_width_m,
        capital_depth_m [m] (None without a capital), top_mass_kg [kg] and
        top_mass_centre_height_m [m above the ground] (None without a top mass),
        total_mass_kg [kg] (the top mass included), height_m [m] (the capital included), static_multiplier_g [g] (B/H for a
        rigid monolith), uplift_acceleration_g [g] (None for elastic interfaces),
        rocking_p_rad_s [rad/s] (the RBM's column rocking as one rigid stack on its base),
        rocking_frequency_hz [Hz], domain_p_rad_s [rad/s] and domain_alpha_rad [rad] (the
        scales a sweep writes in domain.csv's p_rad_s and alpha_rad: the model's monolith,
        the true solid's for housner and bullet), rocking_p_is and domain_p_is (what each
        p is, one line each), elastic_frequencies_hz [Hz]
        (a list; empty when rigid), formulation, restitution [-], damping (interface.damping
        zeta [-]) and damping_ratios (each elastic mode's, zeta f_k / f_1; empty undamped),
        and ``interfaces``, a
        DataFrame with one row per interface (1 at the ground): width_m [m],
        drum_height_m [m], drum_mass_kg [kg], drum_inertia_kgm2 [kg m^2],
        normal_force_N [N], moment_capacity_Nm [N m], rotation_capacity_rad [rad],
        stiffness_Nm_per_rad [N m/rad], normal_stiffness_Pa_per_m [Pa/m] (inf when
        rigid), elastic_limit_rad [rad]; a bullet model adds engine_uplift_g [g] and
        friction [-]. A frame (columns under a beam) adds frame_columns, beam_mass_kg [kg],
        frame_gamma [-] (m_b / (N m)), frame_p_rad_s [rad/s] (p_hat), frame_half_diagonal_m
        [m] (R_hat), frame_restitution [-] (eta), frame_static_multiplier_g [g] and
        frame_block_is (which equivalent block: Makris and Vassiliou's for the rigid blocks
        and the engine, the RBM's own for its models), None each without a frame; a frame
        of drums' ``interfaces`` ends with the beam's joint (no drum above it; a monolith's
        is in its base's law). For a list of
        configs a DataFrame, one row per config (indexed by name) of the figures but
        ``interfaces``

    Raises
    ------
    RbmError  A bad config, or one whose derived figures are not finite (one line)

    Examples
    --------
    p^2 = g (H/2) / ((H^2 + B^2)/12 + H^2/4) for a rigid block: 2.692 rad/s at H = 2 m, B = 0.5 m

    >>> import rbm
    >>> cfg = rbm.load_config({"name": "block", "column": {"height": 2.0, "base_width": 0.5}})
    >>> figures = rbm.info(cfg)  # square 0.5 m x 0.5 m x 2 m, 2700 kg/m^3: m = 1350 kg
    >>> round(figures["static_multiplier_g"], 6), round(figures["rocking_p_rad_s"], 3)  # B/H
    (0.25, 2.692)
    >>> figures["interfaces"][["interface", "width_m", "normal_force_N"]].values.tolist()  # m g
    [[1.0, 0.5, 13243.5]]
    >>> rbm.info([cfg, rbm.with_value(cfg, "column.height", 4.0)])["height_m"].tolist()
    [2.0, 4.0]
    """  # noqa: E501
    # lazy: pandas loads only where needed (docs/architecture.md, Start-up)
    import pandas as pd

    if isinstance(config, list | tuple):
        rows = []
        for k, one in enumerate(config):
            try:
                figures = describe(as_config(one))
            except RbmError as exc:
                raise type(exc)(f"configs[{k}]: {exc}") from None
            figures.pop("interfaces")
            rows.append(figures)
        return pd.DataFrame(rows).set_index("name", drop=False)
    figures = describe(as_config(config))
    figures["interfaces"] = pd.DataFrame(figures["interfaces"])
    return figures
