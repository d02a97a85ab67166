"""A frame of columns under a beam in the contact engine (`model: bullet` with ``frame``).

A frame (a colonnade's bay, Config.frame) is N identical columns, each the config's stack of
drums (:func:`rbm_cli.models.bullet.geometry.drum_solids`), standing in a row along x, the
plane of the motion, under one rigid beam (an architrave): a box resting freely on their
tops, in contact with them with the joints' friction (interface.friction). The beam may
slide and turn, lift off a top and land on it again, and the columns need not move in
unison; every body is held in the plane (rbm_cli.models.bullet.scene.keep_in_plane). The
scene is built by rbm_cli.models.bullet.scene.build_frame. SI units.

Layout (:func:`frame_layout`, the frame as rbm_cli.structures.frame.beam_box draws it)
[assumptions]:

- the columns' axes stand AXIS_SPACING = 2.5 base widths apart (a colonnade's
  intercolumniation, axis to axis, is about 1.5 to 3 base widths), the frame centred on
  x = 0;
- the beam spans from the first column's outer top edge to the last one's:
  L = (N - 1) spacing + the top's width; its depth is the top's (column.depth, or the top's
  width for a square or a circular section); its height makes its mass beam_mass at the
  column's density, h = beam_mass / (density L depth): finite, as the config bounds
  beam_mass, and positive, as a beam of no mass is the free column (its run is the
  column's, rbm_cli.models.bullet.run.bullet_run).

Readings at every check (:class:`FrameWatch`):

- each column's joints as a free column's (rbm_cli.models.bullet.scene.joint_state, read in
  the column's own axes): per joint the largest ratio and slip over the columns, and the
  rotation of largest magnitude, whose openings and closures are counted as a column's
  (a frame rocking in unison counts as one column);
- joint n + 1, the beam's: on each top, the share of the top's width the beam's bottom face
  no longer covers, in the top's own axes, ``1 - overlap / top width`` (0 seated over the
  whole top, 1 once it has left the top in plan), the largest over the tops; its slip on
  each top as a drum's on its support (the offset of the beam's point that stood over the
  top's centre, less the b (1 - cos phi) that turning on the top's corner gives without
  sliding, b the top's half-width, phi the beam's rotation relative to the top; over a
  top it does not touch, its offset from it).

Collapse, whichever comes first (the run stops there):

- a column collapses by the column's rule (a joint's ratio reaches collapse.ratio, or a
  drum drops by DROP_FRACTION of its height): collapse_interface is that joint (1: the
  base) and the message names the column;
- the beam falls (collapse_interface n + 1): its ratio reaches collapse.ratio (with the
  default 1, it has left a top in plan: no longer over it, it cannot land on it again and
  rests on the others or falls), or its centre of mass drops by DROP_FRACTION of the top
  drum's height (only off the tops can it drop that far: a top under it rises as its
  column rocks, the corner it rests on turning up). A beam lifted off a top it still
  stands over may land on it again: that is not its fall.

The beam's seats (:func:`seat_contact`). The share of a rigid beam's weight that each of
three or more tops carries is statically indeterminate: a real frame's follows from the
compliance of its supports. On rigid contacts the engine's solver settles it by the order
it visits the contacts in, its error reduction (erp) and round-off: measured (a beam of
gamma 1 on 2 x 0.4 m columns, at rest, 2026-11-30), 50/0/50 % of the weight on three tops
and 30/0/57/13 % on four, with 100 or 1,000 solver iterations, split impulse on or off;
50/0/50 % with erp 0.02, 23/58/20 % with erp 0.8. A column left unloaded rocks on its own,
out of the unison Makris and Vassiliou's frame assumes (under a 0.5 g, 2 Hz half-sine peak
ratio 0.29 with three columns, 0.39 with four, against 0.22 for the equivalent block). So
the beam's contacts with the tops are compliant where the frame has three or more columns
(the engine's soft contact: each contact point a spring and a dashpot, solved implicitly
with the rest) [assumptions]:

- a top's seat has the joints' normal stiffness over the top's face, k_n A
  (interface.stiffness: {normal: k_n}, else SEAT_NORMAL_STIFFNESS), shared by the
  SEAT_POINTS points the engine keeps on a seated face (springs in parallel);
- its damping is SEAT_DAMPING (critical) of the beam's share bouncing on it,
  2 sqrt(k_n A m_b / N): the seat does not ring, its impacts are near plastic, as the
  engine's rigid contacts are (restitution 0).

Equal columns then share a symmetric beam equally (W / N each within 2.5 % over the first
0.1 s at rest, tests/test_frame_bullet.py), and three columns follow two (the similarity
law of Makris and Vassiliou's frame, whose motion depends on gamma, not N). The seats cost
the rigid frame's precision: a seat of k_n 5e9 Pa/m lets the frame rock further than the
rigid block on a half-sine (peak ratio up to 0.03 above it where two rigid columns match it
to 0.001; the difference shrinks as k_n grows, 0.002 at 1e11), and stiffer seats do not
help three columns: the engine's rigid contacts below (the bases on the ground) settle by
micrometres, and from 2e10 Pa/m up this unloads the middle columns again. At rest the
shares drift as those contacts creep (W / N within 5 % at 0.2 s, the middle column of
three at 0.71 W / N after 1 s). Two columns keep rigid seats (their shares follow from the
beam's balance, and their runs stay those of the stored study) unless the config gives
k_n. A seat holds no more than a contact: the beam may lift off, slide and land again.

Friction demand (FRICTION_DT windows, as a column's): the engine's momentum balance gives
the mean force on a set of bodies that touches the rest through one joint only. A column's
joint i carries its drums above and an unknown share of the beam (how the columns share the
beam is statically indeterminate), so the reading at joint i is that of the frame's level
i: the drums above joint i of every column and the beam together, over the contact normals
any column's faces at that joint admit. It is each column's demand while they move alike
(at rest, rocking in unison) and at most the largest column's otherwise (each column's
force inside its Coulomb cone, their sum lies in the cones' union: the notes of
rbm_cli.models.bullet.scene.joint_friction). The beam's joint: the beam's own mean force,
over the normals of its bottom face and of every top face.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from rbm_cli.config.types import ColumnConfig, FrameConfig, G, InterfaceConfig
from rbm_cli.models.bullet.geometry import DrumSolid
from rbm_cli.models.bullet.scene import (
    Frame,
    Joints,
    StackGeometry,
    joint_normal_range,
    joint_state,
)
from rbm_cli.models.bullet.watch import DROP_FRACTION, OPEN_FRACTION, RunWatch
from rbm_cli.models.outcome import Outcome
from rbm_cli.structures.frame import beam_box


@dataclass(frozen=True)
class FrameLayout:
    """Where a frame's bodies stand (the module's notes).

    axes : (N,) x of each column's axis [m], the frame centred on x = 0
    spacing : float  Axis to axis [m]
    beam : DrumSolid  The beam, a box whose bottom face is at the columns' height
        (half_bottom = half_top: half its length)
    depth : float  The beam's depth [m]
    """

    axes: np.ndarray
    spacing: float
    beam: DrumSolid
    depth: float

    @property
    def length(self) -> float:
        """The beam's length L [m]."""
        return 2.0 * self.beam.half_bottom


def frame_layout(column: ColumnConfig, frame: FrameConfig, solids) -> FrameLayout:
    """The layout of a frame of columns (each the drums ``solids`` of ``column``) under a
    beam of frame.beam_mass [kg] > 0: the module's rules."""
    count = frame.columns
    spacing, length, height, depth = beam_box(dataclasses.asdict(column),
                                              dataclasses.asdict(frame))  # fmt: skip
    axes = (np.arange(count) - 0.5 * (count - 1)) * spacing
    mass = frame.beam_mass
    half = (0.5 * length, 0.5 * depth, 0.5 * height)
    corners = np.array(
        [(sx * half[0], sy * half[1], sz * half[2]) for sz in (-1.0, 1.0)
         for sx in (-1.0, 1.0) for sy in (-1.0, 1.0)]
    )  # fmt: skip
    inertia = (
        mass * (depth**2 + height**2) / 12.0,
        mass * (length**2 + height**2) / 12.0,
        mass * (length**2 + depth**2) / 12.0,
    )
    beam = DrumSolid(
        bottom=solids[-1].bottom + solids[-1].height,
        height=height,
        half_bottom=half[0],
        half_top=half[0],
        mass=mass,
        centre=half[2],
        inertia=inertia,
        vertices=corners,
        box=True,
        half_extents=half,
    )
    return FrameLayout(axes=axes, spacing=spacing, beam=beam, depth=depth)


#: The joints' normal stiffness k_n [Pa/m] of the seats of three or more columns where the
#: config gives none (interface.stiffness rigid or rotational) [assumption: the stone
#: joints' value of the engine's comparisons with the Rigid Beam Model, docs/engine.md].
SEAT_NORMAL_STIFFNESS = 5e9
#: Contact points the engine keeps between the beam and a seated top (measured: 4, the
#: face's corners).
SEAT_POINTS = 4
#: Ratio of critical damping of the beam bouncing on its seats [assumption].
SEAT_DAMPING = 1.0


def seat_contact(column: ColumnConfig, frame: FrameConfig, interface: InterfaceConfig,
                 solids) -> tuple[float, float] | None:  # fmt: skip
    """(stiffness [N/m], damping [N s/m]) of each contact point of the beam on a top (the
    module's notes): compliant seats where the config gives the joints' k_n
    (interface.stiffness: {normal: k_n}) or the frame has three or more columns (k_n
    SEAT_NORMAL_STIFFNESS where none is given); None, rigid seats, otherwise."""
    stiff = interface.stiffness
    if frame.beam_mass <= 0.0 or (frame.columns < 3 and stiff.kind != "normal"):
        return None
    k_n = float(stiff.values[0]) if stiff.kind == "normal" else SEAT_NORMAL_STIFFNESS
    width = 2.0 * solids[-1].half_top
    if column.section == "circular":
        area = 0.25 * math.pi * width**2
    else:
        area = width * (width if column.depth is None else column.depth)
    seat = k_n * area  # one top's [N/m]
    damping = 2.0 * SEAT_DAMPING * math.sqrt(seat * frame.beam_mass / frame.columns)
    return seat / SEAT_POINTS, damping / SEAT_POINTS


@dataclass(frozen=True)
class FrameJoints:
    """The frame's joints at one instant (the module's readings).

    frames : tuple of Frame  Each column's drums, in its own axes (its axis at x = 0)
    columns : tuple of Joints  Each column's joints (scene.joint_state of its frame)
    ratio : (n + 1,) Per joint the largest ratio over the columns; the beam's last
    relative : (n,) Per joint the columns' relative rotation of largest magnitude [rad]
    slip : (n,) Per joint the largest |slip| over the columns [m]
    beam_ratio : (N,) The share of each top's width the beam has left [-]
    beam_slip : (N,) The beam's slip on each top [m]
    """

    frames: tuple[Frame, ...]
    columns: tuple[Joints, ...]
    ratio: np.ndarray
    relative: np.ndarray
    slip: np.ndarray
    beam_ratio: np.ndarray
    beam_slip: np.ndarray


def _friction_demand(force, lo, hi, mass) -> np.ndarray:
    """tan of the distance from each force's angle to its joint's range [lo, hi] of contact
    normals (nan: not loaded), as scene.joint_friction reads it: force (k, 3) [N], lo and
    hi (k,) [rad], mass (k,) the mass the joint carries [kg]."""
    psi = np.arctan2(force[:, 0], force[:, 2])
    gap = np.maximum(0.0, np.maximum(lo - psi, psi - hi))
    normal = np.hypot(force[:, 0], force[:, 2]) * np.cos(gap)
    out = np.full(len(force), np.nan)
    loaded = (gap < 0.5 * math.pi) & (normal > 1e-6 * G * mass)
    out[loaded] = np.tan(gap[loaded])
    return out


def frame_friction(
    before: Frame,
    after: Frame,
    masses: np.ndarray,
    n: int,
    duration: float,
    mean_accel: float,
    tilt_range: tuple[np.ndarray, np.ndarray],
    mean_up: float = 0.0,
) -> np.ndarray:
    """Friction demand of a frame's n + 1 joints over an interval (the module's notes) [-].

    Parameters
    ----------
    before, after : Frame  Every body (columns' drums, column by column, then the beam) at
        the interval's ends
    masses : (N n + 1,) The bodies' masses [kg]
    n : int  Drums per column
    duration : float  The interval [s]
    mean_accel, mean_up : float  Mean a_g and a_v over it, as the engine applied them [m/s^2]
    tilt_range : (lo, hi)  Range of every body's tilt over the interval [rad]
    """
    count = (len(masses) - 1) // n
    momentum = masses[:, None] * (after.velocities - before.velocities)
    beam = momentum[-1]
    levels = momentum[:-1].reshape(count, n, 3).sum(axis=0)
    level_mass = masses[:-1].reshape(count, n).sum(axis=0)
    above = np.vstack([np.cumsum(levels[::-1], axis=0)[::-1] + beam, beam[None]])
    carried = np.append(np.cumsum(level_mass[::-1])[::-1] + masses[-1], masses[-1])
    inertial = np.array([mean_accel, 0.0, G + mean_up])
    force = above / duration + carried[:, None] * inertial
    lo, hi = tilt_range
    lo_c, hi_c = lo[:-1].reshape(count, n), hi[:-1].reshape(count, n)
    ranges = [joint_normal_range(lo_c[c], hi_c[c]) for c in range(count)]
    level_lo = np.min([r[0] for r in ranges], axis=0)
    level_hi = np.max([r[1] for r in ranges], axis=0)
    beam_lo = min(float(lo[-1]), float(np.min(lo_c[:, -1])))
    beam_hi = max(float(hi[-1]), float(np.max(hi_c[:, -1])))
    return _friction_demand(
        force, np.append(level_lo, beam_lo), np.append(level_hi, beam_hi), carried
    )


class FrameWatch(RunWatch):
    """The readings a frame's run carries from check to check, and the tests made at each:
    :class:`rbm_cli.models.bullet.watch.RunWatch`'s checks (divergence, the friction
    windows, collapse, rest after the pulse) on a frame in the plane, with the frame's own
    joints, demand, tracking and collapse rule (the module's notes).

    Parameters
    ----------
    solids : tuple of DrumSolid  A column's drums, bottom first
    layout : FrameLayout
    alpha : (n,) array  Overturning angle of a column above each joint [rad]
    limit : float  collapse.ratio [-]
    dt : float  Engine time step [s]
    accel : (n_steps,) array  a_g at every mid-step, as the engine applies it [m/s^2]
    frame : Frame  Every body at t = 0 (columns' drums, column by column, then the beam)
    upward : (n_steps,) array or None  a_v at every mid-step [m/s^2] (None: 0)

    Attributes
    ----------
    max_slip : (n,) The largest |slip| of each column joint so far, over the columns [m]
    max_beam_slip : float  The beam's largest |slip| on a top so far [m]
    """

    BODY = "body"

    def __init__(self, solids, layout: FrameLayout, alpha, limit: float, dt: float, accel,
                 frame: Frame, upward=None) -> None:  # fmt: skip
        n, count = len(solids), len(layout.axes)
        self.n, self.count = n, count
        self.stack = StackGeometry.of(solids)
        self.layout = layout
        self.half_top = solids[-1].half_top
        self.alpha, self.limit = alpha, limit
        self.shifts = [np.array([x, 0.0, 0.0]) for x in layout.axes]
        beam = layout.beam
        self.masses = np.append(np.tile(self.stack.masses, count), beam.mass)
        column_z = [d.bottom + d.centre for d in solids] * count
        self.rest_z = np.array(column_z + [beam.bottom + beam.centre])
        drops = [DROP_FRACTION * d.height for d in solids] * count
        self.drop = np.array(drops + [DROP_FRACTION * solids[-1].height])
        self.open_tol = OPEN_FRACTION * alpha
        self.max_slip = np.zeros(n)
        self.max_beam_slip = 0.0
        self.was_open = np.zeros(n, bool)
        self.last_sign = np.zeros(n)
        self._start_checks(dt, accel, frame, upward, False)
        self.tilt_lo = self.tilt_hi = frame.tilts
        self.top_start = np.array([j.top[0] for j in self.joints(frame).columns])

    def joints(self, frame: Frame) -> FrameJoints:
        """The frame's joints at a frame of the engine (no reading kept)."""
        n, frames, cols = self.n, [], []
        for c, shift in enumerate(self.shifts):
            s = slice(c * n, (c + 1) * n)
            sub = Frame(frame.centres[s] - shift, frame.rotations[s], frame.rates[s],
                        frame.speeds[s], frame.velocities[s], frame.angular[s])  # fmt: skip
            frames.append(sub)
            cols.append(joint_state(sub, self.stack, self.alpha))
        beam_ratio, beam_slip = self._seat(frame, cols)
        rel = np.array([j.relative for j in cols])
        pick = np.argmax(np.abs(rel), axis=0)
        return FrameJoints(
            frames=tuple(frames),
            columns=tuple(cols),
            ratio=np.append(np.max([j.ratio for j in cols], axis=0), np.max(beam_ratio)),
            relative=rel[pick, np.arange(n)],
            slip=np.max(np.abs([j.slip for j in cols]), axis=0),
            beam_ratio=beam_ratio,
            beam_slip=beam_slip,
        )

    def _seat(self, frame: Frame, cols) -> tuple[np.ndarray, np.ndarray]:
        """The beam on each top: the share of the top's width it has left, and its slip
        (the module's notes), each (N,)."""
        beam, axes, half = self.layout.beam, self.layout.axes, self.half_top
        centre, rot, tilts = frame.centres[-1], frame.rotations[-1], frame.tilts
        ends = np.array([-beam.half_bottom, beam.half_bottom])
        ratio, slip = np.empty(self.count), np.empty(self.count)
        for c, joints in enumerate(cols):
            top = (c + 1) * self.n - 1
            top_rot = frame.rotations[top]
            point = centre + rot @ np.array([axes[c], 0.0, -beam.centre]) - self.shifts[c]
            q = top_rot.T @ (point - joints.top)
            along = top_rot.T @ rot[:, 0]
            x = q[0] + (ends - axes[c]) * along[0]
            overlap = min(float(np.max(x)), half) - max(float(np.min(x)), -half)
            ratio[c] = 1.0 - max(overlap, 0.0) / (2.0 * half)
            phi = tilts[-1] - tilts[top]
            slip[c] = q[0] - math.copysign(half * (1.0 - math.cos(phi)), phi)
        return ratio, slip

    def seen(self, frame: Frame, joints: FrameJoints) -> tuple[Frame, Joints]:
        """The first column's drums and joints (a frame's history is its first column's)."""
        return joints.frames[0], joints.columns[0]

    def residual(self, out: Outcome) -> None:
        """The run's residual state into ``out``, as RunWatch.residual reads a column's:
        the largest |slip| of a joint, the beam's on a top included [m], the largest
        offset of a column's top from its start [m] and the largest |relative rotation| /
        alpha_i of a column's joint [-]; left NaN unless the run survived."""
        if out.status != "survived":
            return
        joints = self.joints(self.frame_last)
        out.residual_slip = float(max(np.max(joints.slip), np.max(np.abs(joints.beam_slip))))
        tops = np.array([j.top[0] for j in joints.columns])
        out.residual_top = float(np.max(np.abs(tops - self.top_start)))
        tilt = np.max([np.abs(j.relative) / self.alpha for j in joints.columns])
        out.residual_tilt = float(tilt)

    def _demand(self, frame: Frame, span: float, mean_accel, mean_up: float) -> np.ndarray:
        """The frame's n + 1 joints' mean-force demand over the window (frame_friction)."""
        demand = frame_friction(self.frame_prev, frame, self.masses, self.n, span, mean_accel,
                                (self.tilt_lo, self.tilt_hi), mean_up)  # fmt: skip
        self.tilt_lo = self.tilt_hi = frame.tilts
        return demand

    def _track(self, out: Outcome, joints: FrameJoints, frame: Frame, t: float) -> np.ndarray:
        """Maxima of ratio, top displacement and slip; joint openings and closures (of the
        rotation of largest magnitude over the columns). Returns which joints are open."""
        out.max_ratio = np.maximum(out.max_ratio, joints.ratio)
        top = max(abs(j.top[0] - j.bottoms[0, 0]) for j in joints.columns)
        out.max_top = max(out.max_top, float(top))
        self.max_slip = np.maximum(self.max_slip, joints.slip)
        self.max_beam_slip = max(self.max_beam_slip, float(np.max(np.abs(joints.beam_slip))))
        is_open = np.abs(joints.relative) > self.open_tol
        sign = np.sign(joints.relative) * is_open
        out.n_uplifts += int(np.sum(is_open & ~self.was_open))
        out.n_impacts += int(np.sum(self.was_open & (~is_open | (sign * self.last_sign < 0))))
        self.was_open, self.last_sign = is_open, np.where(is_open, sign, self.last_sign)
        return is_open

    def _collapsed(self, out: Outcome, k: int, t: float, frame: Frame,
                   joints: FrameJoints) -> bool:  # fmt: skip
        """Collapse (the module's rule): a column's joint or the beam's reached the limit
        (time interpolated between checks), or a body dropped."""
        limit, n = self.limit, self.n
        ratio = joints.ratio
        worst = int(np.argmax(ratio))
        dropped = np.nonzero(self.rest_z - frame.centres[:, 2] > self.drop)[0]
        if ratio[worst] < limit and not dropped.size:
            self.prev_ratio, self.prev_t = float(ratio[worst]), t
            return False
        out.n_steps = out.n_rhs = k
        if ratio[worst] >= limit:
            prev_ratio, prev_t = self.prev_ratio, self.prev_t
            frac = (limit - prev_ratio) / max(ratio[worst] - prev_ratio, 1e-300)
            out.t_collapse = prev_t + min(max(frac, 0.0), 1.0) * (t - prev_t)
            out.collapse_interface = worst + 1
            if worst == n:
                column = int(np.argmax(joints.beam_ratio)) + 1
                why = f"the beam left the top of column {column}"
            else:
                column = int(np.argmax([j.ratio[worst] for j in joints.columns])) + 1
                why = f"the drums above joint {worst + 1} of column {column} passed over its edge"
        else:
            out.t_collapse = t
            body = int(dropped[0])
            if body == len(self.rest_z) - 1:
                out.collapse_interface = n + 1
                why = "the beam dropped by half the top drum's height"
            else:
                column, drum = divmod(body, n)
                out.collapse_interface = drum + 1
                why = f"drum {drum + 1} of column {column + 1} dropped by half its height"
        out.stop("collapsed", why, out.t_collapse)
        return True
