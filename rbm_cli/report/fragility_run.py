"""A record-suite domain to its fragility files and figures, in one step (`rbm fragility`).

:func:`run_fragility` reads the ``domain.csv`` of a sweep over records x intensities,
fits the lognormal fragility (:func:`rbm_cli.study.fragility.fragility`), draws the
fragility and IDA figures (:mod:`rbm_cli.report.fragility_report`) and publishes

    fragility.png, ida.png, fragility.csv, fragility_curve.csv, fragility.json

(with ``damage_states`` also fragility_states.csv and fragility_states.png, the thresholds
marked in ida.png: :mod:`rbm_cli.study.fragility_states`; with ``residual_states`` also
fragility_residual.csv and fragility_residual.png; with ``compare_intensities``
also fragility_intensities.csv: :mod:`rbm_cli.study.intensity_choice`; these before the
five) into the output folder (default: the domain's folder) as one step: the options and the
domains are checked first (a refusal writes nothing); then, with the folder locked against
another fragility run, everything is computed and rendered in memory, staged whole in a
hidden folder and moved onto their names together, fragility.json last
(:class:`rbm_cli.report.fragility_store.FragilityFolder`: a Ctrl-C or a kill leaves the
old set or the new one, never a mix; what a killed run leaves is removed by the next).
The optional files of the set being replaced (its fragility.json names them: damage
states, residual states, intensities compared) that the new set does not have are removed
with it, so the folder never holds one run's states beside another run's fit. No other
file is touched, none deleted. fragility.json names the domain and the SHA-256
of the bytes fitted, so files left beside a domain swept again show whose they are. The
CLI calls this; the API can call the same.
"""

from __future__ import annotations

import io
import json
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from rbm_cli.base.files import check_writable_dir
from rbm_cli.report.fragility_by import tercile_figure
from rbm_cli.report.fragility_report import fragility_texts, plot_fragility, plot_ida
from rbm_cli.report.fragility_states import (
    intensities_csv,
    mark_thresholds,
    states_csv,
    states_figure,
)
from rbm_cli.report.fragility_store import FILES, FragilityFolder
from rbm_cli.study.fragility import FragilityResult, check_options, fragility
from rbm_cli.study.fragility_samples import by_tercile
from rbm_cli.study.fragility_states import (
    RESIDUAL,
    DamageStates,
    check_damage_states,
    state_domain,
)
from rbm_cli.study.fragility_states import damage_states as fit_every_state
from rbm_cli.study.intensities import label as measure_label
from rbm_cli.study.intensity_choice import IntensityComparison, check_carries_measures
from rbm_cli.study.intensity_choice import compare_intensities as fit_every_measure
from rbm_cli.study.outcomes import (
    ENSEMBLE_OUTCOMES,
    is_ensemble,
    prepare_outcomes,
    read_suite_domain_hashed,
)
from rbm_cli.study.schema import C

#: Bootstrap resamples of the records by default.
DEFAULT_RESAMPLES = 500


@dataclass(frozen=True)
class FragilityRun:
    """What :func:`run_fragility` made.

    result : FragilityResult  Counts, fit and band
    domain : pathlib.Path  The domain CSV read
    paths : list of pathlib.Path  The files written (:data:`FILES`, in the output folder)
    intensity_label : str  Axis label of the intensity (its quantity and unit)
    states : DamageStates or None  The damage states' fits (``damage_states`` given)
    intensities : IntensityComparison or None  The fits on every intensity measure
        (``compare_intensities``)
    residual : DamageStates or None  The residual states' fits (``residual_states`` given)
    """

    result: FragilityResult
    domain: Path
    paths: list[Path]
    intensity_label: str
    states: DamageStates | None = None
    intensities: IntensityComparison | None = None
    residual: DamageStates | None = None


def run_fragility(
    domain_csv: str | os.PathLike,
    output: str | os.PathLike | None = None,
    *,
    n_resamples: int = DEFAULT_RESAMPLES,
    seed: int = 0,
    intensity_column: str | None = None,
    ci_percentiles: tuple[float, float] = (5.0, 95.0),
    compare: tuple[str | os.PathLike, ...] = (),
    progress: Callable[[int, int], None] | None = None,
    ensemble_outcome: str = ENSEMBLE_OUTCOMES[0],
    damage_states: tuple[float, ...] | None = None,
    compare_intensities: bool = False,
    by: str | None = None,
    residual_states: tuple[float, ...] | None = None,
) -> FragilityRun:
    """Fragility of a record-suite domain: fit, files and figures.

    Parameters
    ----------
    domain_csv : str or os.PathLike
        ``domain.csv`` of a sweep over records x intensities (columns ``record``, an
        intensity [g] such as ``amplitude_g``, ``status``, ``collapsed``,
        ``max_rotation_ratio``; others are ignored)
    output : str or os.PathLike, optional
        Folder of the files (created if missing); default the domain's folder
    n_resamples : int
        Bootstrap resamples of the records (0: no band, no intervals), at most
        :data:`rbm_cli.study.fragility.MAX_RESAMPLES` (100,000: a few minutes)
    seed : int
        Seed of the bootstrap (numpy PCG64), 0 to 2**64 - 1
    intensity_column : str, optional
        Column of the intensity (default: the first of intensity_g, amplitude_g,
        intensity): the amplitude, or a record's intensity measure (pgv_m_s, sa_t1_g, ...:
        rbm_cli.study.intensities), labelled with its unit in the figures
    ci_percentiles : (float, float)
        Percentiles of the bootstrap that bound the intervals and the band [%]
    compare : sequence of paths
        Other record-suite domains (e.g. another column under the same suite), fitted with
        the same options and drawn in fragility.png beside this one, each labelled by its
        folder's name; their own files are not written
    progress : callable, optional
        ``progress(done, total)`` after each bootstrap resample, of this domain and of the
        compared ones together
    ensemble_outcome : str
        How an ensemble domain's cells count: ``members`` (every member a trial; their
        number per cell from meta.json beside the domain), ``majority`` or ``member0``
        (rbm_cli.study.outcomes)
    damage_states : sequence of float, optional
        Thresholds of ``max_rotation_ratio`` (0 < t <= 1, strictly increasing; 1 is
        collapse): a fragility curve per state (rbm_cli.study.fragility_states), written
        to fragility_states.csv and fragility_states.png, and marked in ida.png
    residual_states : sequence of float, optional
        Thresholds of ``residual_slip_m`` [m] (t > 0, strictly increasing), a domain of the
        contact engine's: a fragility curve per residual state (a run exceeds it when its
        residual slip reaches t or it collapsed), written to fragility_residual.csv and
        fragility_residual.png
    compare_intensities : bool
        Also fit the suite on every intensity measure the domain carries and rank them by
        beta (rbm_cli.study.intensity_choice), written to fragility_intensities.csv
    by : str, optional
        An uncertain key of a domain over samples (its dotted path): a fit per tercile of
        its sampled values, written as fragility_by.csv and fragility_by.png with the set
        (rbm_cli.study.fragility_samples.by_tercile)

    Returns
    -------
    FragilityRun

    Raises
    ------
    RbmError
        One line: a missing or unreadable file, not a domain, a domain without records
        (an amplitude x frequency sweep), bad rows (:func:`rbm_cli.study.outcomes.
        prepare_outcomes`), bad options (:func:`rbm_cli.study.fragility.check_options`),
        an output folder that cannot be written, or that another fragility run is
        writing. The folder's fragility files are as they were then.
    """
    check_options(n_resamples, seed, ci_percentiles)
    thresholds = None if damage_states is None else check_damage_states(damage_states)
    slips = None
    if residual_states is not None:
        slips = check_damage_states(residual_states, "fragility: residual_states", RESIDUAL)
    domain = Path(domain_csv)
    df, digest = read_suite_domain_hashed(domain)
    members = n_members(domain, df)
    # its rows, checked before anything is made
    prepare_outcomes(df, intensity_column, ensemble_outcome, members)
    if thresholds:
        prepare_outcomes(state_domain(df, thresholds[0]), intensity_column, "member0")
    if slips:
        prepare_outcomes(state_domain(df, slips[0], RESIDUAL), intensity_column, "member0")
    if compare_intensities:
        check_carries_measures(df)
    if isinstance(compare, str | os.PathLike):
        compare = (compare,)
    frames = [(Path(p), read_suite_domain_hashed(Path(p))[0]) for p in compare]
    frames = [(p, frame, n_members(p, frame)) for p, frame in frames]
    for _, frame, m in frames:
        prepare_outcomes(frame, intensity_column, ensemble_outcome, m)
    terciles = None if by is None else by_tercile(df, by, intensity_column, ensemble_outcome,
                                                  members)  # fmt: skip
    folder = Path(output) if output is not None else domain.parent
    check_writable_dir(folder)
    options = dict(n_resamples=n_resamples, seed=seed, ci_percentiles=ci_percentiles,
                   intensity_column=intensity_column,
                   ensemble_outcome=ensemble_outcome)  # fmt: skip
    parts = len(frames) + 1 + bool(thresholds) + bool(slips) + bool(compare_intensities)
    states = comparison = residual = None
    with FragilityFolder(folder) as store:
        result = fragility(df, **options, n_members=members, progress=_part(progress, 0, parts))
        others = []
        for k, (path, frame, m) in enumerate(frames, start=1):
            fit = fragility(frame, **options, n_members=m, progress=_part(progress, k, parts))
            others.append((path, _name(path), fit))
        part = len(frames) + 1
        if thresholds:
            states = fit_every_state(df, thresholds, n_resamples=n_resamples, seed=seed,
                                     ci_percentiles=ci_percentiles,
                                     intensity_column=intensity_column,
                                     progress=_part(progress, part, parts))  # fmt: skip
            part += 1
        if slips:
            residual = fit_every_state(df, slips, n_resamples=n_resamples, seed=seed,
                                       ci_percentiles=ci_percentiles,
                                       intensity_column=intensity_column,
                                       progress=_part(progress, part, parts),
                                       measure=RESIDUAL)  # fmt: skip
            part += 1
        if compare_intensities:
            comparison = fit_every_measure(df, **_without(options, "intensity_column"),
                                           n_members=members,
                                           progress=_part(progress, part, parts))  # fmt: skip
        source = {
            "domain": os.path.relpath(domain.resolve(), folder.resolve()),
            "domain_sha256": digest,  # of the bytes fitted: which domain.csv these are of
        }
        source |= extra_summary(states, comparison, residual)
        if terciles is not None:
            source["by"] = by
        label, contents = _contents(domain, df, result, others, source, thresholds or ())
        contents |= extra_contents(states, comparison, label, residual)
        if terciles is not None:
            contents |= _by_contents(terciles, by, label, result)
        paths = store.publish({name: contents[name] for name in extra_files(contents) + FILES},
                              retire=superseded(folder, contents))  # fmt: skip
    return FragilityRun(result=result, domain=domain, paths=paths, intensity_label=label,
                        states=states, intensities=comparison,
                        residual=residual)  # fmt: skip


def _without(options: dict, key: str) -> dict:
    return {k: v for k, v in options.items() if k != key}


def extra_files(contents: dict) -> tuple[str, ...]:
    """The names of ``contents`` beyond the fragility set's :data:`FILES` (the damage and
    residual states', the intensities' and the terciles' files), published before them."""
    return tuple(name for name in contents if name not in FILES)


#: The optional files of a fragility set and the fragility.json entry that claims them.
OPTIONAL_FILES = {"fragility_states.png": "damage_states", "fragility_states.csv": "damage_states",
                  "fragility_residual.png": "residual_states",
                  "fragility_residual.csv": "residual_states",
                  "fragility_intensities.csv": "intensity_statement",
                  "fragility_by.csv": "by", "fragility_by.png": "by"}  # fmt: skip


def superseded(folder: Path, contents: dict) -> tuple[str, ...]:
    """The optional files in ``folder`` that the fragility set there (its fragility.json)
    wrote and the new set (``contents``) does not: they go with the old set. A file of such
    a name that no fragility.json claims is not the set's, and stays."""
    try:
        old = json.loads((folder / "fragility.json").read_text())
    except (OSError, ValueError):
        return ()
    if not isinstance(old, dict):
        return ()
    return tuple(name for name, key in OPTIONAL_FILES.items()
                 if key in old and name not in contents and (folder / name).is_file())  # fmt: skip


def extra_summary(
    states: DamageStates | None,
    comparison: IntensityComparison | None,
    residual: DamageStates | None = None,
) -> dict:
    """fragility.json's entries on the damage states, the residual states and the
    intensities compared (which files of the folder belong to this set)."""
    out: dict = {}
    for key, fits in (("damage_states", states), ("residual_states", residual)):
        if fits is not None:
            out[key] = list(fits.thresholds)
            out[f"{key}_crossings"] = list(fits.crossings)
            out[f"{key}_note"] = fits.note
    if comparison is not None:
        out["intensity_best"] = comparison.best or None
        out["intensity_statement"] = comparison.statement
    return out


def extra_contents(states, comparison, label: str, residual=None) -> dict:
    """The damage states', the residual states' and the intensities' files, by name
    (``label``: the intensity's axis label)."""
    out: dict = {}
    for stem, fits in (("fragility_states", states), ("fragility_residual", residual)):
        if fits is not None:
            out[f"{stem}.png"] = _png(states_figure(fits, label))
            out[f"{stem}.csv"] = states_csv(fits)
    if comparison is not None:
        out["fragility_intensities.csv"] = intensities_csv(comparison)
    return out


def n_members(domain: Path, df: pd.DataFrame) -> int | None:
    """The ensemble's members per cell of an ensemble domain (meta.json beside it says),
    None for a plain domain or when meta.json does not say."""
    if not is_ensemble(df):
        return None
    members = _meta(domain).get("ensemble", {})
    members = members.get("members") if isinstance(members, dict) else None
    return members if isinstance(members, int) and not isinstance(members, bool) else None


def _part(progress, k: int, parts: int):
    """progress(done, total) of the k-th of ``parts`` bootstraps of equal length, as one."""
    if progress is None:
        return None
    return lambda done, total: progress(k * total + done, parts * total)


def _contents(domain: Path, df, result, others, source: dict,
              thresholds=()) -> tuple[str, dict]:  # fmt: skip
    """The intensity's label and the set's files, by name (figures rendered to PNG bytes;
    ``source``: fragility.json's entries naming the domain)."""
    meta = _meta(domain)
    label = intensity_label(result.intensity_column, meta)
    suite = suite_name(meta)
    title = f"{meta.get('name') or domain.parent.name or domain.stem}: " \
        f"{result.n_records} records{f' ({suite})' if suite else ''}, " \
        f"{len(result.table)} intensities" \
        + (f"\n{result.outcome}" if result.ensemble_outcome else "")  # fmt: skip
    frag_title = compare_title([(_name(domain), suite_name(meta))]
                               + [(n, suite_name(_meta(p))) for p, n, _ in others]) \
        if others else title  # fmt: skip
    contents = {
        "fragility.png": _png(
            fragility_figure(
                result, label, frag_title, _name(domain), [(n, r) for _, n, r in others]
            )
        ),
        "ida.png": _png(ida_figure(df, result.intensity_column, label, title, thresholds)),
    }
    contents.update(fragility_texts(result, extra=source))
    return label, contents


def _by_contents(terciles: pd.DataFrame, key: str, label: str, result) -> dict:
    """fragility_by.csv and fragility_by.png of the fits per tercile of ``key``."""
    top = 1.1 * float(result.table["intensity_g"].max())
    return {
        "fragility_by.csv": terciles.to_csv(index=False, float_format="%.12g"),
        "fragility_by.png": _png(tercile_figure(terciles, key, label, top)),
    }


def intensity_label(column: str, meta: dict | None = None) -> str:
    """Axis label of the intensity column: PGA [g], or the records' scale factor [-] when
    the sweep's config says ``excitation.scale: factor``, a record's intensity measure
    with its unit (rbm_cli.study.intensities), or the column's name."""
    written = (meta or {}).get("config_written")
    excitation = written.get("excitation") if isinstance(written, dict) else None
    if column in (C.amplitude_g, "intensity_g"):
        if isinstance(excitation, dict) and excitation.get("scale") == "factor":
            return "intensity: scale factor of the records [-]"
        return "intensity: peak ground acceleration [g]"
    measure = measure_label(column)
    return f"intensity: {measure}" if measure else f"intensity: {column}"


def compare_title(suites: list[tuple[str, str]]) -> str:
    """Title of a fragility.png that compares domains: their names, and the suite of
    records they ran (one line when they share it, else each domain's own)."""
    names = ", ".join(name for name, _ in suites)
    kinds = {suite for _, suite in suites}
    if len(kinds) == 1:
        (suite,) = kinds
        return f"fragility of {names}\nunder the suite {suite or '(not named in meta.json)'}"
    each = "; ".join(f"{name}: {suite or '(not named)'}" for name, suite in suites)
    return f"fragility of {names}\nunder different suites: {each}"


def suite_name(meta: dict) -> str:
    """The suite of records a sweep ran, as its config writes it (excitation.file: a
    pattern such as records/rdk_*.AT2, or a list of files), from its meta.json; "" when
    the meta.json does not say."""
    written = meta.get("config_written")
    excitation = written.get("excitation") if isinstance(written, dict) else None
    files = excitation.get("file") if isinstance(excitation, dict) else None
    if isinstance(files, str):
        return files
    if isinstance(files, list) and files and all(isinstance(f, str) for f in files):
        return files[0] if len(files) == 1 else f"{files[0]} ... ({len(files)} files)"
    return ""


def _name(domain: Path) -> str:
    """A domain's label: its sweep's name (meta.json), else its folder's name."""
    return str(_meta(domain).get("name") or domain.parent.name or domain.stem)


#: Colours of the fitted domains in one figure, the main one first.
COLOURS = ("tab:blue", "tab:red", "tab:green", "tab:purple", "tab:orange", "tab:brown")


def fragility_figure(
    result: FragilityResult, label: str, title: str = "", name: str = "", others=()
):
    """A new figure (no pyplot) with :func:`plot_fragility` of ``result`` and, labelled by
    name, of each (name, result) of ``others`` (no counts then: they would overlap)."""
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.figure import Figure

    ax = Figure(figsize=(7, 5)).subplots()
    if not others:
        plot_fragility(result, ax, xlabel=label)
    else:
        for k, (who, res) in enumerate([(name, result), *others]):
            plot_fragility(res, ax, xlabel=label, label=f"{who} ({res.n_records} records)",
                           color=COLOURS[k % len(COLOURS)],
                           counts=False)  # fmt: skip
    ax.set_title(title, fontsize=9)
    return ax.figure


def ida_figure(df: pd.DataFrame, column: str, label: str, title: str = "", thresholds=()):
    """A new figure (no pyplot) with :func:`plot_ida` of the domain's rows (and the
    damage states' ``thresholds`` marked)."""
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.figure import Figure

    ax = Figure(figsize=(7, 5)).subplots()
    plot_ida(df, ax, intensity_column=column)
    mark_thresholds(ax, thresholds)
    ax.set_ylabel(label)
    ax.set_title(f"IDA, {title}" if title else "IDA", fontsize=9)
    return ax.figure


def _png(fig, dpi: int = 150) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi, bbox_inches="tight")
    return buffer.getvalue()


def _meta(domain: Path) -> dict:
    """The meta.json beside the domain, or {} when there is none or it is not JSON."""
    try:
        meta = json.loads(domain.with_name("meta.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return meta if isinstance(meta, dict) else {}
