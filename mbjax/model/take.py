"""`take`: x[index] for a static index, as slices where it can be.

A model's coordinate maps (which entries of q are body k's, which bodies have revolute joints)
are static integer arrays. Indexing with them is a gather, and its reverse-mode transpose a
scatter-add, which XLA's CPU compiler cannot put inside a loop compiled as one kernel (see
`mbjax.runtime`): a loop with a scatter in it runs as dozens of kernels per step instead of one.
The maps of real robots are a few runs of consecutive indices (all the revolute joints of an arm;
a floating base's six velocities, then one per revolute joint), so `take` writes them as static
slices and one concatenation, whose transposes are pads and slices. Only a map of more than
`MAX_RUNS` runs (joint types interleaved along a chain) is left a gather.
"""

import jax.numpy as jnp
import numpy as np
from jax import Array

MAX_RUNS = 8


def runs(index: np.ndarray) -> list[tuple[int, int]]:
    """(first, length) of each maximal run of consecutive values in index (flattened)."""
    flat = np.asarray(index, dtype=int).ravel()
    if flat.size == 0:
        return []
    cuts = np.flatnonzero(np.diff(flat) != 1) + 1
    starts, ends = np.concatenate([[0], cuts]), np.concatenate([cuts, [flat.size]])
    return [(int(flat[a]), int(b - a)) for a, b in zip(starts, ends, strict=True)]


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
    if len(pieces) == 1 and pieces[0] == (0, x.shape[0]):
        out = x
    else:
        out = jnp.concatenate([x[first:first + length] for first, length in pieces])
    return out.reshape(index.shape + x.shape[1:])
