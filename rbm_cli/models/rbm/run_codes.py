"""How a compiled closed-form run ends (the exact integrator's loop, exact_jit_run, and the
rigid block's, closed_form_jit_run): the codes their loops return (GOING: not ended), and
the guards' verdict in those codes."""

from __future__ import annotations

from numba import njit

from rbm_cli.models.rbm.kernel_guard import GO_ON, PAST_DEADLINE, poll

GOING, SURVIVED, COLLAPSED, STOPPED_EARLY, AT_REST_END = 0, 1, 2, 3, 4
FAILED_STEPS, FAILED_EVENTS, FAILED_WALL, INTERRUPTED = 5, 6, 7, 8


@njit(cache=True)
def guard_code(deadline):
    """kernel_guard.poll as a code: GOING, FAILED_WALL (the monotonic clock past deadline
    [s]) or INTERRUPTED (Ctrl-C)."""
    guard = poll(deadline)
    if guard == GO_ON:
        return GOING
    return FAILED_WALL if guard == PAST_DEADLINE else INTERRUPTED
