"""`model: bullet`'s library pieces beside the run: the physics client a run is
given or opens, the per-step probe (`observe`) and the contact-normal census, the
engine's e for `housner`, the time-step agreement summaries, and what
tools/make_engine.py computes through them.

Expected values come from statics (a block at rest carries its weight on the
ground's normal), from hand-built outcome tables, and from runs of the same cell
made the other way (own client against a given one, probed against not).
"""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from rbm_cli.base.errors import RbmError
from rbm_cli.config.load import parse_config
from rbm_cli.config.types import G
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.models.bullet.convergence import (
    ensemble_agreement,
    outcome_marks,
    step_agreement,
)
from rbm_cli.models.bullet.engine import PhysicsClient
from rbm_cli.models.bullet.geometry import drum_solids
from rbm_cli.models.bullet.impact import engine_restitution, measure_restitution
from rbm_cli.models.bullet.normals import NormalCensus
from rbm_cli.models.bullet.run import bullet_run
from rbm_cli.models.bullet.settings import EngineSettings, settings_from_config
from tests.paths import tool_script

BLOCK = {"height": 4.0, "base_width": 1.0, "depth": 1.0}
TAPER = {"height": 5.0, "base_width": 0.96, "top_width": 0.66}


def config(column, duration=1.0, **interface):
    data = {
        "name": "t",
        "model": "bullet",
        "column": dict(column),
        "excitation": {"type": "harmonic", "duration": duration},
    }
    if interface:
        data["interface"] = interface
    return parse_config(data)


def harmonic(amplitude_g, frequency_hz, duration):
    w = 2 * math.pi * frequency_hz
    return GroundMotion("harmonic", amplitude_g * G, w, 0.0, duration, duration)


def same_outcome(a, b):
    for name in ("status", "t_collapse", "collapse_interface", "max_top", "message"):
        assert getattr(a, name) == getattr(b, name) or (
            getattr(a, name) != getattr(a, name) and getattr(b, name) != getattr(b, name)
        ), name
    for name in ("n_uplifts", "n_impacts", "n_steps", "n_rhs"):
        assert getattr(a, name) == getattr(b, name), name
    assert np.array_equal(a.max_ratio, b.max_ratio)
    assert np.array_equal(a.friction, b.friction, equal_nan=True)


# ------------------------------------------------------------------- the client


def test_settings_and_the_circle_they_end():
    """settings_from_config reads solver.time_step and interface.friction and refuses
    a friction the engine would cap; the impact module no longer needs the run's."""
    cfg = config(BLOCK, friction=0.4)
    assert settings_from_config(cfg) == EngineSettings(time_step=1e-4, friction=0.4)
    with pytest.raises(RbmError, match="<= 10"):
        settings_from_config(config(BLOCK, friction=12.0))
    code = (
        "import sys, rbm_cli.models.bullet.impact;"
        " sys.exit('rbm_cli.models.bullet.run' in sys.modules)"
    )
    assert subprocess.run([sys.executable, "-c", code], check=False).returncode == 0


def test_a_given_client_is_left_open_and_gives_the_same_run():
    """A run handed a client builds its scene there and leaves it open for the next;
    its outcome is the one of a run that opens (and closes) its own client, before
    and after other runs in that client."""
    cfg = config({**TAPER, "drums": 3}, duration=0.6)
    motion = harmonic(0.6, 2.0, 0.6)
    own, _ = bullet_run(cfg, motion)
    with PhysicsClient() as client:
        first, _ = bullet_run(cfg, motion, client=client)
        bullet_run(config(BLOCK, duration=0.3), harmonic(0.5, 1.0, 0.3), client=client)
        again, _ = bullet_run(cfg, motion, client=client)
        assert client.id is not None  # still the caller's
        client.module.getNumBodies(physicsClientId=client.id)  # and connected
    assert client.id is None
    client.close()  # a second close does nothing
    assert own.n_steps == 6000 and own.n_uplifts > 0  # the stack rocked
    same_outcome(own, first)
    same_outcome(own, again)


def test_runs_without_a_client_share_the_process_one():
    """A run not handed a client builds its scene in the process's client, which it
    leaves open for the next run (one connection per process: connecting costs more
    than a short run's scene); a closed process client is replaced, not reused."""
    shared = PhysicsClient.for_process()
    assert PhysicsClient.for_process() is shared
    cfg = config(BLOCK, duration=0.3)
    out, _ = bullet_run(cfg, harmonic(0.5, 1.0, 0.3))
    assert out.n_steps == 3000
    assert PhysicsClient.for_process() is shared
    assert shared.module.getNumBodies(physicsClientId=shared.id) == 2  # its scene: ground, block
    shared.close()
    fresh = PhysicsClient.for_process()
    assert fresh is not shared and fresh.id is not None
    again, _ = bullet_run(cfg, harmonic(0.5, 1.0, 0.3))
    same_outcome(out, again)


# ------------------------------------------------------- observe and the census


def test_observe_sees_every_step_and_changes_nothing():
    """The probe is called once per engine step and the run's outcome is bit for bit
    the one without it (the census only reads the engine)."""
    cfg = config({**TAPER, "drums": 3}, duration=0.5)
    motion = harmonic(0.7, 2.0, 0.5)
    plain, _ = bullet_run(cfg, motion)
    census = NormalCensus()
    probed, _ = bullet_run(cfg, motion, observe=census)
    same_outcome(plain, probed)
    assert census.steps == probed.n_steps == 5000
    assert census.force > 0.0


@pytest.mark.parametrize("drums", [1, 3])
def test_census_of_a_stack_at_rest_carries_its_weight_on_the_faces_normals(drums):
    """A stack standing still (shaken below its uplift level) pushes on the ground
    with its weight, on the ground's normal; every joint's points push along its
    faces' normal: the mean normal force per step is the sum of the drums' weights
    at their joints, and no point is off."""
    cfg = config({**TAPER, "drums": drums}, duration=0.2)
    census = NormalCensus()
    out, _ = bullet_run(cfg, harmonic(0.1, 2.0, 0.2), record=True, observe=census)
    assert out.status == "survived" and np.max(out.max_ratio) < 1e-3
    solids = drum_solids(cfg.column)
    carried = sum(sum(d.mass for d in solids[i:]) for i in range(drums)) * G
    assert census.force / census.steps == pytest.approx(carried, rel=1e-3)
    assert census.share_off == 0.0
    assert census.max_off < 1e-6


def test_census_without_load_has_no_share():
    assert math.isnan(NormalCensus().share_off)


# ------------------------------------------------------------------- impact's e


def test_engine_restitution_is_the_mean_of_the_peaks_reading():
    """The e handed to `housner` is the mean of the per-impact readings (and, on the
    4 x 1 m block, Housner's 1 - 1.5 sin^2(alpha) = 0.912 to 0.002)."""
    cfg = config(BLOCK)
    e = engine_restitution(cfg, impacts=3)
    assert e == float(np.mean(measure_restitution(cfg, impacts=3)))
    assert abs(e - (1.0 - 1.5 * math.sin(math.atan(0.25)) ** 2)) < 0.002


# -------------------------------------------------------- time-step agreement


def test_step_agreement_counts_same_differ_and_chaotic_cells():
    table = {
        (0.3, 1.0): {"a": ["survived", "survived"], "b": ["survived", "survived"]},
        (0.5, 1.0): {"a": ["collapsed", "collapsed"], "b": ["survived", "survived"]},
        (0.7, 1.0): {"a": ["collapsed", "collapsed"], "b": ["collapsed", "survived"]},
        (0.9, 1.0): {"a": ["collapsed", "survived"], "b": ["collapsed", "collapsed"]},
    }
    assert step_agreement(table, "b", "a") == dict(
        same_as_ref=1, differ_from_ref=1, chaotic_here_or_ref=2
    )
    assert step_agreement(table, "a", "a") == dict(
        same_as_ref=3, differ_from_ref=0, chaotic_here_or_ref=1
    )
    marks = outcome_marks(table)
    assert marks[(0.5, 1.0)] == {"a": "C", "b": "S"}
    assert marks[(0.7, 1.0)] == {"a": "C", "b": "CS"}


def test_ensemble_agreement_keeps_chaotic_cells_apart():
    engine = {(0.3, 1.0): 0.0, (0.5, 1.0): 1.0, (0.7, 1.0): 0.5, (0.9, 1.0): 1.0}
    housner = {(0.3, 1.0): 0.0, (0.5, 1.0): 0.0, (0.7, 1.0): 1.0, (0.9, 1.0): 0.25}
    out = ensemble_agreement(engine, housner)
    assert out["agree"] == 1 and out["of"] == 4
    assert out["differ"] == [(0.5, 1.0)]
    assert out["chaotic_engine_housner"] == {"0.7 1.0": (0.5, 1.0), "0.9 1.0": (1.0, 0.25)}


# ---------------------------------------------------------- tools/make_engine.py


def make_engine():
    return tool_script("make_engine")


def test_make_engine_boundaries_come_from_the_domain_library():
    """The script's boundaries (lowest collapsed amplitude per frequency) are
    study.domain.boundary's: a single domain by its status, an ensemble by the
    majority of its members."""
    script = make_engine()
    df = pd.DataFrame(
        {
            "amplitude_g": [0.1, 0.2, 0.3, 0.1, 0.2, 0.3],
            "frequency_hz": [1.0, 1.0, 1.0, 2.0, 2.0, 2.0],
            "status": ["survived", "collapsed", "collapsed"] + ["survived"] * 3,
            "collapse_fraction": [0.0, 0.25, 0.5, 0.0, 0.0, 1.0],
        }
    )
    assert script._boundary(df) == {1.0: 0.2, 2.0: None}
    assert script._boundary_frac(df, "collapse_fraction") == {1.0: 0.3, 2.0: 0.3}
