"""The Rigid Beam Model: its runner and integrators (the step kernel, the exact integrator,
the rigid block's closed form), and the naive scipy loop used as the bench's baseline."""
