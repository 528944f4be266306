"""The argument checks of `mbjax.lie`: one vector or matrix per call (batches go through
`jax.vmap`), real, with integers promoted to the working float precision. They run when a
function is traced, so they cost nothing in a compiled program."""

import jax
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


# how far from a unit quaternion, or from orthonormal with det +1, a rotation that enters a run
# may be (round-off of a value read from a file or computed in float64 is far below)
ROTATION_TOLERANCE = 1e-6


def _concrete(x) -> np.ndarray | None:
    """x as a NumPy array, or None where it is traced (checked then by nobody: a traced start
    cannot raise)."""
    try:
        return np.asarray(x, dtype=float)
    except jax.errors.TracerArrayConversionError:
        return None


def check_rotation(R, name: str) -> Array:
    """R as a (3, 3) float array, checked to be a rotation where it is concrete: orthonormal
    within `ROTATION_TOLERANCE` and det +1 (a reflection is not a rotation); a ValueError naming
    `name` otherwise."""
    R = jnp.asarray(R, dtype=float)
    if R.shape != (3, 3):
        raise ValueError(f"{name} must be a rotation matrix of shape (3, 3), got shape {R.shape}")
    value = _concrete(R)
    if value is not None:
        off = float(np.max(np.abs(value.T @ value - np.eye(3)))) \
            if np.all(np.isfinite(value)) else np.inf
        if not off <= ROTATION_TOLERANCE:
            raise ValueError(f"{name} must be a rotation matrix (R^T R = I within "
                             f"{ROTATION_TOLERANCE:g}), got one off by {off:.3g}")
        if np.linalg.det(value) < 0:
            raise ValueError(f"{name} has determinant -1: a reflection, not a rotation")
    return R


def check_unit_quaternions(q, spans, name: str) -> None:
    """Each q[a:b] for (a, b, what) in `spans` a unit quaternion within `ROTATION_TOLERANCE`
    where q is concrete; a ValueError naming `name`[a:b] and `what` otherwise."""
    value = _concrete(q)
    if value is None:
        return
    for a, b, what in spans:
        norm = float(np.linalg.norm(value[a:b]))
        if not abs(norm - 1.0) <= ROTATION_TOLERANCE:
            raise ValueError(f"{name}[{a}:{b}] ({what}) must be a unit quaternion (norm 1 within "
                             f"{ROTATION_TOLERANCE:g}), got norm {norm:.6g}: normalise it "
                             f"(q / |q|)")


def check_point(x, name: str, what: str = "a vector") -> Array:
    """x as a float array of shape (3,), finite where it is concrete; a ValueError naming
    `name` (`what` it is) otherwise."""
    x = jnp.asarray(x, dtype=float)
    if x.shape != (3,):
        raise ValueError(f"{name} must be {what} of shape (3,), got shape {x.shape}")
    value = _concrete(x)
    if value is not None and not np.all(np.isfinite(value)):
        raise ValueError(f"{name} must be finite, got {value}")
    return x
