"""What the fragility tests share: a made domain written where `rbm fragility` reads it, and
the command run through click's runner."""

from __future__ import annotations

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
