"""Joint limits as data: how far a state and a control lie outside a model's bounds.

URDF's <limit> and MJCF's range, actuatorfrcrange and velocity bounds are kept on the `Model`
(lower, upper, velocity_limit, effort_limit). mbjax does not enforce them as contact forces;
`simulate` flags a saved state beyond them (`Status.LIMIT_EXCEEDED`, a note), and `excess` gives a
smooth-almost-everywhere penalty for trajectory optimisation.
"""

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.model.joints import JOINT_TYPES


@jax.jit
def excess(model, q: Array, v: Array, tau: Array | None = None) -> Array:
    """How far (q, v, tau) lie beyond the model's limits, per coordinate, concatenated
    (nq position, nv velocity, nv effort entries; zero inside the bounds)."""
    tau = jnp.zeros_like(v) if tau is None else tau
    parts = [jnp.maximum(model.lower - q, 0.0) + jnp.maximum(q - model.upper, 0.0),
             jnp.maximum(jnp.abs(v) - model.velocity_limit, 0.0),
             jnp.maximum(jnp.abs(tau) - model.effort_limit, 0.0)]
    return jnp.concatenate(parts)


@jax.jit
def exceeded(model, q: Array, v: Array, tau: Array | None = None) -> Array:
    """True if any coordinate of (q, v, tau) is beyond the model's limits."""
    return jnp.any(excess(model, q, v, tau) > 0)


def first_exceeded(model, q: Array, v: Array, tau: Array | None = None) -> Array:
    """The index into `excess` of the first coordinate beyond its limit, -1 if none (named by
    `excess_names`)."""
    over = excess(model, q, v, tau) > 0
    return jnp.where(jnp.any(over), jnp.argmax(over), -1).astype(jnp.int32)


def excess_names(model) -> tuple[str, ...]:
    """What each entry of `excess` bounds: "joint 'NAME' position out of range" (its nq
    coordinates, a joint's k-th as "position k" where it has several), then velocity and effort
    per velocity coordinate."""
    names = {"position": [], "velocity": []}
    for kind, size_of in (("position", "nq"), ("velocity", "nv")):
        sizes = [getattr(JOINT_TYPES[t], size_of) for t in model.joint_types]
        for joint, size in zip(model.joint_names, sizes):
            names[kind] += [f"joint {joint!r} {kind}" + (f" {k}" if size > 1 else "")
                            + " out of range" for k in range(size)]
    return (*names["position"], *names["velocity"],
            *(name.replace("velocity", "effort") for name in names["velocity"]))
