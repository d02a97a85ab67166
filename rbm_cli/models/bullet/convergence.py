"""How the engine's outcomes hold up as its time step changes (`model: bullet`).

Pure functions on outcomes already computed (no engine): they summarise a study
that runs the same cells under several engine variants (time steps), or as
ensembles, against a reference. A cell is chaotic under a variant when that
variant's own runs of it (the same cell nudged within 1e-6) disagree; only the
cells robust under both can be said to agree or differ. tools/make_engine.py
(parts timestep and converge) prints them for docs/engine.md.
"""

from __future__ import annotations

Cell = tuple[float, float]  # (amplitude [g], frequency [Hz])


def step_agreement(statuses: dict[Cell, dict[str, list[str]]], variant: str, ref: str) -> dict:
    """Cells where a variant's outcome is the reference variant's.

    Parameters
    ----------
    statuses : {cell: {variant: [status of each run]}}  Every variant's runs of every cell
    variant, ref : str  The variant compared, and the reference one

    Returns
    -------
    dict  same_as_ref, differ_from_ref (cells robust in both), chaotic_here_or_ref
        (cells whose runs disagree within the variant or within the reference)
    """
    same = differ = chaotic = 0
    for runs in statuses.values():
        mine, base = set(runs[variant]), set(runs[ref])
        if len(mine) > 1 or len(base) > 1:
            chaotic += 1
        elif mine == base:
            same += 1
        else:
            differ += 1
    return dict(same_as_ref=same, differ_from_ref=differ, chaotic_here_or_ref=chaotic)


def outcome_marks(statuses: dict[Cell, dict[str, list[str]]]) -> dict[Cell, dict[str, str]]:
    """Per cell and variant, the outcomes seen as letters: 'C' collapsed, 'S' survived,
    'F' failed ('CS': the runs disagree)."""
    return {
        cell: {k: "".join(sorted({s[0].upper() for s in v})) for k, v in runs.items()}
        for cell, runs in statuses.items()
    }


def ensemble_agreement(engine: dict[Cell, float], reference: dict[Cell, float]) -> dict:
    """Cells where two models' ensemble collapse fractions agree.

    Parameters
    ----------
    engine, reference : {cell: collapse fraction [-]}  Over the same cells
        (in the order to list them)

    Returns
    -------
    dict  agree (count of cells robust in both with the same outcome), of (cells),
        differ (cells robust in both with different outcomes), chaotic_engine_housner
        ({"a f": (engine fraction, reference fraction)} for cells chaotic in either)
    """
    cells = list(engine)
    robust = [c for c in cells if engine[c] in (0.0, 1.0) and reference[c] in (0.0, 1.0)]
    agree = [c for c in robust if engine[c] == reference[c]]
    chaotic = {
        f"{a} {f}": (engine[(a, f)], reference[(a, f)]) for a, f in cells if (a, f) not in robust
    }
    return dict(
        agree=len(agree),
        of=len(cells),
        differ=[c for c in robust if c not in agree],
        chaotic_engine_housner=chaotic,
    )
