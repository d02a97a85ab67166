"""How a compiled closed-form run ends (the exact integrator's loop, exact_jit_run, and the
rigid block's, closed_form_jit_run): the codes their loops return. GOING: not ended."""

GOING, SURVIVED, COLLAPSED, STOPPED_EARLY, AT_REST_END = 0, 1, 2, 3, 4
FAILED_STEPS, FAILED_EVENTS, FAILED_WALL, INTERRUPTED = 5, 6, 7, 8
