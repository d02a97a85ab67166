"""rbm: seismic rocking of freestanding stone columns with the Rigid Beam Model.

Baraldi, Milani and Sarhosis, "A simple and effective Rigid Beam Model for
studying the dynamic behaviour of freestanding columns".
"""

__version__ = "0.2.0"
