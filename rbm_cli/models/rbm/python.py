"""Event-driven integration of the Rigid Beam Model.

Inside one set of active law pieces the equations are smooth (linear), so the
integrator runs an explicit Runge-Kutta pair (scipy's DOP853/RK45 stepper,
driven step by step here) and stops exactly at every event, found by root
finding on the step's dense output:

- a law argument reaching the end of its current piece (a kink of the law):
  the pieces change and the integrator restarts there;
- a zero crossing of a law argument after an excursion beyond its elastic
  branch (every crossing for a rigid law): an impact, the argument's rate is
  multiplied by the restitution e and the integrator restarts. With e = 1 and
  a law linear through zero (an elastic first piece) the crossing changes
  nothing: it is no event, only counted at the step's end (Pieces.settle);
- a collapse quantity reaching c times its limit: the run stops.

The normalised distances to these surfaces are evaluated once per step
(vectorised over interfaces); a step that comes within reach of a surface is
checked on its dense output, and the earliest crossing of any surface is the
event (events.first_crossing).

For a rigid monolithic column the column stays at rest, with no integration,
until the ground demand exceeds the uplift level (found exactly from the
excitation); a rigid block that loses its velocity at an impact returns to
rest (rest detection: post-impact rate below REST_RATE * p * theta_u).
"""

from __future__ import annotations

import math
import time
from functools import partial

import numpy as np
from scipy.integrate import DOP853, RK23, RK45

from rbm_cli.base.detmath import pow_pos
from rbm_cli.config.types import SolverConfig
from rbm_cli.models.events import (
    BIG,
    EVENT_EPS,
    REST_RATE,
    Pieces,
    first_crossing,
    hermite_peaks,
    within_reach,
)
from rbm_cli.models.outcome import Outcome
from rbm_cli.physics.equations import Model
from rbm_cli.physics.excitation import GroundMotion


class _ErrorNorm(float):
    """An error norm whose power is rbm_cli.base.detmath.pow_pos, the compiled kernel's:
    scipy's step-size control (SAFETY * norm ** exponent) then takes the kernel's
    steps, whatever the machine's libm."""

    __slots__ = ()

    def __pow__(self, exponent):
        return pow_pos(float(self), float(exponent))


def _with_kernel_power(method):
    class Stepper(method):
        def _estimate_error_norm(self, K, h, scale):
            return _ErrorNorm(super()._estimate_error_norm(K, h, scale))

    Stepper.__name__ = method.__name__
    return Stepper


_METHODS = {m.__name__: _with_kernel_power(m) for m in (DOP853, RK45, RK23)}


def initial_step(rhs, t0: float, y0, f0, t_bound: float, order: int, rtol, atol) -> float:
    """scipy's select_initial_step (Hairer, Norsett and Wanner, II.4) with the kernel's
    power (rbm_cli.base.detmath.pow_pos), as rbm_cli.models.rbm.kernel_rk._initial_step computes it.
    rhs(t, y) is the right-hand side (called once), f0 its value at (t0, y0)."""
    interval = abs(t_bound - t0)
    if interval == 0.0:
        return 0.0
    scale = atol + np.abs(y0) * rtol

    def rms(v):
        return math.sqrt(float(np.sum(v * v)) / v.size)

    d0, d1 = rms(y0 / scale), rms(f0 / scale)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, interval)
    d2 = rms((rhs(t0 + h0, y0 + h0 * f0) - f0) / scale) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = pow_pos(0.01 / max(d1, d2), 1.0 / (order + 1))
    return min(100.0 * h0, h1, interval)


def integrate(
    model: Model,
    motion: GroundMotion,
    theta0: np.ndarray,
    rate0: np.ndarray,
    solver: SolverConfig,
    record: bool = False,
    output_dt: float = 0.002,
    early_stop: bool = True,
) -> Outcome:
    """Integrate one run of the model under a ground motion.

    Parameters
    ----------
    model : Model  Assembled equations
    motion : GroundMotion  a_g(t) [m/s^2] and the simulated time
    theta0, rate0 : (n,) Initial absolute rotations [rad] and rates [rad/s]
    solver : SolverConfig  Method, tolerances and budgets
    record : bool  Keep samples every output_dt [s] for a time history
    early_stop : bool  Stop a free motion (after a half-sine pulse) whose
        energy is below the lowest collapse barrier (`relative` only)
    """
    n = model.n
    col = model.column
    out = Outcome()
    deadline = time.monotonic() + solver.max_wall_time
    out.max_ratio = np.zeros(n)
    out.friction = np.zeros(n)
    pieces = Pieces(model, silent=True)
    silent = bool(pieces.silent.any())
    tu = col.rotation_capacity
    c_ratio = model.collapse_ratio
    cmap = model.collapse_map / model.collapse_limit[:, None]
    top = col.heights.copy()
    track = np.vstack([cmap, top[None, :]])
    g_rows = np.vstack([model.arg_map / tu[:, None], -model.arg_map / tu[:, None], -cmap, cmap])
    c_vec = np.full(n, c_ratio)
    argmap = model.arg_map
    arg_inv = model.arg_inverse
    e_rest = model.restitution
    stepper = _METHODS[solver.method]
    atol = solver.atol * np.concatenate([np.full(n, tu.min()), np.full(n, tu.min() * 10.0)])

    rest_rate = REST_RATE * model.rocking_p * tu.min()
    uplift_level = model.uplift_level
    rigid_mono = uplift_level is not None
    # early stop of free motion (after a half-sine pulse), monolithic columns:
    # energy never grows in free motion, so once a peak has been passed with
    # the energy below the collapse barrier, no later peak is larger.
    barrier = None
    if n == 1:
        barrier = float(model.energy(np.array([c_ratio * tu[0]]), np.zeros(1))[0])
    t = 0.0
    y = np.concatenate([np.asarray(theta0, float), np.asarray(rate0, float)])
    at_rest = rigid_mono and not np.any(y)
    pieces.locate(argmap @ y[:n], argmap @ y[n:])
    next_out = 0.0

    def emit_until(t_stop, dense=None, rest=False):
        nonlocal next_out
        while next_out <= t_stop + 1e-12:
            if rest:
                out.samples.append((next_out, np.zeros(n), np.zeros(n)))
            else:
                yy = dense(next_out)
                out.samples.append((next_out, yy[:n].copy(), yy[n:].copy()))
            next_out += output_dt

    for seg_start, seg_end in motion.segments():
        if t >= seg_end:
            continue
        h_carry = None  # the step size proposed before an event, carried over it
        free_seg = not motion.forced(seg_start)
        if free_seg:

            def ag(tt):
                return 0.0
        else:
            amp, om, ph = motion.amplitude, motion.omega, motion.phase

            def ag(tt, amp=amp, om=om, ph=ph):
                return amp * math.sin(om * tt + ph)

        can_stop = early_stop and free_seg and motion.kind == "half-sine"

        while t < seg_end:
            if at_rest:
                kind, t_stop = motion.rest_end(t, seg_end, uplift_level, not free_seg)
                if record:
                    emit_until(t_stop - (1e-15 if kind == "uplift" else 0.0), rest=True)
                t = t_stop
                if kind == "end":
                    out.t_end = t
                    return out
                if kind == "segment":
                    break
                y = np.zeros(2 * n)
                pieces.side[0] = motion.uplift_side(t)
                pieces.k[0] = 0
                at_rest = False
                out.n_uplifts += 1
                h_carry = None

            A, cvec, evec = pieces.system()

            def fun(tt, yy, A=A, cvec=cvec, evec=evec, counted=True):
                out.n_rhs += counted
                return np.concatenate([yy[n:], A @ yy[:n] + cvec + evec * ag(tt)])

            lo, hi = pieces.bounds()
            # event distances, linear in theta: d = G theta + h0 (>= 0 inside)
            h0 = (
                np.concatenate([np.minimum(-lo / tu, BIG), np.minimum(hi / tu, BIG), c_vec, c_vec])
                + EVENT_EPS
            )

            def dist(dense, ts, h0=h0):
                yy = dense(ts)
                return g_rows @ yy[:n] + h0[:, None], g_rows @ yy[n:]

            # after an event the stepper restarts with the step size its error
            # control proposed before it (the solution stays smooth up to its second
            # derivative; a fresh initial-step guess was rejected 1.4 times per event)
            if h_carry is None:  # counted as scipy counts it: its own f0, then one call
                f0 = fun(t, y, counted=False)
                first = initial_step(fun, t, y, f0, seg_end, stepper.order, solver.rtol, atol)
            else:
                first = min(h_carry, seg_end - t)
            integ = stepper(fun, t, y, seg_end, rtol=solver.rtol, atol=atol, first_step=first)
            z_old = track @ y[:n]
            dz_old = track @ y[n:]
            d_old = g_rows @ y[:n] + h0
            dd_old = g_rows @ y[n:]
            d2_old = g_rows @ (A @ y[:n] + cvec + evec * ag(t))
            event = False
            while integ.status == "running":
                msg = integ.step()
                if integ.status == "failed":
                    return out.stop("failed", f"integrator: {msg}", t)
                out.n_steps += 1
                if out.n_steps > solver.max_steps:
                    return out.stop("failed", f"step budget exceeded ({solver.max_steps} steps)", t)
                if time.monotonic() > deadline:
                    budget = f"{solver.max_wall_time:g} s, solver.max_wall_time"
                    return out.stop("failed", f"wall-clock budget exceeded ({budget})", t)
                t_old = integ.t_old
                t_new, y_new = integ.t, integ.y
                d_new = g_rows @ y_new[:n] + h0
                dd_new = g_rows @ y_new[n:]
                acc = A @ y_new[:n] + cvec + evec * ag(t_new)
                d2_new = g_rows @ acc
                hit = None
                dense = None
                # a surface crossed, or touched and left, inside the step: found on
                # the dense output, the earliest crossing of any row
                if within_reach(d_old, d_new, dd_old, dd_new, d2_old, d2_new, t_new - t_old):
                    dense = integ.dense_output()
                    hit = first_crossing(partial(dist, dense), t_old, t_new)
                if hit is not None:
                    t_e, event_row = hit
                    y_new = dense(t_e)
                    acc = A @ y_new[:n] + cvec + evec * ag(t_e)
                    t_new = t_e
                    if record:
                        emit_until(t_e, dense)
                    event = True
                elif record:
                    emit_until(t_new, dense if dense is not None else integ.dense_output())
                if silent:
                    out.n_impacts += pieces.settle(argmap @ y_new[:n])
                # peaks and friction demand over [t_old, t_new]
                z_new = track @ y_new[:n]
                dz_new = track @ y_new[n:]
                peaks = hermite_peaks(z_old, z_new, dz_old, dz_new, t_new - t_old)
                out.max_ratio = np.maximum(out.max_ratio, peaks[:n])
                out.max_top = max(out.max_top, peaks[n])
                fr = model.shear_ratios(acc[None, :], np.array([ag(t_new)]))[0]
                out.friction = np.maximum(out.friction, fr)
                z_prev, dz_prev = z_old, dz_old
                z_old, dz_old = z_new, dz_new
                d_old, dd_old, d2_old = d_new, dd_new, d2_new
                t, y = t_new, y_new
                if event:
                    break
                if (
                    can_stop
                    and barrier is not None
                    and z_prev[0] * dz_prev[0] > 0 >= z_old[0] * dz_old[0]
                ):
                    if float(model.energy(y[:n], y[n:])[0]) < barrier * (1.0 - 1e-9):
                        out.message = "free motion below the collapse barrier: stopped early"
                        out.t_end = t
                        return out
            if not event:
                if integ.status == "finished":
                    t = seg_end
                continue

            # ---- handle the event at (t, y)
            h_carry = integ.h_abs
            out.n_events += 1
            if out.n_events > solver.max_events:
                return out.stop("failed", f"event budget exceeded ({solver.max_events} events)", t)
            which, i = divmod(event_row, n)
            if which >= 2:
                out.status = "collapsed"
                out.t_collapse = t
                out.collapse_interface = i + 1
                out.max_ratio[i] = max(out.max_ratio[i], c_ratio)
                out.message = f"interface {i + 1} reached its collapse limit"
                out.t_end = t
                return out
            going_up = which == 1
            # put the argument exactly on the surface it crossed (the event is
            # located EVENT_EPS beyond it); removes the energy that repeated
            # overshoots would pump into chattering impacts
            bound = hi[i] if going_up else lo[i]
            x_i = float(argmap[i] @ y[:n])
            y = y.copy()
            y[:n] += arg_inv[:, i] * (bound - x_i)
            crossing = pieces.cross(i, going_up)
            if crossing == "uplift":
                out.n_uplifts += 1
            elif crossing == "impact":
                out.n_impacts += 1
                if e_rest < 1.0:
                    y[n:] = model.impact_rates(y[n:], i)
                if rigid_mono and abs(y[n]) < rest_rate:
                    y = np.zeros(2 * n)
                    at_rest = True
    out.t_end = t
    return out
