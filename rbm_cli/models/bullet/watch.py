"""What a `model: bullet` run watches at its checks: collapse, blow-up, rest, the
joints' openings and closures, slips and friction demand.

The run (:func:`rbm_cli.models.bullet.run.bullet_run`) steps the engine; at every
check (every CHECK_DT of simulated time, at every sample and at the end) it hands
the drums' :class:`~rbm_cli.models.bullet.scene.Frame` to a :class:`RunWatch`,
which updates the run's Outcome and says whether the run stops there. SI units.
"""

from __future__ import annotations

import numpy as np

from rbm_cli.models.bullet.scene import (
    Frame,
    Joints,
    StackGeometry,
    joint_friction,
    joint_state,
)
from rbm_cli.models.outcome import Outcome
from rbm_cli.physics.excitation import GroundMotion

#: Interval of the collapse, sliding and contact checks [s].
CHECK_DT = 1e-3
#: Interval over which a joint's mean force gives its friction demand [s]: long
#: enough to average out the contact's step-to-step chatter (measured: +-10 % of
#: a_g / g on a block at rest over 1 ms, docs/engine.md), short against rocking.
FRICTION_DT = 1e-2
#: A joint is open when its relative rotation exceeds this fraction of alpha_i.
OPEN_FRACTION = 1e-3
#: Drop of a drum's centre of mass, as a fraction of its height, that is collapse.
DROP_FRACTION = 0.5
#: Half-sine/free early stop: every rate below this [rad/s] and every joint
#: closed for REST_TIME [s] after the pulse.
REST_ANGULAR_RATE = 1e-4
REST_TIME = 0.2
#: A drum faster than this [m/s or rad/s] means the engine blew up.
BLOWUP = 1e3


class RunWatch:
    """The readings a run carries from check to check, and the tests made at each.

    Parameters
    ----------
    solids : tuple of DrumSolid  The drums, bottom first
    alpha : (n,) array  Overturning angle of the stack above each joint [rad]
    limit : float  collapse.ratio [-]
    dt : float  Engine time step [s]
    accel : (n_steps,) array  a_g at every mid-step, as the engine applies it [m/s^2]
    frame : Frame  The stack at t = 0
    upward : (n_steps,) array or None  a_v at every mid-step, as the engine applies it
        [m/s^2] (excitation.vertical; None: 0)
    """

    def __init__(
        self, solids, alpha, limit: float, dt: float, accel, frame: Frame, upward=None
    ) -> None:
        n = len(solids)
        self.stack = StackGeometry.of(solids)
        self.alpha = alpha
        self.limit = limit
        self.dt = dt
        self.rest_z = np.array([d.bottom + d.centre for d in solids])
        self.drop = np.array([DROP_FRACTION * d.height for d in solids])
        self.open_tol = OPEN_FRACTION * alpha
        self.max_slip = np.zeros(n)
        self.was_open = np.zeros(n, bool)
        self.last_sign = np.zeros(n)
        self.prev_ratio, self.prev_t, self.quiet_since = 0.0, 0.0, None
        self.accel_sum = np.concatenate([[0.0], np.cumsum(accel)])  # for the mean over a window
        self.up_sum = None if upward is None else np.concatenate([[0.0], np.cumsum(upward)])
        self.friction_steps = max(1, int(round(FRICTION_DT / dt)))
        self.k_prev = 0
        self.frame_prev = frame
        self.tilt_lo = self.tilt_hi = frame.tilts

    def joints(self, frame: Frame) -> Joints:
        """The joints of a frame (no reading kept)."""
        return joint_state(frame, self.stack, self.alpha)

    def see(self, frame: Frame) -> Joints:
        """The joints of a checked frame; widens the friction window's tilt range."""
        joints = joint_state(frame, self.stack, self.alpha)
        tilts = frame.tilts
        self.tilt_lo = np.minimum(self.tilt_lo, tilts)
        self.tilt_hi = np.maximum(self.tilt_hi, tilts)
        return joints

    def check(
        self,
        out: Outcome,
        k: int,
        frame: Frame,
        joints: Joints,
        motion: GroundMotion,
        early_stop: bool,
    ) -> bool:
        """Update `out` with the check after engine step k; True when the run stops
        here (diverged, collapsed, or at rest after the pulse with `early_stop`)."""
        t = k * self.dt
        if not (np.all(np.isfinite(frame.centres)) and np.max(frame.speeds) < BLOWUP):
            out.n_steps = out.n_rhs = k
            out.stop("failed", "the engine diverged (non-finite or runaway drum)", t)
            return True
        if k - self.k_prev >= self.friction_steps:
            self._friction(out, k, frame)
        is_open = self._track(out, joints)
        if self._collapsed(out, k, t, frame, joints):
            return True
        if early_stop and motion.kind != "harmonic" and t >= motion.pulse_end:
            return self._at_rest(out, k, t, frame, is_open)
        return False

    def _friction(self, out: Outcome, k: int, frame: Frame) -> None:
        """Close the friction window at step k: the joints' mean-force demand over it."""
        k_prev = self.k_prev
        mean_accel = (self.accel_sum[k] - self.accel_sum[k_prev]) / (k - k_prev)
        up_sum = self.up_sum
        mean_up = 0.0 if up_sum is None else (up_sum[k] - up_sum[k_prev]) / (k - k_prev)
        demand = joint_friction(
            self.frame_prev,
            frame,
            self.stack,
            (k - k_prev) * self.dt,
            mean_accel,
            (self.tilt_lo, self.tilt_hi),
            mean_up,
        )
        out.friction = np.fmax(out.friction, demand)
        self.frame_prev, self.k_prev = frame, k
        self.tilt_lo = self.tilt_hi = frame.tilts

    def _track(self, out: Outcome, joints: Joints) -> np.ndarray:
        """Maxima of ratio, top displacement and slip; joint openings and closures.
        Returns which joints are open."""
        out.max_ratio = np.maximum(out.max_ratio, joints.ratio)
        out.max_top = max(out.max_top, abs(joints.top[0] - joints.bottoms[0, 0]))
        self.max_slip = np.maximum(self.max_slip, np.abs(joints.slip))
        is_open = np.abs(joints.relative) > self.open_tol
        sign = np.sign(joints.relative) * is_open
        out.n_uplifts += int(np.sum(is_open & ~self.was_open))
        out.n_impacts += int(np.sum(self.was_open & (~is_open | (sign * self.last_sign < 0))))
        self.was_open, self.last_sign = is_open, np.where(is_open, sign, self.last_sign)
        return is_open

    def _collapsed(self, out: Outcome, k: int, t: float, frame: Frame, joints: Joints) -> bool:
        """Collapse: a joint's ratio reached the limit (time interpolated between
        checks) or a drum dropped by DROP_FRACTION of its height."""
        limit = self.limit
        worst = int(np.argmax(joints.ratio))
        dropped = np.nonzero(self.rest_z - frame.centres[:, 2] > self.drop)[0]
        if joints.ratio[worst] >= limit or dropped.size:
            out.n_steps = out.n_rhs = k
            if joints.ratio[worst] >= limit:
                prev_ratio, prev_t = self.prev_ratio, self.prev_t
                frac = (limit - prev_ratio) / max(joints.ratio[worst] - prev_ratio, 1e-300)
                out.t_collapse = prev_t + min(max(frac, 0.0), 1.0) * (t - prev_t)
                out.collapse_interface = worst + 1
                why = f"the drums above joint {worst + 1} passed over its edge"
            else:
                out.t_collapse = t
                out.collapse_interface = int(dropped[0]) + 1
                why = f"drum {dropped[0] + 1} dropped by half its height"
            out.stop("collapsed", why, out.t_collapse)
            return True
        self.prev_ratio, self.prev_t = float(joints.ratio[worst]), t
        return False

    def _at_rest(self, out: Outcome, k: int, t: float, frame: Frame, is_open) -> bool:
        """After the pulse: at rest (every rate below REST_ANGULAR_RATE, every joint
        closed) for REST_TIME."""
        still = np.max(np.abs(frame.rates)) < REST_ANGULAR_RATE and not np.any(is_open)
        quiet = self.quiet_since
        self.quiet_since = (quiet if quiet is not None else t) if still else None
        if self.quiet_since is not None and t - self.quiet_since >= REST_TIME:
            out.n_steps = out.n_rhs = k
            out.stop("survived", "at rest after the pulse", t)
            return True
        return False
