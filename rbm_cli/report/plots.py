"""Plots of one run: displacement histories (paper fig. 4) and deformed shapes (fig. 3).

Pure functions: each takes ``ax=None`` (a new figure is made if omitted) and
returns the axes. Nothing here saves a file; :mod:`rbm_cli.report.run_folder` does.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from rbm_cli.models.history import History
from rbm_cli.report.exaggeration import round_factor
from rbm_cli.structures.outline import base_slip, drum_outlines

#: Target of the shape exaggeration: largest drawn top displacement / height.
SHAPE_TARGET_RATIO = 0.25
#: Largest drawn drum rotation s |theta_i| the exaggeration allows [rad].
SHAPE_MAX_ANGLE = 0.35


def _new_axes(ax):
    if ax is not None:
        return ax
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
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


def _plot_top_in_plan(ax, history: History, colour: str, what: str) -> None:
    """A model in three dimensions: the top's displacement in plan (History.top_plan),
    its resultant (gid 'top') and both components (gids 'top-x', 'top-y')."""
    t = np.asarray(history.t, dtype=float)
    xy = np.asarray(history.top_plan, dtype=float)
    ax.plot(t, np.hypot(xy[:, 0], xy[:, 1]), color=colour, linewidth=1.2,
            label=f"{what}: resultant", gid="top")  # fmt: skip
    ax.plot(t, xy[:, 0], color=colour, linewidth=0.7, linestyle="--", alpha=0.8,
            label=f"{what}: x", gid="top-x")  # fmt: skip
    ax.plot(t, xy[:, 1], color=colour, linewidth=0.7, linestyle=":", alpha=0.8,
            label=f"{what}: y", gid="top-y")  # fmt: skip


#: The ground's displacement is said to drift (and plot_history draws the column relative
#: to it by default) when its range over the run is more than this many times the range of
#: the top's displacement relative to the base: drawn together on one scale, the column's
#: motion would be a flat line (a record that is not baseline-corrected can drift metres
#: while a column rocks by centimetres).
DRIFT_RATIO = 20.0


def ground_drifts(history: History) -> bool:
    """Whether the ground's displacement dwarfs the column's motion relative to it (its
    range more than DRIFT_RATIO times the top's relative displacement's range)."""
    ug = np.asarray(history.ground_displacement, dtype=float)
    rel = top_relative_displacement(history)
    if ug.size == 0 or not (np.all(np.isfinite(ug)) and np.all(np.isfinite(rel))):
        return False
    ground = float(np.ptp(ug))
    return ground > 0.0 and ground > DRIFT_RATIO * float(np.ptp(rel))


def plot_history(
    history: History, ax=None, t_collapse: float | None = None, relative: bool | None = None
):
    """Base and top horizontal displacement against time (paper fig. 4).

    Parameters
    ----------
    history : History  Recorded run
    ax : matplotlib Axes, optional
    t_collapse : float, optional  Collapse time [s], drawn as a dashed line
    relative : bool or None  True: the top drawn relative to the ground (the base at 0),
        and the ground's displacement on a second axis on the right, with its own scale;
        False: both absolute, on one scale; None (default): relative when the ground
        drifts (:func:`ground_drifts`), else absolute. A model in three dimensions (the
        history has ``top_plan``) is drawn relative: its top moves in plan

    Notes
    -----
    Base = ground displacement u_g; top = u_g + (u_{n+1} - u_1), the absolute
    displacement of the top node. Harmonic runs use the steady ground motion
    u_g = -a_g / omega^2; pulses and records the ground's displacement integrated from
    rest (a record's after its processing, excitation.processing) (see
    :class:`rbm_cli.models.history.History`). A model in three dimensions draws its top's
    displacement in plan from where it stood (``top_plan``): the resultant and its x and y
    components, the ground's (the motion's own, the first record's for a pair) on the right.
    """
    ax = _new_axes(ax)
    t = np.asarray(history.t, dtype=float)
    ug = np.asarray(history.ground_displacement, dtype=float)
    plan = history.top_plan is not None
    if relative is None or plan:
        relative = plan or ground_drifts(history)
    if relative:
        ax.axhline(0.0, color="0.4", linewidth=1.0, label="base (ground)")
        if plan:
            _plot_top_in_plan(ax, history, "tab:blue", "top in plan")
        else:
            ax.plot(t, top_relative_displacement(history), color="tab:blue", linewidth=1.2,
                    label="top, relative to the ground")  # fmt: skip
        right = ax.twinx()
        right.plot(t, ug, color="0.55", linewidth=0.9, linestyle="--", gid="ground",
                   label="ground (right axis)")  # fmt: skip
        right.set_ylabel("ground displacement [m]", color="0.4")
        # the ground's line in the left axis's legend
        ax.plot([], [], color="0.55", linewidth=0.9, linestyle="--", label="ground (right axis)")
        ax.set_ylabel("top - ground [m]")
        what = "Top in plan (resultant, x, y)" if plan else "Top relative to the ground"
        ax.set_title(f"{what}; the ground, which moves {np.ptp(ug):.3g} m, on the right")
    else:
        ax.plot(t, ug, color="0.4", linewidth=1.0, label="base (ground)")
        ax.plot(t, ug + top_relative_displacement(history), color="tab:blue", linewidth=1.2,
                label="top")  # fmt: skip
        ax.set_ylabel("displacement [m]")
        ax.set_title("Base and top horizontal displacement")
    _mark_collapse(ax, t_collapse)
    ax.set_xlabel("time [s]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    return ax


def plot_top_relative(history: History, ax=None, t_collapse: float | None = None):
    """Top displacement relative to the base, u_{n+1} - u_1, against time; for a model in
    three dimensions the top's displacement in plan from where it stood: its resultant
    (gid 'top') and its x and y components (gids 'top-x', 'top-y').

    Parameters
    ----------
    history : History  Recorded run
    ax : matplotlib Axes, optional
    t_collapse : float, optional  Collapse time [s], drawn as a dashed line
    """
    ax = _new_axes(ax)
    t = np.asarray(history.t, dtype=float)
    if history.top_plan is not None:
        _plot_top_in_plan(ax, history, "tab:orange", "top in plan")
    else:
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
    """Displacement scale of a shapes plot: a round number (1, 2, 5, 10, 20, 50, ...).

    The largest round factor s (never below 1) that keeps, at the drawn
    instants, the largest node displacement relative to the ground (the base's
    slip included, if the history has one) within SHAPE_TARGET_RATIO of the
    height and every drawn drum rotation s |theta_i| within SHAPE_MAX_ANGLE (a
    drum drawn on its side would mislead).
    """
    u = np.abs(np.atleast_2d(np.asarray(history.node_displacements, dtype=float)))
    top = np.max(u, axis=1)
    theta = np.abs(np.atleast_2d(np.asarray(history.rotations, dtype=float)))
    idx = list(times_index)
    peak = float(np.max(top[idx])) if idx else 0.0
    angle = float(np.max(theta[idx])) if idx else 0.0
    if not np.isfinite(peak) or peak <= 0.0:
        return 1.0
    target = SHAPE_TARGET_RATIO * height / peak
    if np.isfinite(angle) and angle > 0.0:
        target = min(target, SHAPE_MAX_ANGLE / angle)
    return round_factor(target)


def _shape_label(t: float, t_collapse: float | None, slip: float) -> str:
    label = f"t = {t:.3g} s"
    if slip != 0.0:
        label += f"\nslip {1e3 * slip:+.3g} mm"
    if t_collapse is not None and np.isfinite(t_collapse) and t >= t_collapse - 1e-12:
        label += "\n(collapse)"
    return label


def _draw_instant(ax, outlines, x0: float, z0: float, pitch: float, height: float, label,
                  frame=None):  # fmt: skip
    """One instant of plot_shapes: its drums (a frame's columns side by side, its beam on
    their tops), the ground with a tick at the rest position, and the label under it."""
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib.patches import Polygon

    colors = ("#c9b79c", "#b39d7d")
    columns, spacing, beam = (1, 0.0, 0.0) if frame is None else frame
    first = x0 - (columns - 1) * spacing / 2.0
    for c in range(columns):
        for i, corners in enumerate(outlines):
            ax.add_patch(
                Polygon(corners + [first + c * spacing, z0], closed=True,
                        facecolor=colors[i % 2], edgecolor="0.2", linewidth=0.8, gid="drum")
            )  # fmt: skip
    if frame is not None:  # the beam rests level on the tops' highest corners
        top = outlines[-1][2:]
        z_b = z0 + float(np.max(top[:, 1]))
        left = first + float(np.min(top[:, 0]))
        right = first + (columns - 1) * spacing + float(np.max(top[:, 0]))
        box = np.array([[left, z_b], [right, z_b], [right, z_b + beam], [left, z_b + beam]])
        ax.add_patch(Polygon(box, closed=True, facecolor="#a89070", edgecolor="0.2",
                             linewidth=0.8, gid="beam"))  # fmt: skip
    ax.plot([x0 - pitch / 2.2, x0 + pitch / 2.2], [z0, z0], color="0.3", linewidth=1.2)
    ax.plot([x0, x0], [z0, z0 - 0.02 * height], color="0.3", linewidth=1.0)
    ax.text(x0, z0 - 0.04 * height, label, ha="center", va="top", fontsize="small")


def plot_shapes(
    history: History,
    widths: Sequence[float],
    times_index: Sequence[int],
    ax=None,
    *,
    elevations: Sequence[float] | None = None,
    scale: float | None = None,
    t_collapse: float | None = None,
    frame: tuple[int, float, float] | None = None,
):
    """Deformed column at chosen instants side by side (paper fig. 3), rotations exaggerated.

    Parameters
    ----------
    history : History  Recorded run
    widths : (n+1,) Column width at the nodes [m]
        (``build_column(...).widths``)
    times_index : sequence of int  Indices into ``history.t`` to draw
    ax : matplotlib Axes, optional
    elevations : (n+1,), optional  Node elevations z_i [m]; inferred from the
        history if omitted (see :func:`infer_elevations`)
    scale : float, optional  Exaggeration s [-]; default from
        :func:`exaggeration_factor` (a round number)
    t_collapse : float, optional  Collapse time [s]; the instant at or after
        it is labelled "collapse"
    frame : (columns, spacing [m], beam height [m]), optional  A frame: its columns drawn
        side by side, their axes spacing apart, rocking in unison, and the beam (gid
        'beam') resting level on their tops (rbm_cli.structures.frame.beam_box)

    Returns
    -------
    matplotlib Axes; its patches are the drums (gid 'drum', instant by instant,
    bottom drum first), the title states the exaggeration.

    Notes
    -----
    Drum i is drawn rigid, turned by s theta_i about the corner it rocks on,
    which sits on the corner of the drum below, so an open joint shows as a
    wedge (:func:`rbm_cli.structures.outline.drum_outlines`: exact for drums
    rocking without sliding, and equal to the RBM's node displacements to first
    order). A base that moves on the ground (a contact engine's history) is
    drawn displaced by s times its slip (:func:`~rbm_cli.structures.outline.base_slip`);
    the slip of upper joints is not drawn. Heights are to scale; the x axis has
    no scale of its own (the instants stand side by side, each over its rest
    position, marked by a tick on the ground).
    """
    ax = _new_axes(ax)
    widths = np.asarray(widths, dtype=float)
    z = infer_elevations(history) if elevations is None else np.asarray(elevations, float)
    if widths.shape != z.shape:
        raise ValueError(f"widths has {widths.size} entries, elevations {z.size}: need n+1 each")
    height = float(z[-1] - z[0])
    idx = [int(k) for k in times_index]
    s = exaggeration_factor(history, idx, height) if scale is None else float(scale)
    theta = np.atleast_2d(np.asarray(history.rotations, dtype=float))
    t = np.asarray(history.t, dtype=float)
    slip = base_slip(history.node_displacements, theta[:, 0], float(widths[0]))

    shapes = [drum_outlines(s * theta[k], widths, np.diff(z), s * slip[k]) for k in idx]
    reach = max([float(np.max(np.abs(np.vstack(o)[:, 0]))) for o in shapes] or [0.0])
    row = 0.0 if frame is None else (frame[0] - 1) * frame[1]  # a frame's row of axes
    pitch = 2.0 * max(reach, 0.5 * float(np.max(widths))) + row + 0.15 * height
    for j, (k, outlines) in enumerate(zip(idx, shapes, strict=True)):
        label = _shape_label(float(t[k]), t_collapse, float(slip[k]))
        _draw_instant(ax, outlines, j * pitch, z[0], pitch, height, label, frame)

    ax.set_xlim(-pitch / 2, (max(len(idx), 1) - 0.5) * pitch)
    beam = 0.0 if frame is None else frame[2]
    top = max([z[-1]] + [float(np.max(np.vstack(o)[:, 1])) for o in shapes]) + beam
    ax.set_ylim(z[0] - 0.22 * height, top + 0.05 * height)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_ylabel("height [m]")
    ax.set_title(f"Deformed shapes: rotations{' and slip' if np.any(slip) else ''} drawn x{s:g}")
    return ax


def plot_joint_rotations(
    history: History,
    rotation_capacity: Sequence[float],
    ax=None,
    *,
    formulation: str = "relative",
    collapse_ratio: float = 1.0,
    t_collapse: float | None = None,
):
    """Each joint's rotation over its limit against time, with the collapse level.

    Parameters
    ----------
    history : History  Recorded run
    rotation_capacity : (n,) theta_u,i [rad] (``Column.rotation_capacity``)
    ax : matplotlib Axes, optional
    formulation : str  'relative' or 'geometric': the joint's relative rotation
        phi_i = theta_i - theta_{i-1} (theta_0 = 0); 'absolute': theta_i
    collapse_ratio : float  The config's collapse.ratio c: dashed lines at +-c
    t_collapse : float, optional  Collapse time [s], drawn as a dashed line

    Returns
    -------
    matplotlib Axes; line k (gid 'joint-<k+1>') is joint k+1's rotation / theta_u,k+1 [-].
    A model in three dimensions (the history has ``rotations_across``): line k is the
    resultant of the rotations seen in the motion's plane and across it (the magnitude of
    the joint's rotation vector, which collapse reads), and the joint that comes nearest
    its limit has its two components drawn too (gids 'joint-<k+1>-along' and
    'joint-<k+1>-across')
    """
    ax = _new_axes(ax)
    theta = np.atleast_2d(np.asarray(history.rotations, dtype=float))
    limits = np.asarray(rotation_capacity, dtype=float)
    if limits.shape != (theta.shape[1],):
        n = theta.shape[1]
        raise ValueError(f"rotation_capacity has {limits.size} entries, the history {n} drums")

    def joint_angles(rotations):
        if formulation == "absolute":
            return rotations
        return np.diff(rotations, axis=1, prepend=0.0)

    symbol = r"\theta_i" if formulation == "absolute" else r"\varphi_i"
    along = joint_angles(theta) / limits
    across = None
    if history.rotations_across is not None:
        seen = np.atleast_2d(np.asarray(history.rotations_across, dtype=float))
        across = joint_angles(seen) / limits
    # lazy: matplotlib loads only where needed (docs/architecture.md, Start-up)
    from matplotlib import colormaps

    colours = colormaps["viridis"](np.linspace(0.0, 0.85, theta.shape[1]))
    t = np.asarray(history.t, dtype=float)
    ratio = along if across is None else np.hypot(along, across)
    for i in range(theta.shape[1]):
        ax.plot(
            t,
            ratio[:, i],
            color=colours[i],
            linewidth=1.0,
            label=f"joint {i + 1}" + ("" if across is None else ": resultant"),
            gid=f"joint-{i + 1}",
        )
    if across is not None and ratio.size:  # the components of the joint nearest its limit
        k = int(np.argmax(np.max(ratio, axis=0)))
        for part, style, where in ((along, "--", "along"), (across, ":", "across")):
            seen_in = "in the motion's plane" if where == "along" else "across it"
            ax.plot(t, part[:, k], color=colours[k], linewidth=0.7, linestyle=style,
                    label=f"joint {k + 1}: {seen_in}", gid=f"joint-{k + 1}-{where}")  # fmt: skip
    for sign in (1.0, -1.0):
        ax.axhline(
            sign * collapse_ratio,
            color="tab:red",
            linestyle=":",
            linewidth=1.0,
            label="collapse limit" if sign > 0 else None,
            gid="limit",
        )
    _mark_collapse(ax, t_collapse)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(rf"${symbol}/\theta_{{u,i}}$ [-]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="x-small", borderaxespad=0.0)
    return ax
