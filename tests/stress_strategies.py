"""Hypothesis strategies over the configurations a user can write.

Every strategy builds a plain mapping, as a YAML file would hold, and passes it
through :func:`rbm_cli.config.load.parse_config`, so each drawn example is a config
that validation accepts. Cost is bounded per example: short durations for
elastic and multi-drum columns (a stiff 8-drum 10 s cell costs seconds), long
durations (up to 100 s) only for rigid monolithic columns, and a solver budget
(``max_steps``, ``max_events``) so that no example can hang: a run that
exceeds it ends with status ``failed`` and a reason.

Strategies return ``(config, amplitude_g, frequency_hz)`` cells, or configs.
"""

from __future__ import annotations

import math

from hypothesis import strategies as st

from rbm_cli.config.load import parse_config
from rbm_cli.config.types import FORMULATIONS
from rbm_cli.structures.column import build_column

#: Per-example solver budget (a run beyond it is 'failed', never a hang).
MAX_STEPS = 200_000
MAX_EVENTS = 20_000
#: Tighter budget for multi-drum columns (an event costs ~0.5 ms with 30+ drums).
MULTI_BUDGET = {"max_steps": 50_000, "max_events": 5_000}

slenderness = st.floats(1.5, 20.0)  # H / B
heights = st.floats(1.0, 12.0)  # m
tapers = st.one_of(st.just(1.0), st.floats(0.6, 1.0))  # top_width / base_width
sections = st.sampled_from(("rectangular", "circular"))
xis = st.one_of(st.just(1.0), st.floats(0.05, 1.0))
restitutions = st.one_of(st.just(1.0), st.floats(0.3, 1.0))
formulations = st.sampled_from(FORMULATIONS)
amplitudes = st.one_of(st.just(0.0), st.floats(0.0, 10.0))  # g
frequencies = st.floats(0.05, 50.0)  # Hz
phases = st.one_of(st.just(0.0), st.floats(0.0, 2.0 * math.pi))


def _round(x: float) -> float:
    """Round to 6 significant digits, as a user writes a number (and for readable reproducers)."""
    return float(f"{x:.6g}")


@st.composite
def column_dicts(draw, n_drums=None):
    """The `column` section: H/B 1.5-20, optional taper and circular section."""
    h = _round(draw(heights))
    ratio = draw(slenderness)
    b = _round(h / ratio)
    col = {
        "height": h,
        "base_width": b,
        "section": draw(sections),
        "density": draw(st.sampled_from((2700.0, 2500.0, 1800.0))),
        "drums": draw(n_drums) if n_drums is not None else 1,
    }
    taper = draw(tapers)
    if taper != 1.0:
        col["top_width"] = _round(b * taper)
    return col


def rocking_stiffness(column: dict) -> float:
    """N_1 zbar_1 [N m/rad]: the slope M_u / theta_u of the law's descending branch at
    interface 1. K_M = r * this gives an elastic frequency ~ sqrt(r) times the rocking p."""
    probe = parse_config(
        {"name": "probe", "column": column, "interface": {"stiffness": {"normal": 1e9}}}
    )
    col = build_column(probe.column, probe.interface)
    return float(col.normal_forces[0] * col.lever_arms[0])


@st.composite
def stiffnesses(draw, column: dict, rigid_ok: bool):
    """`interface.stiffness`: rigid (monolithic), K_M from soft (elastic period near the
    rocking period) to 1e12 N m/rad, or a joint normal stiffness k_n 1e6-1e9 Pa/m."""
    choices = ["soft", "km", "normal"] + (["rigid", "rigid"] if rigid_ok else [])
    kind = draw(st.sampled_from(choices))
    if kind == "rigid":
        return "rigid"
    if kind == "normal":
        return {"normal": _round(10 ** draw(st.floats(6.0, 9.0)))}
    k_rock = rocking_stiffness(column)
    if kind == "soft":
        return {"rotational": _round(k_rock * draw(st.floats(1.5, 10.0)))}
    lo = math.log10(k_rock * 10.0)
    return {"rotational": _round(10 ** draw(st.floats(min(lo, 12.0), 12.0)))}


def _solver(rtol: float = 1e-9, n: int = 1) -> dict:
    if n > 1:
        return {"rtol": rtol, **MULTI_BUDGET}
    return {"rtol": rtol, "max_steps": MAX_STEPS, "max_events": MAX_EVENTS}


def _excitation(draw, kind: str, duration: float, n: int) -> dict:
    exc = {"type": kind, "duration": _round(duration)}
    if kind == "harmonic":
        phase = draw(phases)
        if phase:
            exc["phase"] = _round(phase)
    if kind == "free":
        exc["initial"] = {"velocities": [_round(v) for v in draw(_velocities(n))]}
    return exc


@st.composite
def _velocities(draw, n: int):
    """Initial drum rates [rad/s], not all zero (free motion needs one)."""
    vs = draw(st.lists(st.floats(-2.0, 2.0), min_size=n, max_size=n))
    if not any(abs(v) > 1e-3 for v in vs):
        vs[0] = draw(st.sampled_from((-0.5, 0.05, 1.0)))
    return vs


@st.composite
def any_cells(draw):
    """Any configuration a user can write: rbm (1-50 drums, rigid or elastic, all three
    formulations), housner and housner-linear, under harmonic, half-sine or free motion.
    Returns (config, amplitude_g, frequency_hz)."""
    shape = draw(st.sampled_from(("rigid-mono", "elastic-mono", "multi", "reference")))
    kind = draw(st.sampled_from(("harmonic", "half-sine", "free")))
    if shape == "multi":
        n = draw(st.one_of(st.integers(2, 8), st.integers(9, 50)))
    else:
        n = 1
    column = draw(column_dicts(st.just(n)))
    model = "rbm"
    if shape == "rigid-mono":
        stiffness = "rigid"
        duration = draw(st.floats(0.5, 100.0))
    elif shape == "reference":
        model = draw(st.sampled_from(("housner", "housner-linear")))
        stiffness = "rigid"
        duration = draw(st.floats(0.5, 100.0))
    else:
        stiffness = draw(stiffnesses(column, rigid_ok=False))
        duration = draw(st.floats(0.5, 3.0 if n <= 8 else 1.0))
    interface = {
        "xi": _round(draw(xis)),
        "restitution": _round(draw(restitutions)),
        "formulation": draw(formulations),
    }
    if model == "rbm":
        interface["stiffness"] = stiffness
    else:
        interface.pop("xi")
        interface.pop("formulation")
    data = {
        "name": "stress",
        "model": model,
        "column": column,
        "interface": interface,
        "excitation": _excitation(draw, kind, duration, n),
        "collapse": {"ratio": draw(st.sampled_from((1.0, 1.0, 0.5, 0.9)))},
        "solver": _solver(n=n),
    }
    return parse_config(data), _round(draw(amplitudes)), _round(draw(frequencies))


@st.composite
def monolithic_harmonic_cells(draw, elastic: bool | None = None):
    """Harmonic cells of monolithic rbm columns (rigid or elastic), the non-chaotic
    ones: used by the mirror-symmetry invariant."""
    if elastic is None:
        elastic = draw(st.booleans())
    column = draw(column_dicts())
    if elastic:
        stiffness = draw(stiffnesses(column, rigid_ok=False))
        duration = draw(st.floats(0.5, 3.0))
    else:
        stiffness = "rigid"
        duration = draw(st.floats(0.5, 30.0))
    data = {
        "name": "mirror",
        "column": column,
        "interface": {
            "stiffness": stiffness,
            "xi": _round(draw(xis)),
            "restitution": _round(draw(restitutions)),
        },
        "excitation": {
            "type": "harmonic",
            "duration": _round(duration),
            "phase": _round(draw(st.floats(0.0, math.pi))),
        },
        "solver": _solver(),
    }
    return parse_config(data), _round(draw(amplitudes)), _round(draw(frequencies))


def with_phase(data_config, phase: float):
    """The same config with another harmonic phase (dataclasses are frozen)."""
    import dataclasses

    return dataclasses.replace(
        data_config, excitation=dataclasses.replace(data_config.excitation, phase=phase)
    )


@st.composite
def rigid_monolithic_configs(draw, kinds=("harmonic", "half-sine"), max_duration=100.0):
    """Rigid monolithic rbm configs (cheap: event-driven, at rest below uplift)."""
    column = draw(column_dicts())
    kind = draw(st.sampled_from(kinds))
    data = {
        "name": "rigid",
        "column": column,
        "interface": {
            "stiffness": "rigid",
            "xi": _round(draw(xis)),
            "restitution": _round(draw(restitutions)),
        },
        "excitation": {"type": kind, "duration": _round(draw(st.floats(0.5, max_duration)))},
        "solver": _solver(),
    }
    return parse_config(data)


@st.composite
def free_cells(draw, restitution, drums=None):
    """Free motion (no excitation) of relative/geometric columns, 1-8 drums, from initial
    velocities; `restitution` a strategy of e. Returns a config."""
    n = draw(drums if drums is not None else st.one_of(st.just(1), st.integers(2, 8)))
    column = draw(column_dicts(st.just(n)))
    stiffness = draw(stiffnesses(column, rigid_ok=n == 1))
    data = {
        "name": "free",
        "column": column,
        "interface": {
            "stiffness": stiffness,
            "xi": _round(draw(xis)),
            "restitution": _round(draw(restitution)),
            "formulation": draw(st.sampled_from(("relative", "geometric"))),
        },
        "excitation": {
            "type": "free",
            "duration": _round(draw(st.floats(0.5, 3.0))),
            "initial": {"velocities": [_round(v) for v in draw(_velocities(n))]},
        },
        "solver": _solver(rtol=1e-10, n=n),
    }
    return parse_config(data)


@st.composite
def reference_cells(draw):
    """Convergence cells: rigid monolithic rbm, housner and housner-linear, harmonic or
    half-sine. Returns (config, amplitude_g, frequency_hz)."""
    model = draw(st.sampled_from(("rbm", "housner", "housner-linear")))
    column = draw(column_dicts())
    kind = draw(st.sampled_from(("harmonic", "half-sine")))
    interface = {"restitution": _round(draw(restitutions))}
    if model == "rbm":
        interface["stiffness"] = "rigid"
    data = {
        "name": "conv",
        "model": model,
        "column": column,
        "interface": interface,
        "excitation": {"type": kind, "duration": _round(draw(st.floats(0.5, 30.0)))},
        "solver": _solver(),
    }
    return parse_config(data), _round(draw(amplitudes)), _round(draw(frequencies))
