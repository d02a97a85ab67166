"""One iteration of Brent's root finder (scipy's brentq, zeros.c; R. P. Brent 1973), shared
by the compiled loops that refine events to round-off: the step kernel's
(step.events.brentq) and the rigid block's closed form (block.piece.brent). The
caller evaluates its function at the point a step returns."""

from __future__ import annotations

from rbm_cli.base.jit import jit


@jit
def brent_step(xpre, xcur, xblk, fpre, fcur, fblk, spre, scur, xtol, rtol):
    """One step from the bracket state, f(xcur) = fcur just evaluated.

    Returns (done, xpre, xcur, xblk, fpre, fblk, spre, scur): done, xcur is the root
    (|bracket| / 2 below xtol + rtol |xcur|, or f(xcur) = 0); else xcur is the next point
    to evaluate. Start with xblk = fblk = spre = scur = 0 and f(xpre), f(xcur) nonzero.
    """
    if fpre != 0.0 and fcur != 0.0 and (fpre < 0.0) != (fcur < 0.0):
        xblk, fblk = xpre, fpre
        spre = scur = xcur - xpre
    if abs(fblk) < abs(fcur):
        xpre, xcur, xblk = xcur, xblk, xcur
        fpre, fcur, fblk = fcur, fblk, fcur
    delta = 0.5 * (xtol + rtol * abs(xcur))
    sbis = 0.5 * (xblk - xcur)
    if fcur == 0.0 or abs(sbis) < delta:
        return True, xpre, xcur, xblk, fpre, fblk, spre, scur
    if abs(spre) > delta and abs(fcur) < abs(fpre):
        if xpre == xblk:
            stry = -fcur * (xcur - xpre) / (fcur - fpre)
        else:
            dpre = (fpre - fcur) / (xpre - xcur)
            dblk = (fblk - fcur) / (xblk - xcur)
            stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
        if 2.0 * abs(stry) < min(abs(spre), 3.0 * abs(sbis) - delta):
            spre, scur = scur, stry
        else:
            spre, scur = sbis, sbis
    else:
        spre, scur = sbis, sbis
    xpre, fpre = xcur, fcur
    xcur += scur if abs(scur) > delta else (delta if sbis > 0.0 else -delta)
    return False, xpre, xcur, xblk, fpre, fblk, spre, scur
