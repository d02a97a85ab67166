"""The pieces of an event-located run loop that every structure's loop shares: the
Runge-Kutta work arrays, the verdict after an attempted step (budgets and the polls of the
wall clock and Ctrl-C), and the named record a run returns (RunEnd)."""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from rbm_cli.base.copies import copy_into
from rbm_cli.base.guard import POLL_STEPS
from rbm_cli.base.jit import jit
from rbm_cli.numerics.binding import bind
from rbm_cli.numerics.rk import (
    NS_MAX,
    STEP_TAKEN,
    STEP_TOO_SMALL,
    TAB_EST,
    TAB_NS,
    dense_eval,
)
from rbm_cli.numerics.status import (
    COLLAPSED,
    FAILED_EVENTS,
    FAILED_NONFINITE,
    FAILED_STEP,
    FAILED_STEPS,
    GOING,
    STOP_NEVER,
    STOP_OUTCOME,
    STOPPED_EARLY,
    SURVIVED,
    guard_code,
)

#: What a compiled run returns (built inside the loop; numba boxes it as this class).
#: code: how it ended (numerics.status); t_end [s]; t_collapse [s] and the collapsed
#: interface (nan, -1: none; the planar loop counts interfaces from 1, rbm-3d's from 0);
#: max_ratio (n,) and max_top: the peaks; friction (n,): the peak friction demand; slip (2,):
#: (t [s], interface from 1) where it first exceeded the limit, (nan, 0) if not; the counts
#: of uplifts, impacts, accepted steps, right-hand side calls, events and samples written;
#: azimuth [rad] (rbm-3d: where the lean pointed at collapse; nan otherwise); swept (n,)
#: [rad] (rbm-3d: the angle each joint's lean turned while wobbling; empty otherwise);
#: ledger (5,): the energy account [J] (initial, final, ground work, damping, impacts).
RunEnd = namedtuple(
    "RunEnd",
    ["code", "t_end", "t_collapse", "collapsed", "max_ratio", "max_top", "friction", "slip",
     "n_uplifts", "n_impacts", "n_steps", "n_rhs", "n_events", "n_samples", "azimuth",
     "swept", "ledger"],
)  # fmt: skip


#: What the run loop shares with a structure's functions through the run's record
#: (numerics.records: name, type): the state y and the accepted new state y_new, the
#: Runge-Kutta work arrays (the stages K, the dense output's coefficients F, f = y'(t), the
#: step's end ynew, a stage's argument tmp, a right-hand side's work, the error norm's scale,
#: a state on the dense output yq), the right-hand side's arrays (a structure's rhs, e.g.
#: structures.rates.rhs: As, cs, es as sys_A, sys_c, sys_e), and the run's figures, filled
#: in place: RunEnd's max_ratio, friction, slip, swept and ledger, and top (1,): the top's
#: peak.
LOOP_FIELDS = [
    ("y", "float64[::1]"), ("y_new", "float64[::1]"), ("K", "float64[:, ::1]"),
    ("F", "float64[:, ::1]"), ("f", "float64[::1]"), ("ynew", "float64[::1]"),
    ("tmp", "float64[::1]"), ("work", "float64[::1]"), ("scale", "float64[::1]"),
    ("yq", "float64[::1]"), ("sys_A", "float64[:, ::1]"), ("sys_c", "float64[::1]"),
    ("sys_e", "float64[::1]"), ("max_ratio", "float64[::1]"),
    ("friction", "float64[::1]"), ("slip", "float64[::1]"), ("swept", "float64[::1]"),
    ("ledger", "float64[::1]"), ("top", "float64[::1]"),
]  # fmt: skip


@jit(inline=True)
def loop_into(W, y, system):
    """Set the fields of a run's record W that the loop's own (LOOP_FIELDS but the figures):
    the state y, the Runge-Kutta work arrays for a state of its size and the right-hand
    side's arrays system = (As, cs, es)."""
    m = y.size
    W.y, W.y_new, W.K, W.F = y, np.empty(m), np.empty((NS_MAX, m)), np.empty((8, m))
    W.f, W.ynew, W.tmp, W.work = np.empty(m), np.empty(m), np.empty(m), np.empty(m)
    W.scale, W.yq = np.empty(m), np.empty(m)
    W.sys_A, W.sys_c, W.sys_e = system


@jit(inline=True)
def step_verdict(taken, n_steps, max_steps, deadline):
    """After numerics.rk.attempt_step answered taken: GOING or the code the run ends with (a
    failed step; more steps than max_steps; every POLL_STEPS steps, the wall clock past
    deadline [s] or Ctrl-C), and the count of accepted steps."""
    if taken != STEP_TAKEN:
        return (FAILED_STEP if taken == STEP_TOO_SMALL else FAILED_NONFINITE), n_steps
    n_steps += 1
    if n_steps > max_steps:
        return FAILED_STEPS, n_steps
    if n_steps % POLL_STEPS == 0:
        return guard_code(deadline), n_steps
    return GOING, n_steps


@jit(inline=True)
def run_end(W, code, t, t_col, c_if, counts, n_out, azimuth):
    """The RunEnd of a run that ended with code at t [s] (collapsed at t_col [s], at its
    interface c_if), counts = (uplifts, impacts, accepted steps, right-hand side calls,
    events), n_out samples written and azimuth [rad]; its figures from the run's record W."""
    n_upl, n_imp, n_steps, n_rhs, n_ev = counts
    return RunEnd(code, t, t_col, c_if, W.max_ratio, W.top[0], W.friction, W.slip, n_upl, n_imp,
                  n_steps, n_rhs, n_ev, n_out, azimuth, W.swept, W.ledger)  # fmt: skip


def run_motion(W, motion, solver, n, at_rest, stops, account):
    """Run one motion of a structure from the state y at t = 0: the event-located loop that
    every structure runs (its copy for a structure: :func:`loop_for`).

    The motion's segments (forced or free) are stepped by an embedded Runge-Kutta pair
    (numerics.rk) on the structure's system; after each accepted step the structure locates
    the first of its watched events inside it on the step's dense output; the step is cut
    there, the structure's figures are taken over the step, and at the event the structure
    changes its pieces (an uplift, a kink, an impact, a collapse) and the stepper starts
    anew. A rigid monolith at rest waits, in closed form, for the ground to lift it.

    The step after an event is the one the error control proposed before it. (Bounding it
    by the step proposed after the last event of the same kind, say a joint's closure,
    rejects fewer first attempts but takes more steps: it cost the 8-drum record band
    about 6 % more CPU, docs/performance.md.)

    What is the structure's is called by name (the structure's functions, bound by
    loop_for): enter_segment, rest_to_end, rest, restart, ground_piece, find_event,
    step_figures, may_stop, at_event, and the Runge-Kutta step on its right-hand side,
    attempt_step (numerics.rk.steps_for). They read and write the run's record W
    (numerics.records): the structure's arrays, its work, what they need of the motion and
    the task, and the run's figures (LOOP_FIELDS).

    Parameters
    ----------
    W : record  The run's record (numerics.records), with LOOP_FIELDS among its fields (the
        state at t = 0 in y; at_rest: a rigid monolith at rest there).
    motion : Excitation  The ground motion (rbm_cli.models.rbm.step.inputs).
    solver : SolverSettings  Method code, tolerances, budgets, deadline.
    n : int  The structure's joints (numerics.rk's n: the state holds 2n or 4n values).
    stops : tuple  (early_stop: models.status.stop_level; last_forced: the last segment with
        forcing; outcome_bound: a survival barrier applies; monolith: one joint).
    account : bool  Keep the energy account (ledger).

    Returns
    -------
    RunEnd
    """
    y, y_new, K, F, f, ynew, tmp = W.y, W.y_new, W.K, W.F, W.f, W.ynew, W.tmp
    scale, As, cs, es = W.scale, W.sys_A, W.sys_c, W.sys_e
    early_stop, last_forced, outcome_bound, monolith = stops
    bounds, forced, t_end, clipped = motion.bounds, motion.forced, motion.t_end, motion.clipped
    # the ground (inputs.ground): of the motion, and nothing (a free segment)
    gr_full = (motion.form, motion.gain, motion.omega, motion.phase, motion.center,
               motion.gamma, 0.0, 0.0, 0.0)  # fmt: skip
    gr_free = (motion.form, 0.0, motion.omega, motion.phase, motion.center, motion.gamma,
               0.0, 0.0, 0.0)  # fmt: skip
    mc, rtol, atol = solver.mc, solver.rtol, solver.atol
    max_steps, max_events, deadline = solver.max_steps, solver.max_events, solver.deadline
    err_exp, ns = -1.0 / (TAB_EST[mc] + 1), TAB_NS[mc]
    n_out, next_out = 0, 0.0
    n_upl, n_imp, n_steps, n_rhs, n_ev, t = 0, 0, 0, 0, 0, 0.0
    for seg in range(bounds.size - 1):
        seg_end = bounds[seg + 1]
        if t >= seg_end:
            continue
        free_seg = not forced[seg]
        gr = gr_free if free_seg else gr_full
        seg_gain = gr[1]
        enter_segment(W, free_seg)  # noqa: F821 (the structure's: loop_for)
        # solver.stop: a monolith past a peak of free motion after a pulse or a record;
        # solver.stop: outcome: free motion from here to the end below the survival barrier
        can_stop = early_stop != STOP_NEVER and free_seg and motion.pulse and monolith
        sure_stop = early_stop == STOP_OUTCOME and seg > last_forced and outcome_bound
        h_carry = -1.0  # the step size proposed before an event, carried over it
        while t < seg_end:
            if at_rest:
                if free_seg:  # no ground motion from here on: at rest to the end
                    code, n_out, next_out = rest_to_end(  # noqa: F821
                        W, t, t_end, mc, n_out, next_out)  # fmt: skip
                    return run_end(W, code, t_end, np.nan, -1, (n_upl, n_imp, n_steps, n_rhs, n_ev),
                                   n_out, np.nan)  # fmt: skip
                lifted, t, n_out, next_out = rest(  # noqa: F821
                    W, t, seg_end, gr_full, mc, n_out, next_out)  # fmt: skip
                if not lifted:
                    break
                at_rest = False
                n_upl += 1
                h_carry = -1.0

            # a new stepper from (t, y): the structure's pieces and watched rows
            h_abs, calls, gr = restart(  # noqa: F821
                W, t, seg_end, seg_gain, h_carry, gr, mc, rtol, atol
            )
            n_rhs += calls
            event = False
            running = True
            while running:
                bound = seg_end  # a record's steps end at its samples
                if clipped:
                    gr, bound = ground_piece(W, t, seg_gain, seg_end)  # noqa: F821
                taken, t_new, h, h_abs, calls = attempt_step(  # noqa: F821
                    mc, t, y, f, h_abs, bound, K, ynew, tmp, n, As, cs, es, gr, atol, rtol,
                    scale, err_exp)  # fmt: skip
                n_rhs += calls
                code, n_steps = step_verdict(taken, n_steps, max_steps, deadline)
                if code != GOING:
                    return run_end(W, code, t, np.nan, -1, (n_upl, n_imp, n_steps, n_rhs, n_ev),
                                   n_out, np.nan)  # fmt: skip
                if t_new - seg_end >= 0:
                    running = False
                t_old = t
                copy_into(y_new, ynew)
                # the first watched event inside the step, on its dense output
                t_e, hit, dense_ready, calls = find_event(W, mc, t_old, t_new, h, gr)  # noqa: F821
                n_rhs += calls
                if hit >= 0:
                    t_new = t_e
                    dense_eval(mc, t_new, t_old, h, y, F, y_new)
                    event = True
                # the structure's figures over [t_old, t_new]
                calls, n_out, next_out, impacts = step_figures(  # noqa: F821
                    W, mc, t_old, t_new, h, gr, event, dense_ready, account, n_out, next_out
                )
                n_rhs += calls
                n_imp += impacts
                t = t_new
                copy_into(y, y_new)
                copy_into(f, K[ns])
                if event:
                    break
                if (can_stop or sure_stop) and may_stop(W, can_stop, sure_stop):  # noqa: F821
                    return run_end(W, STOPPED_EARLY, t, np.nan, -1,
                                   (n_upl, n_imp, n_steps, n_rhs, n_ev), n_out, np.nan)  # fmt: skip
            if not event:
                t = seg_end if not running else t
                continue

            # ---- the event at (t, y)
            h_carry = h_abs
            n_ev += 1
            if n_ev > max_events:
                return run_end(W, FAILED_EVENTS, t, np.nan, -1,
                               (n_upl, n_imp, n_steps, n_rhs, n_ev), n_out, np.nan)  # fmt: skip
            code, uplifts, impacts, at_rest, which, angle = at_event(  # noqa: F821
                W, hit, t, gr, account)  # fmt: skip
            n_upl += uplifts
            n_imp += impacts
            if code == COLLAPSED:
                return run_end(W, COLLAPSED, t, t, which, (n_upl, n_imp, n_steps, n_rhs, n_ev),
                               n_out, angle)  # fmt: skip
    return run_end(W, SURVIVED, t, np.nan, -1, (n_upl, n_imp, n_steps, n_rhs, n_ev),
                   n_out, np.nan)  # fmt: skip


#: The functions a structure hands the run loop (run_motion), by name.
STRUCTURE_FUNCTIONS = ("enter_segment", "rest_to_end", "rest", "restart", "ground_piece",
                       "find_event", "step_figures", "may_stop", "at_event",
                       "attempt_step")  # fmt: skip


def loop_for(name: str, functions: dict):
    """The run loop (run_motion) of one structure, compiled on its own: a copy of its code
    whose names STRUCTURE_FUNCTIONS are the structure's functions, taken by name from
    ``functions`` (the structure module's ``globals()``: its event and figure functions,
    each compiled with base.jit.jit, and its Runge-Kutta step, numerics.rk.steps_for). The
    copy is named ``run_motion_<name>`` (numerics.binding)."""
    missing = set(STRUCTURE_FUNCTIONS) - set(functions)
    if missing:
        raise TypeError(f"structure {name!r} lacks {sorted(missing)}")
    given = {key: functions[key] for key in STRUCTURE_FUNCTIONS}
    return bind({"run_motion": (run_motion, {})}, given, name)["run_motion"]
