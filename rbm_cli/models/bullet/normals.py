"""Where Bullet's contact points push, against the normals a joint admits (`model: bullet`).

The friction demand of a joint (:func:`rbm_cli.models.bullet.scene.joint_friction`)
takes any contact normal between the normals of the joint's two faces as
admissible. :class:`NormalCensus` checks that against the engine itself: hooked
into a run (``bullet_run(..., observe=census)``), it reads after every engine step
the normal of each of Bullet's contact points at each joint, and sums the normal
force on points whose normal lies outside that range by more than a tolerance.
A large share there would mean the engine's contacts are not those the reading
assumes (docs/engine.md).
"""

from __future__ import annotations

import math

from rbm_cli.models.bullet.scene import joint_normal_range, read_frame

#: A contact normal further than this from its joint's faces' normals is "off" [rad].
NORMAL_OFF = 0.02


class NormalCensus:
    """The normal forces of Bullet's contact points at the joints, summed over a run.

    Parameters
    ----------
    off : float  Tolerance [rad]: a point whose normal lies further than this
        outside its joint's range of face normals counts as off

    Attributes
    ----------
    force : float  Sum over steps and contact points of the normal force [N]
    force_off : float  The part of it on points that are off [N]
    max_off : float  Largest departure of a loaded point's normal from its range [rad]
    steps : int  Engine steps seen
    """

    def __init__(self, off: float = NORMAL_OFF) -> None:
        self.off = off
        self.force = 0.0
        self.force_off = 0.0
        self.max_off = 0.0
        self.steps = 0

    def __call__(self, p, cid, bodies) -> None:
        """Read the contact points of every joint (the ground is body 0, built
        first by :func:`rbm_cli.models.bullet.scene.build_scene`)."""
        self.steps += 1
        tilts = read_frame(p, cid, bodies).tilts
        lo, hi = joint_normal_range(tilts, tilts)
        below = [0, *bodies[:-1]]
        for i, body in enumerate(bodies):
            for c in p.getContactPoints(bodyA=body, bodyB=below[i], physicsClientId=cid):
                if c[9] <= 0.0:
                    continue
                phi = math.atan2(c[7][0], c[7][2])  # the normal on the support, upwards
                off = max(0.0, lo[i] - phi, phi - hi[i])
                self.force += c[9]
                self.force_off += c[9] if off > self.off else 0.0
                self.max_off = max(self.max_off, off)

    @property
    def share_off(self) -> float:
        """Share of the normal force carried by points that are off [-] (nan: no load)."""
        return self.force_off / self.force if self.force > 0.0 else math.nan
