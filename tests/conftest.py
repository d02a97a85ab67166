"""Test setup: nothing is written into the working tree (Agg backend, no caches here)."""

import os
import tempfile

import matplotlib

matplotlib.use("Agg")

# the first use of the kernel compiles in the foreground in tests (as a library call does):
# a test that runs `rbm run` on an empty cache gets the integrator it asked for, and no
# background compile outlives it; tests/test_first_use.py turns it back on where it tests it
os.environ["RBM_BACKGROUND_COMPILE"] = "0"

from hypothesis import configuration, settings  # noqa: E402

# hypothesis keeps its example database under a home directory: move it out of the tree
configuration.set_hypothesis_home_dir(tempfile.mkdtemp(prefix="rbm-hypothesis-"))
settings.register_profile("rbm", database=None, derandomize=True, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "rbm"))
