"""How a compiled run ends, for every integrator (the step kernel, step.stepper; the exact
integrator's loop, exact.run; the rigid block's closed form, closed_form_jit_run): the
codes their loops return (GOING: not ended), the guards' verdict in those codes and how
often the closed-form loops poll, and the Outcome of a budget's code. The codes never
leave the process."""

from __future__ import annotations

from rbm_cli.base.guard import GO_ON, PAST_DEADLINE, poll
from rbm_cli.base.jit import jit

GOING, SURVIVED, COLLAPSED, STOPPED_EARLY, AT_REST_END = 0, 1, 2, 3, 4
FAILED_STEPS, FAILED_EVENTS, FAILED_WALL, INTERRUPTED = 5, 6, 7, 8
#: The step kernel's own failures: a step below the spacing of the numbers at t, and a
#: state that became NaN or infinite.
FAILED_STEP, FAILED_NONFINITE = 9, 10
#: The exact integrator asked to stop where a joint first leaves its elastic branch
#: (forcing_arrays.run_settings, until_open) has stopped there.
OPENED = 11
#: Loop turns (pieces, certified intervals) between two polls of the wall clock and Ctrl-C.
POLL_PIECES = 64
#: When a run may end before its motion does, as the loops read it: never (a recorded run),
#: once no figure can change (solver.stop: figures), once the outcome cannot (outcome).
STOP_NEVER, STOP_FIGURES, STOP_OUTCOME = 0, 1, 2


def stop_level(early_stop: bool, solver) -> int:
    """The loops' stop level of a run: STOP_NEVER unless early_stop, else as solver.stop
    says (rbm_cli.config.types.STOPS)."""
    if not early_stop:
        return STOP_NEVER
    return STOP_OUTCOME if solver.stop == "outcome" else STOP_FIGURES


@jit
def guard_code(deadline):
    """guard.poll as a code: GOING, FAILED_WALL (the monotonic clock past deadline
    [s]) or INTERRUPTED (Ctrl-C)."""
    guard = poll(deadline)
    if guard == GO_ON:
        return GOING
    return FAILED_WALL if guard == PAST_DEADLINE else INTERRUPTED


def end_by_budget(out, code: int, solver) -> bool:
    """End the Outcome ``out`` as its budget code says (FAILED_STEPS, FAILED_EVENTS,
    FAILED_WALL; INTERRUPTED raises KeyboardInterrupt) at out.t_end; False for a code that
    is not a budget's."""
    t = out.t_end
    if code == FAILED_STEPS:
        out.out_of_steps(solver, t)
    elif code == FAILED_EVENTS:
        out.out_of_events(solver, t)
    elif code == FAILED_WALL:
        out.out_of_time(solver, t)
    elif code == INTERRUPTED:  # pragma: no cover - disarm() raises first
        raise KeyboardInterrupt
    else:
        return False
    return True
