"""The compiled, model-agnostic engine: Runge-Kutta pairs as data and their steps, dense
output and sampling on it (numerics.rk), ONE event-located run loop (numerics.loop), a run's
record (numerics.records), the quadrature of a step's work (numerics.quadrature). It knows
equations as arrays, not structures: a structure hands it its right-hand side (copies of
the steps on it: numerics.rk.steps_for), its arrays and its event functions
(numerics.loop.loop_for). Imports base only."""
