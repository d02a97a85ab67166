"""Housner's rigid rocking block (`housner`, SPEC section 2): true geometry, large rotations.

A monolithic column as one rigid block rocking on the corners of its base:

    theta'' = -p^2 [ sin(alpha sgn(theta) - theta) + (a_g / g) cos(alpha sgn(theta) - theta) ]

with the true centre of mass and the rotary inertia of the tapered solid about
a base corner (not the RBM's mid-height lumping). Integrated by scipy's DOP853
driven step by step, restarted at every impact and at the end of a pulse;
impacts (theta = 0), collapse (|theta| = c alpha) and peaks (theta' = 0) are
located by root finding on the step's dense output.

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
from numpy.polynomial import Polynomial
from scipy.integrate import DOP853, RK23, RK45
from scipy.optimize import brentq

from rbm_cli.config.types import ColumnConfig, G, SolverConfig
from rbm_cli.models.events import first_crossing, hermite_dip
from rbm_cli.models.housner_linear import STOP_MARGIN, Recorder
from rbm_cli.models.rbm.python import EVENT_EPS, REST_RATE, Outcome
from rbm_cli.physics.excitation import GroundMotion

_METHODS = {"DOP853": DOP853, "RK45": RK45, "RK23": RK23}


@dataclass(frozen=True)
class BlockGeometry:
    """True rigid-body geometry of a monolithic column (SPEC section 2).

    height : float  H [m]
    half_base : float  b = B_1 / 2 [m]
    mass : float  m [kg]
    centre_height : float  z_c, height of the true centre of mass [m]
    half_diagonal : float  R = sqrt(b^2 + z_c^2), base corner to centre of mass [m]
    slenderness : float  alpha = atan(b / z_c) [rad]
    corner_inertia : float  I_O, rotary inertia about a base corner [kg m^2]
    frequency_parameter : float  p = sqrt(m g R / I_O) [rad/s]
    """

    height: float
    half_base: float
    mass: float
    centre_height: float
    half_diagonal: float
    slenderness: float
    corner_inertia: float
    frequency_parameter: float


def block_geometry(column: ColumnConfig) -> BlockGeometry:
    """Mass, true centre of mass and corner inertia of a monolithic (tapered) column.

    Parameters
    ----------
    column : ColumnConfig  height [m], base_width and top_width [m], section
        ('rectangular' with depth [m] or None for a square section, or
        'circular' with diameter = width), density [kg/m^3]

    Returns
    -------
    BlockGeometry

    Notes
    -----
    The width is w(z) = B_1 + (B_top - B_1) z / H. A slice at height z has area
    a(z) (d w, w^2 or pi w^2 / 4) and second moment j(z) about its centroidal
    axis normal to the plane of motion (d w^3 / 12, w^4 / 12, pi w^4 / 64).
    With rho the density, exactly (polynomial integrals):

    .. math:: m = \\rho \\int_0^H a\\,dz, \\quad z_c = \\frac{\\rho}{m} \\int_0^H a z\\,dz,
    .. math:: I_O = \\rho \\int_0^H [\\, j + a (b^2 + z^2) \\,] dz

    (each slice's own inertia plus the parallel-axis term to the corner at
    horizontal distance b). For a uniform rectangle I_O = 4 m R^2 / 3 and
    p = sqrt(3 g / (4 R)).
    """
    if column.n_drums > 1:
        raise ValueError("block_geometry: a monolithic column only (one drum)")
    H, b1, bt = column.height, column.base_width, column.top_width
    if not (H > 0.0 and b1 > 0.0 and bt >= 0.0 and column.density > 0.0):
        raise ValueError("height, base_width, density must be > 0 and top_width >= 0")
    w = Polynomial([b1, (bt - b1) / H])
    z = Polynomial([0.0, 1.0])
    if column.section == "circular":
        area, second = math.pi / 4.0 * w**2, math.pi / 64.0 * w**4
    elif column.depth is None:
        area, second = w**2, w**4 / 12.0
    else:
        area, second = column.depth * w, column.depth * w**3 / 12.0
    rho, b = column.density, 0.5 * b1

    def integral(poly):
        return float(poly.integ()(H))

    mass = rho * integral(area)
    z_c = rho * integral(area * z) / mass
    i_o = rho * integral(second + area * (b * b + z * z))
    r = math.hypot(b, z_c)
    return BlockGeometry(
        height=H,
        half_base=b,
        mass=mass,
        centre_height=z_c,
        half_diagonal=r,
        slenderness=math.atan2(b, z_c),
        corner_inertia=i_o,
        frequency_parameter=math.sqrt(mass * G * r / i_o),
    )


def housner_restitution(geometry: BlockGeometry) -> float:
    """Housner's coefficient of restitution (angular-velocity ratio) [-].

    Notes
    -----
    Conservation of angular momentum about the new corner at the impact:

    .. math:: e = 1 - 2 m R^2 \\sin^2\\alpha / I_O

    (uniform rectangle: 1 - 1.5 sin^2 alpha). Housner (1963).
    """
    g = geometry
    return 1.0 - 2.0 * g.mass * (g.half_diagonal * math.sin(g.slenderness)) ** 2 / g.corner_inertia


def top_displacement(geometry: BlockGeometry, theta) -> np.ndarray | float:
    """Horizontal displacement of the top centre relative to the ground [m].

    Notes
    -----
    Rotation |theta| about the base corner at horizontal distance b from the
    axis: u = H sin|theta| + b (1 - cos theta), exact for large rotations.
    """
    a = np.abs(theta)
    return geometry.height * np.sin(a) + geometry.half_base * (1.0 - np.cos(a))


def housner_energy(theta, rate, alpha: float, p: float):
    """Energy per unit corner inertia [rad^2/s^2].

    E = theta'^2 / 2 + p^2 (cos(alpha - |theta|) - cos(alpha)), zero at rest.
    """
    return 0.5 * rate * rate + p * p * (np.cos(alpha - np.abs(theta)) - math.cos(alpha))


def housner_run(
    geometry: BlockGeometry,
    motion: GroundMotion,
    restitution: float | str = 1.0,
    collapse_ratio: float = 1.0,
    solver: SolverConfig = SolverConfig(),  # noqa: B008 (frozen dataclass)
    record: bool = False,
    output_dt: float = 0.002,
    *,
    initial: tuple[float, float] = (0.0, 0.0),
    early_stop: bool = True,
    events: list | None = None,
) -> Outcome:
    """One run of Housner's rigid block (large rotations).

    Parameters
    ----------
    geometry : BlockGeometry  alpha [rad], p [rad/s], H and b [m]
    motion : GroundMotion  a_g(t) [m/s^2] and the simulated time [s]
    restitution : float or 'housner'  Angular-velocity ratio e at impacts, in (0, 1]
    collapse_ratio : float  Collapse at |theta| >= collapse_ratio * alpha [-]
    solver : SolverConfig  Runge-Kutta pair, rtol, atol (scaled by alpha [rad]
        and p alpha [rad/s]), step and event budgets
    record : bool  Keep samples (t [s], [theta] [rad], [rate] [rad/s]) every output_dt [s]
    output_dt : float  Sampling interval of the history [s]
    initial : (float, float)  Initial rotation [rad] and rate [rad/s]
    early_stop : bool  After a half-sine pulse, stop at rest, or at a peak
        when the energy is below the collapse barrier
    events : list or None  If a list, (t [s], kind) is appended for every
        'uplift', 'impact', 'rest' and 'collapse'

    Returns
    -------
    Outcome  max_top is the exact top displacement of :func:`top_displacement`.

    Notes
    -----
    .. math:: \\theta'' = -p^2 [\\sin(\\alpha s - \\theta) + (a_g/g) \\cos(\\alpha s - \\theta)],
              \\quad s = \\mathrm{sgn}\\,\\theta

    Rest until |a_g| > g tan(alpha), lifting on the side turning away from a_g;
    impact at theta = 0 (theta' <- e theta'; a rate below REST_RATE p alpha
    rests); collapse at |theta| = c alpha. Energy per unit corner inertia,
    E = theta'^2/2 + p^2 (cos(alpha - |theta|) - cos(alpha)), is conserved in
    free motion; its barrier is E at |theta| = min(c, 1) alpha.

    References
    ----------
    Housner (1963): see the module references.
    """
    alpha, p = geometry.slenderness, geometry.frequency_parameter
    e_rest = housner_restitution(geometry) if restitution == "housner" else float(restitution)
    if not 0.0 < e_rest <= 1.0:
        raise ValueError("restitution must be in (0, 1]")
    out = Outcome()
    out.friction = np.array([math.nan])
    rec = Recorder(output_dt, out.samples if record else None)
    note = events.append if events is not None else (lambda item: None)
    limit = collapse_ratio * alpha
    barrier = float(housner_energy(min(limit, alpha), 0.0, alpha, p))
    rest_rate = REST_RATE * p * alpha
    eps = EVENT_EPS * alpha
    level = G * math.tan(alpha)
    atol = solver.atol * np.array([alpha, p * alpha])
    stepper = _METHODS[solver.method]
    amp_g, om, ph = motion.amplitude / G, motion.omega, motion.phase
    y = np.array([float(initial[0]), float(initial[1])])
    side = int(np.sign(y[0])) or int(np.sign(y[1])) or 1
    at_rest = not np.any(y)
    peak = abs(y[0])
    t = 0.0

    def finish(status: str = "survived", message: str = "") -> Outcome:
        out.n_events = out.n_uplifts + out.n_impacts
        out.max_ratio = np.array([peak / alpha])
        out.max_top = float(top_displacement(geometry, peak))
        out.status, out.message, out.t_end = status, message, t
        return out

    if peak >= limit:
        out.t_collapse, out.collapse_interface = 0.0, 1
        return finish("collapsed", "initial rotation beyond the collapse limit")

    for seg_start, seg_end in motion.segments():
        if t >= seg_end:
            continue
        forced = motion.forced(seg_start)
        can_stop = early_stop and motion.after_pulse(seg_start)
        while t < seg_end:
            if at_rest:
                kind, t_stop = motion.rest_end(t, seg_end, level, forced)
                rec.rest(t_stop - (1e-15 if kind == "uplift" else 0.0))
                t = t_stop
                if kind == "end":  # no ground motion from here on: rests to the end
                    return finish(message="at rest in free motion: stopped")
                if kind == "segment":
                    break
                y = np.zeros(2)
                side = motion.uplift_side(t)
                at_rest = False
                out.n_uplifts += 1
                note((t, "uplift"))
                if out.n_uplifts + out.n_impacts > solver.max_events:
                    return _fail(finish(), f"event budget exceeded ({solver.max_events} events)")
            s = side

            def fun(tt, yy, s=s, forced=forced):
                out.n_rhs += 1
                arg = alpha * s - yy[0]
                a = amp_g * math.sin(om * tt + ph) if forced else 0.0
                return np.array([yy[1], -p * p * (math.sin(arg) + a * math.cos(arg))])

            def dist(yy, s=s):
                # event distances, >= 0 inside: impact, collapse
                return np.array([s * yy[0] + eps, limit - s * yy[0]])

            def ddist(yy, s=s):
                return np.array([s * yy[1], -s * yy[1]])

            stop_ok = can_stop and housner_energy(y[0], y[1], alpha, p) < barrier * (
                1.0 - STOP_MARGIN
            )
            integ = stepper(fun, t, y, seg_end, rtol=solver.rtol, atol=atol)
            kind = None
            while integ.status == "running":
                msg = integ.step()
                if integ.status == "failed":
                    return _fail(finish(), f"integrator: {msg} at t={t:.6g} s")
                out.n_steps += 1
                if out.n_steps > solver.max_steps:
                    return _fail(finish(), f"step budget exceeded ({solver.max_steps} steps)")
                t_old, y_old, t_new, y_new = integ.t_old, y, integ.t, integ.y
                dense = None
                d_old, d_new = dist(y_old), dist(y_new)
                t_hit = t_new if d_new.min() < 0.0 else None
                if t_hit is None:
                    t_min = hermite_dip(d_old, d_new, ddist(y_old), ddist(y_new), t_new - t_old)
                    if t_min is not None:
                        dense = integ.dense_output()
                        if dist(dense(t_old + t_min)).min() < 0.0:
                            t_hit = t_old + t_min
                if t_hit is not None:
                    dense = integ.dense_output() if dense is None else dense
                    t_e, row = _earliest(dense, dist, ddist, t_old, t_hit)
                    kind = "impact" if row == 0 else "collapse"
                    if kind == "impact":
                        t_e = _polish_zero(dense, t_e, t_old)
                    t_new, y_new = t_e, dense(t_e)
                # peak: the rate turning inward inside [t_old, t_new]
                t_pk = None
                if s * y_old[1] > 0.0 >= s * y_new[1]:
                    dense = integ.dense_output() if dense is None else dense
                    if s * dense(t_new)[1] < 0.0:
                        t_pk = brentq(lambda x, d=dense: d(x)[1], t_old, t_new, xtol=1e-15)
                    else:
                        t_pk = t_new
                    peak = max(peak, abs(float(dense(t_pk)[0])))
                peak = max(peak, abs(float(y_new[0])) if kind != "impact" else 0.0)
                if t_pk is not None and stop_ok:
                    if record:
                        _emit(rec, dense, t_pk)
                    t = t_pk
                    return finish(message="free motion below the collapse barrier: stopped early")
                if record:
                    _emit(rec, integ.dense_output() if dense is None else dense, t_new)
                t, y = t_new, y_new
                if kind is not None:
                    break
            if kind is None:
                t = seg_end
                continue
            if kind == "collapse":
                out.t_collapse, out.collapse_interface = t, 1
                peak = max(peak, limit)
                note((t, "collapse"))
                return finish("collapsed", "the block reached its collapse limit")
            out.n_impacts += 1
            note((t, "impact"))
            if out.n_uplifts + out.n_impacts > solver.max_events:
                return _fail(finish(), f"event budget exceeded ({solver.max_events} events)")
            y = np.array([0.0, e_rest * y[1]])
            side = -side
            if abs(y[1]) < rest_rate:
                y, at_rest = np.zeros(2), True
                note((t, "rest"))
    return finish()


def _earliest(dense, dist, ddist, t_old: float, t_hit: float) -> tuple[float, int]:
    """(time, row) of the earliest crossing of either event row (0: impact, 1:
    collapse) in [t_old, t_hit], each row's own root on the dense output
    (events.first_crossing), not a root of their minimum, which can be a later one."""

    def rows(ts):
        yy = dense(np.atleast_1d(ts))  # (2, m): theta, rate
        return dist(yy), ddist(yy)

    hit = first_crossing(rows, t_old, t_hit, xtol=1e-15)
    if hit is None:  # t_hit is below zero by construction; only round-off gets here
        return t_hit, int(np.argmin(dist(dense(t_hit))))
    return hit


def _polish_zero(dense, t_e: float, t_lo: float) -> float:
    """Move an impact found at s theta = -EVENT_EPS alpha onto theta = 0 (Newton)."""
    for _ in range(2):
        th, v = dense(t_e)
        if v == 0.0:
            break
        t_e = max(t_e - th / v, t_lo)
    return t_e


def _emit(rec: Recorder, dense, t_stop: float) -> None:
    ts = rec.times(t_stop)
    if len(ts):
        yy = dense(ts)
        rec.emit(ts, yy[0], yy[1])


def _fail(out: Outcome, message: str) -> Outcome:
    out.status, out.message = "failed", message
    return out
