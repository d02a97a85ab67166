"""What the fragility tests share: a made domain written where `rbm fragility` reads it, its
outcomes rewritten by hand for a state, and the command run through click's runner."""

from __future__ import annotations

import numpy as np
from click.testing import CliRunner

from rbm_cli.cli.main import cli


def write(folder, df):
    """``df`` as ``folder``/domain.csv (the folder made); returns its path."""
    folder.mkdir(parents=True, exist_ok=True)
    df.to_csv(folder / "domain.csv", index=False, float_format="%.12g")
    return str(folder / "domain.csv")


def invoke(*args):
    """``rbm fragility ARGS``, each argument as text."""
    return CliRunner().invoke(cli, ["fragility", *[str(a) for a in args]])


def exceeding(df, column, threshold):
    """The domain with its outcomes rewritten by hand: a run that did not fail "collapses"
    when its ``column`` >= threshold or it collapsed (a stored collapse_fraction dropped)."""
    out = df.drop(columns=["collapse_fraction"], errors="ignore").copy()
    ok = out["status"] != "failed"
    hit = ok & ((out["collapsed"] == 1) | (out[column] >= threshold))
    out["collapsed"] = hit.astype(int)
    out["status"] = np.where(~ok, "failed", np.where(hit, "collapsed", "survived"))
    return out
