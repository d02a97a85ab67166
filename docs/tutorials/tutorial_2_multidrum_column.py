"""
A multi-drum column of your own: its properties, a domain and its ensemble
==========================================================================

A column of four equal stone drums, 3 m tall and tapering from 0.6 m to 0.48 m, with
elastic joints (normal stiffness k_n = 5e9 Pa/m). ``rbm info`` prints what the Rigid Beam
Model derives from it; a small sweep gives its safe-unsafe domain, and the same sweep as an
ensemble says which cells are robust and which are chaotic.
"""

# %%
# The config, written as YAML
# ---------------------------
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

import rbm

config_text = """\
name: four_drums
model: rbm
column:
  height: 3.0              # m
  base_width: 0.6          # m
  top_width: 0.48          # m, linear taper
  section: circular        # the width is the diameter
  density: 2600            # kg/m^3
  drums: 4                 # equal drums of 0.75 m
interface:
  stiffness: {normal: 5e9} # Pa/m: K_M,i = k_n pi B_i^4 / 64
  xi: 1.0                  # bilinear law
  restitution: 1.0
  formulation: relative
excitation:
  type: harmonic
  duration: 4.0            # s (10 s in the paper's studies; short here)
grid:
  amplitudes: [0.2, 0.3, 0.4, 0.5]   # g
  frequencies: [1.0, 2.0, 3.0]       # Hz
"""
work = Path(tempfile.mkdtemp(prefix="rbm_tutorial_"))
config_file = work / "four_drums.yaml"
_ = config_file.write_text(config_text)

# %%
# What the model derives: ``rbm.info``
# ------------------------------------
# ``rbm.info`` gives, as data, what ``rbm info four_drums.yaml`` prints. Per interface i (1
# at the ground): width B_i, drum height h_i, mass m_i and rotary inertia I_Gi, normal
# force N_i (the weight above), the capacity M_u,i = (B_i / 2) N_i, the zero-moment
# rotation theta_u,i, the joint's rotational stiffness K_M,i and the normal stiffness
# k_n,i that gives it, and the rotation where the elastic branch ends. For the column: the
# static multiplier (the ground acceleration [g] at which it starts to rock), the rocking
# parameter p and the elastic frequencies.
cfg = rbm.load_config(config_file)
figures = rbm.info(cfg)
print(f"total mass {figures['total_mass_kg']:.0f} kg")
print(f"static multiplier {figures['static_multiplier_g']:.3f} g")
print(f"rocking p {figures['rocking_p_rad_s']:.3f} rad/s")
print("elastic frequencies [Hz]:", ", ".join(f"{f:.1f}" for f in figures["elastic_frequencies_hz"]))
per_interface = figures["interfaces"].set_index("interface")
print(per_interface[["width_m", "drum_mass_kg", "normal_force_N", "moment_capacity_Nm",
                     "rotation_capacity_rad", "stiffness_Nm_per_rad"]]
      .to_string(float_format=lambda x: f"{x:.4g}"))  # fmt: skip

# %%
# The domain
# ----------
# Twelve cells (4 amplitudes x 3 frequencies). The first run of an elastic column compiles
# the step integrator once per installation (numba caches it on disk).
domain = rbm.sweep(cfg, jobs=2)
columns = ["amplitude_g", "frequency_hz", "status", "collapse_interface", "max_rotation_ratio"]
print(domain[columns].to_string(index=False))

# %%
# ``collapse_interface`` says where the column broke (1 = at the base): a multi-drum
# column can lose its upper drums before the whole of it overturns.

# %%
# The ensemble: robust and sensitive cells
# ----------------------------------------
# Rocking is chaotic near the boundary: a change of the excitation's phase or amplitude
# by 1e-12 to 1e-6 can change the outcome. ``ensemble=K`` runs every cell K times (member
# 0 is the cell itself; the others are perturbed) and adds ``collapse_fraction`` and
# ``robust`` (1 when all K agree and none failed). The robustness rule needs K >= 16.
ensemble = rbm.sweep(cfg, jobs=2, ensemble=16)
print(
    ensemble[["amplitude_g", "frequency_hz", "status", "collapse_fraction", "robust"]].to_string(
        index=False
    )
)
print(f"sensitive cells: {int((ensemble['robust'] != 1).sum())} of {len(ensemble)}")

# %%
# The figure colours each cell by its collapse fraction, so chaotic cells show.
fig, ax = plt.subplots(figsize=(7, 5))
rbm.plot_domain(ensemble, ax=ax, config=cfg)
fig.tight_layout()
plt.show()

# %%
# A colonnade: the column under an architrave
# -------------------------------------------
# Columns rarely stand alone: a peristyle's carry an architrave resting freely on their
# tops. ``frame: {columns: N, beam_mass: m_b}`` makes the column one of N identical ones
# under a rigid beam of mass m_b [kg], rocking in unison (a rocking frame). gamma =
# m_b / (N m), m a column's mass, measures the beam; ``rbm.info`` gives it and the block a
# frame of the same columns glued into monoliths rocks as (its p_hat and the acceleration
# that lifts it).
mass = figures["total_mass_kg"]
frames = {gamma: rbm.with_value(cfg, "frame", {"columns": 2, "beam_mass": 2 * gamma * mass})
          for gamma in (0.5, 1.0, 2.0)}  # fmt: skip
for gamma, frame in frames.items():
    f = rbm.info(frame)
    print(f"gamma {f['frame_gamma']:.2f}: p_hat {f['frame_p_rad_s']:.3f} rad/s "
          f"(alone {figures['domain_p_rad_s']:.3f}), lifts at {f['static_multiplier_g']:.3f} g, "
          f"beam joint K_M {f['interfaces']['stiffness_Nm_per_rad'].iloc[-1]:.3g} N m/rad")  # fmt: skip

# %%
# The beam rests on a joint of its own at the top (the last row of ``interfaces``); its
# weight loads every joint below. A heavier beam lowers p_hat: the frame rocks as a larger
# block. The same cells, the column alone and under each beam:
for name, one in {"alone": cfg, **{f"gamma {g}": c for g, c in frames.items()}}.items():
    out = rbm.sweep(one, jobs=2)
    print(f"{name:>9}: {int(out['collapsed'].sum())} of {len(out)} cells collapse")
