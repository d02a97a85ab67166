"""What a `model: bullet` run watches at its checks: collapse, blow-up, rest, the
joints' openings and closures, slips and friction demand.

The run (:func:`rbm_cli.models.bullet.run.bullet_run`) steps the engine; at every
check (every CHECK_DT of simulated time, at every sample and at the end) it hands
the drums' :class:`~rbm_cli.models.bullet.scene.Frame` to a :class:`RunWatch`,
which updates the run's Outcome and says whether the run stops there: in the plane, or
free in three dimensions (:mod:`rbm_cli.models.bullet.space`'s readings). SI units.
"""

from __future__ import annotations

import numpy as np

from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.models.bullet.scene import (
    Frame,
    Joints,
    StackGeometry,
    joint_friction,
    joint_state,
)
from rbm_cli.models.bullet.space import (
    Joints3d,
    contact_speeds,
    joint_friction_3d,
    joint_state_3d,
    normals,
)
from rbm_cli.models.outcome import WOBBLE_LEVEL, Outcome

#: Interval of the collapse, sliding and contact checks [s].
CHECK_DT = 1e-3
#: Interval over which a joint's mean force gives its friction demand [s]: long
#: enough to average out the contact's step-to-step chatter (measured: +-10 % of
#: a_g / g on a block at rest over 1 ms, docs/engine.md), short against rocking.
FRICTION_DT = 1e-2
#: A joint is open when its relative rotation exceeds this fraction of alpha_i.
OPEN_FRACTION = 1e-3
#: In three dimensions a joint's lean turning is swept (a wobble) only while it is open by
#: more than this fraction of alpha_i at two checks running (the wobble's level of every
#: model in three dimensions, models.outcome.WOBBLE_LEVEL).
NEAR_FRACTION = WOBBLE_LEVEL
#: In three dimensions a joint lands (an impact) when its lean crosses the line across
#: the direction it leant to at the peak of its excursion, nearer closure than this
#: fraction of that peak (or when it closes).
LANDING_FRACTION = 0.5
#: Drop of a drum's centre of mass, as a fraction of its height, that is collapse.
DROP_FRACTION = 0.5
#: Half-sine/free early stop: every rate below this [rad/s], every drum's speed below
#: REST_SPEED [m/s] and every joint closed for REST_TIME [s] after the pulse.
REST_ANGULAR_RATE = 1e-4
REST_TIME = 0.2
#: A drum sliding on its support at rest in rotation (a block sliding to a stop) is not
#: at rest: stopped there the run would cut its slip short (measured: a 1 m block with
#: friction 0.2 under a 0.6 g, 2 Hz half-sine stopped with 117.4 mm of the 119.0 mm it
#: slides). From this speed friction stops it within 1e-8 m.
REST_SPEED = 1e-4
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
    accel : (n_steps,) array  a_g at every mid-step, as the engine applies it [m/s^2]; in
        three dimensions (n_steps, 2): (a_x, a_y)
    frame : Frame  The stack at t = 0
    upward : (n_steps,) array or None  a_v at every mid-step, as the engine applies it
        [m/s^2] (excitation.vertical; None: 0)
    space : bool  The stack moves freely in three dimensions (circular drums): the joints
        are read by :func:`~rbm_cli.models.bullet.space.joint_state_3d`. A joint's lean
        turning while it stays farther than NEAR_FRACTION alpha_i from closure is swept
        (``swept``: a wobble). An impact is a closure, or the lean crossing the line
        across the direction of the excursion's peak nearer closure than LANDING_FRACTION
        of that peak, as a sign change is in the plane: a drum that passes beside the
        upright in a rocking motion has landed and rocks on to the other side, whether or
        not its face came down flat between two checks; one that rolls round at its
        peak's tilt wobbles.
    """

    #: What a moving body is called where the engine diverged.
    BODY = "drum"

    def __init__(
        self,
        solids,
        alpha,
        limit: float,
        dt: float,
        accel,
        frame: Frame,
        upward=None,
        space: bool = False,
    ) -> None:
        n = len(solids)
        self.stack = StackGeometry.of(solids)
        self.alpha = alpha
        self.limit = limit
        self.rest_z = np.array([d.bottom + d.centre for d in solids])
        self.drop = np.array([DROP_FRACTION * d.height for d in solids])
        self.open_tol = OPEN_FRACTION * alpha
        self.max_slip = np.zeros(n)
        self.was_open = np.zeros(n, bool)
        self.last_sign = np.zeros(n)
        self._start_checks(dt, accel, frame, upward, space)
        self.top_start = self.joints(frame).top.copy()
        if space:
            self.faces = [normals(frame)]
            self.lean_last = np.zeros((n, 2))
            self.near_tol = NEAR_FRACTION * alpha
            self.was_far = np.zeros(n, bool)
            self.peak = np.zeros(n)  # the excursion's largest lean so far [rad]
            self.peak_dir = np.zeros((n, 2))  # ... and its direction
            self.swept = np.zeros(n)
            self.max_twist = np.zeros(n)
            self.slid = np.zeros(n)  # path slid at each joint's contact [m]
            self.t_track = 0.0
        else:
            self.tilt_lo = self.tilt_hi = frame.tilts

    def _start_checks(self, dt: float, accel, frame: Frame, upward, space: bool) -> None:
        """The state the checks carry (check, _friction, _collapsed, _at_rest), at t = 0."""
        self.dt, self.space = dt, space
        self.prev_ratio, self.prev_t, self.quiet_since = 0.0, 0.0, None
        accel = np.asarray(accel, dtype=float)
        zero = np.zeros((1,) + accel.shape[1:])
        self.accel_sum = np.concatenate([zero, np.cumsum(accel, axis=0)])  # means over windows
        self.up_sum = None if upward is None else np.concatenate([[0.0], np.cumsum(upward)])
        self.friction_steps = max(1, int(round(FRICTION_DT / dt)))
        self.k_prev = 0
        self.frame_prev = frame
        self.frame_last = frame  # the last frame checked (see): the run's state at its end

    def joints(self, frame: Frame) -> Joints | Joints3d:
        """The joints of a frame (no reading kept)."""
        if self.space:
            return joint_state_3d(frame, self.stack, self.alpha)
        return joint_state(frame, self.stack, self.alpha)

    def see(self, frame: Frame) -> Joints | Joints3d:
        """The joints of a checked frame; widens the friction window's range of normals."""
        joints = self.joints(frame)
        self.frame_last = frame
        if self.space:
            self.faces.append(normals(frame))
            return joints
        tilts = frame.tilts
        self.tilt_lo = np.minimum(self.tilt_lo, tilts)
        self.tilt_hi = np.maximum(self.tilt_hi, tilts)
        return joints

    def seen(self, frame: Frame, joints):
        """The (frame, joints) a run's history samples: the stack's."""
        return frame, joints

    def residual(self, out: Outcome) -> None:
        """The run's residual state, read from the last frame checked (where the run
        ended: the motion and its free time over, or at rest after the pulse), into
        ``out``: the largest |slip| over the joints [m], the top's offset in plan from its
        start [m] and the largest |relative rotation| / alpha_i over the joints [-]. Left
        NaN for a run that collapsed or failed (the column is down, or its state is not
        the engine's). Notes: :func:`rbm_cli.models.bullet.scene.joint_state` (the slip in
        the plane) and :func:`rbm_cli.models.bullet.space.joint_state_3d` (in three
        dimensions, its magnitude in plan)."""
        if out.status != "survived":
            return
        joints = self.joints(self.frame_last)
        offset = joints.top - self.top_start
        if self.space:
            slip = np.hypot(joints.slip[:, 0], joints.slip[:, 1])
            top = float(np.hypot(offset[0], offset[1]))
        else:
            slip = np.abs(joints.slip)
            top = abs(float(offset[0]))
        out.residual_slip = float(np.max(slip))
        out.residual_top = top
        out.residual_tilt = float(np.max(np.abs(joints.relative) / self.alpha))

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
            out.stop("failed", f"the engine diverged (non-finite or runaway {self.BODY})", t)
            return True
        if k - self.k_prev >= self.friction_steps:
            self._friction(out, k, frame)
        is_open = self._track(out, joints, frame, t)
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
        demand = self._demand(frame, (k - k_prev) * self.dt, mean_accel, mean_up)
        out.friction = np.fmax(out.friction, demand)
        self.frame_prev, self.k_prev = frame, k

    def _demand(self, frame: Frame, span: float, mean_accel, mean_up: float) -> np.ndarray:
        """The joints' mean-force demand over the window closing at ``frame`` (span [s],
        the ground's mean accelerations over it [m/s^2])."""
        if self.space:
            # the window's normals, this frame's last (see() read them)
            window = self.faces
            demand = joint_friction_3d(self.frame_prev, frame, self.stack, span, mean_accel,
                                       window, mean_up)  # fmt: skip
            self.faces = window[-1:]
            return demand
        tilts = (self.tilt_lo, self.tilt_hi)
        demand = joint_friction(self.frame_prev, frame, self.stack, span, mean_accel, tilts,
                                mean_up)  # fmt: skip
        self.tilt_lo = self.tilt_hi = frame.tilts
        return demand

    def _track(self, out: Outcome, joints, frame: Frame, t: float) -> np.ndarray:
        """Maxima of ratio, top displacement and slip; joint openings and closures.
        Returns which joints are open."""
        if self.space:
            return self._track_3d(out, joints, frame, t)
        out.max_ratio = np.maximum(out.max_ratio, joints.ratio)
        out.max_top = max(out.max_top, abs(joints.top[0] - joints.bottoms[0, 0]))
        self.max_slip = np.maximum(self.max_slip, np.abs(joints.slip))
        is_open = np.abs(joints.relative) > self.open_tol
        sign = np.sign(joints.relative) * is_open
        out.n_uplifts += int(np.sum(is_open & ~self.was_open))
        out.n_impacts += int(np.sum(self.was_open & (~is_open | (sign * self.last_sign < 0))))
        self.was_open, self.last_sign = is_open, np.where(is_open, sign, self.last_sign)
        return is_open

    def _track_3d(self, out: Outcome, joints: Joints3d, frame: Frame, t: float) -> np.ndarray:
        """_track in three dimensions: the top's displacement in plan, the twists'
        magnitudes, the path slid at each contact (its sliding speed times the time since
        the last check); uplifts, impacts and the lean swept (class notes)."""
        self.slid += contact_speeds(frame, joints.pivots) * (t - self.t_track)
        self.t_track = t
        out.max_ratio = np.maximum(out.max_ratio, joints.ratio)
        top = joints.top[:2] - joints.bottoms[0, :2]
        out.max_top = max(out.max_top, float(np.hypot(top[0], top[1])))
        self.max_twist = np.maximum(self.max_twist, np.abs(joints.twist))
        rel, lean, last = joints.relative, joints.lean, self.lean_last
        is_open = rel > self.open_tol
        far = rel > self.near_tol
        higher = is_open & (rel > self.peak)
        self.peak[higher], self.peak_dir[higher] = rel[higher], lean[higher]
        crossed = (
            self.was_open
            & is_open
            & (np.sum(lean * self.peak_dir, axis=1) < 0.0)
            & (rel < LANDING_FRACTION * self.peak)
        )
        out.n_uplifts += int(np.sum(is_open & ~self.was_open))
        out.n_impacts += int(np.sum(self.was_open & ~is_open) + np.sum(crossed))
        # a new excursion: from the landing, or from closure
        self.peak[crossed], self.peak_dir[crossed] = rel[crossed], lean[crossed]
        self.peak[~is_open] = 0.0
        held = self.was_far & far
        dot = np.sum(lean * last, axis=1)
        cross = last[:, 0] * lean[:, 1] - last[:, 1] * lean[:, 0]
        self.swept[held] += np.abs(np.arctan2(cross, dot))[held]
        self.was_open, self.was_far = is_open, far
        self.lean_last = np.where(is_open[:, None], lean, last)
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
                if self.space:
                    out.azimuth = float(joints.azimuth[worst])
            else:
                out.t_collapse = t
                out.collapse_interface = int(dropped[0]) + 1
                why = f"drum {dropped[0] + 1} dropped by half its height"
                if self.space:
                    out.azimuth = float(joints.azimuth[dropped[0]])
            out.stop("collapsed", why, out.t_collapse)
            return True
        self.prev_ratio, self.prev_t = float(joints.ratio[worst]), t
        return False

    def _at_rest(self, out: Outcome, k: int, t: float, frame: Frame, is_open) -> bool:
        """After the pulse: at rest (every rate below REST_ANGULAR_RATE, every speed
        below REST_SPEED, every joint closed) for REST_TIME."""
        rates = np.linalg.norm(frame.angular, axis=1) if self.space else np.abs(frame.rates)
        moving = np.max(rates) >= REST_ANGULAR_RATE or np.max(frame.speeds) >= REST_SPEED
        still = not moving and not np.any(is_open)
        quiet = self.quiet_since
        self.quiet_since = (quiet if quiet is not None else t) if still else None
        if self.quiet_since is not None and t - self.quiet_since >= REST_TIME:
            out.n_steps = out.n_rhs = k
            out.stop("survived", "at rest after the pulse", t)
            return True
        return False
