"""Numerical constants against the answers they could move: a constant changed 100-fold,
a grid run with it, the difference from the unchanged code.

    python tools/constants.py list                       # the variants and the grids
    python tools/constants.py run EVENT_EPS REST_RATE    # measure these variants
    python tools/constants.py run EVENT_EPS --grids slender,halfsine
    python tools/constants.py show                       # the measurements made so far

A variant is a temporary copy of the package (rbm_cli and rbm) with its constants edited
(each edit must find its text exactly once, or the variant is refused: a constant that
moved in the code is never measured as if it had not). Each grid then runs in a process of
its own whose PYTHONPATH is the copy and whose NUMBA_CACHE_DIR is a fresh folder: numba
freezes a module's constants into the compiled code, so the copy compiles anew. The
unchanged code runs the same grids the same way (its results kept per source digest under
--work, default /tmp/rbm-constants). Nothing is written into the working tree.

What is compared, cell by cell: the outcome (status and collapse interface), the peaks
(max_rotation_ratio, max_top_displacement_m), the collapse time, the counts (n_uplifts,
n_impacts), the intensity measures of a record suite, and, for information, the friction
demand. A grid whose stored domain (results/) holds a `robust` column is judged on the
cells it marks robust (the others are chaotic: their outcome is not an answer of the model
at any tolerance); its other cells are counted apart.

A constant is divided by 100, or multiplied by 100 where a larger value is the stricter
one (the variant's `change` says which); an integer count where 100-fold makes no sense
says what it is set to and why.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("rbm_cli", "rbm")
WORK = Path(tempfile.gettempdir()) / "rbm-constants"

#: The result fields of a domain row that are answers (the rest: the cell, the work done).
OUTCOME = ("status", "collapse_interface")
PEAKS = ("max_rotation_ratio", "max_top_displacement_m")
COUNTS = ("n_uplifts", "n_impacts")
MEASURES = ("pga_g", "pgv_m_s", "pgd_m", "arias_m_s", "cav_m_s", "d5_95_s", "sa_t1_g")
#: A variant's value that scales every amplitude of the grid by 1 + it (the control: what
#: moves when the input moves by rounding, the robustness rule's smallest perturbation).
NUDGE = "_nudge"
#: The last column of a row's cell: the columns before "status" are its axes.
FIRST_RESULT = "status"


@dataclass(frozen=True)
class Grid:
    """A grid to measure on: a config (a file of the repository or a mapping), the values
    set in it (dotted keys, rbm.with_values; "grid" replaces the grid), and the stored
    domain whose `robust` column says which cells are not chaotic."""

    what: str
    config: str | dict
    values: dict = field(default_factory=dict)
    stored: str | None = None


def _cylinder(model: str, drums: int, restitution: float, **interface) -> dict:
    return {
        "name": f"{model}_grid",
        "model": model,
        "column": {
            "height": 3.0 if drums == 1 else 4.0,
            "base_width": 0.75 if drums == 1 else 0.8,
            "top_width": 0.75 if drums == 1 else 0.65,
            "section": "circular",
            "density": 2500,
            "drums": drums,
        },  # fmt: skip
        "interface": {"restitution": restitution, "formulation": "relative", **interface},
        "excitation": {"type": "harmonic", "duration": 6.0, "angle": 30.0},
        "collapse": {"ratio": 1.0},
    }


#: The 4 m x 1 m rigid monolith of the block grids.
BLOCK_COLUMN = {"height": 4.0, "base_width": 1.0, "section": "rectangular", "depth": 1.0,
                "density": 2700, "drums": 1}  # fmt: skip
BULLET = {
    "name": "bullet_block",
    "model": "bullet",
    "column": dict(BLOCK_COLUMN),
    "excitation": {"type": "harmonic", "duration": 3.0},
    "collapse": {"ratio": 1.0},
}
HOUSNER_3D = _cylinder("housner-3d", 1, 0.9, stiffness="rigid")
RBM_3D = _cylinder("rbm-3d", 4, 1.0, stiffness={"normal": 1e9})
RICKER = {
    "name": "ricker_block",
    "model": "rbm",
    "column": dict(BLOCK_COLUMN),
    "interface": {"stiffness": "rigid", "restitution": "housner"},
    "excitation": {"type": "ricker", "duration": 10.0},
    "collapse": {"ratio": 1.0},
}

RECORD_BLOCK = {
    **RICKER,
    "name": "record_block",
    "excitation": {
        "type": "record",
        "file": str(ROOT / "configs/records/synthetic/rdk_*.AT2"),
        "units": "g",
        "scale": "pga",
        "free_time": 5.0,
    },  # fmt: skip
    "grid": {"amplitudes": [0.2, 0.3, 0.5, 0.8]},
}
RICKER_GRID = {"amplitudes": [0.2, 0.3, 0.4, 0.6, 0.8, 1.2], "frequencies": [0.5, 1.0, 2.0, 4.0]}

GRIDS: dict[str, Grid] = {
    "multidrum": Grid(
        "8 drums, k_n 5e9 Pa/m, e 1, harmonic 10 s, the chaotic band along the boundary "
        "(66 cells, DOP853)",
        "configs/ci/harmonic_multidrum_ci.yaml",
        stored="results/harmonic_multidrum_ci/domain.csv",
    ),
    "multidrum-exact": Grid(
        "the same 66 cells, solver.method exact",
        "configs/ci/harmonic_multidrum_ci.yaml",
        {"solver.method": "exact"},
        stored="results/harmonic_multidrum_ci/domain.csv",
    ),
    "suite": Grid(
        "8 drums under 4 synthetic records x 10 PGAs, 5 s of free motion after (40 cells, DOP853)",
        "configs/ci/suite_multidrum_ci.yaml",
        stored="results/suite_multidrum_ci/domain.csv",
    ),
    "suite-exact": Grid(
        "the same 40 record cells, solver.method exact",
        "configs/ci/suite_multidrum_ci.yaml",
        {"solver.method": "exact"},
        stored="results/suite_multidrum_ci/domain.csv",
    ),
    "damped": Grid(
        "the 8-drum band with 5 % joint damping (66 cells, DOP853)",
        "configs/harmonic_multidrum_damped.yaml",
        stored="results/harmonic_multidrum_damped/domain.csv",
    ),
    "slender": Grid(
        "rigid block H/B 4, e 1, harmonic 10 s (468 cells, closed form)",
        "configs/spanos_koh_slender.yaml",
        stored="results/spanos_koh_slender/domain.csv",
    ),
    "slender-step": Grid(
        "the same block, DOP853 (every other row of amplitudes: 240 cells)",
        "configs/spanos_koh_slender.yaml",
        {
            "solver.method": "DOP853",
            "grid.amplitudes": {"start": 0.1, "stop": 2.0, "step": 0.1},
        },  # fmt: skip
        stored="results/spanos_koh_slender/domain.csv",
    ),
    "slender-e": Grid(
        "rigid block H/B 4, Housner's e (0.91), harmonic 10 s (468 cells, closed form)",
        "configs/spanos_koh_slender_housner_e.yaml",
        stored="results/spanos_koh_slender_housner_e/domain.csv",
    ),
    "halfsine": Grid(
        "rigid monolith H/B 5.2 under half-sine pulses, then free motion to 20 s (1770 "
        "cells, closed form)",
        "configs/housner_halfsine.yaml",
        stored="results/housner_halfsine/domain.csv",
    ),
    "housner-e": Grid(
        "`housner`, the block H/B 4 with e 0.91, harmonic 10 s (a 20 x 6 sub-grid: 0.1-2 g "
        "by 0.1, 0.5-3 Hz by 0.5)",
        "configs/spanos_koh_slender_housner_e_housner.yaml",
        {
            "grid": {
                "amplitudes": {"start": 0.1, "stop": 2.0, "step": 0.1},
                "frequencies": [0.5, 1.0, 1.5, 2.0, 2.5, 3.0],
            }
        },  # fmt: skip
        stored="results/spanos_koh_slender_housner_e_housner/domain.csv",
    ),
    "housner-halfsine": Grid(
        "`housner`, the half-sine monolith (a 15 x 8 sub-grid: 0.2-3 g by 0.2, 0.2-3 Hz by 0.4)",
        "configs/housner_halfsine_housner.yaml",
        {
            "grid": {
                "amplitudes": {"start": 0.2, "stop": 3.0, "step": 0.2},
                "frequencies": {"start": 0.2, "stop": 3.0, "step": 0.4},
            }
        },  # fmt: skip
        stored="results/housner_halfsine_housner/domain.csv",
    ),
    "ricker": Grid(
        "`housner-linear`, the block H/B 4, e 0.91, Ricker pulses (the closed form on the "
        "pulse sampled; 6 x 4 cells: 0.2-1.2 g, 0.5-4 Hz)",
        RICKER,
        {"model": "housner-linear", "grid": RICKER_GRID},
    ),
    "ricker-step": Grid(
        "the same Ricker cells, `rbm` (DOP853 on the pulse's formula)",
        RICKER,
        {"grid": RICKER_GRID},
    ),
    "records-block": Grid(
        "rigid block H/B 4, e 0.91, under the 20 synthetic records at 0.2, 0.3, 0.5, 0.8 g "
        "and 5 s of free motion (80 cells, closed form): a block that comes to rest",
        RECORD_BLOCK,
    ),
    "records-housner": Grid(
        "the same 80 record cells, `housner`",
        RECORD_BLOCK,
        {"model": "housner"},
    ),
    "suite-im": Grid(
        "the intensity measures of the 20 synthetic records (suite_monolithic at 0.5 g)",
        "configs/suite_monolithic.yaml",
        {"grid.amplitudes": [0.5]},
    ),
    "bullet": Grid(
        "`bullet`, the block 4 x 1 m, harmonic 3 s (3 x 3 cells: 0.3, 0.7, 1.1 g x 0.5, 1.5, "
        "2.5 Hz)",
        BULLET,
        {"grid": {"amplitudes": [0.3, 0.7, 1.1], "frequencies": [0.5, 1.5, 2.5]}},
    ),
    "housner-3d": Grid(
        "`housner-3d`, cylinder D 0.75 m, H 3 m, e 0.9, harmonic at 30 deg, 6 s (4 x 3 cells)",
        HOUSNER_3D,
        {"grid": {"amplitudes": [0.2, 0.3, 0.4, 0.5], "frequencies": [0.5, 1.0, 2.0]}},
    ),
    "rbm-3d": Grid(
        "`rbm-3d`, 4 circular drums H 4 m, D 0.8-0.65 m, k_n 1e9, e 1, harmonic at 30 deg, "
        "6 s (3 x 2 cells)",
        RBM_3D,
        {"grid": {"amplitudes": [0.2, 0.3, 0.4], "frequencies": [1.5, 2.92]}},
    ),
}


STORED = "stored:"


def grid_spec(name: str) -> Grid:
    """A grid of GRIDS, or "stored:NAME": the whole grid of configs/NAME.yaml, judged on
    the cells results/NAME/domain.csv calls robust (to see whether a change would move a
    stored domain)."""
    if name.startswith(STORED):
        study = name[len(STORED) :]
        return Grid(f"the stored study {study}", f"configs/{study}.yaml",
                    stored=f"results/{study}/domain.csv")  # fmt: skip
    return GRIDS[name]


@dataclass(frozen=True)
class Variant:
    """Constants changed together (each edit: file, text, replacement; the text must occur
    exactly once), how (the change), and the grids that run code reading them. Constants
    of different integrators share a variant only where no grid runs two of them. A
    setting of the config (values: dotted keys) is changed in the grids instead."""

    constants: tuple[str, ...]
    change: str
    edits: tuple[tuple[str, str, str], ...]
    grids: tuple[str, ...]
    values: dict = field(default_factory=dict)


EVENTS = "rbm_cli/base/events.py"
STEP_EVENTS = "rbm_cli/models/rbm/step/events.py"
SEARCH = "rbm_cli/models/rbm/exact/search.py"
BOUNDS = "rbm_cli/models/rbm/exact/bounds.py"
BLOCK = "rbm_cli/models/block/piece.py"
RBM3D = "rbm_cli/models/rbm3d/kernel.py"
H3D = "rbm_cli/models/housner3d/runner.py"
ARRAYS = "rbm_cli/structures/arrays.py"
REST_NOW = "REST_RATE = math.sqrt(200.0 * EVENT_EPS)"
RK = "rbm_cli/numerics/rk.py"

VARIANTS: dict[str, Variant] = {
    "NUDGE": Variant(
        ("(control: no constant)",),
        "every amplitude x (1 + 1e-12): what moves when the input moves by rounding",
        (),
        tuple(GRIDS),
        {NUDGE: 1e-12},
    ),
    "NUDGE_MINUS": Variant(
        ("(control: no constant)",),
        "every amplitude x (1 - 1e-12)",
        (),
        ("multidrum", "multidrum-exact", "suite", "suite-exact", "damped", "rbm-3d"),
        {NUDGE: -1e-12},
    ),
    "NUDGE_10": Variant(
        ("(control: no constant)",),
        "every amplitude x (1 + 1e-10)",
        (),
        ("multidrum", "multidrum-exact", "suite", "suite-exact", "damped", "rbm-3d"),
        {NUDGE: 1e-10},
    ),
    "EVENT_EPS": Variant(
        ("EVENT_EPS",),
        "1e-12 -> 1e-14 (/100)",
        ((EVENTS, "EVENT_EPS = 1e-12", "EVENT_EPS = 1e-14"),),
        (
            "multidrum",
            "multidrum-exact",
            "suite",
            "slender",
            "slender-step",
            "slender-e",
            "halfsine",
            "housner-e",
            "housner-3d",
            "rbm-3d",
        ),  # fmt: skip
    ),
    "STOP_MARGIN": Variant(
        ("STOP_MARGIN", "below_barrier"),
        "1e-9 -> 1e-11 (/100; the same margin, written twice)",
        (
            (EVENTS, "STOP_MARGIN = 1e-9", "STOP_MARGIN = 1e-11"),
            ("rbm_cli/models/rbm/pieces.py", "barrier * (1.0 - 1e-9)", "barrier * (1.0 - 1e-11)"),
        ),  # fmt: skip
        ("halfsine", "housner-halfsine", "suite", "suite-exact", "ricker"),
    ),
    # REST_RATE is sqrt(200 EVENT_EPS) = 1.4e-5 (it was 1e-3 until the measurement below
    # showed that 1e-3 moved an answer and 1e-4 and 1e-5 did not); below sqrt(2 EVENT_EPS)
    # = 1.4e-6 the hops sink under the event offset and a Zeno sequence never ends.
    "REST_RATE": Variant(
        ("REST_RATE",),
        "sqrt(200 EVENT_EPS) = 1.4e-5 -> 1.4e-7 (/100: below the floor 1.4e-6, where a "
        "Zeno sequence never ends; expected to fail runs)",
        ((ARRAYS, REST_NOW, "REST_RATE = math.sqrt(200.0 * EVENT_EPS) / 100.0"),),
        ("records-block",),
    ),
    "REST_RATE_1E5": Variant(
        ("REST_RATE",),
        "sqrt(200 EVENT_EPS) = 1.4e-5 -> 1e-5 (/1.4; 1/100 of the former 1e-3)",
        ((ARRAYS, REST_NOW, "REST_RATE = 1e-5"),),
        (
            "slender",
            "slender-step",
            "slender-e",
            "halfsine",
            "housner-e",
            "ricker",
            "housner-3d",
            "records-block",
            "records-housner",
        ),
    ),
    "REST_RATE_X10": Variant(
        ("REST_RATE",),
        "sqrt(200 EVENT_EPS) = 1.4e-5 -> 1.4e-4 (x10)",
        ((ARRAYS, REST_NOW, "REST_RATE = 10.0 * math.sqrt(200.0 * EVENT_EPS)"),),
        ("records-block", "records-housner"),
    ),
    "REST_RATE_FORMER": Variant(
        ("REST_RATE",),
        "sqrt(200 EVENT_EPS) = 1.4e-5 -> 1e-3 (x71: the former value)",
        ((ARRAYS, REST_NOW, "REST_RATE = 1e-3"),),
        (
            "records-block",
            "records-housner",
            "housner-3d",
            "slender-step",
            "ricker",
            "stored:spanos_koh_thick_housner_e",
            "stored:spanos_koh_thick_linear",
            "stored:spanos_koh_slender_linear",
            "stored:spanos_koh_thick_housner_e_housner",
        ),
    ),
    "CHECK_INTERVALS": Variant(
        ("CHECK_INTERVALS",),
        "8 -> 800 sub-intervals of a step (x100: more is stricter)",
        (
            (EVENTS, "CHECK_INTERVALS = 8", "CHECK_INTERVALS = 800"),
            (STEP_EVENTS, "CHECK_INTERVALS = 8", "CHECK_INTERVALS = 800"),
            (RBM3D, "CHECK_INTERVALS = 8", "CHECK_INTERVALS = 800"),
        ),  # fmt: skip
        ("multidrum", "suite", "slender-step", "housner-e", "housner-3d", "rbm-3d"),
    ),
    "ROOT_XTOL": Variant(
        (
            "step XTOL",
            "block XTOL",
            "exact ROOT_XTOL",
            "housner xtol",
            "housner-3d xtol",
            "rbm-3d XTOL",
        ),  # fmt: skip
        "the event roots' absolute tolerance /100 (1e-14 -> 1e-16 s, 1e-15 -> 1e-17 s); "
        "each grid runs one of them",
        (
            (STEP_EVENTS, "XTOL, RTOL, MAXITER = 1e-14,", "XTOL, RTOL, MAXITER = 1e-16,"),
            (BLOCK, "XTOL, RTOL = 1e-15,", "XTOL, RTOL = 1e-17,"),
            (SEARCH, "ROOT_XTOL = 1e-15", "ROOT_XTOL = 1e-17"),
            (
                "rbm_cli/models/housner/runner.py",
                "hit = first_crossing(rows, t_old, t_hit, xtol=1e-15)",
                "hit = first_crossing(rows, t_old, t_hit, xtol=1e-17)",
            ),
            (
                "rbm_cli/models/housner/steps.py",
                "t_old, t_new, xtol=1e-15)",
                "t_old, t_new, xtol=1e-17)",
            ),
            (
                H3D,
                "hit = first_crossing(rows, t_old, integ.t, xtol=1e-15)",
                "hit = first_crossing(rows, t_old, integ.t, xtol=1e-17)",
            ),
            (
                H3D,
                "lean_rate(dense(t)), t_old, t_new, xtol=1e-15)",
                "lean_rate(dense(t)), t_old, t_new, xtol=1e-17)",
            ),
            (RBM3D, "XTOL, RTOL, MAXITER = 1e-15,", "XTOL, RTOL, MAXITER = 1e-17,"),
        ),  # fmt: skip
        (
            "multidrum",
            "multidrum-exact",
            "suite",
            "slender",
            "halfsine",
            "housner-e",
            "housner-3d",
            "rbm-3d",
        ),  # fmt: skip
    ),
    "MIN_STEP": Variant(
        ("MIN_STEP",),
        "1e-13 -> 1e-15 (/100, of the time)",
        ((SEARCH, "MIN_STEP = 1e-13", "MIN_STEP = 1e-15"),),
        ("multidrum-exact", "suite-exact"),
    ),
    "PEAK_RTOL": Variant(
        ("PEAK_RTOL",),
        "1e-12 -> 1e-14 (/100)",
        ((SEARCH, "PEAK_RTOL = 1e-12", "PEAK_RTOL = 1e-14"),),
        ("multidrum-exact", "suite-exact"),
    ),
    "STATIONARY_GAP": Variant(
        ("STATIONARY_GAP",),
        "1e-9 -> 1e-11 (/100)",
        ((SEARCH, "STATIONARY_GAP = 1e-9", "STATIONARY_GAP = 1e-11"),),
        ("multidrum-exact", "suite-exact"),
    ),
    "FIRST_STEP": Variant(
        ("FIRST_STEP",),
        "1e-3 -> 1e-5 s (/100)",
        (("rbm_cli/models/rbm/exact/run.py", "FIRST_STEP = 1e-3", "FIRST_STEP = 1e-5"),),
        ("multidrum-exact", "suite-exact"),
    ),
    "STEP_GUESS": Variant(
        ("initial_step",),
        "the first step's guess after every event (scipy's select_initial_step: h0 = 0.01 "
        "d0/d1, h1 = (0.01/max(d1, d2))^(1/(order+1))) with 0.0001 for 0.01 (/100)",
        (
            (RK, "else 0.01 * d0 / d1", "else 0.0001 * d0 / d1"),
            (RK, "h1 = pow_pos(0.01 / max(d1, d2)", "h1 = pow_pos(0.0001 / max(d1, d2)"),
        ),  # fmt: skip
        ("multidrum", "slender-step", "rbm-3d"),
    ),
    "SAFETY": Variant(
        ("exact SAFETY",),
        "1 + 1e-9 -> 1 + 1e-7 (the bounds' inflation x100: larger is stricter)",
        ((BOUNDS, "SAFETY = 1.0 + 1e-9", "SAFETY = 1.0 + 1e-7"),),
        ("multidrum-exact", "suite-exact"),
    ),
    "BOUND_CHOICE": Variant(
        ("ENVELOPE_RATIO", "HYPERBOLIC_LIMIT"),
        "8 -> 0.08 and 4 -> 0.04 (/100: which of two valid bounds is used)",
        (
            (BOUNDS, "ENVELOPE_RATIO = 8.0", "ENVELOPE_RATIO = 0.08"),
            (BOUNDS, "HYPERBOLIC_LIMIT = 4.0", "HYPERBOLIC_LIMIT = 0.04"),
        ),  # fmt: skip
        ("multidrum-exact", "suite-exact"),
    ),
    "SCAN_STEP": Variant(
        ("SCAN_STEP",),
        "1 -> 0.01 (/100, of 1/p or 1/omega)",
        ((BLOCK, "SCAN_STEP = 1.0", "SCAN_STEP = 0.01"),),
        ("slender", "slender-e", "halfsine", "ricker"),
    ),
    "HALVINGS": Variant(
        ("MIN_WIDTH", "MAX_HALVINGS"),
        "1e-12 -> 1e-14 (/100) and 40 -> 4000 halvings (x100; the width binds first)",
        (
            (BLOCK, "MAX_HALVINGS = 40", "MAX_HALVINGS = 4000"),
            (BLOCK, "MIN_WIDTH = 1e-12", "MIN_WIDTH = 1e-14"),
        ),  # fmt: skip
        ("slender", "slender-e", "halfsine", "ricker"),
    ),
    "BISECTION_STEPS": Variant(
        ("BISECTION_STEPS",),
        "200 -> 20000 (x100: more is stricter)",
        (("rbm_cli/inputs/ground.py", "BISECTION_STEPS = 200", "BISECTION_STEPS = 20000"),),
        ("ricker-step", "slender-step"),
    ),
    "SAMPLES_PER_PERIOD": Variant(
        ("SAMPLES_PER_PERIOD",),
        "2000 -> 200000 samples a period of a pulse made a record (x100: more is stricter)",
        (
            (
                "rbm_cli/inputs/motion.py",
                "SAMPLES_PER_PERIOD = 2000",
                "SAMPLES_PER_PERIOD = 200000",
            ),
        ),  # fmt: skip
        ("ricker",),
    ),
    "DAMPING_DIGITS": Variant(
        ("DAMPING_DIGITS",),
        "10 -> 12 significant digits (the rounding of f_1 100x finer)",
        (("rbm_cli/structures/equations.py", "DAMPING_DIGITS = 10", "DAMPING_DIGITS = 12"),),
        ("damped",),
    ),
    "TIME_STEP": Variant(
        ("solver.time_step",),
        "1e-4 -> 1e-6 s (/100; a config setting, the engine's fixed step)",
        (),
        ("bullet",),
        {"solver.time_step": 1e-6},
    ),
    "TIME_STEP_10": Variant(
        ("solver.time_step",),
        "1e-4 -> 1e-5 s (/10)",
        (),
        ("bullet",),
        {"solver.time_step": 1e-5},
    ),
    "CHECK_DT": Variant(
        ("CHECK_DT",),
        "1e-3 -> 1e-5 s (/100: the engine's checks at every step)",
        (("rbm_cli/models/bullet/watch.py", "CHECK_DT = 1e-3", "CHECK_DT = 1e-5"),),
        ("bullet",),
    ),
    "OPEN_FRACTION": Variant(
        ("OPEN_FRACTION",),
        "1e-3 -> 1e-5 of alpha (/100)",
        (("rbm_cli/models/bullet/watch.py", "OPEN_FRACTION = 1e-3", "OPEN_FRACTION = 1e-5"),),
        ("bullet",),
    ),
    "IM_STEPS": Variant(
        ("FREE_STEPS", "INNER_POINTS"),
        "400 -> 40000 and 65 -> 6500 (x100: more is stricter)",
        (
            ("rbm_cli/inputs/intensity.py", "FREE_STEPS = 400", "FREE_STEPS = 40000"),
            ("rbm_cli/inputs/intensity.py", "INNER_POINTS = 65", "INNER_POINTS = 6500"),
        ),
        ("suite-im",),
    ),
}


# ------------------------------------------------------------------ the copy and the runs
def source_digest(root: Path) -> str:
    """SHA-256 of the package sources under root (the unchanged code's results are kept
    under it: a change to any source runs them again)."""
    h = hashlib.sha256()
    for package in PACKAGES:
        for path in sorted((root / package).rglob("*.py")):
            h.update(str(path.relative_to(root)).encode())
            h.update(path.read_bytes())
    return h.hexdigest()[:16]


def make_copy(edits, into: Path) -> Path:
    """A copy of the packages under into/src with the edits made; RbmError-free: a
    ValueError names an edit whose text is not found exactly once."""
    src = into / "src"
    for package in PACKAGES:
        shutil.copytree(ROOT / package, src / package,
                        ignore=shutil.ignore_patterns("__pycache__"))  # fmt: skip
    for rel, old, new in edits:
        path = src / rel
        text = path.read_text()
        if text.count(old) != 1:
            raise ValueError(f"{rel}: {old!r} found {text.count(old)} times, not once")
        path.write_text(text.replace(old, new))
    return src


def run_grid(grid: str, pythonpath: Path, cache: Path | None, out: Path,
             values: dict | None = None) -> dict:  # fmt: skip
    """Run one grid in a process of its own (the code under pythonpath, numba's cache in
    cache, or numba's default; the config values set in the grid's); the domain to out
    (CSV). Returns what ran: the package's path, CPU and wall time [s], cells."""
    env = dict(
        os.environ, PYTHONPATH=str(pythonpath), RBM_CONSTANTS_VALUES=json.dumps(values or {})
    )
    if cache is not None:
        env["NUMBA_CACHE_DIR"] = str(cache)
    cmd = ["nice", "-n", "5", sys.executable, str(Path(__file__).resolve()), "_worker", grid,
           str(out)]  # fmt: skip
    t0 = time.time()
    done = subprocess.run(cmd, env=env, cwd=tempfile.gettempdir(), capture_output=True,
                          text=True)  # fmt: skip
    if done.returncode != 0:
        raise RuntimeError(f"grid {grid} failed:\n{done.stderr[-3000:]}")
    info = json.loads(done.stdout.strip().splitlines()[-1])
    if not info["package"].startswith(str(pythonpath)):
        raise RuntimeError(f"grid {grid} imported {info['package']}, not the copy")
    info["wall_s"] = round(time.time() - t0, 1)
    return info


def worker(grid: str, out: str) -> None:
    """In the copy's process: run the grid, write its domain, print what ran."""
    import rbm
    import rbm_cli

    spec = grid_spec(grid)
    cfg = spec.config if isinstance(spec.config, dict) else str(ROOT / spec.config)
    cfg = rbm.load_config(cfg)
    values = {**spec.values, **json.loads(os.environ.get("RBM_CONSTANTS_VALUES", "{}"))}
    nudge = values.pop(NUDGE, 0.0)
    if values:
        cfg = rbm.with_values(cfg, values)
    if nudge:
        amplitudes = [a * (1.0 + nudge) for a in cfg.grid.amplitudes_g]
        cfg = rbm.with_value(cfg, "grid.amplitudes", amplitudes)
    t0 = time.process_time()
    df = rbm.sweep(cfg, jobs=1)
    df.to_csv(out, index=False, float_format="%.17g")
    print(json.dumps({"package": rbm_cli.__file__, "cpu_s": round(time.process_time() - t0, 1),
                      "cells": len(df)}))  # fmt: skip


# ------------------------------------------------------------------ the comparison
def _key(df):
    cols = list(df.columns[: list(df.columns).index(FIRST_RESULT)])
    return cols


def _rounded(df, cols):
    out = df.copy()
    for c in cols:
        if out[c].dtype.kind == "f":
            out[c] = out[c].round(9)
    return out


def _rel(a, b):
    """Largest relative change |a - b| / |b| (0 where both are 0; NaN where none)."""
    import numpy as np

    a, b = np.asarray(a, float), np.asarray(b, float)
    ok = np.isfinite(a) & np.isfinite(b)
    if not ok.any():
        return math.nan
    d = np.abs(a[ok] - b[ok])
    s = np.abs(b[ok])
    r = np.where(d == 0.0, 0.0, d / np.where(s > 0.0, s, np.inf))
    r = np.where((d > 0.0) & (s == 0.0), np.inf, r)
    return float(r.max())


def compare(base_csv: Path, var_csv: Path, stored: str | None) -> dict:
    """What moved between the unchanged code's domain and the variant's (see the module)."""
    import numpy as np
    import pandas as pd

    base, var = pd.read_csv(base_csv), pd.read_csv(var_csv)
    key = _key(base)
    base, var = _rounded(base, key), _rounded(var, key)
    both = base.merge(var, on=key, suffixes=("_b", "_v"), how="inner", validate="1:1")
    if len(both) != len(base) or len(both) != len(var):
        raise RuntimeError(f"the grids differ: {len(base)} and {len(var)} cells")
    robust = np.ones(len(both), dtype=bool)
    if stored is not None:
        st = pd.read_csv(ROOT / stored)
        skey = [c for c in key if c in st.columns]
        st = _rounded(st, skey)[skey + ["robust"]]
        both = both.merge(st, on=skey, how="left", validate="m:1")
        if both["robust"].isna().any():
            raise RuntimeError(f"{both['robust'].isna().sum()} cells not in {stored}")
        robust = both["robust"].to_numpy() == 1

    def same(c):
        b, v = both[c + "_b"], both[c + "_v"]
        return ((b == v) | (b.isna() & v.isna())).to_numpy()

    outcome = same("status")
    answers = [*OUTCOME, "t_collapse_s", *PEAKS, *COUNTS]
    identical = np.logical_and.reduce([same(c) for c in answers])
    collapsed = outcome & (both["status_b"] == "collapsed").to_numpy()
    survived = outcome & (both["status_b"] != "collapsed").to_numpy()
    counted = np.logical_and.reduce([same(c) for c in COUNTS])

    def on(mask):
        sub = both[mask]
        kept, col, sur = outcome[mask], collapsed[mask], survived[mask]
        res = {
            "cells": int(mask.sum()),
            "identical": int(identical[mask].sum()),
            "outcomes_differ": int((~kept).sum()),
            "which": [
                {
                    **{k: (None if pd.isna(r[k]) else r[k]) for k in key},
                    "base": r["status_b"],
                    "variant": r["status_v"],
                }
                for _, r in sub[~kept].iterrows()
            ][:12],  # fmt: skip
            "collapsed": int(col.sum()),
            "interface_differs": int((col & ~same("collapse_interface")[mask]).sum()),
            "t_collapse_rel": _rel(sub["t_collapse_s_v"][col], sub["t_collapse_s_b"][col]),
            "survived": int(sur.sum()),
            "counts_differ": int((kept & ~counted[mask]).sum()),
            "counts_rel": max(_rel(sub[c + "_v"][kept], sub[c + "_b"][kept]) for c in COUNTS),
        }
        for c in PEAKS:  # of the cells that survive in both (a collapse's peak is its limit)
            res[c + "_rel"] = _rel(sub[c + "_v"][sur], sub[c + "_b"][sur])
        if "friction_demand_b" in sub:
            res["friction_demand_rel"] = _rel(sub["friction_demand_v"][kept],
                                              sub["friction_demand_b"][kept])  # fmt: skip
        ims = [c for c in MEASURES if c + "_b" in sub]
        if ims:
            res["measures_rel"] = max(_rel(sub[c + "_v"], sub[c + "_b"]) for c in ims)
        return res

    out = {"robust": on(robust)}
    if (~robust).any():
        out["chaotic"] = on(~robust)
    return out


def _base_csv(grid: str, work: Path) -> Path:
    """The unchanged code's domain of a grid (run once per source digest)."""
    folder = work / f"base-{source_digest(ROOT)}"
    folder.mkdir(parents=True, exist_ok=True)
    out = folder / f"{grid}.csv"
    if not out.exists():
        info = run_grid(grid, ROOT, None, out.with_suffix(".tmp.csv"))
        out.with_suffix(".tmp.csv").rename(out)
        (folder / f"{grid}.json").write_text(json.dumps(info))
    return out


def measure(name: str, grids: list[str] | None, work: Path, keep: bool) -> dict:
    """One variant on its grids (or those named): the comparison per grid, saved as
    work/<name>.json (merged with earlier grids of the same variant)."""
    var = VARIANTS[name]
    grids = list(var.grids) if grids is None else grids
    tmp = Path(tempfile.mkdtemp(prefix=f"rbm-const-{name}-"))
    path = work / f"{name}.json"
    saved = json.loads(path.read_text()) if path.exists() else {"grids": {}}
    try:
        # a setting of the config alone runs the unchanged code (its compiled cache too)
        src, cache = (make_copy(var.edits, tmp), tmp / "numba-cache") if var.edits else (ROOT, None)
        for grid in grids:
            base = _base_csv(grid, work)
            out = tmp / f"{grid}.csv"
            info = run_grid(grid, src, cache, out, var.values)
            res = compare(base, out, grid_spec(grid).stored)
            res.update(info, when=time.strftime("%Y-%m-%d %H:%M"), load=os.getloadavg())
            saved["grids"][grid] = res
            print(name, grid, json.dumps(res["robust"]), flush=True)
            shutil.copy(out, work / f"{name}.{grid}.csv")
    finally:
        if not keep:
            shutil.rmtree(tmp, ignore_errors=True)
    saved.update(constants=var.constants, change=var.change, source=source_digest(ROOT),
                 machine=f"{platform.machine()}, {os.cpu_count()} cores")  # fmt: skip
    path.write_text(json.dumps(saved, indent=1, default=str))
    return saved


def _fmt(x) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "-"
    return "0" if x == 0 else f"{x:.1e}"


def _line(r: dict) -> str:
    """One comparison (compare's 'robust' or 'chaotic' part) in a line."""
    out = (
        f"{r['cells']:4d} cells, {r['identical']:4d} identical; status {r['outcomes_differ']}"
        f" differ; {r['collapsed']} collapse: t_c {_fmt(r['t_collapse_rel'])}, interface"
        f" {r['interface_differs']}; {r['survived']} survive: peak"
        f" {_fmt(r['max_rotation_ratio_rel'])}, top {_fmt(r['max_top_displacement_m_rel'])};"
        f" counts {r['counts_differ']} ({_fmt(r['counts_rel'])})"
    )
    if "measures_rel" in r:
        out += f"; IM {_fmt(r['measures_rel'])}"
    return out


def show(work: Path, names: list[str] | None = None) -> None:
    """Per variant and grid, recomputed from the domains kept in work: the cells the stored
    domain calls robust (their outcome, collapse times and interfaces, peaks and counts),
    the chaotic ones' outcomes, and under it the control's line (NUDGE) on the same grid."""
    control = work / "NUDGE.json"
    control = json.loads(control.read_text()) if control.exists() else {"grids": {}}
    for name in names or list(VARIANTS):
        path = work / f"{name}.json"
        if not path.exists():
            continue
        saved = json.loads(path.read_text())
        print(f"{name}: {saved['change']}")
        for grid, info in saved["grids"].items():
            base = work / f"base-{saved['source']}" / f"{grid}.csv"
            res = compare(base, work / f"{name}.{grid}.csv", grid_spec(grid).stored)
            ch = res.get("chaotic")
            print(
                f"  {grid:17s} {_line(res['robust'])}"
                + (f" | chaotic {ch['cells']}: status {ch['outcomes_differ']}" if ch else "")
                + f" | {info['when']} load {info['load'][0]:.1f}, {info['cpu_s']} s CPU"
            )
            if name != "NUDGE" and grid in control["grids"]:
                ref = compare(base, work / f"NUDGE.{grid}.csv", grid_spec(grid).stored)
                ch = ref.get("chaotic")
                print(
                    f"  {'  control':17s} {_line(ref['robust'])}"
                    + (f" | chaotic {ch['cells']}: status {ch['outcomes_differ']}" if ch else "")
                )


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    sub.add_parser("list")
    b = sub.add_parser("base", help="run the unchanged code's grids (kept per source digest)")
    b.add_argument("grids", nargs="*", default=list(GRIDS))
    b.add_argument("--work", type=Path, default=WORK)
    r = sub.add_parser("run")
    r.add_argument("variants", nargs="+", choices=list(VARIANTS))
    r.add_argument("--grids", help="comma-separated grids (default: the variant's)")
    r.add_argument("--work", type=Path, default=WORK)
    r.add_argument("--keep", action="store_true", help="keep the copy (for a look)")
    s = sub.add_parser("show")
    s.add_argument("variants", nargs="*", choices=[*VARIANTS, []])
    s.add_argument("--work", type=Path, default=WORK)
    w = sub.add_parser("_worker")
    w.add_argument("grid")
    w.add_argument("out")
    args = ap.parse_args(argv)
    if args.cmd == "list":
        for name, v in VARIANTS.items():
            found = all((ROOT / rel).read_text().count(old) == 1 for rel, old, _ in v.edits)
            print(
                f"{name}: {', '.join(v.constants)}: {v.change}; grids {', '.join(v.grids)}"
                + ("" if found else "  [an edit's text is not in the code once]")
            )
        for name, g in GRIDS.items():
            print(f"  grid {name}: {g.what}")
    elif args.cmd == "base":
        args.work.mkdir(parents=True, exist_ok=True)
        for grid in args.grids:
            print(grid, _base_csv(grid, args.work), flush=True)
    elif args.cmd == "run":
        args.work.mkdir(parents=True, exist_ok=True)
        for name in args.variants:
            grids = args.grids.split(",") if args.grids else None
            measure(name, grids, args.work, args.keep)
    elif args.cmd == "show":
        show(args.work, args.variants)
    else:
        worker(args.grid, args.out)


if __name__ == "__main__":
    main()
