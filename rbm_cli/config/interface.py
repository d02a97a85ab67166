"""The ``interface`` section of a config: joint stiffness, xi, restitution, formulation.

The stiffness is written with its unit explicit: ``rigid``, ``{rotational: K_M}``
(a joint bending stiffness [N m/rad], one value or one per interface) or
``{normal: k_n}`` (a joint normal stiffness [Pa/m], from which K_M,i follows). A bare
number or list is refused: 5e9 read as K_M is a column 20x stiffer than 5e9 read as k_n,
and the file cannot say which the user meant.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from rbm_cli.base.errors import ConfigError
from rbm_cli.config.types import FORMULATIONS, MODELS, InterfaceConfig, StiffnessConfig
from rbm_cli.config.validate import (
    SOUND_WHY,
    choice,
    describe,
    fmt,
    in_bounds,
    is_number,
    mapping,
    number,
    number_list,
)

INTERFACE_KEYS = ("stiffness", "xi", "restitution", "formulation", "friction", "damping")
STIFFNESS_KEYS = ("rotational", "normal")
#: Stiffnesses the tool accepts [assumption]: far beyond any stone joint on either side,
#: and inside the range where K_M theta^2, K_M / I and their products stay finite.
ROTATIONAL_RANGE = (1e-3, 1e30)  # K_M [N m/rad]
NORMAL_RANGE = (1e-3, 1e20)  # k_n [Pa/m]
FRICTION_MAX = 100.0
BOTH_FORMS = "{rotational: K_M} [N m/rad] or {normal: k_n} [Pa/m]"


def interface_section(
    raw: Any, n: int, model: str = "rbm", beam_joint: bool = False
) -> InterfaceConfig:
    """Validate the ``interface`` mapping of a column of n drums for a model; beam_joint:
    the column carries a frame's beam on a joint of its own above the top drum (a list of
    K_M then has n + 1 values, the beam joint's last)."""
    i = mapping(raw, "interface", INTERFACE_KEYS)
    if "friction" in i and not (model == "bullet" or MODELS[model].beam):
        beams = " and ".join(name for name, entry in MODELS.items() if entry.beam)
        raise ConfigError(
            f"interface.friction applies only to models bullet (its contacts) and {beams}"
            f" (their friction demand is checked against it); model {model} computes no"
            " friction demand: delete it"
        )
    friction = number(i.get("friction", 1.0), "interface.friction", "", 0.0)
    if friction > FRICTION_MAX:
        raise ConfigError(
            f"interface.friction must be at most {fmt(FRICTION_MAX)}, got {fmt(friction)}"
        )
    damping = damping_value(i, model)
    stiffness = i.get("stiffness", "rigid")
    if model == "bullet" and isinstance(stiffness, str) and stiffness == "rigid":
        n = 1  # the engine's drums are rigid; the RBM's joint law is not used
    restitution = i.get("restitution", 1.0)
    if isinstance(restitution, str) and restitution == "housner":
        if n != 1:
            raise ConfigError(
                f"interface.restitution: housner needs a monolithic column (drums: 1), got {n}"
                " drums; give a number in (0, 1]"
            )
    elif is_number(restitution):
        restitution = number(restitution, "interface.restitution", "", 0.0, 1.0)
    else:
        raise ConfigError(
            f"interface.restitution must be a number in (0, 1] or housner, got"
            f" {describe(restitution)}"
        )
    stiffness = stiffness_value(
        i.get("stiffness", "rigid"), n, given="stiffness" in i, beam_joint=beam_joint
    )
    if damping > 0.0 and stiffness.kind == "rigid":
        raise ConfigError(
            "interface.damping damps the joints' elastic branch, which a rigid interface does"
            f" not have: give {BOTH_FORMS} as interface.stiffness, or delete interface.damping"
        )
    return InterfaceConfig(
        stiffness=stiffness,
        xi=number(i.get("xi", 1.0), "interface.xi", "", 0.0, 1.0),
        restitution=restitution,
        formulation=choice(i.get("formulation", "relative"), "interface.formulation", FORMULATIONS),
        friction=friction,
        friction_limit=friction if MODELS[model].beam and "friction" in i else None,
        damping=damping,
    )


def damping_value(i: Mapping, model: str) -> float:
    """``interface.damping``: the ratio zeta of critical damping of the first elastic mode,
    a number in [0, 1) (the Rigid Beam Model's joints only; 0 when not given)."""
    if "damping" not in i:
        return 0.0
    if not MODELS[model].beam:
        beams = " and ".join(name for name, entry in MODELS.items() if entry.beam)
        raise ConfigError(
            f"interface.damping applies only to models {beams} (model is {model}, which has"
            " no elastic joints to damp): delete it"
        )
    return number(i["damping"], "interface.damping", "", 0.0, 1.0, lo_open=False, hi_open=True)


def stiffness_value(
    value: Any, n: int, *, given: bool = True, beam_joint: bool = False
) -> StiffnessConfig:
    """``rigid``, ``{rotational: K_M or [K_M,i]}`` or ``{normal: k_n}`` (beam_joint: a
    frame's beam joint above the n drums' takes the list's last value)."""
    path = "interface.stiffness"
    if isinstance(value, str) and value == "rigid":
        if n > 1:
            raise ConfigError(
                f"{path}: rigid{'' if given else ' (the default)'} needs a monolithic column"
                f" (drums: 1); give {BOTH_FORMS} for multi-drum columns"
            )
        return StiffnessConfig("rigid", ())
    if is_number(value) or isinstance(value, list | tuple):
        what = "number" if is_number(value) else "list"
        raise ConfigError(
            f"{path}: a bare {what} does not say its unit: write {BOTH_FORMS},"
            f" got {describe(value)}"
        )
    if isinstance(value, Mapping):
        m = mapping(value, path, STIFFNESS_KEYS)
        if len(m) != 1:
            raise ConfigError(f"{path} needs exactly one of rotational and normal: {BOTH_FORMS}")
        if "rotational" in m:
            return _rotational(m["rotational"], n, beam_joint)
        sub = f"{path}.normal"
        k_n = number(m["normal"], sub, "Pa/m", 0.0, inf_hint="use rigid for an infinite stiffness")
        return StiffnessConfig("normal", (in_bounds(k_n, sub, "Pa/m", NORMAL_RANGE, SOUND_WHY),))
    raise ConfigError(
        f"{path} must be rigid, {BOTH_FORMS} (K_M one value or a list with one per interface),"
        f" got {describe(value)}"
    )


def _rotational(value: Any, n: int, beam_joint: bool = False) -> StiffnessConfig:
    path = "interface.stiffness.rotational"
    if isinstance(value, list | tuple):
        per = f"one K_M per interface ({n} for {n} drum{'s' if n > 1 else ''})"
        if beam_joint:
            per = f"one K_M per interface ({n + 1}: {n} of the drums, then the beam's joint)"
        length = n + 1 if beam_joint else n
        values = number_list(value, path, "N m/rad", 0.0, length=length, length_text=per)
        for i, k in enumerate(values):
            in_bounds(k, f"{path}[{i}]", "N m/rad", ROTATIONAL_RANGE, SOUND_WHY)
        return StiffnessConfig("moment", values)
    k_m = number(value, path, "N m/rad", 0.0, inf_hint="use rigid for an infinite stiffness")
    return StiffnessConfig(
        "moment", (in_bounds(k_m, path, "N m/rad", ROTATIONAL_RANGE, SOUND_WHY),)
    )
