"""solver.stop: outcome on the Rigid Beam Model's frame of drums (rbm_cli.structures.frame):
the survival certificate of free motion when a joint's collapse limit lies past its law's
zero.

A frame's joint i collapses where its law plus the beam joint's cap vanish, at
L_i = theta_u,i (1 + xi M_u,b / M_u,i), past theta_u,i where the law's moment turns
negative: the law's potential falls between them, and another joint's may be below 0
when joint i collapses. What is held here:

- the barrier is the least, over the joints, of F_i(c L_i) plus every other joint's floor
  min(0, F_j(c L_j)) (the beam joint's potential is never negative), each potential an
  integral of the law's moment (the trapezoid rule between its kinks, exact for a law
  linear between them) and L_i from the moment capacities, not the code's sums; no
  barrier (NaN) where that least value is not positive (a heavy beam);
- runs of free motion stopped where the certificate allows keep the outcome of the same
  runs to their end, and do stop.
"""

from __future__ import annotations

import math
import re

import pytest

from rbm_cli.api import load_config, run
from rbm_cli.structures.arrays import survival_barrier
from rbm_cli.structures.assembly import model_from_config

G = 9.81
H, B, RHO, DRUMS = 3.0, 0.6, 2700.0, 3
STOPPED = re.compile(r"stopped at ([0-9.e+-]+) s \(solver\.stop: outcome\)")


def _frame(gamma: float, stop: str = "outcome", rotation: float = 0.3, rate: float = 0.0,
           restitution: float = 0.9, ratio: float = 1.0) -> dict:  # fmt: skip
    """Two square columns of DRUMS drums under a beam of gamma = m_b / (2 m), damped, in
    free motion from a tilt of the whole stack by `rotation` of the base's theta_u."""
    mass = RHO * B * B * H
    tu = B / H  # the base's rotation capacity, (B / 2) / (H / 2)
    return {
        "name": "frame",
        "model": "rbm",
        "column": {"height": H, "base_width": B, "drums": DRUMS},
        "frame": {"columns": 2, "beam_mass": 2.0 * gamma * mass},
        "interface": {"stiffness": {"normal": 5e8}, "damping": 0.05, "restitution": restitution},
        "excitation": {"type": "free", "duration": 4.0,
                       "initial": {"rotations": [tu * rotation] * DRUMS,
                                   "velocities": [rate] * DRUMS}},
        "collapse": {"ratio": ratio},
        "solver": {"stop": stop},
    }  # fmt: skip


def _potential(law, x: float) -> float:
    """integral_0^x of the law's moment: the law is linear between its kinks, so the
    trapezoid rule between them (the moment evaluated by the law) is exact."""
    points = [0.0] + [e for e in law.edges if 0.0 < e < x] + [x]
    return sum(0.5 * (float(law(a)) + float(law(b))) * (b - a)
               for a, b in zip(points[:-1], points[1:], strict=True))  # fmt: skip


def _expected_barrier(model, ratio: float) -> float:
    n = model.n
    col = model.column
    cap = (col.widths[-1] / 2.0) * col.beam_mass * G  # M_u,b = (B_top / 2) W_b / N
    xi = model.xi
    reach = []
    for i in range(n):  # the drums' joints: the collapse limit past theta_u
        limit = col.rotation_capacity[i] * (1.0 + xi * cap / col.moment_capacity[i])
        reach.append(_potential(model.laws[i], ratio * limit))
    floors = [min(0.0, f) for f in reach]  # the beam joint's floor is 0
    best = min(reach[i] + sum(floors[:i] + floors[i + 1 :]) for i in range(n))
    return best if best > 0.0 else math.nan


@pytest.mark.parametrize("gamma, ratio", [(0.5, 1.0), (1.0, 0.9), (3.0, 1.0), (30.0, 1.0)])
def test_the_frames_barrier_takes_the_other_joints_floors(gamma, ratio):
    model = model_from_config(load_config(_frame(gamma, ratio=ratio)))
    assert model.joints == model.n + 1  # a beam joint of its own
    expected = _expected_barrier(model, ratio)
    got = survival_barrier(model)
    if math.isnan(expected):
        assert math.isnan(got)
    else:
        assert got == pytest.approx(expected, rel=1e-9)


def test_a_heavy_beam_leaves_no_barrier():
    """Under a heavy enough beam a drum joint's F_i(c L_i) is below 0 (its law's descending
    branch runs far past theta_u before the beam's cap holds it) and no energy bounds the
    frame; a lighter one keeps a barrier, every joint's F_i(c L_i) positive."""
    for gamma, bounded in ((10.0, True), (30.0, False)):
        model = model_from_config(load_config(_frame(gamma)))
        assert math.isnan(_expected_barrier(model, 1.0)) is not bounded
        assert math.isnan(survival_barrier(model)) is not bounded


@pytest.mark.parametrize("rotation, rate, restitution", [(0.3, 0.0, 0.9), (0.5, -0.3, 0.7),
                                                         (0.6, 0.4, 0.9)])  # fmt: skip
def test_stopped_frames_keep_the_outcome_of_their_full_runs(rotation, rate, restitution):
    full = run(_frame(0.5, "figures", rotation, rate, restitution), amplitude_g=0.0,
               record=False).result  # fmt: skip
    quick = run(_frame(0.5, "outcome", rotation, rate, restitution), amplitude_g=0.0,
                record=False).result  # fmt: skip
    assert quick["status"] == full["status"]
    assert quick["collapse_interface"] == full["collapse_interface"]
    found = STOPPED.search(quick["message"])
    if full["status"] == "survived":
        assert found is not None, quick["message"]
        assert quick["n_steps"] < full["n_steps"]
        assert quick["max_rotation_ratio"] <= full["max_rotation_ratio"]
    else:
        assert found is None
        assert quick["t_collapse_s"] == full["t_collapse_s"]
