# %% [markdown]
# # rbm from Python: one block, one cell, a sweep and the size effect
#
# A notebook-style script (cells marked `# %%`, as Jupyter, VS Code and Spyder read them);
# `python docs/examples/api_example.py` runs it and writes its figure into
# `out/api_example/` under the current folder. The tests run it (tests/test_api.py).
#
# Units at the API's edge: amplitudes in g (9.81 m/s^2), frequencies in Hz, times in s;
# in the config lengths in m. See docs/api.md.

# %%
from pathlib import Path

import pandas as pd
from matplotlib.figure import Figure

import rbm

# A rigid stone block 2 m tall and 0.5 m wide: it starts to rock when the ground
# acceleration exceeds g B/H = 0.25 g (the RBM's static multiplier).
block = {
    "name": "api_block",
    "column": {"height": 2.0, "base_width": 0.5},  # [m]
    "interface": {"stiffness": "rigid", "restitution": "housner"},
    "excitation": {"type": "harmonic", "duration": 5.0},  # [s]
    "grid": {
        "amplitudes": {"start": 0.1, "stop": 1.3, "step": 0.2},  # [g]
        "frequencies": {"start": 0.5, "stop": 4.0, "step": 0.5},  # [Hz]
    },
}
cfg = rbm.load_config(block)  # a dict, as a notebook writes it (or a YAML file's path)

# %% [markdown]
# ## One cell: the run's outcome and its history as a DataFrame

# %%
cell = rbm.run(cfg, amplitude_g=0.3, frequency_hz=1.0)
print(f"0.3 g at 1 Hz: {cell.status}, t_collapse = {cell.t_collapse_s:.3g} s")
cell.history.head()  # t_s, ag_m_s2, ug_m, u1_m, u2_m, theta1_rad

# %% [markdown]
# ## The size effect: the same slenderness at twice the size
#
# `with_values` changes the written config by key path and validates it again.

# %%
big_cfg = rbm.with_values(
    cfg, {"name": "api_block_big", "column.height": 4.0, "column.base_width": 1.0}
)
small = rbm.sweep(cfg)  # a DataFrame with the rows of domain.csv (no files kept)
big = rbm.sweep(big_cfg)


def lowest_collapse(df):
    """The lowest collapsed amplitude [g] per frequency [Hz] (nan where none collapsed)."""
    collapsed = df[df["status"] == "collapsed"]
    frequencies = sorted(df["frequency_hz"].unique())
    return collapsed.groupby("frequency_hz")["amplitude_g"].min().reindex(frequencies)


boundaries = pd.DataFrame({"H = 2 m": lowest_collapse(small), "H = 4 m": lowest_collapse(big)})
print("lowest collapsed amplitude [g]; the larger block needs more (or never collapses):")
print(boundaries.to_string(na_rep="none"))

# %% [markdown]
# ## Figures on axes of your own

# %%
fig = Figure(figsize=(11, 4.2))
ax_history, ax_domain = fig.subplots(1, 2)
rbm.plot_history(cell, ax=ax_history)
rbm.plot_domain(
    small,
    ax=ax_domain,
    config=cfg,
    compare=[big],
    labels=["H = 2 m, B = 0.5 m", "H = 4 m, B = 1 m"],
)
fig.tight_layout()
out = Path("out") / "api_example"
out.mkdir(parents=True, exist_ok=True)
fig.savefig(out / "api_example.png", dpi=120)
print(f"wrote {out / 'api_example.png'}")
