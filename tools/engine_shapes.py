"""Which collision shape holds a circular drum's contact better in three dimensions: the
engine's cylinders or polygonal prisms (docs/engine.md, "In three dimensions").

The paper's column (H 5 m, diameters 0.96 m to 0.66 m) as one drum, in the engine with
the run's settings (step 1e-4 s, 100 iterations, friction 1), collided as prisms of 32,
64 and 128 sides (their apothem the true radius) or as two of the engine's cylinders:

- **steady wobble**: started on the rigid cylinder's steady wobble at a tilt of 0.05 and
  0.15 rad (the centre of mass at rest, the axis precessing at Omega, derived by hand in
  tests/test_housner3d.py), free for three of its turns: the turns the lean makes (3 on
  the solution) and the tilt's largest departure from its start;
- **rocking in a turned plane**: a sine of 0.3 g at 1 Hz for 4 s along the azimuths 0,
  37 and 90 degrees: the largest lean across the motion's plane over the largest in it
  (0 for rocking that stays in its plane, as the exact cylinder's does);
- **the cylinders' contact under that sine**: every 5 ms, the engine's contact points
  between the drum and the ground (Bullet keeps at most four for a pair of bodies) and
  the centre of their normal forces: its largest distance across the motion's plane, in
  radii (0 for contact forces that leave the rocking in its plane).

    python tools/engine_shapes.py     # about 15 s on one core; prints two Markdown tables
"""

from __future__ import annotations

import math

import numpy as np

from rbm_cli.config.load import parse_config
from rbm_cli.config.types import G
from rbm_cli.models.bullet.engine import PhysicsClient
from rbm_cli.models.bullet.geometry import drum_solids
from rbm_cli.models.bullet.scene import build_scene, read_frame
from rbm_cli.models.bullet.settings import EngineSettings
from rbm_cli.structures.cylinder import cylinder_geometry

COLUMN = {"height": 5.0, "base_width": 0.96, "top_width": 0.66, "section": "circular"}
SHAPES = (32, 64, 128, "cylinders")
STEP = 1e-4


def _scene(client, shape):
    column = parse_config({"name": "s", "column": COLUMN}).column
    solids = drum_solids(column, 32 if shape == "cylinders" else shape)
    (body,) = build_scene(client, solids, EngineSettings(), cylinders=shape == "cylinders")
    return body


def wobble(shape, theta: float) -> tuple[float, float]:
    """(turns in three of the solution's turns, largest |tilt - theta| / theta)."""
    geo = cylinder_geometry(parse_config({"name": "s", "column": COLUMN}).column)
    m, rad, h = geo.mass, geo.radius, geo.centre_height
    i_t, i_a = geo.transverse, geo.axial
    st, ct = math.sin(theta), math.cos(theta)
    omega = math.sqrt(m * G * rad * (rad * ct - h * st) / (st * (i_t * rad * ct - i_a * h * st)))
    n, u = np.array([st, 0.0, ct]), np.array([ct, 0.0, -st])
    with PhysicsClient() as client:
        p, cid = client.module, client.id
        body = _scene(client, shape)
        centre = np.array([rad, 0.0, 0.0]) + h * n - rad * u
        quat = p.getQuaternionFromEuler([0.0, theta, 0.0])
        p.resetBasePositionAndOrientation(body, centre.tolist(), quat, physicsClientId=cid)
        spin = omega * st / rad * (h * n - rad * u)
        p.resetBaseVelocity(body, [0.0, 0.0, 0.0], spin.tolist(), physicsClientId=cid)
        p.setGravity(0.0, 0.0, -G, physicsClientId=cid)
        swept, last, worst = 0.0, 0.0, 0.0
        for k in range(int(3 * 2 * math.pi / omega / STEP)):
            p.stepSimulation(physicsClientId=cid)
            if k % 10 == 9:
                axis = read_frame(p, cid, [body]).rotations[0, :, 2]
                worst = max(worst, abs(math.acos(axis[2]) - theta) / theta)
                az = math.atan2(axis[1], axis[0])
                swept += math.remainder(az - last, 2 * math.pi)
                last = az
    return swept / (2 * math.pi), worst


def turned(shape, azimuth_deg: float) -> float:
    """Largest lean across the motion's plane over the largest in it, under 0.3 g, 1 Hz."""
    d = np.array([math.cos(math.radians(azimuth_deg)), math.sin(math.radians(azimuth_deg))])
    along = across = 0.0
    with PhysicsClient() as client:
        p, cid = client.module, client.id
        body = _scene(client, shape)
        for k in range(int(4.0 / STEP)):
            a = 0.3 * G * math.sin(2 * math.pi * (k + 0.5) * STEP)
            p.setGravity(-a * d[0], -a * d[1], -G, physicsClientId=cid)
            p.stepSimulation(physicsClientId=cid)
            if k % 10 == 9:
                axis = read_frame(p, cid, [body]).rotations[0, :, 2]
                along = max(along, abs(math.atan2(axis[:2] @ d, axis[2])))
                side = -axis[0] * d[1] + axis[1] * d[0]
                across = max(across, abs(math.atan2(side, axis[2])))
    return across / along


def contact(azimuth_deg: float) -> tuple[int, float]:
    """(most contact points seen, largest distance of their normal forces' centre across
    the motion's plane over the radius) for the cylinders under 0.3 g, 1 Hz."""
    d = np.array([math.cos(math.radians(azimuth_deg)), math.sin(math.radians(azimuth_deg))])
    across = np.array([-d[1], d[0]])
    radius = COLUMN["base_width"] / 2.0
    most, worst = 0, 0.0
    with PhysicsClient() as client:
        p, cid = client.module, client.id
        body = _scene(client, "cylinders")
        for k in range(int(4.0 / STEP)):
            a = 0.3 * G * math.sin(2 * math.pi * (k + 0.5) * STEP)
            p.setGravity(-a * d[0], -a * d[1], -G, physicsClientId=cid)
            p.stepSimulation(physicsClientId=cid)
            if k % 50 == 0:
                points = p.getContactPoints(bodyA=body, physicsClientId=cid)
                most = max(most, len(points))
                force = np.array([c[9] for c in points])
                if force.sum() > 0.0:
                    where = np.array([c[6][:2] for c in points]) @ across
                    worst = max(worst, abs(where @ force) / force.sum() / radius)
    return most, worst


def main() -> None:
    print("| shape | wobble 0.05 rad: turns (3) | tilt off | wobble 0.15 rad: turns (3)"
          " | tilt off | across / along at 0 deg | at 37 deg | at 90 deg |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    for shape in SHAPES:
        w1, w2 = wobble(shape, 0.05), wobble(shape, 0.15)
        t = [turned(shape, az) for az in (0.0, 37.0, 90.0)]
        name = f"prism, {shape} sides" if shape != "cylinders" else "two cylinders"
        print(f"| {name} | {w1[0]:.3f} | {100 * w1[1]:.2f} % | {w2[0]:.3f} | {100 * w2[1]:.2f} %"
              f" | {t[0]:.3f} | {t[1]:.3f} | {t[2]:.3f} |")  # fmt: skip
    print("\n| azimuth | contact points, most | normal forces' centre across the plane [radii] |")
    print("|---|---|---|")
    for az in (0.0, 37.0, 90.0):
        most, worst = contact(az)
        print(f"| {az:.0f} deg | {most} | {worst:.3f} |")


if __name__ == "__main__":
    main()
