"""Derived properties a user checks first (`rbm info`): the figures, their text, and the
note naming the grid point a run of the config is."""

from __future__ import annotations

import dataclasses
import math

from rbm_cli.config.grid import VIRTUAL_PATHS
from rbm_cli.config.types import MODELS, Config, G, InterfaceConfig, StiffnessConfig
from rbm_cli.structures.assembly import model_from_config
from rbm_cli.structures.block import block_geometry
from rbm_cli.structures.frame import frame_figures, rbm_frame_restitution
from rbm_cli.structures.similarity import rocking_scales


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
    (for n = 1: m g (H/2) / (I_G + m H^2 / 4)); a capital is one of the drums, a top
    mass part of the top drum's mass and inertia (height_m: the shaft and the capital).
    domain_p_rad_s and domain_alpha_rad are the scales a sweep writes in domain.csv's
    p_rad_s and alpha_rad (rbm_cli.structures.similarity: the model's monolith, the true
    solid's for housner and bullet); rocking_p_is and domain_p_is say what each p is
    (:func:`p_meaning`), as `rbm info` prints them.
    Elastic frequencies are those of the elastic branches of the laws in the chosen
    formulation. For `model: bullet` the figures are the RBM's, plus the engine's own uplift
    level (true solids, min(tan alpha_i, friction) g). A frame (columns under a beam) adds
    its figures (:func:`frame_info`; None for a column standing alone).
    """
    model = model_from_config(config)
    col = model.column
    n = col.n
    p = model.rocking_p
    freqs = model.elastic_frequencies_hz()
    uplift = model.uplift_level / G if model.uplift_level is not None else None
    interfaces = []
    for i in range(model.joints):  # a frame's beam joint last: no drum above it
        drum = i < n
        interfaces.append(
            {
                "interface": i + 1,
                "width_m": float(col.widths[i]),
                "drum_height_m": float(col.heights[i]) if drum else None,
                "drum_mass_kg": float(col.masses[i]) if drum else None,
                "drum_inertia_kgm2": float(col.inertias[i]) if drum else None,
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
        # lazy: loads pybullet only where needed (docs/architecture.md, Start-up)
        from rbm_cli.models.bullet.run import engine_uplift_g

        engine = {"engine_uplift_g": engine_uplift_g(config), "friction": config.interface.friction}
    scales = rocking_scales(config)
    geometry = config.column
    capital = geometry.capital
    top = geometry.top_mass
    return {
        "name": config.name,
        "n_drums": n,
        "capital_height_m": None if capital is None else capital.height,
        "capital_width_m": None if capital is None else capital.width,
        "capital_depth_m": None
        if capital is None
        else (capital.width if capital.depth is None else capital.depth),
        "top_mass_kg": None if top is None else top.mass,
        "top_mass_centre_height_m": None if top is None else col.height + top.height_of_centre,
        "total_mass_kg": col.total_mass,
        "height_m": col.height,
        "static_multiplier_g": col.static_multiplier,
        "uplift_acceleration_g": uplift,
        "rocking_p_rad_s": p,
        "rocking_frequency_hz": p / (2 * math.pi),
        "domain_p_rad_s": scales.p,
        "domain_alpha_rad": scales.alpha,
        **p_meaning(config, col.n, float(col.lever_arms[0])),
        "elastic_frequencies_hz": freqs,
        "formulation": model.formulation,
        "restitution": model.restitution,
        "damping": model.damping,
        "damping_ratios": [model.damping * f / freqs[0] for f in freqs] if model.damping else [],
        "interfaces": interfaces,
        **engine,
        **frame_info(config),
    }


#: The figures of a frame in `rbm info`'s data (None each for a column standing alone).
FRAME_KEYS = (
    "frame_columns", "beam_mass_kg", "frame_gamma", "frame_p_rad_s", "frame_half_diagonal_m",
    "frame_restitution", "frame_static_multiplier_g", "frame_block_is",
)  # fmt: skip


def frame_info(config: Config) -> dict:
    """A frame's figures: its columns N, the beam's mass [kg], gamma = m_b / (N m) [-] (m a
    column's mass, drums and capital), and the block its columns glued into rigid
    monoliths rock as under the beam: p_hat [rad/s], R_hat [m] (the size of a block of
    the column's shape that rocks with p_hat alone), eta [-] (Housner's rule for the frame)
    and the acceleration that lifts it [g]. The true solids' exact frame of Makris and
    Vassiliou (rbm_cli.structures.frame.frame_figures) for the reference blocks and the
    engine, the RBM's own (its equivalent block, structures.frame) for the RBM's models.
    None each without a frame."""
    frame = config.frame
    if frame is None:
        return dict.fromkeys(FRAME_KEYS)
    glued = dataclasses.replace(config.column, drum_heights=(config.column.height,))
    if MODELS[config.model].beam:
        rigid = InterfaceConfig(stiffness=StiffnessConfig("rigid", ()))
        alone = model_from_config(dataclasses.replace(config, column=glued, interface=rigid,
                                                      frame=None))  # fmt: skip
        under = model_from_config(dataclasses.replace(config, column=glued, interface=rigid))
        p, p_hat = alone.rocking_p, under.rocking_p
        col = alone.column
        r = math.hypot(float(col.widths[0]) / 2.0, float(col.lever_arms[0]))
        gamma = frame.ratio(col.total_mass)
        values = (gamma, p_hat, r * (p / p_hat) ** 2, rbm_frame_restitution(col, frame),
                  under.column.static_multiplier,
                  "the RBM's equivalent block (its rigid monolithic frame)")  # fmt: skip
    else:
        figures = frame_figures(block_geometry(glued), frame)
        values = (figures.ratio, figures.frequency_parameter, figures.half_diagonal,
                  figures.restitution, figures.static_multiplier,
                  "Makris and Vassiliou's equivalent block (true rigid solids)")  # fmt: skip
    return dict(zip(FRAME_KEYS, (frame.columns, frame.beam_mass, *values), strict=True))


def p_meaning(config: Config, n: int, lever: float) -> dict[str, str]:
    """What each of the two p's is, by name: ``rocking_p_is`` (`rbm info`'s: the RBM's column
    as configured, its n drums rocking as one rigid stack on the base, p^2 = N_1 zbar_1 /
    (1^T M 1)) and ``domain_p_is`` (domain.csv's p_rad_s and alpha_rad: the similarity scales
    of rbm_cli.structures.similarity, the model's own monolith); one line each. ``lever``:
    zbar_1, the height of the weight's resultant above the base [m]."""
    stack = (f"the RBM's {n} drums rocking as one rigid stack on the base (centre of mass at "
             f"zbar_1 = {lever:.4g} m, tan alpha = theta_u,1)" if n > 1 else
             f"the RBM's monolith on its base (its weight at zbar_1 = {lever:.4g} m over the "
             "base's centre: tan alpha = theta_u,1 = (B_1/2)/zbar_1, p^2 = m g zbar_1 / "
             "(I_G + m zbar_1^2))")  # fmt: skip
    if MODELS[config.model].beam and config.column.capital is not None:
        domain = "the RBM's shaft and capital glued into one rigid stack: the rocking p"
    elif MODELS[config.model].beam and n > 1:
        domain = (
            "the RBM's one-drum monolith (the drums glued into one drum of height H: "
            "its weight at H/2, tan alpha = B_1/H), not the stack of the rocking p"
        )
    elif MODELS[config.model].beam:
        domain = "the RBM's monolith: the rocking p"
    elif config.frame is not None:
        domain = (f"the block the frame rocks as ({config.model}: its columns' true "
                  "solids under the beam, tan alpha = b/z_c, p = p_hat), not the RBM's"
                  " rocking p")  # fmt: skip
    else:
        domain = (f"the true solid's ({config.model}: a rigid block, tan alpha = b/z_c with "
                  "z_c its true centre of mass, p^2 = m g R / I_O about the base corner), "
                  "not the RBM's approximation of the rocking p")  # fmt: skip
    return {"rocking_p_is": stack, "domain_p_is": domain}


def _fmt(value, spec: str = ".4g") -> str:
    if value is None:
        return "-"
    if isinstance(value, float) and math.isinf(value):
        return "inf"
    if isinstance(value, int | float):
        return format(value, spec)
    return str(value)


#: Columns of the per-interface table of ``rbm info``: (key, header, unit).
INTERFACE_COLUMNS = (
    ("interface", "i", "-"),
    ("width_m", "B_i", "m"),
    ("drum_height_m", "h_i", "m"),
    ("drum_mass_kg", "m_i", "kg"),
    ("drum_inertia_kgm2", "I_Gi", "kg m2"),
    ("normal_force_N", "N_i", "N"),
    ("moment_capacity_Nm", "M_u,i", "N m"),
    ("rotation_capacity_rad", "theta_u,i", "rad"),
    ("stiffness_Nm_per_rad", "K_M,i", "N m/rad"),
    ("normal_stiffness_Pa_per_m", "k_n,i", "Pa/m"),
    ("elastic_limit_rad", "elastic lim", "rad"),
)


def format_info(info: dict) -> str:
    """The text printed by ``rbm info``: global figures, then one row per interface."""
    n = info.get("n_drums")
    freqs = info.get("elastic_frequencies_hz") or []
    rows = [
        ("name", info.get("name")),
        ("drums", n),
        ("formulation", info.get("formulation")),
        ("total mass", f"{_fmt(info.get('total_mass_kg'))} kg"),
        ("height", f"{_fmt(info.get('height_m'))} m"),
        ("static multiplier", f"{_fmt(info.get('static_multiplier_g'))} g"),
        (
            "uplift acceleration",
            f"{_fmt(info.get('uplift_acceleration_g'))} g"
            if info.get("uplift_acceleration_g") is not None
            else "- (elastic interfaces)",
        ),
        ("rocking p", f"{_fmt(info.get('rocking_p_rad_s'))} rad/s"),
        ("rocking frequency", f"{_fmt(info.get('rocking_frequency_hz'))} Hz"),
        (
            "elastic frequencies",
            (", ".join(_fmt(f) for f in freqs) + " Hz") if freqs else "- (rigid)",
        ),
    ]
    if info.get("damping"):
        ratios = ", ".join(_fmt(z, ".3g") for z in info.get("damping_ratios") or [])
        text = (f"zeta {_fmt(info['damping'])} of the first elastic mode, stiffness-"
                f"proportional: the modes' ratios {ratios}")  # fmt: skip
        rows.append(("damping", text))
    if info.get("domain_p_rad_s") is not None:
        rows.append(("rocking p is", info.get("rocking_p_is") or "-"))
        values = (f"{_fmt(info['domain_p_rad_s'])} rad/s, alpha_rad "
                  f"{_fmt(info.get('domain_alpha_rad'))} rad (domain.csv's scales): ")  # fmt: skip
        rows.append(("domain p_rad_s", values + (info.get("domain_p_is") or "-")))
    if info.get("capital_height_m") is not None:
        size = f"{_fmt(info['capital_width_m'])} x {_fmt(info['capital_depth_m'])} m"
        rows.insert(2, ("capital", f"{_fmt(info['capital_height_m'])} m high, {size} (the top"
                                   " drum)"))  # fmt: skip
    if info.get("top_mass_kg") is not None:
        rows.insert(2, ("top mass", f"{_fmt(info['top_mass_kg'])} kg, centre at "
                                    f"{_fmt(info['top_mass_centre_height_m'])} m above the"
                                    " ground (in the top drum's m_i and I_Gi)"))  # fmt: skip
    if info.get("frame_columns") is not None:
        rows.insert(2, ("frame", f"{info['frame_columns']} columns under a beam of"
                                 f" {_fmt(info['beam_mass_kg'])} kg (gamma"
                                 f" {_fmt(info['frame_gamma'])})"))  # fmt: skip
        rows.append(("frame rocks as", (
            f"{info.get('frame_block_is')}: p_hat"
            f" {_fmt(info['frame_p_rad_s'])} rad/s, R_hat {_fmt(info['frame_half_diagonal_m'])}"
            f" m, eta {_fmt(info['frame_restitution'])}, lifting at"
            f" {_fmt(info['frame_static_multiplier_g'])} g")))  # fmt: skip
    if info.get("engine_uplift_g") is not None:
        rows.append(
            (
                "engine uplift",
                f"{_fmt(info['engine_uplift_g'])} g (model: bullet, true solids, friction "
                f"{_fmt(info.get('friction'))}; the figures above are the RBM's)",
            )
        )
    width = max(len(k) for k, _ in rows)
    lines = [f"{k + ':':<{width + 1}} {v}" for k, v in rows]

    table = [[h for _, h, _ in INTERFACE_COLUMNS], [f"[{u}]" for _, _, u in INTERFACE_COLUMNS]]
    for row in info.get("interfaces", []):
        table.append(
            [
                _fmt(row.get(key), "d" if key == "interface" else ".4g")
                for key, _, _ in INTERFACE_COLUMNS
            ]
        )
    widths = [max(len(r[c]) for r in table) for c in range(len(INTERFACE_COLUMNS))]
    lines.append("")
    lines.append("interfaces (i = 1 at the ground):")
    for r in table:
        lines.append("  ".join(cell.rjust(w) for cell, w in zip(r, widths, strict=True)))
    return "\n".join(lines)


def own_point_note(config: Config) -> str | None:
    """The note of a run of a config whose grid has axes over config keys (a suite of
    records, a column.height axis...): one run is the config's own point, named here;
    None without such axes."""
    axes = config.grid.axes
    if not axes:
        return None
    n_points = math.prod(len(axis.points) for axis in axes)
    own = ", ".join(f"{path} = {_value_at(config, path)}" for path in config.grid.axis_paths)
    return (
        f"the grid has {n_points} points over {', '.join(config.grid.axis_paths)};"
        f" this run is the config's own point ({own}): set another value in the config"
        " to run it, or sweep them all with rbm sweep"
    )


def _value_at(config: Config, path: str) -> str:
    """The value a run of the config takes for a grid axis's key path, as written."""
    if path in VIRTUAL_PATHS:
        return "as written"
    if path in ("excitation.file", "excitation.file_y", "excitation.vertical"):
        return str(getattr(config.excitation, path.split(".")[1]))  # a suite's first record
    node = config.written or {}
    for key in path.split("."):
        node = node.get(key) if isinstance(node, dict) else None
    if node is None:
        return "its default"
    return str(node) if not isinstance(node, dict) else "as written"
