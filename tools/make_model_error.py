"""The RBM against the exact block (`housner`) on the shipped monolithic rigid studies.

    python tools/make_model_error.py                 # docs/figures/rbm_vs_housner.png
    python tools/make_model_error.py --out /tmp/fig.png

Reads the stored domains of the STUDIES below (results/<study>/domain.csv and
results/<study>_housner/domain.csv, made by `rbm sweep configs/<study>.yaml -o results
--ensemble 16`), prints for each pair its ModelError (tools/model_error.py: the
fraction that differs, the cells by side, the boundary shifts) and the cells where the RBM
is unconservative, and draws one panel per study: the RBM's cells and boundary, the exact
block's boundary, the differing cells by side, and the two uplift levels. Runs nothing;
takes a few seconds.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from matplotlib.figure import Figure
from model_error import CONSERVATIVE, UNCONSERVATIVE, ModelError, model_error  # beside this

from rbm_cli.report.plot_domain import plot_domain
from rbm_cli.structures.block import block_geometry
from rbm_cli.structures.column import build_column
from rbm_cli.study.domain import domain_config, read_domain

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "results"
FIGURE = ROOT / "docs" / "figures" / "rbm_vs_housner.png"

#: The RBM studies compared, with the title of their panel.
STUDIES = {
    "spanos_koh_slender": "Spanos-Koh slender block, H/B = 4, e = 1",
    "spanos_koh_thick": "Spanos-Koh thick block, H/B = 2, e = 1",
    "spanos_koh_slender_housner_e": "slender block, H/B = 4, Housner's e = 0.91",
    "spanos_koh_thick_housner_e": "thick block, H/B = 2, Housner's e = 0.70",
    "housner_halfsine": "tapered column, half-sine pulse, e = 1",
}
#: Marks of the differing cells, by side.
SIDES = {
    UNCONSERVATIVE: dict(marker="s", color="black", label="RBM survives, exact block collapses"),
    CONSERVATIVE: dict(marker="D", color="tab:purple", label="RBM collapses, exact block survives"),
}


def pair(study: str, results: Path = RESULTS):
    """The RBM domain of a study, its exact-block domain and their ModelError."""
    rbm = read_domain(results / study / "domain.csv")
    exact = read_domain(results / f"{study}_housner" / "domain.csv")
    return rbm, exact, model_error(rbm, exact)


def uplift_levels(study: str, results: Path = RESULTS) -> tuple[float, float]:
    """The RBM's static multiplier theta_u and the exact block's tan(alpha) [g]."""
    rbm_cfg = domain_config(results / study / "domain.csv")
    exact_cfg = domain_config(results / f"{study}_housner" / "domain.csv")
    column = build_column(rbm_cfg.column, rbm_cfg.interface)
    return column.static_multiplier, math.tan(block_geometry(exact_cfg.column).slenderness)


def draw_panel(ax, study: str, title: str, results: Path = RESULTS) -> ModelError:
    """One study: the RBM's cells (member 0) and boundary, the exact block's boundary,
    the differing cells by side and both uplift levels. Returns the ModelError."""
    rbm, exact, err = pair(study, results)
    level_rbm, level_exact = uplift_levels(study, results)
    plain = rbm.drop(columns=["collapse_fraction"], errors="ignore")
    plot_domain(
        plain,
        ax=ax,
        compare=[exact],
        labels=["RBM boundary (small rotations)", "exact block boundary (housner)"],
        static_multiplier=level_rbm,
        static_label="RBM uplift",
    )
    ax.axhline(level_exact, color="tab:orange", linestyle=":", linewidth=1.2,
               label=f"exact block uplift {level_exact:.3g} g", gid="static-exact")  # fmt: skip
    for side, style in SIDES.items():
        cells = err.cells[err.cells["side"] == side]
        ax.plot(cells["frequency_hz"], cells["amplitude_g"], linestyle="none", markersize=8,
                markerfacecolor="none", markeredgewidth=1.6, gid=side,
                **{**style, "label": f"{style['label']} ({len(cells)})"})  # fmt: skip
    ax.set_title(f"{title}: {100 * err.fraction:.1f} % of cells differ", fontsize="medium")
    handles, texts = ax.get_legend_handles_labels()
    ax.legend(handles, texts, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
              fontsize="small")  # fmt: skip
    return err


def make_figure(results: Path = RESULTS) -> tuple[Figure, dict[str, ModelError]]:
    """One panel per study (3 x 2, the last one empty) and the ModelError of each study."""
    fig = Figure(figsize=(17, 14.5), layout="constrained")
    axes = fig.subplots(3, 2).ravel()
    errors = {}
    for ax, (study, title) in zip(axes, STUDIES.items(), strict=False):
        errors[study] = draw_panel(ax, study, title, results)
    axes[-1].set_axis_off()
    fig.suptitle("The RBM (small rotations) against the exact rocking block (housner), "
                 "same column, restitution and grid (cells: the RBM's)")  # fmt: skip
    return fig, errors


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=FIGURE, help="PNG to write")
    args = parser.parse_args(argv)
    fig, errors = make_figure()
    for study, err in errors.items():
        print(f"{study} vs {study}_housner: {err.summary()}")
        unsafe = err.cells[err.cells["side"] == UNCONSERVATIVE]
        for row in unsafe.itertuples():
            robust = "" if row.robust is True else " (sensitive)"
            print(
                f"    unconservative: {row.amplitude_g:.2f} g at {row.frequency_hz:.2f} Hz{robust}"
            )
        moved = err.shifts[err.shifts["shift_g"].abs() > 1e-9]
        for row in moved.itertuples():
            print(f"    boundary at {row.frequency_hz:5.2f} Hz: RBM {row.boundary_model_g:.2f} g,"
                  f" exact {row.boundary_reference_g:.2f} g ({row.shift_g:+.2f} g)")  # fmt: skip
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
