"""Copies between arrays in compiled code, as loops.

``a[:] = b`` between arrays makes numba compile its shape check and the message it raises
on a mismatch (string formatting of the shapes): about 7 s of a first use of the step
integrator, for copies whose shapes are equal by construction. :func:`copy_into` is the
loop; the values are the same.
"""

from __future__ import annotations

from rbm_cli.base.jit import jit


@jit(inline=True)
def copy_into(dst, src):
    """dst[i] = src[i] for every i of src (1-D arrays, dst at least as long)."""
    for i in range(src.size):
        dst[i] = src[i]
