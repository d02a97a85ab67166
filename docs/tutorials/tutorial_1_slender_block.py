"""
The paper's slender block: from a config to its safe-unsafe domain
==================================================================

Spanos and Koh's slender rectangular block (H/B = 4) under 10 s of harmonic ground
acceleration is the first study of the Rigid Beam Model paper (section 3.1). The shipped
config ``configs/spanos_koh_slender.yaml`` holds it on a 39 x 12 grid; here the same block
is swept on a coarser grid, so the page builds in seconds. The command line does the same
with ``rbm sweep configs/spanos_koh_slender.yaml``.
"""

# %%
# The config
# ----------
# A config is one YAML file: the column, the interface law, the excitation and the grid.
# ``rbm.load_config`` reads and validates it (every error is one line naming the key).
from pathlib import Path

import matplotlib.pyplot as plt

import rbm

# the repository's root: the folder above that holds configs/ (run from the root or docs/)
ROOT = next(p for p in [Path.cwd(), *Path.cwd().parents] if (p / "configs").is_dir())

cfg = rbm.load_config(ROOT / "configs" / "spanos_koh_slender.yaml")
print(cfg.column)
print(cfg.interface)
print(cfg.excitation.type, cfg.excitation.duration, "s")

# %%
# One cell: 0.5 g at 1 Hz
# -----------------------
# The paper's figures 3 and 4 show this cell: the block rocks and overturns. ``rbm.run``
# returns its outcome and its history (a pandas DataFrame: time, ground acceleration,
# displacements, the drum's rotation).
cell = rbm.run(cfg, amplitude_g=0.5, frequency_hz=1.0)
print(f"{cell.status}, t_collapse = {cell.t_collapse_s:.3f} s")
fig, ax = plt.subplots(figsize=(7, 3.5))
rbm.plot_history(cell, ax=ax)
fig.tight_layout()
plt.show()

# %%
# A coarse domain
# ---------------
# 0.1 g steps from 0.1 to 2.0 g and 0.5 Hz steps from 0.5 to 3 Hz: 120 cells instead of
# the study's 468. ``rbm.with_value`` changes one key by its path and validates the
# config again; ``rbm.sweep`` runs the grid in memory and returns the rows of
# ``domain.csv``.
coarse = rbm.with_value(
    cfg,
    "grid",
    {
        "amplitudes": {"start": 0.1, "stop": 2.0, "step": 0.1},  # [g]
        "frequencies": {"start": 0.5, "stop": 3.0, "step": 0.5},  # [Hz]
    },
)
domain = rbm.sweep(coarse)
print(domain[["amplitude_g", "frequency_hz", "status", "t_collapse_s"]].head())
print(domain["status"].value_counts().to_string())

# %%
# The lowest amplitude that overturns the block, per frequency. Collapse starts just
# above the static multiplier B/H = 0.25 g at low frequency and the boundary rises with
# frequency, as the paper finds. A domain of rocking is not monotonic: a cell above the
# boundary may survive again.
collapsed = domain[domain["status"] == "collapsed"]
print(collapsed.groupby("frequency_hz")["amplitude_g"].min().to_string())

# %%
# The figure
# ----------
# ``rbm.plot_domain`` draws safe (o) and unsafe (x) cells, the boundary and, given the
# config, the static multiplier: the same figure as ``domain.png``. It draws on an axes
# of your own (without one it makes a new figure, not held by pyplot).
fig, ax = plt.subplots(figsize=(7, 5))
rbm.plot_domain(domain, ax=ax, config=coarse)
fig.tight_layout()
plt.show()
