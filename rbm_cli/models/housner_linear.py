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
from scipy.optimize import brentq

from rbm_cli.config.types import Config, G, SolverConfig
from rbm_cli.models.contract import DEFAULT_OUTPUT_DT
from rbm_cli.models.events import EVENT_EPS, REST_RATE
from rbm_cli.models.outcome import Outcome
from rbm_cli.models.result import history_from_samples
from rbm_cli.physics.block import block_geometry, block_initial
from rbm_cli.physics.excitation import GroundMotion
from rbm_cli.physics.restitution import block_restitution, resolve

#: Samples per scanning chunk of a closed-form piece.
_CHUNK = 64
#: Scanning step, in units of the shorter of 1/p and 1/omega [-].
_SCAN_STEP = 0.05
#: Energy margin of the early stop of free motion [fraction of the barrier].
STOP_MARGIN = 1e-9


def _sign(x: float) -> int:
    return 1 if x > 0 else -1 if x < 0 else 0


class Recorder:
    """Time-history samples (t, [theta], [rate]) every output_dt [s], at k * output_dt."""

    def __init__(self, output_dt: float, samples: list | None):
        self.dt = output_dt
        self.samples = samples
        self.k = 0

    def times(self, t_stop: float) -> np.ndarray:
        """The sample times not yet emitted up to t_stop [s] (consumed)."""
        if self.samples is None:
            return np.zeros(0)
        k_last = math.floor((t_stop + 1e-12) / self.dt)
        ts = self.dt * np.arange(self.k, k_last + 1)
        self.k = max(self.k, k_last + 1)
        return ts

    def emit(self, ts, theta, rate) -> None:
        for t, th, v in zip(
            ts, np.broadcast_to(theta, ts.shape), np.broadcast_to(rate, ts.shape), strict=True
        ):
            self.samples.append((float(t), np.array([float(th)]), np.array([float(v)])))

    def rest(self, t_stop: float) -> None:
        ts = self.times(t_stop)
        self.emit(ts, 0.0, 0.0)


@dataclass(frozen=True)
class LinearPiece:
    """Closed-form motion on side s between two events, from time t0 [s].

    theta(tau) = s alpha + C sin(omega tau + phi0) + c1 exp(p tau) + c2 exp(-p tau),
    tau = t - t0 [s]; C = p^2 A / (p^2 + omega^2), A the ground amplitude in g
    (C = 0 in free motion).
    """

    t0: float
    side: int
    alpha: float
    p: float
    forced_amplitude: float  # C [rad]
    omega: float
    phi0: float
    c1: float
    c2: float

    @classmethod
    def start(cls, t0, theta0, rate0, side, alpha, p, amplitude_g, omega, phase):
        """The piece through (theta0 [rad], rate0 [rad/s]) at t0 [s]; amplitude_g = A [g]."""
        c = p * p * amplitude_g / (p * p + omega * omega) if amplitude_g else 0.0
        phi0 = math.fmod(omega * t0 + phase, 2.0 * math.pi) if c else 0.0
        x0 = theta0 - side * alpha - c * math.sin(phi0)
        v0 = rate0 - c * omega * math.cos(phi0)
        return cls(t0, side, alpha, p, c, omega, phi0, 0.5 * (x0 + v0 / p), 0.5 * (x0 - v0 / p))

    def _exps(self, tau):
        tau = np.asarray(tau, dtype=float)
        with np.errstate(divide="ignore", over="ignore"):
            # c * exp(x) as sign(c) exp(log|c| + x): no 0 * inf when c = 0
            e1 = np.sign(self.c1) * np.exp(np.log(abs(self.c1)) + self.p * tau)
            e2 = np.sign(self.c2) * np.exp(np.log(abs(self.c2)) - self.p * tau)
        return tau, e1, e2

    def theta(self, tau):
        """Rotation theta(t0 + tau) [rad]."""
        tau, e1, e2 = self._exps(tau)
        forced = self.forced_amplitude * np.sin(self.omega * tau + self.phi0)
        return self.side * self.alpha + forced + e1 + e2

    def rate(self, tau):
        """Rate theta'(t0 + tau) [rad/s]."""
        tau, e1, e2 = self._exps(tau)
        forced = self.forced_amplitude * self.omega * np.cos(self.omega * tau + self.phi0)
        return forced + self.p * (e1 - e2)


@dataclass
class Scan:
    """What a piece does up to its first event (times from the piece start) [s]."""

    tau: float  # end of the piece: the event, or the end of the segment
    kind: str | None  # 'impact', 'collapse' or None
    peak: float  # largest s theta on [0, tau] [rad]
    tau_peak: float | None  # time of an interior maximum (theta' = 0) holding the peak
    n_evals: int


def scan_piece(piece: LinearPiece, tau_max: float, limit: float) -> Scan:
    """First impact (s theta back to 0) or collapse (s theta = limit) of a piece.

    The closed form is sampled with a step short against 1/p and 1/omega, so
    that no sign change of s theta or of its rate is skipped; a turn of the
    rate between samples (an interior extremum) is located by brentq on the
    rate and checked, so grazing returns and grazing collapses are not missed.
    Roots are then refined by brentq on the closed form (xtol 1e-15 s).
    """
    s = piece.side
    eps = EVENT_EPS * piece.alpha
    n_evals = 0

    def f(x):
        nonlocal n_evals
        n_evals += 1
        return s * float(piece.theta(x))

    def df(x):
        nonlocal n_evals
        n_evals += 1
        return s * float(piece.rate(x))

    def root(fun, a, b):
        return brentq(fun, a, b, xtol=1e-15)

    def impact(a, b):
        # f(a) > 0 >= f(b) or f(a) = 0 at a restart: root of f + eps, then Newton to f = 0
        if f(a) > 0.0:
            return root(f, a, b)
        tau = root(lambda x: f(x) + eps, a, b)
        for _ in range(2):
            v = df(tau)
            if v >= 0.0:
                break
            tau = min(max(tau - f(tau) / v, a), b)
        return tau

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
        n_evals += 2 * len(taus)
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
                    return Scan(
                        root(lambda x: f(x) - limit, ta, tm), "collapse", limit, None, n_evals
                    )
                if fm > peak:
                    peak, tau_peak = fm, tm
            elif turn_min[i]:
                tm = root(df, ta, tb)
                if f(tm) + eps <= 0.0:
                    return Scan(impact(ta, tm), "impact", peak, tau_peak, n_evals)
            if big_f[i] >= limit:
                return Scan(root(lambda x: f(x) - limit, ta, tb), "collapse", limit, None, n_evals)
            if big_f[i] + eps <= 0.0:
                return Scan(impact(ta, tb), "impact", peak, tau_peak, n_evals)
        a, fa, da = taus[-1], big_f[-1], big_d[-1]
    if fa > peak:
        peak, tau_peak = fa, None
    return Scan(tau_max, None, peak, tau_peak, n_evals)


def linear_energy(theta: float, rate: float, alpha: float, p: float) -> float:
    """Energy per unit corner inertia of the linear block [rad^2/s^2].

    E = theta'^2 / 2 + p^2 (alpha |theta| - theta^2 / 2), zero at rest.
    """
    a = abs(theta)
    return 0.5 * rate * rate + p * p * (alpha * a - 0.5 * a * a)


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
    out = Outcome()
    out.friction = np.array([math.nan])
    rec = Recorder(output_dt, out.samples if record else None)
    note = events.append if events is not None else (lambda item: None)
    limit = collapse_ratio * alpha
    lim_e = min(limit, alpha)
    barrier = p * p * (alpha * lim_e - 0.5 * lim_e * lim_e)
    rest_rate = REST_RATE * p * alpha
    amp_g = motion.amplitude / G
    theta, rate = float(initial[0]), float(initial[1])
    side = _sign(theta) or _sign(rate) or 1
    at_rest = theta == 0.0 and rate == 0.0
    peak = abs(theta)
    t = 0.0

    def finish(status: str = "survived", message: str = "") -> Outcome:
        out.n_events = out.n_uplifts + out.n_impacts
        out.max_ratio = np.array([peak / alpha])
        out.max_top = height * peak if height else 0.0
        out.status, out.message = status, message
        out.t_end = t
        return out

    if abs(theta) >= limit:
        out.t_collapse, out.collapse_interface = 0.0, 1
        return finish("collapsed", "initial rotation beyond the collapse limit")

    for seg_start, seg_end in motion.segments():
        if t >= seg_end:
            continue
        forced = motion.forced(seg_start)
        can_stop = early_stop and motion.after_pulse(seg_start)
        while t < seg_end:
            if at_rest:
                kind, t_stop = motion.rest_end(t, seg_end, G * alpha, forced)
                rec.rest(t_stop - (1e-15 if kind == "uplift" else 0.0))
                t = t_stop
                if kind == "end":  # no ground motion from here on: rests to the end
                    return finish(message="at rest in free motion: stopped")
                if kind == "segment":
                    break
                theta, rate = 0.0, 0.0
                side = motion.uplift_side(t)
                at_rest = False
                out.n_uplifts += 1
                note((t, "uplift"))
            if out.n_steps >= max_pieces:
                return finish(
                    "failed", f"piece budget exceeded ({max_pieces} pieces) at t={t:.6g} s"
                )
            piece = LinearPiece.start(
                t,
                theta,
                rate,
                side,
                alpha,
                p,
                amp_g if forced else 0.0,
                motion.omega,
                motion.phase,
            )
            out.n_steps += 1
            sc = scan_piece(piece, seg_end - t, limit)
            out.n_rhs += sc.n_evals
            stop_here = (
                can_stop
                and sc.tau_peak is not None
                and linear_energy(theta, rate, alpha, p) < barrier * (1.0 - STOP_MARGIN)
            )
            tau_end = sc.tau_peak if stop_here else sc.tau
            t_new = seg_end if sc.kind is None and not stop_here else t + tau_end
            if record:
                ts = rec.times(t_new)
                rec.emit(ts, piece.theta(ts - t), piece.rate(ts - t))
            peak = max(peak, sc.peak)
            theta, rate = float(piece.theta(tau_end)), float(piece.rate(tau_end))
            t = t_new
            if stop_here:
                return finish(message="free motion below the collapse barrier: stopped early")
            if sc.kind == "collapse":
                out.t_collapse, out.collapse_interface = t, 1
                note((t, "collapse"))
                return finish("collapsed", "the block reached its collapse limit")
            if sc.kind == "impact":
                out.n_impacts += 1
                note((t, "impact"))
                theta, rate, side = 0.0, restitution * rate, -side
                if abs(rate) < rest_rate:
                    theta, rate, at_rest = 0.0, 0.0, True
                    note((t, "rest"))
    return finish()


class HousnerLinearRunner:
    """`housner-linear` (rbm_cli.models.contract.Runner): the config's monolithic column as
    Spanos and Koh's piecewise-linear block (true geometry), integrated in closed form."""

    n_interfaces = 1

    def __init__(self, config: Config) -> None:
        self.config = config
        self.geometry = block_geometry(config.column)
        self.restitution = resolve(
            config.interface.restitution, lambda: block_restitution(self.geometry)
        )
        self.initial = block_initial(config)
        self.node_map = np.array([[0.0], [config.column.height]])

    def run(
        self,
        motion: GroundMotion,
        solver: SolverConfig,
        *,
        record: bool = False,
        output_dt: float = DEFAULT_OUTPUT_DT,
        early_stop: bool = True,
    ) -> Outcome:
        """One run (rbm_cli.models.contract.Runner.run); closed form, so `solver` is unused."""
        out = housner_linear_run(
            self.geometry.slenderness,
            self.geometry.frequency_parameter,
            motion,
            restitution=self.restitution,
            collapse_ratio=self.config.collapse.ratio,
            record=record,
            output_dt=output_dt,
            height=self.config.column.height,
            initial=self.initial,
            early_stop=early_stop,
        )
        if record:
            out.history = history_from_samples(self.node_map, motion, out.samples)
        return out
