"""An initial state across the motion's plane from a config
(`excitation.initial.rotations_across`, `velocities_across`) for `housner-3d` and `rbm-3d`.

Checked against what does not follow the code:

- the rigid cylinder started tilted with a rate across its tilt (its angular velocity
  horizontal, along its lean) on the steady rolling of its rim derived here by hand: its
  tilt, its precession rate and the circle its top runs on;
- the rigid monolith of the Rigid Beam Model started on its circular orbit, whose rate
  comes from the planar linear block's closed-form parameters (alpha, p);
- an elastic column of three drums, linear while its joints stay closed, so that its
  motion across the plane is the planar model's run from the state across it
  (superposition, the planar RBM as the second model).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rbm_cli.base.errors import ConfigError
from rbm_cli.config import parse_config
from rbm_cli.config.types import G
from rbm_cli.structures.assembly import model_from_config
from rbm_cli.structures.closed_forms import linear_rocking_parameters
from rbm_cli.structures.column import build_column
from rbm_cli.structures.cylinder import cylinder_geometry
from rbm_cli.study.simulate import simulate

COLUMN = {"height": 4.0, "base_width": 1.0, "top_width": 0.8, "section": "circular",
          "density": 2700}  # fmt: skip
SOLVER = {"method": "DOP853", "rtol": 1e-12, "atol": 1e-14}


def config(model, initial, duration, drums=1, interface=None, angle=None):
    excitation = {"type": "free", "duration": duration, "initial": initial}
    if angle is not None:
        excitation["angle"] = angle
    return parse_config({
        "name": "wobble", "model": model, "column": {**COLUMN, "drums": drums},
        "interface": interface or {"restitution": 1.0}, "excitation": excitation,
        "solver": dict(SOLVER),
    })  # fmt: skip


def rolling_rate(geo, theta: float) -> float:
    """Precession rate Omega [rad/s] of the cylinder rolling steadily on its rim at a tilt
    theta with a horizontal angular velocity (no component about the vertical).

    In the frame turning at Omega about the vertical with the lean e1 (e2 = e_z x e1):
    n = (sin, 0, cos), the arm from the contact to the centre r = h n - R (cos, 0, -sin),
    w = (w1, 0, 0) with n' = w x n = Omega e_z x n, so w1 = -Omega tan(theta). The centre
    moves at v = w x r = (0, -w1 r3, 0) on a horizontal circle, a = Omega e_z x v; the
    angular momentum about it L = I_t w + (I_a - I_t)(w . n) n turns with the frame,
    L' = Omega e_z x L, and the contact force F = m (a + g e_z) gives L' = -r x F. Its e2
    component: Omega L1 = m (g r1 + Omega v2 r3), so

        Omega^2 = -m g r1 / (tan(theta) (I_t + (I_a - I_t) sin^2 + m r3^2)),

    r1 = h sin - R cos < 0 below the collapse tilt, r3 = h cos + R sin."""
    m, rad, h = geo.mass, geo.radius, geo.centre_height
    st, ct = math.sin(theta), math.cos(theta)
    r1, r3 = h * st - rad * ct, h * ct + rad * st
    inertia = geo.transverse + (geo.axial - geo.transverse) * st * st + m * r3 * r3
    return math.sqrt(-m * G * r1 / (math.tan(theta) * inertia))


@pytest.mark.parametrize("angle", [None, 37.0])
def test_a_cylinder_started_on_its_steady_rolling_stays_on_it(angle):
    """Tilted by theta in the motion's plane, its tilt seen across the plane turning at
    Omega tan(theta) (velocities_across), e = 1, no ground motion, three turns: the tilt
    stays theta (1e-9), no impact, three turns of the lean (1e-8); the lean seen in the
    plane and across it are atan(tan(theta) cos(Omega t)) and atan(tan(theta) sin(Omega
    t)) (1e-7 rad); the centre runs on a circle of radius tan(theta) r3 on the lean's
    side of its centre, so the top, (H - h) sin(theta) further along the lean, is at
    -tan(theta) r3 e(0) + (tan(theta) r3 + (H - h) sin(theta)) e(t) from where the column
    stood, e(t) the lean's direction at angle + Omega t (1e-7 m), its farthest point 2
    tan(theta) r3 + (H - h) sin(theta) (max_top_displacement_m, taken at step ends and
    where the tilt turns, within 1e-3 below it). Turned to 37 degrees, the same."""
    theta = 0.1
    geo = cylinder_geometry(config("housner-3d", {"rotations": [theta]}, 1.0).column)
    omega = rolling_rate(geo, theta)
    period = 2.0 * math.pi / omega
    initial = {"rotations": [theta], "velocities_across": [omega * math.tan(theta)]}
    cfg = config("housner-3d", initial, 3.0 * period, angle=angle)
    import rbm

    run = rbm.run(cfg, output_dt=period / 40.0)
    out = run.result
    assert out.status == "survived" and out.n_impacts == 0
    assert out.max_rotation_ratio == pytest.approx(theta / geo.slenderness, rel=1e-9)
    assert out.wobble_turns == pytest.approx(3.0, rel=1e-8)
    st, ct = math.sin(theta), math.cos(theta)
    r3 = geo.centre_height * ct + geo.radius * st
    centre, top = math.tan(theta) * r3, (geo.height - geo.centre_height) * st
    reach = 2.0 * centre + top
    assert reach * (1.0 - 1e-3) < out.max_top_displacement_m <= reach * (1.0 + 1e-12)
    t = run.history["t_s"].to_numpy()
    turn = math.radians(angle or 0.0) + omega * t
    x = -centre * math.cos(turn[0]) + (centre + top) * np.cos(turn)
    y = -centre * math.sin(turn[0]) + (centre + top) * np.sin(turn)
    np.testing.assert_allclose(run.history["top_x_m"], x, rtol=0, atol=1e-7)
    np.testing.assert_allclose(run.history["top_y_m"], y, rtol=0, atol=1e-7)
    along = np.arctan(math.tan(theta) * np.cos(omega * t))
    across = np.arctan(math.tan(theta) * np.sin(omega * t))
    np.testing.assert_allclose(run.history["theta1_rad"], along, rtol=0, atol=1e-7)
    np.testing.assert_allclose(run.history["theta1_across_rad"], across, rtol=0, atol=1e-7)


def test_a_monolith_of_the_rbm_started_on_its_orbit_stays_on_it():
    """The rigid monolith of rbm-3d (xi 1): its moment is central, M_u (1 - r / alpha)
    toward phi = 0, which with the planar linear block's closed form, theta'' = p^2 (theta
    - alpha) for theta > 0, makes a circle of radius r0 an orbit at Omega^2 = p^2 (alpha -
    r0) / r0 (alpha, p: structures.closed_forms.linear_rocking_parameters). Started at r0 in
    the motion's plane (turned to 30 degrees) with r0 Omega across it, three turns: the
    peak ratio stays r0 / alpha (1e-9), three turns (1e-8), no impact, and the rotations
    seen in the plane and across it are r0 cos(Omega t), r0 sin(Omega t) (1e-7 alpha)."""
    import rbm

    probe = config("rbm-3d", {"rotations": [0.01]}, 1.0, interface={"stiffness": "rigid"})
    alpha, p = linear_rocking_parameters(build_column(probe.column, probe.interface))
    r0 = 0.3 * alpha
    omega = p * math.sqrt((alpha - r0) / r0)
    period = 2.0 * math.pi / omega
    initial = {"rotations": [r0], "velocities_across": [r0 * omega]}
    cfg = config("rbm-3d", initial, 3.0 * period, interface={"stiffness": "rigid"}, angle=30.0)
    run = rbm.run(cfg, output_dt=period / 40.0)
    out = run.result
    assert out.status == "survived" and out.n_impacts == 0
    assert out.max_rotation_ratio == pytest.approx(r0 / alpha, rel=1e-9)
    assert out.wobble_turns == pytest.approx(3.0, rel=1e-8)
    t = run.history["t_s"].to_numpy()
    np.testing.assert_allclose(run.history["theta1_rad"], r0 * np.cos(omega * t), rtol=0,
                               atol=1e-7 * alpha)  # fmt: skip
    np.testing.assert_allclose(run.history["theta1_across_rad"], r0 * np.sin(omega * t),
                               rtol=0, atol=1e-7 * alpha)  # fmt: skip


def test_an_elastic_column_across_its_plane_is_the_planar_run_of_that_state():
    """Three elastic drums whose joints stay closed are linear, their two directions
    independent: started with rotations and rates in the motion's plane (turned to 30
    degrees) and others across it, per drum, the history in the plane is the planar RBM's
    run from the first, and across it the planar run from the second (1e-8 of its peak).
    The drums' values differ, so each reaches its own drum."""
    import rbm

    interface = {"stiffness": {"normal": 5e9}, "restitution": 1.0}
    probe = config("rbm", {"rotations": [0.0, 0.0, 1e-9]}, 1.0, 3, interface)
    edge = min(float(law.edges[0]) for law in model_from_config(probe).laws)  # elastic limit
    along = {"rotations": [0.02 * edge, -0.01 * edge, 0.015 * edge],
             "velocities": [0.0, 0.5 * edge, 0.0]}  # [rad/s]  # fmt: skip
    across = {"rotations": [-0.01 * edge, 0.0, 0.02 * edge],
              "velocities": [0.3 * edge, -0.2 * edge, 0.1 * edge]}  # fmt: skip
    spatial = config("rbm-3d", {**along, "rotations_across": across["rotations"],
                                "velocities_across": across["velocities"]},
                     1.0, 3, interface, angle=30.0)  # fmt: skip
    run = rbm.run(spatial, output_dt=0.01)
    assert run.result.n_uplifts == 0  # every joint stays closed: the column is linear
    for initial, suffix in ((along, "_rad"), (across, "_across_rad")):
        planar = rbm.run(config("rbm", initial, 1.0, 3, interface), output_dt=0.01)
        for i in (1, 2, 3):
            got = run.history[f"theta{i}{suffix}"].to_numpy()
            want = planar.history[f"theta{i}_rad"].to_numpy()
            scale = np.max(np.abs(want))
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-8 * scale)
            assert scale > 1e-3 * edge


def test_with_no_state_across_the_run_is_unchanged():
    """rotations_across and velocities_across of zeros: the run without them, to the bit
    (housner-3d and rbm-3d, rocking in a harmonic); absent, the config's hash is the one it
    had before the keys existed (they are not in its resolved form)."""
    from rbm_cli.study.sweep import config_hash

    for model in ("housner-3d", "rbm-3d"):
        base = {"name": "c", "model": model, "column": dict(COLUMN),
                "interface": {"restitution": 0.9}, "solver": dict(SOLVER)}  # fmt: skip
        exc = {"type": "harmonic", "duration": 3.0, "angle": 20.0,
               "initial": {"rotations": [0.01], "velocities": [0.02]}}  # fmt: skip
        plain = parse_config({**base, "excitation": exc})
        zeros = parse_config({**base, "excitation": {**exc, "initial": {
            **exc["initial"], "rotations_across": [0.0], "velocities_across": [0.0]}}})  # fmt: skip
        a, b = simulate(plain, 0.4, 1.0), simulate(zeros, 0.4, 1.0)
        assert (a.status, a.n_impacts, a.max_rotation_ratio) == (
            b.status, b.n_impacts, b.max_rotation_ratio)  # fmt: skip
        assert plain.resolved()["excitation"]["initial"]["rotations_across"] == ()
        assert config_hash(plain) != config_hash(zeros)


@pytest.mark.parametrize(
    ("model", "initial", "message"),
    [
        ("rbm", {"rotations_across": [0.01]}, "model rbm rocks in one plane"),
        ("housner", {"velocities_across": [0.1]}, "model housner rocks in one plane"),
        ("housner-linear", {"rotations_across": [0.0]}, "housner-3d, rbm-3d"),
        ("bullet", {"rotations_across": [0.01]}, "model bullet starts its stack"),
        ("rbm-3d", {"rotations_across": [0.01, 0.02]}, r"one value per drum \(1\)"),
        ("rbm-3d", {"rotations_across": [20.0]}, "excitation.initial.rotations_across.0"),
        ("housner-3d", {"velocities_across": ["fast"]}, "excitation.initial.velocities_across"),
        ("housner-3d", {"rotations_across": [float("nan")]}, "rotations_across"),
    ],
)
def test_a_bad_state_across_is_refused_in_one_line(model, initial, message):
    raw = {"name": "bad", "model": model, "column": dict(COLUMN),
           "excitation": {"type": "harmonic", "angle": 0.0, "initial": initial}}  # fmt: skip
    with pytest.raises(ConfigError, match=message) as err:
        parse_config(raw)
    assert "\n" not in str(err.value)


def test_free_motion_may_start_from_a_state_across_alone():
    """type free needs a state: a rate across the plane alone is one (the column rocks
    across the motion's plane, its peak seen there)."""
    cfg = config("housner-3d", {"velocities_across": [0.5]}, 2.0, interface={"restitution": 0.9})
    out = simulate(cfg, 0.0, None)
    assert out.max_rotation_ratio > 0.0
    with pytest.raises(ConfigError, match="needs a non-zero initial rotation"):
        config("housner-3d", {"velocities_across": [0.0]}, 2.0)
