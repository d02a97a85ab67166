"""The physical systems that rock, one module per system and its parts: the column of drums
(its properties, its joints' law, the Rigid Beam Model's equations, the arrays and
right-hand side the compiled engine reads), the column in two horizontal directions, the
true rigid block and the rigid cylinder; their restitution and their similarity scales.
Pure functions and frozen dataclasses; no I/O, no run loop. Imports numerics, inputs,
config and base."""
