"""
A column in three dimensions under record pairs: planar against 3D fragility
============================================================================

A station records two horizontal components of a ground motion; a planar model takes one.
The Rigid Beam Model of circular drums in two directions (``model: rbm-3d``) takes both:
each drum rotates about any horizontal axis, and a joint can wobble (its rotation vector
turns round without passing through zero) instead of rocking to and fro. Is the planar
assessment, each component alone and the worse of the two, on the safe side?

The column: the paper's tapered column (5 m, 0.96 m at the base, 0.66 m at the top) in 4
circular drums with elastic joints, as in the shipped study ``configs/suite_pairs.yaml``
(which has 1 and 8 drums). The motions: the 10 pairs of synthetic records shipped in
``configs/records/synthetic/`` (``rdk_01`` with ``rdk_02``, ..., ``rdk_19`` with
``rdk_20``: independent realisations of one stochastic model taken as a station's two
components; they exercise the method, they do not assess a site), each pair scaled by one
factor, its larger PGA to 0.1-0.8 g: 80 runs in 3D and 160 in the plane, about 25 s of
CPU. The stored study, with ensembles of 16, is in the models guide ("Planar against
3D").
"""

# %%
# The column and a pair of records
# --------------------------------
# ``excitation.file`` and ``excitation.file_y`` are the two components (x and y, at 90
# degrees counter-clockwise); ``scale: pga`` scales both by one factor, the larger PGA to
# the amplitude [g]. A rectangular section is refused in 3D: its capacity is not the
# same in every direction.
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import rbm

# the repository's root: the folder above that holds configs/ (run from the root or docs/)
ROOT = next(p for p in [Path.cwd(), *Path.cwd().parents] if (p / "configs").is_dir())
RECORDS = ROOT / "configs" / "records" / "synthetic"
PAIRS = [(RECORDS / f"rdk_{k:02d}.AT2", RECORDS / f"rdk_{k + 1:02d}.AT2") for k in range(1, 20, 2)]

column = {
    "height": 5.0,  # [m]
    "base_width": 0.96,  # [m], the diameter at the base
    "top_width": 0.66,  # [m]
    "section": "circular",
    "density": 2700,  # [kg/m^3]
    "drums": 4,
}
interface = {
    "stiffness": {"normal": 5e9},  # [Pa/m]
    "xi": 1.0,
    "restitution": 1.0,
    "formulation": "relative",
}


def config(name: str, model: str, files, **excitation) -> rbm.Config:
    """The column under records: ``files`` one record, a list of them, or a list of
    {x, y} pairs; amplitudes [g] from 0.1 to 0.8 g (the larger component's PGA)."""
    return rbm.load_config(
        {
            "name": name,
            "model": model,
            "column": column,
            "interface": interface,
            "excitation": {
                "type": "record",
                "file": files,
                "units": "g",
                "scale": "pga",
                "free_time": 5.0,  # [s] of free motion after the records
                **excitation,
            },
            "grid": {"amplitudes": {"start": 0.1, "stop": 0.8, "step": 0.1}},
        }
    )


one_pair = config("column_3d", "rbm-3d", str(PAIRS[0][0]), file_y=str(PAIRS[0][1]))
print(f"static multiplier: {rbm.info(one_pair)['static_multiplier_g']:.3f} g")

# %%
# One pair at 0.5 g
# -----------------
# The first use of ``rbm-3d`` compiles its kernel once per installation (numba caches it
# on disk; minutes on a loaded machine); later runs of this column take a fraction of a
# second. The history holds each drum's rotation in the motion's plane and across it
# (``theta<i>_rad``, ``theta<i>_across_rad``) and the top's displacement in plan
# (``top_x_m``, ``top_y_m`` [m]).
cell = rbm.run(one_pair, amplitude_g=0.5)
h = cell.history
print(f"{cell.status}, t_collapse = {cell.t_collapse_s:.2f} s,"
      f" {cell.result['n_impacts']} impacts")  # fmt: skip

fig, (ax_plan, ax_t) = plt.subplots(1, 2, figsize=(11, 4.5))
ax_plan.plot(h["top_x_m"], h["top_y_m"], lw=0.8)
ax_plan.plot(h["top_x_m"].iloc[-1], h["top_y_m"].iloc[-1], "x", color="C3", label="last sample")
ax_plan.set_aspect("equal", adjustable="datalim")
ax_plan.set_xlabel("top displacement along x [m]")
ax_plan.set_ylabel("along y [m]")
ax_plan.set_title("the top's path in plan")
ax_plan.legend()
ax_t.plot(h["t_s"], h["theta1_rad"], lw=0.8, label="drum 1, along x")
ax_t.plot(h["t_s"], h["theta1_across_rad"], lw=0.8, label="drum 1, along y")
ax_t.set_xlabel("t [s]")
ax_t.set_ylabel("rotation [rad]")
ax_t.set_title("the base drum's rotation in both directions")
ax_t.legend()
fig.tight_layout()
plt.show()

# %%
# The suite in three dimensions
# -----------------------------
# A list of ``{x, y}`` pairs is a suite of pairs: one row per pair and level, the pair
# named by its x record in ``record``. ``collapse_azimuth_deg`` says where the column
# leaned when it fell [deg from x], ``wobble_turns`` how far an open joint's rotation
# turned round, in turns (0 for rocking in a plane).
suite_3d = config("column_3d_pairs", "rbm-3d", [{"x": str(x), "y": str(y)} for x, y in PAIRS])
three_d = rbm.sweep(suite_3d)
columns = ["record", "amplitude_g", "status", "collapse_azimuth_deg", "wobble_turns"]
print(three_d[columns].round(2).to_string(index=False))

# %%
# The planar counterpart
# ----------------------
# The same column in its plane (``model: rbm``) under each of the 20 records alone, scaled
# to the same levels. A pair counts as collapsed at a level when either of its components
# alone collapses there: the worse of the two, as a planar assessment would take it.
suite_2d = config("column_planar", "rbm", [str(r) for pair in PAIRS for r in pair])
planar = rbm.sweep(suite_2d)
pair_of = {y.stem: x.stem for x, y in PAIRS} | {x.stem: x.stem for x, _ in PAIRS}
worse = (
    planar.assign(record=planar["record"].map(pair_of))
    .groupby(["record", "amplitude_g"], as_index=False)["collapsed"]
    .max()
)
worse["status"] = np.where(worse["collapsed"] == 1, "collapsed", "survived")
both = three_d.merge(worse, on=["record", "amplitude_g"], suffixes=("_3d", "_2d"))
print(both.groupby("amplitude_g")[["collapsed_3d", "collapsed_2d"]].sum().to_string())
only_3d = int(((both["collapsed_3d"] == 1) & (both["collapsed_2d"] == 0)).sum())
only_2d = int(((both["collapsed_3d"] == 0) & (both["collapsed_2d"] == 1)).sum())
print(f"of {len(both)} pair-levels: 3D collapses where the plane survives {only_3d},"
      f" the plane collapses where 3D survives {only_2d}")  # fmt: skip

# %%
# Fragility, planar against 3D
# ----------------------------
# ``rbm.fragility`` fits a lognormal curve by maximum likelihood over the pairs, with a
# bootstrap band over them (200 resamples here), as ``rbm fragility`` does. Ten pairs are
# few and the bands wide; a fit fails (and says why) where every pair collapses at the
# same level.
fig, ax = plt.subplots(figsize=(7, 4.5))
for label, domain, colour in (("3D (rbm-3d, the pair)", three_d, "C0"),
                              ("planar (rbm, the worse component)", worse, "C3")):  # fmt: skip
    trials = domain[["record", "amplitude_g", "status", "collapsed"]]
    fit = rbm.fragility(trials, n_resamples=200, seed=1)
    levels = trials.groupby("amplitude_g")["collapsed"].mean()
    ax.plot(levels.index, levels.to_numpy(), "o", color=colour, ms=5)
    if fit.fitted:
        curve = fit.curve
        text = f"{label}: median {fit.fit.median_g:.2f} g, beta {fit.fit.beta:.2f}"
        ax.plot(curve["intensity_g"], curve["probability"], color=colour, label=text)
        ax.fill_between(curve["intensity_g"], curve["lower"], curve["upper"], color=colour,
                        alpha=0.15)  # fmt: skip
        print(text)
    else:
        ax.plot([], [], "o", color=colour, label=f"{label}: no fit ({fit.note})")
        print(f"{label}: no fit: {fit.note}")
ax.set_xlabel("PGA of the larger component [g]")
ax.set_ylabel("P(collapse)")
ax.set_ylim(-0.02, 1.02)
ax.set_title("fractions collapsed (dots) and lognormal fits")
ax.legend(fontsize="small", loc="lower right")
fig.tight_layout()
plt.show()

# %%
# The pair-levels where only one of the two collapses, with how far the 3D run's joints
# turned round:
differ = both[both["collapsed_3d"] != both["collapsed_2d"]]
print(differ[["record", "amplitude_g", "collapsed_3d", "collapsed_2d", "wobble_turns"]]
      .round(2).to_string(index=False))  # fmt: skip

# %%
# The same study from the command line: ``rbm sweep configs/suite_pairs.yaml`` and
# ``rbm sweep configs/suite_pairs_planar.yaml`` (1 and 8 drums, 10 levels), then
# ``python docs/make_pairs_study.py`` for the two fragility curves of each drum count.
