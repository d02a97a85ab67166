"""The Rigid Beam Model: the readable Python loop and the compiled kernel, two
implementations of the same runner; the naive scipy loop used as the bench's baseline."""
