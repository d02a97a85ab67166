"""The moment-rotation law of an interface (paper fig. 2 and eq. 6).

f(x) = sign(x) * min(K_M |x|, xi M_u, M_u (1 - |x| / theta_u))

an elastic branch of stiffness K_M, a cap xi M_u (0 < xi <= 1; xi = 1 gives the
bilinear law, xi < 1 the tri-linear one) and Housner's descending branch. With
K_M = inf (rigid) the elastic branch is absent and f jumps at x = 0.

The law is stored as its pieces on x >= 0, f(x) = a_k + b_k x on
[x_k, x_{k+1}); f is odd, so on the mirrored piece f(x) = -a_k + b_k x.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Law:
    """Piecewise-linear odd moment-rotation law of one interface.

    edges : (m,) Breakpoints on x > 0 where the active branch changes [rad]
    intercepts, slopes : (m+1,) f = a_k + b_k x on the k-th piece of x >= 0
        [N m], [N m/rad]; piece 0 starts at x = 0
    rigid : bool  No elastic branch (K_M = inf): f jumps at 0
    elastic_limit : float  End of the elastic branch [rad] (0 if rigid)
    """

    edges: np.ndarray
    intercepts: np.ndarray
    slopes: np.ndarray
    rigid: bool
    elastic_limit: float

    def __call__(self, x: np.ndarray | float) -> np.ndarray:
        """Moment f(x) [N m] (odd; f(0) = 0 for a rigid law by convention)."""
        x = np.asarray(x, dtype=float)
        ax = np.abs(x)
        k = np.searchsorted(self.edges, ax, side="right")
        return np.sign(x) * (self.intercepts[k] + self.slopes[k] * ax)

    def potential(self, x: np.ndarray | float) -> np.ndarray:
        """F(x) = integral_0^x f(s) ds [J] (even in x)."""
        x = np.asarray(x, dtype=float)
        ax = np.abs(x)
        starts = np.concatenate([[0.0], self.edges])
        # energy accumulated up to each piece start
        cum = np.zeros(len(starts))
        for k in range(1, len(starts)):
            a, b = self.intercepts[k - 1], self.slopes[k - 1]
            x0, x1 = starts[k - 1], starts[k]
            cum[k] = cum[k - 1] + a * (x1 - x0) + 0.5 * b * (x1 * x1 - x0 * x0)
        k = np.searchsorted(self.edges, ax, side="right")
        x0 = starts[k]
        a, b = self.intercepts[k], self.slopes[k]
        return cum[k] + a * (ax - x0) + 0.5 * b * (ax * ax - x0 * x0)


def make_law(
    moment_capacity: float,
    rotation_capacity: float,
    stiffness: float,
    xi: float = 1.0,
    extra_slope: float = 0.0,
) -> Law:
    """Build the law of one interface.

    Parameters
    ----------
    moment_capacity : float  M_u [N m]
    rotation_capacity : float  theta_u, zero-moment rotation [rad]
    stiffness : float  K_M [N m/rad]; np.inf for a rigid law
    xi : float  Smoothing parameter, 0 < xi <= 1
    extra_slope : float  Slope added to every piece [N m/rad]; the `geometric`
        formulation adds M_u / theta_u, taking the rigid-stack P-Delta out of
        the joint law (c(x) = f(x) + (M_u / theta_u) x)

    Notes
    -----
    The pieces are the lower envelope of the three lines K_M x, xi M_u and
    M_u (1 - x / theta_u) on x >= 0.
    """
    mu, tu = float(moment_capacity), float(rotation_capacity)
    rigid = not np.isfinite(stiffness)
    lines = []  # (intercept, slope)
    if not rigid:
        lines.append((0.0, float(stiffness)))
    lines.append((xi * mu, 0.0))
    lines.append((mu, -mu / tu))

    cands = {0.0}
    for i in range(len(lines)):
        for j in range(i + 1, len(lines)):
            (a1, b1), (a2, b2) = lines[i], lines[j]
            if b1 != b2:
                x = (a2 - a1) / (b1 - b2)
                if x > 0 and np.isfinite(x):
                    cands.add(float(x))
    pts = sorted(cands)

    def active(x: float) -> int:
        vals = [a + b * x for a, b in lines]
        return int(np.argmin(vals))

    probes = [0.5 * (pts[k] + pts[k + 1]) for k in range(len(pts) - 1)] + [pts[-1] + 1.0]
    act = [active(x) for x in probes]
    edges, pieces = [], [act[0]]
    for k in range(1, len(act)):
        if act[k] != pieces[-1]:
            edges.append(pts[k])
            pieces.append(act[k])
    intercepts = np.array([lines[p][0] for p in pieces])
    slopes = np.array([lines[p][1] for p in pieces]) + extra_slope
    elastic_limit = 0.0 if rigid else (edges[0] if edges else np.inf)
    return Law(
        edges=np.array(edges, dtype=float),
        intercepts=intercepts,
        slopes=slopes,
        rigid=rigid,
        elastic_limit=float(elastic_limit),
    )


def law_sum(a: Law, b: Law) -> Law:
    """The law f_a(x) + f_b(x) of two joints that read one argument (a monolithic frame's
    base and beam joint, rbm_cli.structures.frame): pieces on the union of their edges,
    each the sum of the two pieces there; rigid if either jumps at 0."""
    edges = np.unique(np.concatenate([a.edges, b.edges]))
    starts = np.concatenate([[0.0], edges])
    ka = np.searchsorted(a.edges, starts, side="right")
    kb = np.searchsorted(b.edges, starts, side="right")
    rigid = a.rigid or b.rigid
    return Law(
        edges=edges,
        intercepts=a.intercepts[ka] + b.intercepts[kb],
        slopes=a.slopes[ka] + b.slopes[kb],
        rigid=rigid,
        elastic_limit=0.0 if rigid else float(edges[0] if edges.size else np.inf),
    )


def law_arrays(laws) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The pieces of n laws as padded arrays (the form compiled code reads).

    Parameters
    ----------
    laws : sequence of Law  One law per interface.

    Returns
    -------
    edges : (n, max(m, 1))  Each law's edges [rad], padded with inf (m the most edges of a law).
    nedges : (n,) int64  Number of edges of each law.
    intercepts, slopes : (n, m + 1)  Each law's pieces [N m], [N m/rad], padded with 0.
    rigid : (n,) bool  Rigid laws.
    """
    n = len(laws)
    m = max(len(law.edges) for law in laws)
    edges = np.full((n, max(m, 1)), np.inf)
    intercepts = np.zeros((n, m + 1))
    slopes = np.zeros((n, m + 1))
    nedges = np.zeros(n, dtype=np.int64)
    for i, law in enumerate(laws):
        e = len(law.edges)
        edges[i, :e] = law.edges
        intercepts[i, : e + 1] = law.intercepts
        slopes[i, : e + 1] = law.slopes
        nedges[i] = e
    rigid = np.array([law.rigid for law in laws], dtype=np.bool_)
    return edges, nedges, intercepts, slopes, rigid
