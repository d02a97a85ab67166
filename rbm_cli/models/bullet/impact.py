"""The contact engine's own impact loss (`model: bullet`), measured by free rocking.

Bullet's impacts are plastic at the contact points (restitution 0); the loss of
rocking energy at an impact comes out of the contact dynamics. It is measured
here on the monolith (or a stack that rocks as one) released from rest, tilted
on its base corner, with no ground motion, and expressed as Housner's
coefficient e (the ratio of angular velocities after / before an impact).

Two readings are offered:

- :func:`measure_restitution` (the one rbm uses; :func:`engine_restitution` is
  its mean): from the rocking energy at successive peaks. Between impacts the
  block is a conservative pendulum, so the energy just before impact k is that
  of the peak before it and the energy just after it that of the peak after it;
  e_k = sqrt(E_after / E_before).
- :func:`impact_rate_ratios`: the angular velocity just before and just after
  the impact, each extrapolated to the crossing from 2 ms line fits. It reads
  the velocity in the few ms after the impact, where Bullet is still pushing
  the contact's penetration out through the velocity (Baumgarte, erp; split
  impulse does not apply to multibody contacts), and so scatters below
  Housner's e (docs/engine.md).
"""

from __future__ import annotations

import math

import numpy as np

from rbm_cli.config.types import Config, G
from rbm_cli.models.bullet.engine import PhysicsClient
from rbm_cli.models.bullet.geometry import drum_solids, stack_slenderness
from rbm_cli.models.bullet.scene import build_scene, keep_in_plane
from rbm_cli.models.bullet.settings import EngineSettings, settings_from_config

#: Longest free rocking simulated to find the impacts [s] per impact.
T_PER_IMPACT = 20.0


def measure_restitution(
    config: Config,
    tilt_fraction: float = 0.5,
    impacts: int = 4,
    settings: EngineSettings | None = None,
) -> np.ndarray:
    """The engine's impact loss as Housner's e, from the energy of successive peaks [-].

    Parameters
    ----------
    config : Config  The column (its base drum's tilt is read; meaningful for a
        monolith or a stack that rocks as one)
    tilt_fraction : float  Release tilt as a fraction of alpha_1 [-]
    impacts : int  Number of impacts measured
    settings : EngineSettings  Override the config's engine settings

    Returns
    -------
    (impacts,) array of e_k = sqrt(E_k / E_(k-1)), E_0 the energy at release.

    Notes
    -----
    Rocking on a corner, the energy above rest at a peak (rate 0, tilt
    theta_k) is m g R [cos(alpha - |theta_k|) - cos(alpha)]; between two peaks
    the only loss is the impact, which multiplies the angular velocity by e and
    so the energy by e^2 (Housner 1963). The peak tilt is the sampled maximum
    refined by a parabola through its neighbours.
    """
    tilt, _, dt = _free_rocking(config, tilt_fraction, impacts + 1, settings)
    alpha = float(stack_slenderness(drum_solids(config.column))[0])
    crossings = np.nonzero(tilt[1:] * tilt[:-1] < 0.0)[0]
    peaks = [tilt_fraction * alpha]
    for a, b in zip(crossings[:-1], crossings[1:], strict=False):
        seg = np.abs(tilt[a + 1 : b + 1])
        i = int(np.argmax(seg))
        top = seg[i]
        if 0 < i < len(seg) - 1:
            y0, y1, y2 = seg[i - 1], seg[i], seg[i + 1]
            den = y0 - 2.0 * y1 + y2
            if den < 0.0:
                top = y1 - 0.125 * (y2 - y0) ** 2 / den
        peaks.append(top)
    energy = np.cos(alpha - np.array(peaks[: impacts + 1])) - math.cos(alpha)
    return np.sqrt(energy[1:] / energy[:-1])


def engine_restitution(
    config: Config, impacts: int = 4, settings: EngineSettings | None = None
) -> float:
    """The engine's impact loss of a column as one Housner e [-]: the mean of
    :func:`measure_restitution` over the first `impacts` impacts (release at half
    alpha_1). The e to give `housner` to compare it with the engine.
    """
    return float(np.mean(measure_restitution(config, impacts=impacts, settings=settings)))


def impact_rate_ratios(
    config: Config,
    tilt_fraction: float = 0.5,
    impacts: int = 4,
    settings: EngineSettings | None = None,
) -> np.ndarray:
    """Angular-velocity ratios after / before the first impacts, from 2 ms line fits [-].

    The rate just before and just after each crossing of the base drum's tilt
    is extrapolated to the crossing from straight lines fitted over 2 ms on
    either side, leaving out 0.5 ms around it (the contact switches corners).
    Biased by the contact's position correction after the impact (module notes).
    """
    tilt, rate, dt = _free_rocking(config, tilt_fraction, impacts, settings, tail=3e-3)
    crossings = np.nonzero(tilt[1:] * tilt[:-1] < 0.0)[0][:impacts]
    fit, gap = max(3, int(round(2e-3 / dt))), max(1, int(round(5e-4 / dt)))
    ratios = []
    for c in crossings:
        if c - gap - fit < 0 or c + 1 + gap + fit > len(rate):
            continue
        t_c = (c + tilt[c] / (tilt[c] - tilt[c + 1])) * dt
        before = np.arange(c - gap - fit, c - gap)
        after = np.arange(c + 1 + gap, c + 1 + gap + fit)
        w_b = np.polyval(np.polyfit(before * dt, rate[before], 1), t_c)
        w_a = np.polyval(np.polyfit(after * dt, rate[after], 1), t_c)
        ratios.append(w_a / w_b)
    return np.array(ratios)


def _free_rocking(config, tilt_fraction, crossings, settings, tail=0.0):
    """Base drum's tilt [rad] and rate [rad/s] at every step of free rocking from
    rest, until `crossings` sign changes of the tilt (then `tail` [s] more), in the
    process's client."""
    solids = drum_solids(config.column)
    settings = settings or settings_from_config(config)
    alpha = stack_slenderness(solids)
    client = PhysicsClient.for_process()
    circular = config.column.section == "circular"  # the engine's cylinders, as a run's
    bodies = build_scene(client, solids, settings, tilt_fraction * alpha[0], 0.0, circular)
    tilt, rate = _rock(client.module, client.id, bodies, settings.time_step, crossings, tail)
    return tilt, rate, settings.time_step


def _rock(p, cid, bodies, dt, crossings, tail):
    """Step the scene under gravity alone; the base drum's tilt and rate per step."""
    p.setGravity(0.0, 0.0, -G, physicsClientId=cid)
    base = bodies[0]
    t_max = T_PER_IMPACT * (crossings + 1)
    tilt, rate = [], []
    found, k, k_stop = 0, 0, None
    while k * dt < t_max and (k_stop is None or k < k_stop):
        p.stepSimulation(physicsClientId=cid)
        k += 1
        keep_in_plane(p, cid, bodies, pose=k % 10 == 0)
        _, quat = p.getBasePositionAndOrientation(base, physicsClientId=cid)
        _, ang = p.getBaseVelocity(base, physicsClientId=cid)
        m = p.getMatrixFromQuaternion(quat)
        tilt.append(math.atan2(m[2], m[8]))
        rate.append(ang[1])
        if len(tilt) > 1 and tilt[-1] * tilt[-2] < 0.0:
            found += 1
            if found == crossings:
                k_stop = k + int(round(tail / dt))
    return np.array(tilt), np.array(rate)
