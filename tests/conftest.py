"""Test setup: nothing is written into the working tree (Agg backend, no caches here)."""

import os
import tempfile

import matplotlib

matplotlib.use("Agg")

from hypothesis import configuration, settings  # noqa: E402

# hypothesis keeps its example database under a home directory: move it out of the tree
configuration.set_hypothesis_home_dir(tempfile.mkdtemp(prefix="rbm-hypothesis-"))
settings.register_profile("rbm", database=None, derandomize=True, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "rbm"))
