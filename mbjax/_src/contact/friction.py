"""Friction cones, in one place: the exact cone a stance's contacts are held to
(`cone_flags`, `Status.PULLING` and `SLIPPING`), its linearisation into facets and the contact
wrench cone of a rectangular sole (`cone_rows`, `wrench_cone_rows`, the rows the trajectory
costs `mbjax.trajopt.friction_cone_residual` and `wrench_cone_residual` bound), and the
ground's frame they are written in."""

import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.system.status import Status


def friction(mu) -> Array:
    """mu as an array, or a ValueError naming it where it is concrete and not positive."""
    mu = jnp.asarray(mu, dtype=float)
    if mu.ndim != 0:
        raise ValueError(f"mu must be a scalar friction coefficient, got shape {mu.shape}")
    if not isinstance(mu, jax.core.Tracer) and not (float(mu) > 0 and np.isfinite(float(mu))):
        raise ValueError(f"mu must be a positive friction coefficient, got {float(mu)!r}")
    return mu


def cone_flags(forces: Array, normals: Array, mu) -> Array:
    """`Status.PULLING` where a contact's normal force is negative, `Status.SLIPPING` where its
    tangential force exceeds mu times the normal one (the exact cone), each beyond round-off
    (1e-9 of the force): forces and normals of shape (k, 3), an int scalar of flags."""
    fn = jnp.sum(forces * normals, axis=1)
    ft = jnp.linalg.norm(forces - fn[:, None] * normals, axis=1)
    slack = 1e-9 * jnp.linalg.norm(forces, axis=1)
    return (jnp.where(jnp.any(fn < -slack), int(Status.PULLING), 0)
            | jnp.where(jnp.any(ft > mu * fn + slack), int(Status.SLIPPING), 0))


def ground_frame(normal: Array) -> Array:
    """The ground's frame (t1, t2, n) as columns: n the unit normal, t1 the world's x made
    normal to it (y where x is nearly along n), t2 = n x t1; the identity for n = z."""
    n = normal / jnp.linalg.norm(normal)
    helper = jnp.where(jnp.abs(n[0]) < 0.9, jnp.array([1.0, 0.0, 0.0]), jnp.array([0.0, 1.0, 0.0]))
    t1 = helper - (helper @ n) * n
    t1 = t1 / jnp.linalg.norm(t1)
    return jnp.stack([t1, jnp.cross(n, t1), n], axis=1)


def cone_rows(normal: Array, mu, facets: int) -> Array:
    """The linearised cone's rows, (t_i - mu n) for each facet then n, shape (facets + 1, 3)."""
    t1, t2, n = ground_frame(normal).T
    angles = 2 * np.pi * np.arange(facets) / facets
    tangents = np.cos(angles)[:, None] * t1 + np.sin(angles)[:, None] * t2
    return jnp.concatenate([tangents - mu * n, n[None]])


def wrench_cone_rows(mu, length, width, inner: bool = True) -> np.ndarray:
    """The contact wrench cone of a rectangular sole (Caron, Pham and Nakamura 2015, eqs 13-17,
    in Crocoddyl's `WrenchCone` order), rows on the ground-frame wrench (torque; force), shape
    (17, 6): four friction facets, the normal force (bounded below), four centre-of-pressure
    rows and eight yaw-torque rows, each bounded above by 0 but the normal's."""
    m = mu / np.sqrt(2.0) if inner else mu
    X, Y = length / 2, width / 2
    rows = [[1, 0, -m, 0, 0, 0], [-1, 0, -m, 0, 0, 0], [0, 1, -m, 0, 0, 0], [0, -1, -m, 0, 0, 0],
            [0, 0, 1, 0, 0, 0],
            [0, 0, -Y, 1, 0, 0], [0, 0, -Y, -1, 0, 0], [0, 0, -X, 0, 1, 0], [0, 0, -X, 0, -1, 0]]
    for yaw in (-1, 1):
        for sx, sy in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
            rows.append([sx * Y, sy * X, -m * (X + Y), yaw * sx * m, yaw * sy * m, yaw])
    rows = np.asarray(rows, dtype=float)                # on (force; torque)
    return np.concatenate([rows[:, 3:], rows[:, :3]], axis=1)
