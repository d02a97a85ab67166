"""The Rigid Beam Model: the readable Python loop and the compiled kernel, two
implementations of the same runner; the naive scipy loop used as the bench's baseline."""

from rbm_cli.base.compile_cache import key_numba_cache

# before any kernel module decorates a function: numba's cache of the compiled kernel is
# keyed on every compiled source, not only on the file of each function (issue 18)
key_numba_cache()
