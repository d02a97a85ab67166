"""`housner-3d`: the rigid cylinder that rocks and rolls on its rim in three dimensions
(rbm_cli.structures.cylinder), integrated by scipy's Runge-Kutta pairs (runner.py)."""
