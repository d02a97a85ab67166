"""Exact integration of the Rigid Beam Model (`solver.method: exact`).

Inside one set of active law pieces the column's equations are linear with constant
coefficients; the integrator decomposes them once per set of pieces (cached) and moves
every mode in closed form (modal, piece): no time step and no truncation error, only
rounding. A column of n drums has n modes and m joints with a law: n, or n + 1 on a frame's
column (structures.equations.Model.joints; the beam's joint on the top drum, argument
-theta_n), whose pieces, event rows, impacts, friction demand and collapse ratios are
those of the m joints, as in the step integrator. The events are those of the Runge-Kutta
integrator (rbm_cli.models.rbm.step, same surfaces, same EVENT_EPS, same actions):

- a law argument reaching the end of its piece (uplift, kink, impact with restitution;
  the pieces change and a new piece starts there);
- a collapse quantity reaching c times its limit (the run stops);
- with e = 1 and a law linear through zero, the first zero crossing after an excursion
  (a silent impact: counted, nothing changes). The step integrators count these at step
  ends; here they are located like any other event, so none is missed;
- a rigid monolith at rest, lifting when the ground demand exceeds its uplift level, and
  put to rest by an impact that leaves it almost no rate (REST_RATE);
- the end of the pulse, the end of the run, and the early stop of free motion after a
  pulse or a record once a peak is passed below the collapse barrier (monolithic columns).

Events are roots of sums of exponentials and sinusoids, found without a chance of missing
one by certified intervals (bounds, search); the peaks of the tracked quantities are
refined at the end of the run (peaks). Outcome counters: n_steps counts the certified
intervals, n_rhs the closed-form evaluations of the state.

Formulations `relative` and `geometric` (symmetric stiffness) only; `absolute` stays with
the Runge-Kutta methods. Excitations: harmonic, free, the sine pulses (half-sine, one-sine,
cycloidal) and records, piecewise linear in time, which the closed form takes exactly per
sample interval (a 'linear' forcing, forcing_arrays); motion says what is refused and why.

The algorithm is written once, in the Python that numba compiles (run, piece, search,
bounds, peaks, modal); integrate runs it compiled, or uncompiled with
``solver.implementation: python`` (rbm_cli.base.jit.plain: the same bits).

Modules: integrate (the entry from Python), run (the run loop), piece (law pieces, modes
and their cache, rows and points of a linear piece), search (certified intervals, event
roots, peak refinement), bounds (bounds of the modes and rows over an interval), peaks (the
deferred refinement of peaks), modal (the closed forms of one mode) and motion (what it
takes of a ground motion). The column's arrays are structures.arrays.ColumnArrays; the law
pieces, the friction demand and a state's energy are the step integrator's too
(rbm_cli.models.rbm.pieces).
"""
