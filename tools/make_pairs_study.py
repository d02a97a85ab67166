"""Planar against three-dimensional fragility: the paper's column in circular drums.

    python tools/make_pairs_study.py                 # docs/figures/pairs_fragility.png
    python tools/make_pairs_study.py --out /tmp/fig.png

Reads the stored domains results/suite_pairs (model rbm-3d: ten pairs of synthetic records,
each pair scaled by one factor, its larger PGA to the amplitude) and
results/suite_pairs_planar (model rbm: each of the twenty records alone in its plane, scaled
to the same PGA levels), both made by `rbm sweep configs/<study>.yaml -o results --ensemble
16`, for 1 and 8 drums. A cell counts as collapsed when most of its 16 members collapsed
(the domain figure's majority rule). The planar assessment of a pair at a level is the
worse of its two components: it collapses when either component alone collapses there.
For each drum count it fits the lognormal fragility of both (rbm.fragility: maximum
likelihood over the records, 5-95 % bootstrap intervals over 2,000 resamples), prints the
medians, dispersions and the levels where the two differ, and draws both curves in one
panel. Runs no model; takes a few seconds.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

import rbm

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "results"
FIGURE = ROOT / "docs" / "figures" / "pairs_fragility.png"
RESAMPLES = 2000


def majority(domain: pd.DataFrame) -> pd.DataFrame:
    """One trial per cell: collapsed when at least half its members collapsed (failed
    cells left out)."""
    out = domain[domain["status"] != "failed"].copy()
    out["collapsed"] = (out["collapse_fraction"] >= 0.5).astype(int)
    out["status"] = np.where(out["collapsed"] == 1, "collapsed", "survived")
    return out.drop(columns=["collapse_fraction"])


def worse_of_pairs(planar: pd.DataFrame, pairs: pd.DataFrame) -> pd.DataFrame:
    """The planar domain with each pair's two records as one trial per level: collapsed
    when either collapsed (a pair is named by its x record, as the 3D domain names it)."""
    name_of = {}
    for x, y in zip(pairs["excitation.file"], pairs["excitation.file_y"], strict=True):
        name_of[Path(x).stem] = name_of[Path(y).stem] = Path(x).stem
    rows = planar.assign(record=planar["record"].map(name_of))
    keys = ["record", "amplitude_g"]
    worse = rows.groupby(keys, as_index=False)["collapsed"].max()
    counts = rows.groupby(keys)["collapsed"].size().to_numpy()
    if not np.all(counts == 2):
        raise SystemExit("each pair needs both of its records at every level in the planar domain")
    worse["status"] = np.where(worse["collapsed"] == 1, "collapsed", "survived")
    return worse


def main(out: Path) -> None:
    three_d = pd.read_csv(RESULTS / "suite_pairs" / "domain.csv")
    planar = pd.read_csv(RESULTS / "suite_pairs_planar" / "domain.csv")
    fig = Figure(figsize=(11.0, 5.0))
    axes = fig.subplots(1, 2)
    for ax, drums in zip(axes, (1, 8), strict=True):
        d3 = majority(three_d[three_d["column.drums"] == drums])
        d2 = worse_of_pairs(majority(planar[planar["column.drums"] == drums]), d3)
        print(f"{drums} drum{'s' if drums > 1 else ''}:")
        for label, domain, style in (("3D (rbm-3d, the pair)", d3, "C0"),
                                     ("planar (rbm, the worse component)", d2, "C3")):  # fmt: skip
            fit = rbm.fragility(domain[["record", "amplitude_g", "status", "collapsed"]],
                                n_resamples=RESAMPLES)  # fmt: skip
            c, (m_lo, m_hi), (b_lo, b_hi) = fit.curve, fit.median_ci_g, fit.beta_ci
            text = f"{label}: median {fit.fit.median_g:.3f} g, beta {fit.fit.beta:.2f}"
            ax.plot(c["intensity_g"], c["probability"], color=style, label=text)
            ax.fill_between(c["intensity_g"], c["lower"], c["upper"], color=style, alpha=0.15)
            levels = domain.groupby("amplitude_g")["collapsed"].mean()
            ax.plot(levels.index, levels.to_numpy(), "o", color=style, ms=4)
            print(f"  {label}: median {fit.fit.median_g:.4f} g ({m_lo:.4f}-{m_hi:.4f}),"
                  f" beta {fit.fit.beta:.3f} ({b_lo:.3f}-{b_hi:.3f})")  # fmt: skip
        both = d3.merge(d2, on=["record", "amplitude_g"], suffixes=("_3d", "_2d"))
        more = int(((both["collapsed_3d"] == 1) & (both["collapsed_2d"] == 0)).sum())
        less = int(((both["collapsed_3d"] == 0) & (both["collapsed_2d"] == 1)).sum())
        print(f"  of {len(both)} pair-levels: 3D collapses where the plane survives {more},"
              f" the plane collapses where 3D survives {less}")  # fmt: skip
        ax.set_title(f"{drums} drum{'s' if drums > 1 else ''}\n3D collapses, plane survives: "
                     f"{more} of {len(both)} pair-levels; the reverse: {less}",
                     fontsize="medium")  # fmt: skip
        ax.set_xlabel("PGA of the larger component [g]")
        ax.set_ylabel("P(collapse)")
        ax.set_xlim(0.0, 1.05)
        ax.set_ylim(-0.02, 1.02)
        ax.grid(alpha=0.3)
        ax.legend(fontsize="small", loc="lower right")
    fig.suptitle("The paper's column in circular drums under 10 pairs of synthetic records:\n"
                 "planar (each component alone, the worse) against 3D")  # fmt: skip
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    print(f"figure: {out}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=FIGURE)
    main(parser.parse_args().out)
