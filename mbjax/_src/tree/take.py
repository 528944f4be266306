"""`take`: x[index] for a static index, as slices where it can be.

A model's coordinate maps (which entries of q are body k's, which bodies have revolute joints)
are static integer arrays. Indexing with them is a gather, and its reverse-mode transpose a
scatter-add, which XLA's CPU compiler cannot put inside a loop compiled as one kernel (see
`mbjax._src.runtime`): a loop with a scatter in it runs as dozens of kernels per step instead of one.
The maps of real robots are a few runs of consecutive indices, ascending or descending (all the
revolute joints of an arm; a floating base's six velocities, then one per revolute joint; a tree
pass's bodies, tips first), so `take` writes them as static slices, reversals and one
concatenation, whose transposes are pads, slices and reversals. Only a map of more than
`MAX_RUNS` runs (joint types interleaved along a chain) is left a gather.
"""

import jax.numpy as jnp
import numpy as np
from jax import Array

MAX_RUNS = 8


def runs(index: np.ndarray) -> list[tuple[int, int, int]]:
    """(first, length, step) of each maximal run of consecutive values in index (flattened),
    ascending (step 1) or descending (step -1, as a reversed tree order visits bodies)."""
    out = []
    for value in np.asarray(index, dtype=int).ravel():
        if out:
            first, length, step = out[-1]
            if length == 1 and abs(value - first) == 1:
                out[-1] = (first, 2, int(value - first))
                continue
            if value == first + step * length:
                out[-1] = (first, length + 1, step)
                continue
        out.append((int(value), 1, 1))
    return out


def _piece(x: Array, first: int, length: int, step: int) -> Array:
    if step == 1:
        return x[first:first + length]
    return jnp.flip(x[first - length + 1:first + 1], 0)


def take(x: Array, index: np.ndarray) -> Array:
    """x[index] along x's first axis for a static integer array index (any shape): the result
    has shape index.shape + x.shape[1:]. Static slices and a concatenation where index is at most
    MAX_RUNS runs of consecutive values (the identity costs nothing), a gather otherwise."""
    index = np.asarray(index, dtype=int)
    pieces = runs(index)
    if not pieces:
        return jnp.zeros(index.shape + x.shape[1:], x.dtype)
    if len(pieces) > MAX_RUNS:
        return x[index]
    if len(pieces) == 1 and pieces[0] == (0, x.shape[0], 1):
        out = x
    else:
        out = jnp.concatenate([_piece(x, *piece) for piece in pieces])
    return out.reshape(index.shape + x.shape[1:])
