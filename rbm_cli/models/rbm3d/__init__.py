"""`rbm-3d`: the Rigid Beam Model of a column of circular drums in two horizontal directions
(rbm_cli.structures.column3d), integrated by scipy's Runge-Kutta pairs (runner.py)."""
