"""Scoring a run of `rbm bench` against its reference, cell by cell.

Errors: (a) cells whose outcome differs from the reference (converged cells
only), (b) the largest boundary shift [g], (c) relative errors of the peak
rotation ratio (cells with a well-conditioned reference peak that survive in
both) and of the collapse time (converged cells that collapse in both), median
and max.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from rbm_cli.study.domain import compare
from rbm_cli.study.schema import C


def cell_keys(df: pd.DataFrame) -> pd.Series:
    return df[C.amplitude_g].round(9).astype(str) + "|" + df[C.frequency_hz].round(9).astype(str)


def errors(run: pd.DataFrame, ref: pd.DataFrame) -> dict:
    """Errors of a run's rows against the reference rows of the same cells."""
    m = run.assign(key=cell_keys(run)).merge(ref.assign(key=cell_keys(ref)), on="key",
                                        suffixes=("", "_ref"))  # fmt: skip
    n_failed = int((m[C.status] == "failed").sum())
    conv = m[(m["converged"] == 1) & (m[C.status] != "failed")]
    differ = int((conv[C.collapsed] != conv["collapsed_ref"]).sum())
    both_surv = m[(m["peak_converged"] == 1) & (m[C.collapsed] == 0) & (m["collapsed_ref"] == 0)]
    both_surv = both_surv[both_surv["max_rotation_ratio_ref"] > 0]
    peak = (both_surv[C.max_rotation_ratio] - both_surv["max_rotation_ratio_ref"]).abs()
    peak = (peak / both_surv["max_rotation_ratio_ref"]).to_numpy()
    both_col = conv[(conv[C.collapsed] == 1) & (conv["collapsed_ref"] == 1)]
    tcol = ((both_col[C.t_collapse_s] - both_col["t_collapse_s_ref"]).abs()
            / both_col["t_collapse_s_ref"]).to_numpy()  # fmt: skip
    shift = math.nan
    if len(conv) and conv[C.frequency_hz].nunique() > 0:
        a = conv[[C.amplitude_g, C.frequency_hz, C.collapsed]].assign(
            status=np.where(conv[C.collapsed] == 1, "collapsed", "survived")
        )
        b = conv[[C.amplitude_g, C.frequency_hz, "collapsed_ref"]].rename(
            columns={"collapsed_ref": "collapsed"}
        )
        b = b.assign(status=np.where(b[C.collapsed] == 1, "collapsed", "survived"))
        shift = compare(a, b).max_shift_g
    return {
        "n_cells": len(m),
        "n_failed": n_failed,
        "n_converged": len(conv),
        "n_sensitive": len(m) - len(conv),
        "cells_differ": differ,
        "fraction_differ": differ / len(conv) if len(conv) else math.nan,
        "boundary_err_g": shift,
        "n_peak": len(peak),
        "peak_err_median": float(np.median(peak)) if len(peak) else math.nan,
        "peak_err_max": float(np.max(peak)) if len(peak) else math.nan,
        "n_tcol": len(tcol),
        "tcol_err_median": float(np.median(tcol)) if len(tcol) else math.nan,
        "tcol_err_max": float(np.max(tcol)) if len(tcol) else math.nan,
    }


def agreement(run: pd.DataFrame, other: pd.DataFrame, ref: pd.DataFrame) -> dict:
    """How a method's rows agree with another method's on the cells both ran (the default
    step kernel's, for the exact method): converged cells of the reference whose outcome
    differs, the largest relative difference of the peak rotation ratio (cells with a
    well-conditioned reference peak that survive in both; a chaotic cell agrees with no
    other run), and the paired time ratio other / run (run times summed over all common
    cells)."""
    m = run.assign(key=cell_keys(run)).merge(other.assign(key=cell_keys(other)), on="key",
                                        suffixes=("", "_other"))  # fmt: skip
    own, theirs = float(m["wall_time_s"].sum()), float(m["wall_time_s_other"].sum())
    flags = ref.assign(key=cell_keys(ref))[["key", "converged", "peak_converged"]]
    m = m.merge(flags, on="key")
    ok = (m[C.status] != "failed") & (m["status_other"] != "failed") & (m["converged"] == 1)
    differ = int((m.loc[ok, "collapsed"] != m.loc[ok, "collapsed_other"]).sum())
    surv = m[ok & (m["peak_converged"] == 1) & (m[C.collapsed] == 0) & (m["collapsed_other"] == 0)]
    surv = surv[surv["max_rotation_ratio_other"] > 0]
    rel = ((surv[C.max_rotation_ratio] - surv["max_rotation_ratio_other"]).abs()
           / surv["max_rotation_ratio_other"]).to_numpy()  # fmt: skip
    return {
        "differ_vs_default": differ,
        "peak_diff_vs_default_median": float(np.median(rel)) if len(rel) else math.nan,
        "peak_diff_vs_default_max": float(np.max(rel)) if len(rel) else math.nan,
        "speedup_vs_default": theirs / own if own > 0 else math.nan,
    }
