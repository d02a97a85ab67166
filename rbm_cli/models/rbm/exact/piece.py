"""One linear piece of the exact integrator (numba): the modes of a set of law pieces (the
pieces each interface is on: rbm_cli.models.rbm.pieces), a linear piece's rows, and its
points.

The modes solve the symmetric pencil K phi = lam M phi (through the Cholesky factor of M:
M symmetric positive definite in the `relative` and `geometric` formulations, K symmetric,
possibly indefinite or singular), M-orthonormal: Phi^T M Phi = I, so q = Phi^T M theta.
They depend only on the slopes of the active pieces, so they are cached by the pieces'
indices across the runs of one column (modes, in the cache new_cache makes), with what
follows from them alone (the family rows gf = Gf Phi and |gf|); the intercepts (which side)
only move the constant load f. A column of n drums has m joints with a law: n, or n + 1
with a frame's beam joint (structures.equations.Model.joints), so n modes and m sets of
pieces. A piece reads its modes in the cache, not a copy: it lives
until the next piece is made, and only making a piece can change the cache.

Every event surface and every tracked peak quantity is linear in theta, so in modal
coordinates a row is d(t) = G q(t) + h0 (event distances, >= 0 inside the piece) or
z(t) = T q(t) (peaks). A point of a piece is a row of a pool array: [t, q (n), v (n),
F (nf), F' (nf), F'' (nf)], F = Gf q the family values (nf = 2m + 1: the m law arguments
over their scale, structures.equations.event_families, the m collapse ratios, the top
displacement; the tracked ones, whose peaks are kept, are the families m and above). An
event row r is sgn[r] * F[fam[r]] + off[r], in the order: lower law bounds, upper law
bounds, collapse on either side (m each), then the silent zero crossings of the joints
awaiting one.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from rbm_cli.base.jit import jit
from rbm_cli.models.rbm.exact.modal import HARMONIC, advance, f_accel
from rbm_cli.models.rbm.pieces import bound_rows

#: A linear piece: modes (lam, phi, tom = Phi^T M), modal loads f, g, the eligible modes
#: and their frequencies w (exact.bounds), family rows gf = Gf Phi and |gf|, event rows
#: (sgn, off, fam), the joints awaiting a silent crossing, the forcing fc; n modes (the
#: drums), m joints, nf = 2m + 1 families; cphi = centre_map Phi, the bodies' horizontal
#: accelerations per modal acceleration (the friction demand's).
#: The pool slot root finding works in.
SCRATCH_SLOT = 2

Piece = namedtuple("Piece", "lam phi tom f g elig w gf absgf sgn off fam silent fc n m nf cphi")


# ------------------------------------------------------------------ modes (cached)
@jit
def _slot(keys, used, k):
    """Slot of the key k in the open-addressing table: where it is, or the free slot
    where it goes."""
    cap = used.size
    hsh = 17
    for x in k:
        hsh = (hsh * 1000003 + x + 1) & 0xFFFFFFFFFF  # < 2^40: its product < 2^60
    i = hsh % cap
    while used[i]:
        same = True
        for j in range(k.size):
            if keys[i, j] != k[j]:
                same = False
                break
        if same:
            return i
        i = (i + 1) % cap
    return i


def new_cache(n: int, m: int | None = None, bodies: int | None = None) -> tuple:
    """An empty cache of modes for n drums, m joints and the bodies whose accelerations the
    friction demand sums (n each if None; exact.piece.modes): a power-of-two table of at
    most 8192 sets of pieces and 64 MB."""
    m = n if m is None else m
    bodies = n if bodies is None else bodies
    nf = 2 * m + 1
    # bytes: keys, lam, phi, tom, g, gf, |gf|, the bodies' map
    per_set = 8 * (m + n * (2 * n + 2) + 2 * nf * n + bodies * n)
    cap = 64
    while cap * 2 <= min(8192, (64 << 20) // per_set):
        cap *= 2
    return (
        np.zeros((cap, m), dtype=np.int64), np.zeros(cap, dtype=np.bool_), np.zeros((cap, n)),
        np.zeros((cap, n, n)), np.zeros((cap, n, n)), np.zeros((cap, n)),
        np.zeros(1, dtype=np.int64), np.zeros((cap, nf, n)), np.zeros((cap, nf, n)),
        np.zeros((cap, bodies, n)),
    )  # fmt: skip


@jit
def modes(mdl, cache, k):
    """Slot of the cache holding the modes of the pieces k (m joints; computed when absent:
    the pencil (K, M), K = D^T diag(slopes) P - K_g, through the Cholesky factor M = L L^T,
    eigh of L^-1 K L^-T), their family rows and the bodies' accelerations per mode
    (centre_map Phi: the friction demand's)."""
    keys, used, lam_s, phi_s, tom_s, g_s, count, gf_s, absgf_s, cphi_s = cache
    if count[0] >= (used.size * 3) // 4:  # full: start again
        used[:] = False
        count[0] = 0
    i = _slot(keys, used, k)
    if used[i]:
        return i
    m = k.size  # the joints
    slopes = np.empty(m)
    for j in range(m):
        slopes[j] = mdl.slopes[j, k[j]]
    stiff = mdl.diff_t @ (slopes[:, None] * mdl.argmap) - mdl.gravity
    stiff = 0.5 * (stiff + stiff.T)
    red = mdl.linv @ stiff @ mdl.linv.T
    red = 0.5 * (red + red.T)
    lam, u = np.linalg.eigh(red)
    phi = mdl.linv.T @ u
    keys[i, :] = k
    used[i] = True
    count[0] += 1
    lam_s[i, :] = lam
    phi_s[i, :, :] = phi
    tom_s[i, :, :] = u.T @ mdl.chol.T
    g_s[i, :] = -(phi.T @ mdl.ground_load)
    gf = mdl.families @ phi
    gf_s[i, :, :] = gf
    absgf_s[i, :, :] = np.abs(gf)
    cphi_s[i, :, :] = mdl.centre_map @ phi
    return i


# ------------------------------------------------------------------ a piece
@jit
def _rows(mdl, side, k, pending, awaiting):
    """(sgn, off, fam, silent) of the event rows of the current pieces (m joints)."""
    m = side.size
    ns = 0
    for i in range(m):
        ns += awaiting[i]
    rows = 4 * m + ns
    sgn, off, fam = np.empty(rows), np.empty(rows), np.empty(rows, dtype=np.int64)
    silent = np.empty(ns, dtype=np.int64)
    bound_rows(side, k, pending, mdl.rigid, mdl.edges, mdl.nedges, mdl.tu, mdl.c_ratio,
               np.empty(m), np.empty(m), off)  # fmt: skip
    for i in range(m):
        sgn[i], fam[i] = 1.0, i
        sgn[m + i], fam[m + i] = -1.0, i
        sgn[2 * m + i], fam[2 * m + i] = -1.0, m + i
        sgn[3 * m + i], fam[3 * m + i] = 1.0, m + i
    j = 0
    for i in range(m):
        if awaiting[i]:
            silent[j] = i
            sgn[4 * m + j], off[4 * m + j], fam[4 * m + j] = float(side[i]), 0.0, i
            j += 1
    return sgn, off, fam, silent


@jit
def make_piece(mdl, cache, side, k, pending, awaiting, fc):
    """The linear piece of the current law pieces (side, k, ...: one per joint) under the
    forcing fc."""
    m = side.size  # the joints
    slot = modes(mdl, cache, k)
    lam, phi, tom, g = cache[2][slot], cache[3][slot], cache[4][slot], cache[5][slot]
    a = np.empty(m)
    for i in range(m):
        a[i] = side[i] * mdl.intercepts[i, k[i]]
    f = -(phi.T @ (mdl.diff_t @ a))
    elig = lam > 0.0
    if int(fc[0]) == HARMONIC:
        elig &= lam >= 4.0 * fc[2] * fc[2]
    w = np.sqrt(np.where(elig, lam, 1.0))
    sgn, off, fam, silent = _rows(mdl, side, k, pending, awaiting)
    return Piece(lam, phi, tom, f, g, elig, w, cache[7][slot], cache[8][slot], sgn, off, fam,
                 silent, fc, lam.size, m, 2 * m + 1, cache[9][slot])  # fmt: skip


def point_size(n: int, m: int | None = None) -> int:
    """Length of a point row for n modes and m joints (n if None)."""
    m = n if m is None else m
    return 1 + 2 * n + 3 * (2 * m + 1)


@jit(borrow=True)
def _derived(pc, pts, i):
    """Family values and rates of point i from its (t, q, v), and the second derivatives
    of the tracked families (the peaks' rows, m and above)."""
    n, nf = pc.n, pc.nf
    of = 1 + 2 * n
    for r in range(nf):
        fv = dv = 0.0
        for j in range(n):
            fv += pc.gf[r, j] * pts[i, 1 + j]
            dv += pc.gf[r, j] * pts[i, 1 + n + j]
        pts[i, of + r] = fv
        pts[i, of + nf + r] = dv
    ag = f_accel(pc.fc, pts[i, 0])
    for r in range(pc.m, nf):
        ff = 0.0
        for j in range(n):  # the modal acceleration q''_j, as eval_family forms it
            ff += pc.gf[r, j] * (-pc.lam[j] * pts[i, 1 + j] + pc.f[j] + pc.g[j] * ag)
        pts[i, of + 2 * nf + r] = ff


@jit(borrow=True)
def eval_family(pc, pts, src, tau, k, second):
    """(F_k, F_k', and F_k'' if second else 0) tau [s] after point src, through the
    scratch point's (q, v) only (SCRATCH_SLOT)."""
    n = pc.n
    dst = SCRATCH_SLOT
    t = pts[src, 0]
    advance(pc.lam, pts[src, 1 : 1 + n], pts[src, 1 + n : 1 + 2 * n], pc.f, pc.g, pc.fc, t,
            tau, pts[dst, 1 : 1 + n], pts[dst, 1 + n : 1 + 2 * n])  # fmt: skip
    fv = dv = ff = 0.0
    ag = f_accel(pc.fc, t + tau) if second else 0.0
    for j in range(n):
        gj = pc.gf[k, j]
        qj = pts[dst, 1 + j]
        fv += gj * qj
        dv += gj * pts[dst, 1 + n + j]
        if second:
            ff += gj * (-pc.lam[j] * qj + pc.f[j] + pc.g[j] * ag)
    return fv, dv, ff


@jit
def set_point(pc, pts, i, t, q, v):
    """Point i at time t [s] with modal (q, v)."""
    n = pc.n
    pts[i, 0] = t
    pts[i, 1 : 1 + n] = q
    pts[i, 1 + n : 1 + 2 * n] = v
    _derived(pc, pts, i)


@jit(borrow=True)
def eval_point(pc, pts, src, tau, dst):
    """Point dst, tau [s] after point src."""
    n = pc.n
    t = pts[src, 0]
    advance(pc.lam, pts[src, 1 : 1 + n], pts[src, 1 + n : 1 + 2 * n], pc.f, pc.g, pc.fc, t,
            tau, pts[dst, 1 : 1 + n], pts[dst, 1 + n : 1 + 2 * n])  # fmt: skip
    pts[dst, 0] = t + tau
    _derived(pc, pts, dst)


@jit(borrow=True)
def row_at(pc, pts, i, r):
    """(value, rate) of event row r at point i."""
    of = 1 + 2 * pc.n
    kf = pc.fam[r]
    return (pc.sgn[r] * pts[i, of + kf] + pc.off[r], pc.sgn[r] * pts[i, of + pc.nf + kf])
