"""The compiled, model-agnostic engine: Runge-Kutta pairs as data and their steps, dense
output and sampling on it (numerics.rk), the quadrature of a step's work (numerics.quadrature).
It knows equations as arrays, not structures: a structure hands it its right-hand side
(structures.rates) and its arrays. Imports base, config and physics only."""
