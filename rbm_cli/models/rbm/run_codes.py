"""How a compiled closed-form run ends (the exact integrator's loop, exact_jit_run, and the
rigid block's, closed_form_jit_run): the codes their loops return (GOING: not ended), the
guards' verdict in those codes and how often they poll, and the Outcome of a budget's code."""

from __future__ import annotations

from rbm_cli.base.jit import jit
from rbm_cli.models.rbm.kernel_guard import GO_ON, PAST_DEADLINE, poll

GOING, SURVIVED, COLLAPSED, STOPPED_EARLY, AT_REST_END = 0, 1, 2, 3, 4
FAILED_STEPS, FAILED_EVENTS, FAILED_WALL, INTERRUPTED = 5, 6, 7, 8
#: Loop turns (pieces, certified intervals) between two polls of the wall clock and Ctrl-C.
POLL_PIECES = 64


@jit
def guard_code(deadline):
    """kernel_guard.poll as a code: GOING, FAILED_WALL (the monotonic clock past deadline
    [s]) or INTERRUPTED (Ctrl-C)."""
    guard = poll(deadline)
    if guard == GO_ON:
        return GOING
    return FAILED_WALL if guard == PAST_DEADLINE else INTERRUPTED


#: The budgets' codes, in end_by_budget's order.
BUDGETS = (FAILED_STEPS, FAILED_EVENTS, FAILED_WALL, INTERRUPTED)


def end_by_budget(out, code: int, solver, budgets: tuple = BUDGETS) -> bool:
    """End the Outcome ``out`` as its budget code says (steps, events, wall clock; Ctrl-C
    raises KeyboardInterrupt) at out.t_end; False for a code that is not a budget's.
    budgets: those four codes in a loop's own numbering (the step kernel's differs)."""
    t = out.t_end
    steps, events, wall, interrupted = budgets
    if code == steps:
        out.out_of_steps(solver, t)
    elif code == events:
        out.out_of_events(solver, t)
    elif code == wall:
        out.out_of_time(solver, t)
    elif code == interrupted:  # pragma: no cover - disarm() raises first
        raise KeyboardInterrupt
    else:
        return False
    return True
