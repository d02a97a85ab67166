"""The physics: column, law, ground motions, the RBM's equations and closed forms.

Pure functions and frozen dataclasses; no I/O, no run loop. Imports config and base.
"""
