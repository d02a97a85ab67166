"""Plots of one run: displacement histories (paper fig. 4) and deformed shapes (fig. 3).

Pure functions: each takes ``ax=None`` (a new figure is made if omitted) and
returns the axes. Nothing here saves a file; :mod:`rbm_cli.report.run_folder` does.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from rbm_cli.models.result import History

#: Target of the shape exaggeration: largest drawn top displacement / height.
SHAPE_TARGET_RATIO = 0.25


def _new_axes(ax):
    if ax is not None:
        return ax
    from matplotlib.figure import Figure

    return Figure().subplots()


def _mark_collapse(ax, t_collapse: float | None) -> None:
    if t_collapse is None or not np.isfinite(t_collapse):
        return
    ax.axvline(
        t_collapse,
        color="tab:red",
        linestyle="--",
        linewidth=1.0,
        label=f"collapse, t = {t_collapse:.3g} s",
    )


def top_relative_displacement(history: History) -> np.ndarray:
    """Top displacement relative to the base, u_{n+1} - u_1 [m], per sample."""
    u = np.atleast_2d(np.asarray(history.node_displacements, dtype=float))
    return u[:, -1] - u[:, 0]


def plot_history(history: History, ax=None, t_collapse: float | None = None):
    """Base and top horizontal displacement against time (paper fig. 4).

    Parameters
    ----------
    history : History  Recorded run
    ax : matplotlib Axes, optional
    t_collapse : float, optional  Collapse time [s], drawn as a dashed line

    Notes
    -----
    Base = ground displacement u_g; top = u_g + (u_{n+1} - u_1), the absolute
    displacement of the top node. Harmonic runs use the steady ground motion
    u_g = -a_g / omega^2 (see :class:`rbm_cli.models.result.History`).
    """
    ax = _new_axes(ax)
    t = np.asarray(history.t, dtype=float)
    ug = np.asarray(history.ground_displacement, dtype=float)
    ax.plot(t, ug, color="0.4", linewidth=1.0, label="base (ground)")
    ax.plot(
        t, ug + top_relative_displacement(history), color="tab:blue", linewidth=1.2, label="top"
    )
    _mark_collapse(ax, t_collapse)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("displacement [m]")
    ax.set_title("Base and top horizontal displacement")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    return ax


def plot_top_relative(history: History, ax=None, t_collapse: float | None = None):
    """Top displacement relative to the base, u_{n+1} - u_1, against time.

    Parameters
    ----------
    history : History  Recorded run
    ax : matplotlib Axes, optional
    t_collapse : float, optional  Collapse time [s], drawn as a dashed line
    """
    ax = _new_axes(ax)
    t = np.asarray(history.t, dtype=float)
    ax.plot(
        t,
        top_relative_displacement(history),
        color="tab:orange",
        linewidth=1.2,
        label="top relative to base",
    )
    ax.axhline(0.0, color="0.6", linewidth=0.6)
    _mark_collapse(ax, t_collapse)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("top - base [m]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    return ax


def infer_elevations(history: History) -> np.ndarray:
    """Node elevations z_1..z_{n+1} [m] recovered from the history.

    Uses theta_i = (u_{i+1} - u_i) / h_i at the sample where |theta_i| is
    largest. Prefer passing the elevations from the column when known.

    Raises
    ------
    ValueError
        If a drum never rotates, so its height cannot be recovered.
    """
    u = np.atleast_2d(np.asarray(history.node_displacements, dtype=float))
    theta = np.atleast_2d(np.asarray(history.rotations, dtype=float))
    heights = []
    for i in range(theta.shape[1]):
        k = int(np.argmax(np.abs(theta[:, i])))
        if theta[k, i] == 0.0:
            raise ValueError(f"drum {i + 1} never rotates: pass elevations explicitly")
        heights.append((u[k, i + 1] - u[k, i]) / theta[k, i])
    return np.concatenate([[0.0], np.cumsum(heights)])


def exaggeration_factor(history: History, times_index: Sequence[int], height: float) -> float:
    """Displacement scale of a shapes plot.

    The largest top displacement (relative to the base) at the drawn instants
    becomes ~25% of the height, but the factor is never below 1.
    """
    top = np.abs(top_relative_displacement(history))
    idx = list(times_index)
    peak = float(np.max(top[idx])) if idx else 0.0
    if not np.isfinite(peak) or peak <= 0.0:
        return 1.0
    return max(1.0, SHAPE_TARGET_RATIO * height / peak)


def plot_shapes(
    history: History,
    widths: Sequence[float],
    times_index: Sequence[int],
    ax=None,
    *,
    elevations: Sequence[float] | None = None,
    scale: float | None = None,
    t_collapse: float | None = None,
):
    """Deformed column, to scale, at chosen instants side by side (paper fig. 3).

    Parameters
    ----------
    history : History  Recorded run
    widths : (n+1,) Column width at the nodes [m]
        (``build_column(...).widths``)
    times_index : sequence of int  Indices into ``history.t`` to draw
    ax : matplotlib Axes, optional
    elevations : (n+1,), optional  Node elevations z_i [m]; inferred from the
        history if omitted (see :func:`infer_elevations`)
    scale : float, optional  Displacement exaggeration; default from
        :func:`exaggeration_factor`
    t_collapse : float, optional  Collapse time [s]; the instant at or after
        it is labelled "collapse"

    Notes
    -----
    Drum i is drawn as the quadrilateral of its end widths whose axis goes from
    node i at (s u_i, z_i) to node i+1 at (s u_{i+1}, z_{i+1}), s the
    exaggeration and u relative to the ground; its faces stay horizontal, as
    in the small-displacement RBM.
    """
    from matplotlib.patches import Polygon

    ax = _new_axes(ax)
    widths = np.asarray(widths, dtype=float)
    z = infer_elevations(history) if elevations is None else np.asarray(elevations, float)
    if widths.shape != z.shape:
        raise ValueError(f"widths has {widths.size} entries, elevations {z.size}: need n+1 each")
    height = float(z[-1] - z[0])
    idx = [int(k) for k in times_index]
    s = exaggeration_factor(history, idx, height) if scale is None else float(scale)
    u = np.atleast_2d(np.asarray(history.node_displacements, dtype=float))
    t = np.asarray(history.t, dtype=float)

    drawn = s * u[idx] if idx else np.zeros((0, z.size))
    reach = float(np.max(np.abs(drawn))) if drawn.size else 0.0
    pitch = 1.4 * float(np.max(widths)) + 2.0 * reach + 0.1 * height
    n = z.size - 1
    colors = ("#c9b79c", "#b39d7d")
    for j, k in enumerate(idx):
        x0 = j * pitch
        for i in range(n):
            xb, xt = x0 + s * u[k, i], x0 + s * u[k, i + 1]
            corners = [
                (xb - widths[i] / 2, z[i]),
                (xb + widths[i] / 2, z[i]),
                (xt + widths[i + 1] / 2, z[i + 1]),
                (xt - widths[i + 1] / 2, z[i + 1]),
            ]
            ax.add_patch(
                Polygon(
                    corners, closed=True, facecolor=colors[i % 2], edgecolor="0.2", linewidth=0.8
                )
            )
        ax.plot([x0 - pitch / 2.2, x0 + pitch / 2.2], [z[0], z[0]], color="0.3", linewidth=1.2)
        label = f"t = {t[k]:.3g} s"
        if t_collapse is not None and np.isfinite(t_collapse) and t[k] >= t_collapse - 1e-12:
            label += "\n(collapse)"
        ax.text(x0, z[0] - 0.04 * height, label, ha="center", va="top", fontsize="small")

    ax.set_xlim(-pitch / 2, (max(len(idx), 1) - 0.5) * pitch)
    ax.set_ylim(z[0] - 0.2 * height, z[-1] + 0.05 * height)
    ax.set_aspect("equal")
    ax.set_xlabel("horizontal position [m] (columns side by side)")
    ax.set_ylabel("height [m]")
    ax.set_title(f"Deformed shapes, displacements exaggerated x{s:.3g}")
    return ax
