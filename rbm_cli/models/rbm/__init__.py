"""The Rigid Beam Model: its runner and integrators (the step kernel, the exact integrator;
a rigid monolith also runs the rigid block's closed form, rbm_cli.models.block)."""
