"""The model of a config, assembled once and checked before any run: the column's
equations (rbm_cli.structures.equations.Model, with the restitution rule resolved) and the
one limit a ground motion sets on them (the time a vertical record changes the order of a
law's pieces). Every integrator of the Rigid Beam Model takes the Model built here."""

from __future__ import annotations

import math

import numpy as np

from rbm_cli.base.errors import RbmError
from rbm_cli.config.types import Config, G
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.structures.column import Column, build_column
from rbm_cli.structures.equations import Model, build_model
from rbm_cli.structures.frame import frame_column, rbm_frame_restitution
from rbm_cli.structures.restitution import column_restitution, resolve

#: Why a run stops where g + a_v(t) changes the order of a law's pieces (shape_change).
SHAPE_CHANGE = (
    "g + a_v(t) changes the order of a joint law's pieces (the elastic end xi gam M_u / K_M"
    " passes the cap's end theta_u (1 - xi)), which this version does not integrate"
    " (excitation.vertical)"
)


def shape_change(model: Model, motion: GroundMotion) -> float | None:
    """First time [s] gam = (g + a_v(t)) / g leaves Model.shape_range() (the pieces of
    every law keep their order inside it), or None. a_v is linear between the knots."""
    if motion.vertical is None:
        return None
    lo, hi = model.shape_range()
    if lo <= 0.0 and hi == math.inf:
        return None
    gam = 1.0 + np.asarray(motion.vertical) / G
    bad = (gam < lo) | (gam > hi)
    if not bad.any():
        return None
    k = int(np.argmax(bad))
    knots = motion.knots
    if k == 0 or knots[k] == knots[k - 1]:
        return float(knots[k])
    limit = lo if gam[k] < lo else hi
    frac = (limit - gam[k - 1]) / (gam[k] - gam[k - 1])
    return float(knots[k - 1] + (knots[k] - knots[k - 1]) * frac)


def model_from_config(config: Config, column: Column | None = None) -> Model:
    """Assemble the model of a config (column may be overridden, e.g. in tests).

    Raises RbmError if a derived quantity (mass, inertia, capacity, stiffness, the
    mass matrix or its inverse, a law's pieces, p) is not finite: see check_derived."""
    with np.errstate(over="ignore", invalid="ignore", divide="ignore", under="ignore"):
        if column is None:
            column = build_column(config.column, config.interface)
            if config.frame is not None:  # columns under a beam (structures.frame)
                alone, frame = column, config.frame
                column = frame_column(alone, frame, config.interface)
                e = resolve(
                    config.interface.restitution, lambda: rbm_frame_restitution(alone, frame)
                )
        if config.frame is None or column.beam_mass == 0.0:
            e = resolve(config.interface.restitution, lambda: column_restitution(column))
        try:
            model = build_model(
                column,
                xi=config.interface.xi,
                restitution=float(e),
                formulation=config.interface.formulation,
                collapse_ratio=config.collapse.ratio,
                damping=config.interface.damping,
            )
        except (ArithmeticError, ValueError, np.linalg.LinAlgError) as exc:
            raise RbmError(
                f"the column's model cannot be assembled ({type(exc).__name__}: {exc}): its"
                " inputs are outside the range where the arithmetic is sound"
            ) from None
        check_derived(model)
    return model


def check_derived(model: Model) -> None:
    """Every derived quantity of a model finite (and positive where it must be), before a
    run starts: a density of 1e307 once made masses overflow and a collapsing column
    report 'survived'. Raises RbmError naming the first bad quantity."""
    col = model.column
    n = col.n  # a frame's beam joint: its weight at the joint (lever 0, theta_u inf)
    positive = {
        "drum masses": col.masses,
        "drum inertias": col.inertias,
        "normal forces N_i": col.normal_forces,
        "moment capacities M_u,i": col.moment_capacity,
        "rotation capacities theta_u,i": col.rotation_capacity[:n],
        "lever arms": col.lever_arms[:n],
    }
    finite = {
        "mass matrix": model.mass,
        "inverse mass matrix": model.mass_inv,
        "gravity matrix": model.gravity,
        "ground load": model.ground_load,
        "collapse limits": model.collapse_limit,
    }
    for i, law in enumerate(model.laws):
        finite[f"law of interface {i + 1}"] = np.concatenate(
            [law.edges, law.intercepts, law.slopes]
        )
    stiff = col.stiffness
    bad_stiffness = not np.all(np.isinf(stiff) | (np.isfinite(stiff) & (stiff > 0)))
    for name, values in positive.items():
        v = np.asarray(values, dtype=float)
        if not (np.all(np.isfinite(v)) and np.all(v > 0)):
            derived_error(name, v)
    for name, values in finite.items():
        v = np.asarray(values, dtype=float)
        if not np.all(np.isfinite(v)):
            derived_error(name, v)
    if bad_stiffness:
        derived_error("joint stiffnesses K_M,i", stiff)
    p = model.rocking_p
    if not (math.isfinite(p) and p > 0):
        derived_error("rocking parameter p", np.array([p]))


def derived_error(name: str, values: np.ndarray) -> None:
    """RbmError: a derived quantity of the column (named) is not finite and positive."""
    shown = ", ".join(f"{x:.4g}" for x in values.ravel()[:3])
    raise RbmError(
        f"the column's {name} are not finite and positive ({shown}...): the inputs are"
        " outside the range where the arithmetic is sound (check column sizes, density"
        " and interface.stiffness)"
    )
