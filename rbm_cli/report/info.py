"""Derived properties a user checks first (`rbm info`)."""

from __future__ import annotations

import math

from rbm_cli.config.types import Config, G
from rbm_cli.models.rbm.runner import model_from_config


def normal_stiffness(col, i: int) -> float:
    """The joint normal stiffness k_n [Pa/m] of interface i that gives its K_M,i:
    K_M = k_n depth B^3 / 12 (rectangle), k_n pi B^4 / 64 (circle); inf if rigid."""
    k_m, width = float(col.stiffness[i]), float(col.widths[i])
    if col.section == "circular":
        return k_m * 64.0 / (math.pi * width**4)
    return k_m * 12.0 / (float(col.depths[i]) * width**3)


def describe(config: Config) -> dict:
    """Masses, capacities, stiffnesses and frequencies of a configured column.

    The rocking p is that of the rigid stack, p^2 = N_1 zbar_1 / (1^T M 1)
    (for n = 1: m g (H/2) / (I_G + m H^2 / 4)). Elastic frequencies are those
    of the elastic branches of the laws in the chosen formulation. For
    `model: bullet` the figures are the RBM's, plus the engine's own uplift
    level (true solids, min(tan alpha_i, friction) g).
    """
    model = model_from_config(config)
    col = model.column
    n = col.n
    p = model.rocking_p
    freqs = model.elastic_frequencies_hz()
    uplift = model.uplift_level / G if model.uplift_level is not None else None
    interfaces = []
    for i in range(n):
        interfaces.append(
            {
                "interface": i + 1,
                "width_m": float(col.widths[i]),
                "drum_height_m": float(col.heights[i]),
                "drum_mass_kg": float(col.masses[i]),
                "drum_inertia_kgm2": float(col.inertias[i]),
                "normal_force_N": float(col.normal_forces[i]),
                "moment_capacity_Nm": float(col.moment_capacity[i]),
                "rotation_capacity_rad": float(col.rotation_capacity[i]),
                "stiffness_Nm_per_rad": float(col.stiffness[i]),
                "normal_stiffness_Pa_per_m": normal_stiffness(col, i),
                "elastic_limit_rad": float(model.laws[i].elastic_limit),
            }
        )
    engine = {}
    if config.model == "bullet":  # the engine's true solids move at their own level
        from rbm_cli.models.bullet.run import engine_uplift_g

        engine = {"engine_uplift_g": engine_uplift_g(config), "friction": config.interface.friction}
    return {
        "name": config.name,
        "n_drums": n,
        "total_mass_kg": col.total_mass,
        "height_m": col.height,
        "static_multiplier_g": col.static_multiplier,
        "uplift_acceleration_g": uplift,
        "rocking_p_rad_s": p,
        "rocking_frequency_hz": p / (2 * math.pi),
        "elastic_frequencies_hz": freqs,
        "formulation": model.formulation,
        "restitution": model.restitution,
        "interfaces": interfaces,
        **engine,
    }
