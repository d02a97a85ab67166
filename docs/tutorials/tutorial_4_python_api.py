"""
The Python API: a parametric study over slenderness
===================================================

``import rbm`` gives the functions the commands run: load a config from a dict or a file,
change values by key path, run one cell, sweep a grid into a pandas DataFrame, and draw on
matplotlib axes of your own. Units at this edge: amplitudes in g, frequencies in Hz, times
in s, lengths in m.

The study: rigid stone blocks 3 m tall of slenderness H/B = 3 to 8 under 5 s of harmonic
ground acceleration. How does the amplitude that overturns a block depend on its
slenderness, and does the static multiplier B/H tell it?
"""

# %%
# A block from a dict
# -------------------
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

import rbm

base = rbm.load_config(
    {
        "name": "block",
        "column": {"height": 3.0, "base_width": 0.75, "depth": 1.0},  # [m]
        "interface": {"stiffness": "rigid", "restitution": "housner"},
        "excitation": {"type": "harmonic", "duration": 5.0},  # [s]
        "grid": {
            "amplitudes": {"start": 0.05, "stop": 1.5, "step": 0.05},  # [g]
            "frequencies": [0.5, 1.0, 2.0],  # [Hz]
        },
    }
)

# %%
# One cell, and its history
# -------------------------
cell = rbm.run(base, amplitude_g=0.4, frequency_hz=1.0)
print(cell.status, cell.t_collapse_s)
print(cell.history[["t_s", "ag_m_s2", "theta1_rad"]].describe().loc[["min", "max"]])

# %%
# The parametric study
# --------------------
# ``rbm.with_values`` changes keys by their dotted path and validates the config again;
# ``rbm.sweep`` returns the rows of ``domain.csv`` as a DataFrame and writes nothing.
# (A grid axis does the same in one sweep: ``grid: {column.slenderness: [3, 4, 6, 8]}``.)
slenderness = [3.0, 4.0, 5.0, 6.0, 8.0]
rows = []
for s in slenderness:
    cfg = rbm.with_values(base, {"name": f"block_s{s:g}", "column.base_width": 3.0 / s})
    df = rbm.sweep(cfg)
    lowest = df[df["status"] == "collapsed"].groupby("frequency_hz")["amplitude_g"].min()
    for f, a in lowest.items():
        rows.append({"H/B": s, "frequency_hz": f, "lowest_collapse_g": a, "B/H": 1.0 / s})
study = pd.DataFrame(rows)
print(study.pivot(index="H/B", columns="frequency_hz", values="lowest_collapse_g"))

# %%
# A figure of your own
# --------------------
# The lowest amplitude that overturns each block, per frequency, against its slenderness,
# beside the static multiplier B/H where a rigid block starts to rock. At 0.5 Hz every
# block falls just above its B/H; at 2 Hz each needs several times its B/H, and the ratio
# does not follow the slenderness smoothly (a 0.05 g grid, and a boundary where rocking is
# chaotic): the static multiplier alone does not tell how safe a block is.
fig, (ax, ax_ratio) = plt.subplots(1, 2, figsize=(11, 4.2))
for f, part in study.groupby("frequency_hz"):
    ax.plot(part["H/B"], part["lowest_collapse_g"], "o-", label=f"{f:g} Hz")
    ax_ratio.plot(part["H/B"], part["lowest_collapse_g"] / part["B/H"], "o-", label=f"{f:g} Hz")
ax.plot(slenderness, [1 / s for s in slenderness], "k--", label="static multiplier B/H")
ax.set_xlabel("slenderness H/B")
ax.set_ylabel("lowest collapsed amplitude [g]")
ax.legend()
ax_ratio.set_xlabel("slenderness H/B")
ax_ratio.set_ylabel("lowest collapsed amplitude / (B/H)")
ax_ratio.axhline(1.0, color="k", lw=0.8, ls="--")
ax_ratio.legend()
fig.tight_layout()
plt.show()

# %%
# Your own ground motions, as arrays
# ----------------------------------
# A motion a notebook already holds (a record read by your own code, a simulated one) goes
# in as two arrays: ``rbm.motion_from_arrays`` checks them as a record file is checked
# (times increasing, finite values; one line naming the problem otherwise) and returns a
# ``Motion`` that runs as a record of the config. Here: three pulse-like motions made with
# numpy, a cosine-tapered burst of two cycles at 0.8, 1.5 and 3 Hz, sampled at 200 Hz.
# As with a record, the amplitude of a cell is the peak ground acceleration the motion is
# scaled to.


def burst(f_hz, cycles=2.0, dt=0.005):
    """Time [s] and a tapered sine burst of unit peak [g]."""
    t = np.arange(0.0, cycles / f_hz + dt / 2, dt)
    taper = np.sin(np.pi * t / t[-1]) ** 2
    a = taper * np.sin(2 * np.pi * f_hz * t)
    return t, a / np.abs(a).max()


motions = [rbm.motion_from_arrays(*burst(f), units="g", name=f"burst {f:g} Hz")
           for f in (0.8, 1.5, 3.0)]  # fmt: skip
amplitudes = {"start": 0.1, "stop": 2.0, "step": 0.1}  # [g]
block4 = rbm.with_values(
    base, {"name": "block_s4", "column.base_width": 3.0 / 4.0, "grid.amplitudes": amplitudes}
)
one = rbm.run(block4, amplitude_g=1.0, motion=motions[0])
print(one.status, one.t_collapse_s)

# %%
# A sweep over the motions is an incremental dynamic analysis of this block: one row per
# motion and amplitude (the motion's name in the ``record`` column), in memory. The
# slowest burst overturns the block from 0.4 g (1.6 times its B/H); the 1.5 Hz burst needs
# 1.2 g, and its peak rotation does not grow steadily on the way; the 3 Hz burst, two short
# cycles, does not overturn it up to 2 g.
ida = rbm.sweep(block4, motions=motions)
first = ida[ida["status"] == "collapsed"].groupby("record", sort=False)["amplitude_g"].min()
print(first)

fig, ax = plt.subplots(figsize=(6, 4))
for name, part in ida.groupby("record", sort=False):
    ax.plot(part["amplitude_g"], part["max_rotation_ratio"].clip(upper=1.0), "o-", ms=3,
            label=name)  # fmt: skip
ax.axvline(0.25, color="k", lw=0.8, ls="--", label="B/H = 0.25 g")
ax.set_xlabel("peak ground acceleration [g]")
ax.set_ylabel("peak rotation / slenderness angle (1: overturned)")
ax.legend()
fig.tight_layout()
plt.show()
