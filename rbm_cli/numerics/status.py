"""How a compiled run ends: the codes the engine's loops return (GOING: not ended) and the
guards' verdict (wall-clock budget, Ctrl-C) in those codes. The codes never leave the
process; rbm_cli.models.status turns them into an Outcome."""

from __future__ import annotations

from rbm_cli.base.guard import GO_ON, PAST_DEADLINE, poll
from rbm_cli.base.jit import jit

GOING, SURVIVED, COLLAPSED, STOPPED_EARLY, AT_REST_END = 0, 1, 2, 3, 4
FAILED_STEPS, FAILED_EVENTS, FAILED_WALL, INTERRUPTED = 5, 6, 7, 8
#: The Runge-Kutta engine's own failures: a step below the spacing of the numbers at t, and
#: a state that became NaN or infinite.
FAILED_STEP, FAILED_NONFINITE = 9, 10
#: The exact integrator asked to stop where a joint first leaves its elastic branch
#: (forcing_arrays.run_settings, until_open) has stopped there.
OPENED = 11
#: When a run may end before its motion does, as the loops read it: never (a recorded run),
#: once no figure can change (solver.stop: figures), once the outcome cannot (outcome).
STOP_NEVER, STOP_FIGURES, STOP_OUTCOME = 0, 1, 2


@jit
def guard_code(deadline):
    """guard.poll as a code: GOING, FAILED_WALL (the monotonic clock past deadline
    [s]) or INTERRUPTED (Ctrl-C)."""
    guard = poll(deadline)
    if guard == GO_ON:
        return GOING
    return FAILED_WALL if guard == PAST_DEADLINE else INTERRUPTED
