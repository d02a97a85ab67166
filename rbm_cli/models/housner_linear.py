"""The piecewise-linear rocking block (`housner-linear`, SPEC section 2), in closed form.

The linearised rocking equation of a rigid block on a rigid ground
(Spanos and Koh 1984),

    theta'' = p^2 (theta - alpha sgn(theta)) - p^2 a_g(t) / g,

is linear on each side of theta = 0, so between two events it is solved
exactly: a sum of exp(+-p tau) and the harmonic particular solution. Events
(impacts at theta = 0, collapse at |theta| = c alpha, peaks at theta' = 0) are
found by root finding on that closed form, to round-off. Nothing here
integrates numerically.

References
----------
.. [1] G. W. Housner (1963). The behavior of inverted pendulum structures
   during earthquakes. Bulletin of the Seismological Society of America
   53(2), 403-417.
.. [2] P. D. Spanos and A.-S. Koh (1984). Rocking of rigid blocks due to
   harmonic shaking. Journal of Engineering Mechanics 110(11), 1627-1642.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rbm_cli.config.types import G, SolverConfig
from rbm_cli.models.block_runner import BlockRunner
from rbm_cli.models.events import EVENT_EPS, REST_RATE
from rbm_cli.models.housner_linear_piece import LinearPiece, PieceScanner, Scan
from rbm_cli.models.housner_state import STOP_MARGIN, BlockRun
from rbm_cli.models.outcome import Outcome
from rbm_cli.physics.excitation import GroundMotion
from rbm_cli.physics.ground_forms import gravity_factor

#: Samples per scanning chunk of a closed-form piece.
_CHUNK = 64
#: Scanning step, in units of the shorter of 1/p and 1/omega [-].
_SCAN_STEP = 0.05


def _sign(x: float) -> int:
    return 1 if x > 0 else -1 if x < 0 else 0


def scan_piece(piece: LinearPiece, tau_max: float, limit: float) -> Scan:
    """First impact (s theta back to 0) or collapse (s theta = limit) of a piece.

    The closed form is sampled with a step short against 1/p and 1/omega, so
    that no sign change of s theta or of its rate is skipped; a turn of the
    rate between samples (an interior extremum) is located by brentq on the
    rate and checked, so grazing returns and grazing collapses are not missed.
    Roots are then refined by brentq on the closed form (xtol 1e-15 s).
    """
    sc = PieceScanner(piece, EVENT_EPS * piece.alpha, limit)
    s, eps, f, df, root = sc.s, sc.eps, sc.f, sc.df, sc.root
    omega = piece.omega if piece.forced_amplitude else 0.0
    h = _SCAN_STEP / max(piece.p, omega)
    a, fa, da = 0.0, f(0.0), df(0.0)
    peak, tau_peak = fa, None
    while a < tau_max:
        taus = a + h * np.arange(1, _CHUNK + 1)
        if taus[-1] >= tau_max:
            taus = np.append(taus[taus < tau_max], tau_max)
        big_f = s * piece.theta(taus)
        big_d = s * piece.rate(taus)
        sc.n_evals += 2 * len(taus)
        lo_t = np.concatenate([[a], taus[:-1]])
        lo_d = np.concatenate([[da], big_d[:-1]])
        turn_max = (lo_d > 0.0) & (big_d < 0.0)
        turn_min = (lo_d < 0.0) & (big_d > 0.0)
        flag = (big_f + eps <= 0.0) | (big_f >= limit) | turn_max | turn_min
        for i in np.nonzero(flag)[0]:
            ta, tb = lo_t[i], taus[i]
            if turn_max[i]:
                tm = root(df, ta, tb)
                fm = f(tm)
                if fm >= limit:
                    return Scan(sc.collapse(ta, tm), "collapse", limit, None, sc.n_evals)
                if fm > peak:
                    peak, tau_peak = fm, tm
            elif turn_min[i]:
                tm = root(df, ta, tb)
                if f(tm) + eps <= 0.0:
                    return Scan(sc.impact(ta, tm), "impact", peak, tau_peak, sc.n_evals)
            if big_f[i] >= limit:
                return Scan(sc.collapse(ta, tb), "collapse", limit, None, sc.n_evals)
            if big_f[i] + eps <= 0.0:
                return Scan(sc.impact(ta, tb), "impact", peak, tau_peak, sc.n_evals)
        a, fa, da = taus[-1], big_f[-1], big_d[-1]
    if fa > peak:
        peak, tau_peak = fa, None
    return Scan(tau_max, None, peak, tau_peak, sc.n_evals)


def linear_energy(theta: float, rate: float, alpha: float, p: float) -> float:
    """Energy per unit corner inertia of the linear block [rad^2/s^2].

    E = theta'^2 / 2 + p^2 (alpha |theta| - theta^2 / 2), zero at rest.
    """
    a = abs(theta)
    return 0.5 * rate * rate + p * p * (alpha * a - 0.5 * a * a)


@dataclass(frozen=True)
class _LinearBlock:
    """The block's constants and the run's thresholds and settings."""

    alpha: float  # slenderness [rad]
    p: float  # frequency parameter [rad/s]
    restitution: float  # [-]
    limit: float  # collapse rotation c alpha [rad]
    barrier: float  # energy at min(c, 1) alpha [rad^2/s^2]
    rest_rate: float  # post-impact rate below which the block rests [rad/s]
    amp_g: float  # ground amplitude [g]
    omega: float  # ground circular frequency [rad/s]
    phase: float  # ground phase [rad]
    max_pieces: int
    record: bool
    knots: np.ndarray | None = None  # a record's sample times [s] (pieces end there)
    values: np.ndarray | None = None  # its accelerations [m/s^2]
    vertical: np.ndarray | None = None  # its upward accelerations a_v [m/s^2]

    @classmethod
    def make(cls, alpha, p, motion, restitution, collapse_ratio, max_pieces, record):
        limit = collapse_ratio * alpha
        lim_e = min(limit, alpha)
        return cls(
            alpha=alpha,
            p=p,
            restitution=restitution,
            limit=limit,
            barrier=p * p * (alpha * lim_e - 0.5 * lim_e * lim_e),
            rest_rate=REST_RATE * p * alpha,
            amp_g=motion.amplitude / G,
            omega=motion.omega,
            phase=motion.phase,
            max_pieces=max_pieces,
            record=record,
            knots=motion.knots if motion.clipped else None,
            values=motion.values if motion.clipped else None,
            vertical=motion.vertical,
        )


@dataclass
class _LinearRun(BlockRun):
    """BlockRun with the state theta [rad], rate [rad/s]."""

    theta: float = 0.0
    rate: float = 0.0

    @classmethod
    def make(cls, blk: _LinearBlock, record, output_dt, events, height, initial) -> _LinearRun:
        """The state at t = 0 from initial = (theta [rad], rate [rad/s])."""
        theta, rate = float(initial[0]), float(initial[1])
        return cls(
            alpha=blk.alpha,
            limit=blk.limit,
            **BlockRun.parts(record, output_dt, events),
            top=lambda peak: height * peak if height else 0.0,
            side=_sign(theta) or _sign(rate) or 1,
            at_rest=theta == 0.0 and rate == 0.0,
            peak=abs(theta),
            theta=theta,
            rate=rate,
        )


def _start_piece(blk: _LinearBlock, run: _LinearRun, seg_end: float, forced: bool):
    """The closed-form piece from the current state, and where it ends [s]: seg_end, or
    under a record the next sample (the ground acceleration is one line up to it). With a
    vertical record, theta'' = p^2 gam (theta - s alpha) - p^2 a_g / g, gam = (g + a_v) / g
    taken constant on the piece at its middle: exact for a_v constant between samples (the
    similarity test of tests/test_vertical.py), second order in the sample step otherwise."""
    t = run.t
    if not forced or blk.knots is None:
        amp = blk.amp_g if forced else 0.0
        piece = LinearPiece.start(
            t, run.theta, run.rate, run.side, blk.alpha, blk.p, amp, blk.omega, blk.phase
        )
        return piece, seg_end
    knots, values = blk.knots, blk.values
    k = int(np.searchsorted(knots, t, side="right"))  # the first sample after t
    end = min(float(knots[k]), seg_end) if k < knots.size else seg_end
    q0 = q1 = 0.0  # at rest before the first sample
    if 0 < k < knots.size:
        q1 = (values[k] - values[k - 1]) / (knots[k] - knots[k - 1]) / G
        q0 = values[k - 1] / G + q1 * (t - knots[k - 1])
    p = blk.p
    if blk.vertical is not None:  # g -> g + a_v: p^2 gam (theta - s alpha) - p^2 a_g / g
        gam = gravity_factor(0.5 * (t + end), knots, blk.vertical)  # the piece's middle
        p, q0, q1 = p * math.sqrt(gam), q0 / gam, q1 / gam
    piece = LinearPiece.start_line(t, run.theta, run.rate, run.side, blk.alpha, p, q0, q1)
    return piece, end


def _piece(blk: _LinearBlock, run: _LinearRun, seg_end: float, forced: bool, can_stop: bool):
    """One closed-form piece from the current state up to its first event, a peak of free
    motion below the barrier (when can_stop) or its end (seg_end [s], or a record's next
    sample). Returns the Outcome if the run ends there, else None."""
    out, rec, t = run.out, run.rec, run.t
    alpha, p = blk.alpha, blk.p
    piece, seg_end = _start_piece(blk, run, seg_end, forced)
    out.n_steps += 1
    sc = scan_piece(piece, seg_end - t, blk.limit)
    out.n_rhs += sc.n_evals
    stop_here = (
        can_stop
        and sc.tau_peak is not None
        and linear_energy(run.theta, run.rate, alpha, p) < blk.barrier * (1.0 - STOP_MARGIN)
    )
    tau_end = sc.tau_peak if stop_here else sc.tau
    t_new = seg_end if sc.kind is None and not stop_here else t + tau_end
    if blk.record:
        ts = rec.times(t_new)
        rec.emit(ts, piece.theta(ts - t), piece.rate(ts - t))
    run.peak = max(run.peak, sc.peak)
    run.theta, run.rate = float(piece.theta(tau_end)), float(piece.rate(tau_end))
    run.t = t = t_new
    if stop_here:
        return run.finish(message="free motion below the collapse barrier: stopped early")
    if sc.kind == "collapse":
        out.t_collapse, out.collapse_interface = t, 1
        run.note((t, "collapse"))
        return run.finish("collapsed", "the block reached its collapse limit")
    if sc.kind == "impact":
        out.n_impacts += 1
        run.note((t, "impact"))
        run.theta, run.rate, run.side = 0.0, blk.restitution * run.rate, -run.side
        if abs(run.rate) < blk.rest_rate:
            run.theta, run.rate, run.at_rest = 0.0, 0.0, True
            run.note((t, "rest"))
    return None


def _linear_segment(
    blk: _LinearBlock,
    run: _LinearRun,
    motion: GroundMotion,
    seg_end: float,
    forced: bool,
    can_stop: bool,
) -> Outcome | None:
    """Run up to seg_end [s], the end of a segment of the motion, from rest to uplift and
    piece by piece. Returns the Outcome if the run ends inside the segment, else None."""
    while run.t < seg_end:
        if run.at_rest:
            kind = run.wait(motion, seg_end, G * blk.alpha, forced)
            if kind == "end":  # no ground motion from here on: rests to the end
                return run.finish(message="at rest in free motion: stopped")
            if kind == "segment":
                return None
            run.theta, run.rate = 0.0, 0.0
        if run.out.n_steps >= blk.max_pieces:
            return run.finish(
                "failed", f"piece budget exceeded ({blk.max_pieces} pieces) at t={run.t:.6g} s"
            )
        stop = _piece(blk, run, seg_end, forced, can_stop)
        if stop is not None:
            return stop
    return None


def housner_linear_run(
    alpha: float,
    p: float,
    motion: GroundMotion,
    restitution: float = 1.0,
    collapse_ratio: float = 1.0,
    record: bool = False,
    output_dt: float = 0.002,
    *,
    height: float | None = None,
    initial: tuple[float, float] = (0.0, 0.0),
    early_stop: bool = True,
    max_pieces: int = 1_000_000,
    events: list | None = None,
) -> Outcome:
    """One run of the piecewise-linear rocking block, in closed form.

    Parameters
    ----------
    alpha : float  Slenderness, also the uplift level in g [rad]
    p : float  Frequency parameter [rad/s]
    motion : GroundMotion  a_g(t) [m/s^2] and the simulated time [s]
    restitution : float  Angular-velocity ratio e at impacts, in (0, 1] [-]
    collapse_ratio : float  Collapse at |theta| >= collapse_ratio * alpha [-]
    record : bool  Keep samples (t [s], [theta] [rad], [rate] [rad/s]) every output_dt [s]
    output_dt : float  Sampling interval of the history [s]
    height : float or None  Block height H [m] for the top displacement
        H |theta| [m]; None reports 0
    initial : (float, float)  Initial rotation [rad] and rate [rad/s]
    early_stop : bool  After a half-sine pulse, stop at rest, or at a peak
        when the energy is below the collapse barrier (no later peak is larger)
    max_pieces : int  Budget of closed-form pieces; beyond it the run is 'failed'
    events : list or None  If a list, (t [s], kind) is appended for every
        'uplift', 'impact', 'rest' and 'collapse'

    Returns
    -------
    Outcome  status 'collapsed' or 'survived' (or 'failed' past the budget);
        n_steps counts closed-form pieces, n_rhs closed-form evaluations.
        Records: exact pieces between samples; Ricker / MP pulses sampled first
        (GroundMotion.sampled); a vertical record's gam = (g + a_v) / g constant on each
        piece at its middle (_start_piece).

    Notes
    -----
    On side s = sgn(theta), with A = a_g amplitude / g and a_g / g = A sin(omega t + phi),

    .. math:: \\theta = s\\alpha + C \\sin(\\omega t + \\phi) + c_1 e^{p\\tau} + c_2 e^{-p\\tau},
              \\quad C = p^2 A / (p^2 + \\omega^2)

    (C = 0 after a half-sine pulse). The block rests until |a_g| > g alpha and
    lifts on the side turning away from a_g. At theta = 0 the rate is
    multiplied by e; a post-impact rate below REST_RATE p alpha puts the block
    to rest (the RBM integrator's rule). Energy per unit inertia,
    E = theta'^2/2 + p^2 (alpha |theta| - theta^2/2), is conserved in free
    motion between impacts; its barrier is E at |theta| = min(c, 1) alpha.

    References
    ----------
    Spanos and Koh (1984); Housner (1963): see the module references.
    """
    if not (alpha > 0.0 and p > 0.0):
        raise ValueError("alpha [rad] and p [rad/s] must be > 0")
    if not 0.0 < restitution <= 1.0:
        raise ValueError("restitution must be in (0, 1]")
    motion = motion.sampled()  # a pulse with no closed form as a record; else itself
    blk = _LinearBlock.make(alpha, p, motion, restitution, collapse_ratio, max_pieces, record)
    run = _LinearRun.make(blk, record, output_dt, events, height, initial)
    finish = run.finish
    if run.collapsed_at_start() is not None:
        return run.out
    for seg_start, seg_end in motion.segments():
        if run.t >= seg_end:
            continue
        forced = motion.forced(seg_start)
        can_stop = early_stop and motion.after_pulse(seg_start)
        stop = _linear_segment(blk, run, motion, seg_end, forced, can_stop)
        if stop is not None:
            return stop
    return finish()


class HousnerLinearRunner(BlockRunner):
    """`housner-linear` (rbm_cli.models.contract.Runner): the config's monolithic column as
    Spanos and Koh's piecewise-linear block (true geometry), in closed form: compiled
    (rbm_cli.models.rbm.closed_form) with `solver.implementation: compiled` (the default),
    housner_linear_run with `python` or a vertical record (its gam taken per piece). Its
    method is `closed-form` whatever solver.method says (as before `auto` existed, when the
    solver was unused), so configs that name a method still run."""

    def _integrate(self, motion: GroundMotion, solver: SolverConfig, **options) -> Outcome:
        geometry = self.geometry
        args = (geometry.slenderness, geometry.frequency_parameter)
        kw = dict(restitution=self.restitution, collapse_ratio=self.config.collapse.ratio)
        motion = motion.sampled()  # a pulse with no closed form as a record; else itself
        if solver.implementation == "compiled" and not motion.has_vertical:
            from rbm_cli.models.rbm.closed_form import linear_block, run_closed_form

            block = linear_block(*args, height=self.config.column.height, **kw)
            out = run_closed_form(block, motion, *self.initial, solver, **options)
        else:
            out = housner_linear_run(*args, motion, height=self.config.column.height,
                                     initial=self.initial, **kw, **options)  # fmt: skip
        out.method = "closed-form"
        return out
