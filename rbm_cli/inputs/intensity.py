"""Intensity measures of a ground-motion record, as the column meets it (SI inside).

A record here is what rbm runs: accelerations a_i [m/s^2] at times t_i [s] (steps may be
uneven), linear between its samples, the ground at rest before its first sample. The
measures are those of that piecewise-linear signal, integrated exactly on each interval,
with no processing (no baseline correction, no filtering: the record as run):

- PGA = max |a| [m/s^2];
- PGV = max |v|, v = int a dt from rest (v is quadratic on an interval: its extremum
  inside one, where a crosses zero, is counted) [m/s];
- PGD = max |u|, u = int v dt from rest (cubic on an interval: its extremum inside one,
  where v = 0, is counted) [m];
- Arias intensity I_A = pi / (2 g) int a^2 dt [m/s];
- CAV = int |a| dt (the zero crossing inside an interval exact) [m/s];
- significant duration D5-95: the time between 5 % and 95 % of int a^2 dt (the Husid
  plot, a cubic in time inside a step: solved there) [s];
- the 5 %-damped pseudo-spectral acceleration Sa(T) = (2 pi / T)^2 max |u_T|, u_T the
  relative displacement of a linear oscillator of period T from rest, by the exact
  solution for an input linear between samples (Nigam and Jennings 1969): exact for any
  step, uneven ones too, then one period of free vibration after the record (a peak that
  comes after the ground stops is counted) [m/s^2].

Why not a library: eqsig and pyrotd compute spectra of a record on a uniform step (eqsig
by Newmark's average acceleration, exact only as dt / T -> 0; pyrotd in the frequency
domain, which wraps the record around unless padded), and rbm's records may have uneven
steps. The recurrence here is exact for the signal the column integrates; the tests check
it against closed forms and against eqsig on a uniform record.

Scaling: a record scaled by a factor c has PGA, PGV, PGD, CAV and Sa times |c|, Arias
times c^2 and the same D5-95. Each measure here is a function of the record as read;
:func:`record_measures` gathers them (:class:`RecordMeasures`). Which measures a domain
holds, and how each scales with a cell's factor, is the registry of
rbm_cli.study.intensities (``MEASURES``), so a sweep over N amplitudes integrates each
record once.

References
----------
.. [1] N. C. Nigam and P. C. Jennings (1969). Calculation of response spectra from
   strong-motion earthquake records. BSSA 59(2), 909-922.
.. [2] A. Arias (1970). A measure of earthquake intensity. In Seismic Design for Nuclear
   Power Plants, MIT Press, 438-483.
.. [3] M. D. Trifunac and A. G. Brady (1975). A study on the duration of strong earthquake
   ground motion. BSSA 65(3), 581-626.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rbm_cli.config.types import G

#: Damping ratio of the response spectrum [-].
DAMPING = 0.05
#: Periods of the response spectrum a config may list (excitation.im_periods) [s].
PERIOD_RANGE_S = (0.01, 20.0)
#: Steps per period of the free vibration followed after the record.
FREE_STEPS = 400
#: Points of the exact response evaluated inside a step where the oscillator turns (its
#: peak there is found within a relative (pi dt / (T INNER_POINTS))^2 / 2).
INNER_POINTS = 65


@dataclass(frozen=True)
class RecordMeasures:
    """Intensity measures of one record (SI): pga [m/s^2], pgv [m/s], pgd [m], arias [m/s],
    cav [m/s], d5_95 [s], sa: {period [s]: Sa [m/s^2]} (5 % damping)."""

    pga: float
    pgv: float
    pgd: float
    arias: float
    cav: float
    d5_95: float
    sa: dict


def _checked(t, a) -> tuple[np.ndarray, np.ndarray]:
    t = np.asarray(t, dtype=float).ravel()
    a = np.asarray(a, dtype=float).ravel()
    if t.size != a.size or t.size < 2:
        raise ValueError(
            f"a record needs as many times as accelerations, 2 or more: {t.size}, {a.size}"
        )
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(a)) and np.all(np.diff(t) > 0.0)):
        raise ValueError("a record's times must increase and its values be finite")
    return t, a


def velocity_displacement(t, a) -> tuple[np.ndarray, np.ndarray]:
    """Ground velocity [m/s] and displacement [m] at the samples, from rest at t_0, exact
    for a linear between samples."""
    t, a = _checked(t, a)
    dt = np.diff(t)
    dv = 0.5 * dt * (a[:-1] + a[1:])
    v = np.concatenate([[0.0], np.cumsum(dv)])
    du = v[:-1] * dt + dt * dt * (a[:-1] / 3.0 + a[1:] / 6.0)
    u = np.concatenate([[0.0], np.cumsum(du)])
    return v, u


def peak_velocity(t, a) -> float:
    """PGV [m/s]: max |v| at the samples and at the zero crossings of a inside intervals."""
    t, a = _checked(t, a)
    v, _ = velocity_displacement(t, a)
    a0, a1, dt = a[:-1], a[1:], np.diff(t)
    cross = a0 * a1 < 0.0
    tau = dt[cross] * a0[cross] / (a0[cross] - a1[cross])
    inner = v[:-1][cross] + 0.5 * a0[cross] * tau
    return float(max(np.max(np.abs(v)), np.max(np.abs(inner), initial=0.0)))


def peak_displacement(t, a) -> float:
    """PGD [m]: max |u| at the samples and where v = 0 inside a step (u is cubic there:
    v = v0 + a0 tau + s tau^2 / 2, s the step's slope of a)."""
    t, a = _checked(t, a)
    v, u = velocity_displacement(t, a)
    dt = np.diff(t)
    a0, s, v0, u0 = a[:-1], np.diff(a) / dt, v[:-1], u[:-1]
    peak = float(np.max(np.abs(u)))
    with np.errstate(invalid="ignore", divide="ignore"):
        disc = a0 * a0 - 2.0 * s * v0
        root = np.sqrt(np.maximum(disc, 0.0))
        linear = -v0 / a0  # s = 0
        cands = [np.where(s != 0.0, (-a0 + root) / s, linear),
                 np.where(s != 0.0, (-a0 - root) / s, linear)]  # fmt: skip
    for tau in cands:
        ok = np.isfinite(tau) & (tau > 0.0) & (tau < dt) & (disc >= 0.0)
        if ok.any():
            x = tau[ok]
            inner = u0[ok] + v0[ok] * x + a0[ok] * x * x / 2.0 + s[ok] * x**3 / 6.0
            peak = max(peak, float(np.max(np.abs(inner))))
    return peak


def peak_acceleration(t, a) -> float:
    """PGA [m/s^2]: max |a| (a record linear between samples peaks at one)."""
    t, a = _checked(t, a)
    return float(np.max(np.abs(a)))


def arias_intensity(t, a) -> float:
    """Arias intensity I_A = pi / (2 g) int a^2 dt [m/s], exact for a linear between
    samples."""
    t, a = _checked(t, a)
    return math.pi / (2.0 * G) * float(husid(t, a)[-1])


def cumulative_absolute_velocity(t, a) -> float:
    """CAV = int |a| dt [m/s], exact for a linear between samples (its zero crossing inside
    a step counted)."""
    t, a = _checked(t, a)
    return _abs_integral(t, a)


def _abs_integral(t, a) -> float:
    a0, a1, dt = a[:-1], a[1:], np.diff(t)
    same = a0 * a1 >= 0.0
    total = np.sum(0.5 * dt[same] * (np.abs(a0[same]) + np.abs(a1[same])))
    s0, s1 = np.abs(a0[~same]), np.abs(a1[~same])
    total += np.sum(0.5 * dt[~same] * (s0 * s0 + s1 * s1) / (s0 + s1))
    return float(total)


def husid(t, a) -> np.ndarray:
    """int_t0^t_i a^2 dt at the samples [m^2/s^3], exact for a linear between samples."""
    t, a = _checked(t, a)
    a0, a1, dt = a[:-1], a[1:], np.diff(t)
    return np.concatenate([[0.0], np.cumsum(dt * (a0 * a0 + a0 * a1 + a1 * a1) / 3.0)])


def significant_duration(t, a, low: float = 0.05, high: float = 0.95) -> float:
    """D5-95 [s]: from the time int a^2 dt reaches ``low`` of its total to the time it
    reaches ``high`` (exact: the integral is a cubic in time inside a step, solved for
    its level there); nan for a record of zeros."""
    t, a = _checked(t, a)
    cum = husid(t, a)
    if cum[-1] <= 0.0:
        return math.nan
    start, end = (_husid_time(t, a, cum, level * cum[-1]) for level in (low, high))
    return float(end - start)


def _husid_time(t, a, cum, target: float) -> float:
    """The time int_t0^t a^2 dt first equals ``target`` (0 < target <= the total): inside the
    step that holds it the integral is a cubic in time, increasing (its rate is a^2 >= 0),
    solved by bisection to the last bits of the step (no root finder to import: a worker
    measuring its first record would pay scipy.optimize's import, 0.4 s)."""
    i = int(np.searchsorted(cum, target, side="left")) - 1
    i = min(max(i, 0), t.size - 2)
    dt = float(t[i + 1] - t[i])
    a0, slope = float(a[i]), float(a[i + 1] - a[i]) / dt
    base = float(cum[i])

    def above(tau: float) -> float:
        return base + a0 * a0 * tau + a0 * slope * tau * tau + slope * slope * tau**3 / 3.0 - target

    if above(dt) <= 0.0:
        return float(t[i + 1])
    lo, hi = 0.0, dt
    while True:
        mid = 0.5 * (lo + hi)
        if not lo < mid < hi:  # the interval is down to adjacent floats
            break
        if above(mid) < 0.0:
            lo = mid
        else:
            hi = mid
    return float(t[i] + hi)


def spectral_acceleration(t, a, period: float, damping: float = DAMPING) -> float:
    """Sa(T) [m/s^2]: (2 pi / T)^2 times the peak relative displacement of a linear
    oscillator (period T [s], damping ratio) from rest under the ground acceleration a
    (linear between samples, then zero for one period), by the exact recurrence of Nigam
    and Jennings."""
    t, a = _checked(t, a)
    if not (period > 0.0 and 0.0 <= damping < 1.0):
        raise ValueError(f"period must be > 0 and damping in [0, 1), got {period}, {damping}")
    w = 2.0 * math.pi / period
    tail = t[-1] + period * np.arange(1, FREE_STEPS + 1) / FREE_STEPS
    times = np.concatenate([t, tail])
    accel = np.concatenate([a, np.zeros(FREE_STEPS)])
    if a[-1] != 0.0:  # the record ends with a jump to rest: one step of zero length
        times = np.concatenate([t, [t[-1]], tail])
        accel = np.concatenate([a, [0.0], np.zeros(FREE_STEPS)])
    steps = np.diff(times)
    a11, a12, a21, a22 = _free_response(steps, w, damping)
    w2 = w * w
    # the loop reads and writes Python floats (the same IEEE doubles as numpy's scalars, a
    # few times faster to index and combine one by one)
    ts, ps = times.tolist(), (-accel).tolist()
    c11, c12, c21, c22 = a11.tolist(), a12.tolist(), a21.tolist(), a22.tolist()
    us, vs, up0s, rs = [0.0], [0.0], [], []
    u, v = 0.0, 0.0
    for i in range(times.size - 1):
        dt = ts[i + 1] - ts[i]
        p0 = ps[i]  # the oscillator's load per unit mass, linear over the step
        r = (ps[i + 1] - p0) / dt if dt > 0.0 else 0.0
        # particular solution u_p = (p0 + r tau) / w^2 - 2 z r / w^3, u_p' = r / w^2;
        # the rest is the free response from what u_p leaves at the step's start
        up0 = p0 / w2 - 2.0 * damping * r / (w2 * w)
        h0, g0 = u - up0, v - r / w2
        u = up0 + r * dt / w2 + c11[i] * h0 + c12[i] * g0
        v = r / w2 + c21[i] * h0 + c22[i] * g0
        us.append(u)
        vs.append(v)
        up0s.append(up0)
        rs.append(r)
    us, vs, up0s, rs = np.array(us), np.array(vs), np.array(up0s), np.array(rs)
    peak = float(np.max(np.abs(us)))
    # a peak inside a step (v changes sign there): the exact response on a fine grid
    turn = np.flatnonzero((vs[:-1] * vs[1:] <= 0.0) & (steps > 0.0))
    if turn.size:
        tau = steps[turn, None] * np.linspace(0.0, 1.0, INNER_POINTS)[None, :]
        b11, b12, _, _ = (np.asarray(x) for x in _free_response(tau, w, damping))
        up0, r = up0s[turn, None], rs[turn, None]
        inner = (up0 + r * tau / w2 + b11 * (us[turn, None] - up0)
                 + b12 * (vs[turn, None] - r / w2))  # fmt: skip
        peak = max(peak, float(np.max(np.abs(inner))))
    return w2 * peak


def _free_response(dt: np.ndarray, w: float, z: float):
    """Per step of length dt: (A11, A12, A21, A22) of the free response of
    u'' + 2 z w u' + w^2 u = 0: u1 = A11 u0 + A12 v0, v1 = A21 u0 + A22 v0 (the Nigam and
    Jennings recurrence's homogeneous part; a step of length 0 is the identity)."""
    root = math.sqrt(1.0 - z * z)
    wd = w * root
    e = np.exp(-z * w * dt)
    s, c = np.sin(wd * dt), np.cos(wd * dt)
    a11 = e * (c + z / root * s)
    a12 = e * s / wd
    a21 = -w / root * e * s
    a22 = e * (c - z / root * s)
    return a11, a12, a21, a22


def record_measures(t, a, periods=(), damping: float = DAMPING) -> RecordMeasures:
    """The measures of a record (times [s], accelerations [m/s^2]) as read (module
    docstring); ``periods`` [s] of the spectral accelerations."""
    t, a = _checked(t, a)
    return RecordMeasures(
        pga=peak_acceleration(t, a),
        pgv=peak_velocity(t, a),
        pgd=peak_displacement(t, a),
        arias=arias_intensity(t, a),
        cav=cumulative_absolute_velocity(t, a),
        d5_95=significant_duration(t, a),
        sa={float(p): spectral_acceleration(t, a, float(p), damping) for p in periods},
    )


def first_elastic_period(mass: np.ndarray, stiffness: np.ndarray) -> float | None:
    """The longest period 2 pi / sqrt(lam) [s] of the undamped system M x'' + K x = 0
    (lam the smallest eigenvalue of the pencil (K, M)); None when it is not positive
    (a mechanism or an unstable system: no elastic period)."""
    # lazy: scipy.linalg loads only where needed (docs/architecture.md, Start-up)
    from scipy.linalg import eigh

    lam = eigh(np.asarray(stiffness, float), np.asarray(mass, float), eigvals_only=True)
    smallest = float(np.min(lam))
    if not (math.isfinite(smallest) and smallest > 0.0):
        return None
    return 2.0 * math.pi / math.sqrt(smallest)


__all__ = [
    "DAMPING",
    "PERIOD_RANGE_S",
    "RecordMeasures",
    "arias_intensity",
    "cumulative_absolute_velocity",
    "first_elastic_period",
    "husid",
    "peak_acceleration",
    "peak_displacement",
    "peak_velocity",
    "record_measures",
    "significant_duration",
    "spectral_acceleration",
    "velocity_displacement",
]
