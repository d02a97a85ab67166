"""rbm-3d against the contact engine in three dimensions: the paper's column in 8 circular
drums under record pairs, cell by cell.

    python tools/make_pairs_engine.py      # prints a Markdown table and the agreement

Reads the stored domains results/suite_pairs (model rbm-3d, made by `rbm sweep
configs/suite_pairs.yaml -o results --ensemble 16`; its 8-drum cells) and
results/suite_pairs_bullet (model bullet free in three dimensions, one run a cell, made by
`rbm sweep configs/suite_pairs_bullet.yaml -o results`), on the cells both have (five pairs
x five levels, 0.2-1.0 g). A cell of rbm-3d is robust when its 16 members agree; its
outcome is then theirs, and the engine's run agrees with it or not. On a sensitive cell
the fraction of members that collapsed is given beside the engine's outcome. Runs no
model; takes a second.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "results"
DRUMS = 8


def compare(engine: pd.DataFrame, beam: pd.DataFrame) -> pd.DataFrame:
    """One row per cell both domains have: record, amplitude_g, the engine's status and
    collapse time, rbm-3d's collapse fraction, robustness and (robust) outcome, and
    whether they agree (robust cells only; NaN on a sensitive one)."""
    if "column.drums" in beam.columns:
        beam = beam[beam["column.drums"] == DRUMS]
    keys = ["record", "amplitude_g"]
    for frame in (engine, beam):
        frame["amplitude_g"] = frame["amplitude_g"].round(6)
    both = engine[keys + ["status", "t_collapse_s"]].merge(
        beam[keys + ["collapse_fraction", "robust", "t_collapse_s"]],
        on=keys,
        suffixes=("_engine", "_rbm3d"),
    )
    both = both[both["status"] != "failed"].sort_values(keys).reset_index(drop=True)
    collapsed = both["status"] == "collapsed"
    robust = both["robust"] == 1
    rbm_collapsed = both["collapse_fraction"] >= 0.5
    both["rbm3d"] = np.where(robust, np.where(rbm_collapsed, "collapsed", "survived"), "sensitive")
    both["agree"] = np.where(robust, (collapsed == rbm_collapsed).astype(float), np.nan)
    return both


def summary(both: pd.DataFrame) -> dict:
    """Counts: cells, robust cells, robust cells where the two agree, and where they do
    not, which collapsed (the engine or rbm-3d)."""
    robust = both[both["agree"].notna()]
    differ = robust[robust["agree"] == 0.0]
    return {
        "cells": len(both),
        "robust": len(robust),
        "agree": int(robust["agree"].sum()),
        "engine_only": int(np.sum(differ["status"] == "collapsed")),
        "rbm3d_only": int(np.sum(differ["rbm3d"] == "collapsed")),
    }


def main() -> None:
    engine = pd.read_csv(RESULTS / "suite_pairs_bullet" / "domain.csv")
    beam = pd.read_csv(RESULTS / "suite_pairs" / "domain.csv")
    both = compare(engine, beam)
    print("| pair (x record) | PGA [g] | engine | t [s] | rbm-3d | collapsed members | t [s] |")
    print("|---|---|---|---|---|---|---|")
    for row in both.itertuples():
        print(f"| {row.record} | {row.amplitude_g:.1f} | {row.status} |"
              f" {row.t_collapse_s_engine:.2f} | {row.rbm3d} | {row.collapse_fraction:.3f} |"
              f" {row.t_collapse_s_rbm3d:.2f} |".replace(" nan ", " - "))  # fmt: skip
    s = summary(both)
    print(f"\n{s['cells']} cells, {s['robust']} robust in rbm-3d; the same outcome on"
          f" {s['agree']} of them; of the others the engine alone collapsed on"
          f" {s['engine_only']}, rbm-3d alone on {s['rbm3d_only']}")  # fmt: skip


if __name__ == "__main__":
    main()
