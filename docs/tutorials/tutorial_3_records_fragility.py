"""
A record suite: incremental dynamic analysis and fragility curves
=================================================================

A suite of ground-motion records, each scaled to a range of peak ground accelerations
(PGA), is one sweep: records x intensities. Its outcomes give the incremental dynamic
analysis (IDA: a curve per record, the intensity against its peak rotation) and a
lognormal fragility curve, fitted by maximum likelihood (Baker 2015) with a bootstrap band
over the records.

The records are the 20 synthetic motions shipped in ``configs/records/synthetic/``
(Rezaeian-Der Kiureghian's stochastic model, seeded; they exercise the method, they do not
assess a site). Here: the first 8, on the paper's tapered column as a rigid monolith, PGA
0.1-1.0 g. The shipped study ``configs/suite_monolithic.yaml`` runs all 20 on the column
with elastic joints.
"""

# %%
# The suite as a config
# ---------------------
# ``excitation.type: record`` with a list, a folder or a glob of files is a suite: the
# grid axis ``excitation.file``. ``scale: pga`` makes each grid amplitude the scaled
# record's PGA [g].
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import rbm

# the repository's root: the folder above that holds configs/ (run from the root or docs/)
ROOT = next(p for p in [Path.cwd(), *Path.cwd().parents] if (p / "configs").is_dir())
records = sorted((ROOT / "configs" / "records" / "synthetic").glob("rdk_*.AT2"))[:8]

cfg = rbm.load_config(
    {
        "name": "suite_rigid",
        "column": {"height": 5.0, "base_width": 0.96, "top_width": 0.66},  # [m]
        "interface": {"stiffness": "rigid", "restitution": "housner"},
        "excitation": {
            "type": "record",
            "file": [str(p) for p in records],
            "scale": "pga",
            "free_time": 5.0,  # [s] of free motion after each record
        },
        "grid": {"amplitudes": {"start": 0.1, "stop": 1.0, "step": 0.1}},  # PGA [g]
    }
)

# %%
# The sweep
# ---------
# Written to a folder, as ``rbm sweep`` writes it: ``domain.csv`` has a row per record and
# intensity, with the record's file and its name in ``record``.
out = Path(tempfile.mkdtemp(prefix="rbm_suite_"))
domain = rbm.sweep(cfg, output=out, jobs=2)
print(domain[["record", "amplitude_g", "status", "max_rotation_ratio"]].head(12))
print(f"{len(domain)} runs, {int(domain['collapsed'].sum())} collapses")

# %%
# The fragility
# -------------
# ``rbm.fragility`` fits the lognormal curve by maximum likelihood over the records, with a
# bootstrap band over them, as ``rbm fragility`` does; it writes nothing.
# ``rbm fragility <folder>/domain.csv`` fits the same and writes its files beside the
# domain (``fragility.csv``, ``fragility_curve.csv``, ``fragility.json``, ``fragility.png``,
# ``ida.png``).
result = rbm.fragility(domain, n_resamples=200, seed=1)
print(result.table[["intensity_g", "n_records", "n_collapsed", "fraction"]].to_string(index=False))
if result.fitted:
    lo, hi = result.median_ci_g
    print(
        f"median PGA {result.fit.median_g:.2f} g (5-95 %: {lo:.2f}-{hi:.2f} g), "
        f"dispersion beta {result.fit.beta:.2f}"
    )
else:
    print("no fit:", result.note)
print("the same, with its files:", f"rbm fragility {Path(domain.attrs['folder']) / 'domain.csv'}")

# %%
# IDA and the fragility curve, drawn here
# ---------------------------------------
# Left: the IDA in the field's convention, the intensity (PGA) up and each record's peak
# rotation ratio (1 = collapse) across, its curve flat from its first collapse on (`rbm
# fragility`'s ida.png draws it so). Right: the fraction of records that topple the column
# at each intensity, and the fitted lognormal curve with its band.
fig, (ax_ida, ax_fr) = plt.subplots(1, 2, figsize=(11, 4.2))
for name, runs in domain.groupby("record"):
    runs = runs.sort_values("amplitude_g")
    pga, ratio = runs["amplitude_g"].to_numpy(), runs["max_rotation_ratio"].to_numpy()
    hit = np.flatnonzero(runs["collapsed"].to_numpy() == 1)
    if hit.size:  # up to the first collapse, then flat at its PGA
        k = hit[0]
        pga, ratio = np.append(pga[: k + 1], pga[k]), np.append(ratio[: k + 1], 1.5)
    ax_ida.plot(ratio, pga, marker=".", lw=1, label=name)
ax_ida.set_xlim(0.0, 1.5)
ax_ida.axvline(1.0, color="k", ls="--", lw=0.8)
ax_ida.set_xlabel("peak rotation / collapse limit")
ax_ida.set_ylabel("PGA [g]")
ax_ida.set_title("IDA, one curve per record")
ax_ida.legend(fontsize=7, ncol=2)

table, curve = result.table, result.curve
ax_fr.plot(table["intensity_g"], table["fraction"], "o", color="k", label="fraction collapsed")
if result.fitted:
    ax_fr.plot(curve["intensity_g"], curve["probability"], color="C3", label="lognormal fit")
    ax_fr.fill_between(
        curve["intensity_g"],
        curve["lower"],
        curve["upper"],
        color="C3",
        alpha=0.2,
        label="5-95 % band over records",
    )
ax_fr.set_xlabel("PGA [g]")
ax_fr.set_ylabel("P(collapse)")
ax_fr.set_ylim(-0.02, 1.02)
ax_fr.set_title("fragility")
ax_fr.legend(fontsize=8)
fig.tight_layout()
plt.show()
