"""The argument checks of `mbjax.lie`: one vector or matrix per call (batches go through
`jax.vmap`), real, with integers promoted to the working float precision. They run when a
function is traced, so they cost nothing in a compiled program."""

import jax.numpy as jnp
import numpy as np
from jax import Array


def real(x, shape: tuple[int, ...], function: str, name: str, what: str) -> Array:
    """x as a real array of `shape`; a ValueError naming `function`'s argument `name` (a `what`)
    for another shape, a TypeError for complex or non-numeric values."""
    try:
        x = jnp.asarray(x)
    except TypeError as error:
        raise TypeError(f"mbjax.lie.{function}: {name} must be {what}, an array of shape {shape}; "
                        f"got {type(x).__name__}") from error
    if jnp.iscomplexobj(x) or not (jnp.issubdtype(x.dtype, jnp.number)
                                   or x.dtype == np.bool_):
        raise TypeError(f"mbjax.lie.{function}: {name} must be real ({what}), got dtype {x.dtype}")
    if x.shape != shape:
        raise ValueError(f"mbjax.lie.{function}: {name} must be {what} of shape {shape}, got shape "
                         f"{x.shape} (use jax.vmap for a batch)")
    if not jnp.issubdtype(x.dtype, jnp.floating):
        x = x.astype(jnp.result_type(float))
    return x


def rotation_vector(r, function: str) -> Array:
    return real(r, (3,), function, "r", "a rotation vector")


def quaternion(q, function: str, name: str = "q") -> Array:
    return real(q, (4,), function, name, "a quaternion (w, x, y, z)")


def matrix(R, function: str, name: str = "R") -> Array:
    return real(R, (3, 3), function, name, "a 3x3 matrix")
