"""The planar column's right-hand side for the compiled engine's Runge-Kutta steps
(numerics.rk.steps_for): the rates of the linear system of its current pieces, theta'' = c +
e a_g + A theta, with the joints' damping and a vertical record's factor."""

from __future__ import annotations

from rbm_cli.base.jit import jit
from rbm_cli.inputs.ground import gravity_factor, ground


@jit(inline=True)
def _damping(i, y, n, As):
    """The damping term of theta''_i, As[i, 2n:] theta' (a damped column's As has 3n
    columns, step.events.system; callers add it only then, so an undamped run's arithmetic
    is the same to the bit)."""
    s = 0.0
    for j in range(n):
        s += As[i, 2 * n + j] * y[n + j]
    return s


# The sums below run four at a time: four rows (or components), each summed in its own
# order as a plain loop would, in four registers. The processor then overlaps four chains of
# additions instead of waiting on one; every sum is the same, to the bit.


@jit(inline=True)
def rhs(t, y, n, As, cs, es, gr, out):
    g = ground(t, gr)
    damped = As.shape[1] > 2 * n
    if gr[6] == 0.0:
        for i in range(n):
            out[i] = y[n + i]
        n4 = n - n % 4
        for i in range(0, n4, 4):  # theta''_i = c_i + e_i g + sum_j A_ij theta_j
            s0, s1 = cs[i] + es[i] * g, cs[i + 1] + es[i + 1] * g
            s2, s3 = cs[i + 2] + es[i + 2] * g, cs[i + 3] + es[i + 3] * g
            for j in range(n):
                yj = y[j]
                s0 += As[i, j] * yj
                s1 += As[i + 1, j] * yj
                s2 += As[i + 2, j] * yj
                s3 += As[i + 3, j] * yj
            out[n + i], out[n + i + 1], out[n + i + 2], out[n + i + 3] = s0, s1, s2, s3
        for i in range(n4, n):
            s = cs[i] + es[i] * g
            for j in range(n):
                s += As[i, j] * y[j]
            out[n + i] = s
        if damped:
            for i in range(n):
                out[n + i] += _damping(i, y, n, As)
        return
    # a vertical record: every weight (the law's weight part and gravity, As[:, :n] and cs)
    # times (g + a_v) / g; the joints' stiffness (As[:, n:2n], step.events.system) and
    # damping not
    gam = gravity_factor(t, gr)
    for i in range(n):
        out[i] = y[n + i]
        s = cs[i]
        el = 0.0
        for j in range(n):
            s += As[i, j] * y[j]
            el += As[i, n + j] * y[j]
        out[n + i] = gam * s + el + es[i] * g
        if damped:
            out[n + i] += _damping(i, y, n, As)


@jit(inline=True)
def acc_of(t, y, n, As, cs, es, gr, acc):
    """Angular accelerations theta'' at (t, y) into acc [rad/s^2]; returns a_g(t) [m/s^2]
    and (g + a_v(t)) / g [-]. (gam * x + e g is x + e g to the bit when gam = 1; the
    elastic part As[:, n:2n] is read with a vertical record only, as rhs reads it.)"""
    g = ground(t, gr)
    gam = gravity_factor(t, gr)
    vert = gr[6] != 0.0
    damped = As.shape[1] > 2 * n
    for i in range(n):
        d = cs[i]
        el = 0.0
        for j in range(n):
            d += As[i, j] * y[j]
            if vert:
                el += As[i, n + j] * y[j]
        acc[i] = (gam * d + el + es[i] * g) if vert else (gam * d + es[i] * g)
        if damped:
            acc[i] += _damping(i, y, n, As)
    return g, gam
