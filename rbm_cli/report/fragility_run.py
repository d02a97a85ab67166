"""A record-suite domain to its fragility files and figures, in one step (`rbm fragility`).

:func:`run_fragility` reads the ``domain.csv`` of a sweep over records x intensities,
fits the lognormal fragility (:func:`rbm_cli.study.fragility.fragility`), draws the
fragility and IDA figures (:mod:`rbm_cli.report.fragility_report`) and publishes

    fragility.png, ida.png, fragility.csv, fragility_curve.csv, fragility.json

into the output folder (default: the domain's folder) as one step: everything is computed
and rendered in memory, staged in full under temporary names, then moved onto the five
names (:func:`rbm_cli.base.files.publish_files_atomic`). A failure before that leaves the
folder as it was; no other file is touched, none deleted. fragility.json names the domain
and its SHA-256, so files left beside a domain swept again show whose they are. The CLI
calls this; the API can call the same.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from rbm_cli.base.errors import RbmError
from rbm_cli.base.files import check_writable_dir, make_dirs, publish_files_atomic
from rbm_cli.report.fragility_report import fragility_texts, plot_fragility, plot_ida
from rbm_cli.study.fragility import FragilityResult, fragility
from rbm_cli.study.outcomes import read_suite_domain

#: The files :func:`run_fragility` writes, in the order they are moved into place.
FILES = ("fragility.png", "ida.png", "fragility.csv", "fragility_curve.csv", "fragility.json")

#: Bootstrap resamples of the records by default.
DEFAULT_RESAMPLES = 500


@dataclass(frozen=True)
class FragilityRun:
    """What :func:`run_fragility` made.

    result : FragilityResult  Counts, fit and band
    domain : pathlib.Path  The domain CSV read
    paths : list of pathlib.Path  The files written (:data:`FILES`, in the output folder)
    intensity_label : str  Axis label of the intensity (its quantity and unit)
    """

    result: FragilityResult
    domain: Path
    paths: list[Path]
    intensity_label: str


def run_fragility(
    domain_csv: str | os.PathLike,
    output: str | os.PathLike | None = None,
    *,
    n_resamples: int = DEFAULT_RESAMPLES,
    seed: int = 0,
    intensity_column: str | None = None,
    ci_percentiles: tuple[float, float] = (5.0, 95.0),
    compare: tuple[str | os.PathLike, ...] = (),
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
        Bootstrap resamples of the records (0: no band, no intervals)
    seed : int
        Seed of the bootstrap (numpy PCG64), >= 0
    intensity_column : str, optional
        Column of the intensity (default: the first of intensity_g, amplitude_g, intensity)
    ci_percentiles : (float, float)
        Percentiles of the bootstrap that bound the intervals and the band
    compare : sequence of paths
        Other record-suite domains (e.g. another column under the same suite), fitted with
        the same options and drawn in fragility.png beside this one, each labelled by its
        folder's name; their own files are not written

    Returns
    -------
    FragilityRun

    Raises
    ------
    RbmError
        One line: a missing or unreadable file, not a domain, a domain without records
        (an amplitude x frequency sweep), bad rows (:func:`rbm_cli.study.outcomes.
        prepare_outcomes`), bad options, an output folder that cannot be written.
        Nothing is written then.
    """
    domain = Path(domain_csv)
    df = read_suite_domain(domain)
    result = fragility(
        df,
        n_resamples=n_resamples,
        seed=seed,
        ci_percentiles=ci_percentiles,
        intensity_column=intensity_column,
    )
    folder = Path(output) if output is not None else domain.parent
    check_writable_dir(folder)
    meta = _meta(domain)
    label = intensity_label(result.intensity_column, meta)
    title = f"{meta.get('name') or domain.parent.name or domain.stem}: " \
        f"{result.n_records} records, {len(result.table)} intensities"  # fmt: skip
    others = [(_name(Path(p)), _fit_other(p, n_resamples, seed, intensity_column,
                                          ci_percentiles)) for p in compare]  # fmt: skip
    names = ", ".join([_name(domain)] + [n for n, _ in others])
    frag_title = f"fragility under one suite: {names}" if others else title
    contents = {
        "fragility.png": _png(fragility_figure(result, label, frag_title, _name(domain), others)),
        "ida.png": _png(ida_figure(df, result.intensity_column, label, title)),
    }
    source = {
        "domain": os.path.relpath(domain.resolve(), folder.resolve()),
        "domain_sha256": _sha256(domain),  # which domain.csv these files are of
    }
    contents.update(fragility_texts(result, extra=source))
    make_dirs(folder)
    try:
        paths = publish_files_atomic(folder, {name: contents[name] for name in FILES})
    except OSError as exc:
        raise RbmError(f"{folder}: cannot write the fragility files ({exc.strerror})") from None
    return FragilityRun(result=result, domain=domain, paths=paths, intensity_label=label)


def intensity_label(column: str, meta: dict | None = None) -> str:
    """Axis label of the intensity column: PGA [g], or the records' scale factor [-] when
    the sweep's config says ``excitation.scale: factor``, or the column's name."""
    written = (meta or {}).get("config_written")
    excitation = written.get("excitation") if isinstance(written, dict) else None
    if column in ("amplitude_g", "intensity_g"):
        if isinstance(excitation, dict) and excitation.get("scale") == "factor":
            return "intensity: scale factor of the records [-]"
        return "intensity: peak ground acceleration [g]"
    return f"intensity: {column}"


def _name(domain: Path) -> str:
    """A domain's label: its sweep's name (meta.json), else its folder's name."""
    return str(_meta(domain).get("name") or domain.parent.name or domain.stem)


def _fit_other(path, n_resamples, seed, intensity_column, ci) -> FragilityResult:
    """The fit of a compared domain (same options as the main one)."""
    return fragility(read_suite_domain(Path(path)), n_resamples=n_resamples, seed=seed,
                     ci_percentiles=ci, intensity_column=intensity_column)  # fmt: skip


#: Colours of the fitted domains in one figure, the main one first.
COLOURS = ("tab:blue", "tab:red", "tab:green", "tab:purple", "tab:orange", "tab:brown")


def fragility_figure(
    result: FragilityResult, label: str, title: str = "", name: str = "", others=()
):
    """A new figure (no pyplot) with :func:`plot_fragility` of ``result`` and, labelled by
    name, of each (name, result) of ``others`` (no counts then: they would overlap)."""
    from matplotlib.figure import Figure

    ax = Figure(figsize=(7, 5)).subplots()
    if not others:
        plot_fragility(result, ax, xlabel=label)
    else:
        for k, (who, res) in enumerate([(name, result), *others]):
            plot_fragility(res, ax, xlabel=label, label=who, color=COLOURS[k % len(COLOURS)],
                           counts=False)  # fmt: skip
    ax.set_title(title, fontsize=9)
    return ax.figure


def ida_figure(df: pd.DataFrame, column: str, label: str, title: str = ""):
    """A new figure (no pyplot) with :func:`plot_ida` of the domain's rows."""
    from matplotlib.figure import Figure

    ax = Figure(figsize=(7, 5)).subplots()
    plot_ida(df, ax, intensity_column=column)
    ax.set_xlabel(label)
    ax.set_title(f"IDA, {title}" if title else "IDA", fontsize=9)
    return ax.figure


def _png(fig, dpi: int = 150) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi, bbox_inches="tight")
    return buffer.getvalue()


def _sha256(path: Path) -> str:
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError as exc:
        raise RbmError(f"cannot read {path}: {exc.strerror or exc}") from None


def _meta(domain: Path) -> dict:
    """The meta.json beside the domain, or {} when there is none or it is not JSON."""
    try:
        meta = json.loads(domain.with_name("meta.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return meta if isinstance(meta, dict) else {}
