"""How a compiled run ends, for every integrator (the step kernel, step.stepper; the exact
integrator's loop, exact.run; the rigid block's closed form, closed_form_jit_run): the
codes their loops return (GOING: not ended) and the guards' verdict in those codes (both
defined with the engine, rbm_cli.numerics.status), how often the closed-form loops poll,
and the Outcome of a budget's code. The codes never leave the process."""

from __future__ import annotations

from rbm_cli.numerics.status import (  # the codes, defined with the engine
    AT_REST_END,
    COLLAPSED,
    FAILED_EVENTS,
    FAILED_NONFINITE,
    FAILED_STEP,
    FAILED_STEPS,
    FAILED_WALL,
    GOING,
    INTERRUPTED,
    OPENED,
    STOP_FIGURES,
    STOP_NEVER,
    STOP_OUTCOME,
    STOPPED_EARLY,
    SURVIVED,
    guard_code,
)

#: Loop turns (pieces, certified intervals) between two polls of the wall clock and Ctrl-C.
POLL_PIECES = 64


def stop_level(early_stop: bool, solver) -> int:
    """The loops' stop level of a run: STOP_NEVER unless early_stop, else as solver.stop
    says (rbm_cli.config.types.STOPS)."""
    if not early_stop:
        return STOP_NEVER
    return STOP_OUTCOME if solver.stop == "outcome" else STOP_FIGURES


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


__all__ = [
    "AT_REST_END", "COLLAPSED", "FAILED_EVENTS", "FAILED_NONFINITE", "FAILED_STEP",
    "FAILED_STEPS", "FAILED_WALL", "GOING", "INTERRUPTED", "OPENED", "POLL_PIECES",
    "STOPPED_EARLY", "STOP_FIGURES", "STOP_NEVER", "STOP_OUTCOME", "SURVIVED", "end_by_budget",
    "guard_code", "stop_level",
]  # fmt: skip
