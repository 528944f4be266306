"""Outward kinematics of a tree (seed 002 §2.3 step (i), eqs 20-31 for rigid bodies).

Seed 002 writes its recursions with vectors and dyadics, free of any frame; mbjax evaluates them in
ground-frame components, with 6-D spatial vectors (angular; linear) taken at the ground origin.
Then the recursions need no frame changes at all:

    V[k] = V[parent] + S[k] v[k]                                     (eqs 21, 23)
    c[k] = V[k] x (S[k] v[k]) + S_dot_local v[k]                      (eqs 29, 31: the remainder)

where S[k] is joint k's motion subspace at the ground origin. Only the poses need a sequential
product (`forward_kinematics`); everything else is vectorized over the bodies.
"""

from typing import NamedTuple

import jax
import jax.numpy as jnp
from jax import Array

from mbjax.model import Model
from mbjax.spatial import cross_motion, inertia_matrix, skew
from mbjax.tree import forward_pass


class Kinematics(NamedTuple):
    R: Array      # (n, 3, 3) body orientations in the ground frame
    p: Array      # (n, 3) body-frame origins (the hinge points h_k), ground frame
    S: Array      # (n, 6, width) motion subspaces, ground frame at the ground origin
    V: Array      # (n, 6) spatial velocities, ground frame at the ground origin
    c: Array      # (n, 6) remainder (velocity-product) accelerations, same frame
    I: Array      # (n, 6, 6) spatial inertias about the ground origin, ground frame  # noqa: E741 (the papers' name)
    v: Array      # (n, width) joint velocities, zero-padded


@jax.jit
def forward_kinematics(model: Model, q: Array) -> tuple[Array, Array]:
    """World orientation (n, 3, 3) and origin (n, 3) of every body frame."""
    R, p, _, _ = model.joints(q, jnp.zeros(model.nv, q.dtype))
    return compose(model, R, p)


def compose(model: Model, R: Array, p: Array) -> tuple[Array, Array]:
    """World poses (R, p) of every body from each body's pose (R, p) in its parent's frame: the
    outward product along the tree (one tree pass)."""
    def step(parent, local):
        (R_parent, p_parent), (R_local, p_local) = parent, local
        return R_parent @ R_local, p_parent + R_parent @ p_local

    return forward_pass(model.topology, step, (jnp.eye(3, dtype=R.dtype), jnp.zeros(3, R.dtype)),
                        (R, p))


def to_ground(R: Array, p: Array, m: Array) -> Array:
    """Motion vectors (or the columns of a matrix, (..., 6, k)) from body coordinates at the body
    origin to ground coordinates at the ground origin: (R w; p x R w + R v)."""
    w, v = R @ m[..., :3, :], R @ m[..., 3:, :]
    return jnp.concatenate([w, skew(p) @ w + v], -2)


@jax.jit
def body_kinematics(model: Model, q: Array, v: Array) -> Kinematics:
    """Poses, motion subspaces, velocities, remainder accelerations and inertias of every body."""
    R_local, p_local, S_local, S_dot_local = model.joints(q, v)
    R, p = compose(model, R_local, p_local)
    S = to_ground(R, p, S_local)
    vb = model.body_v(v)
    joint_velocity = jnp.einsum("kij,kj->ki", S, vb)
    V = forward_pass(model.topology, lambda V_parent, Sv: V_parent + Sv, jnp.zeros(6, q.dtype),
                     joint_velocity)
    c = (cross_motion(V, joint_velocity)
         + jnp.einsum("kij,kj->ki", to_ground(R, p, S_dot_local), vb))
    com = p + jnp.einsum("kij,kj->ki", R, model.com)
    inertia = inertia_matrix(model.mass, com, R @ model.inertia @ jnp.swapaxes(R, -1, -2))
    return Kinematics(R, p, S, V, c, inertia, vb)


def gravity_acceleration(model: Model) -> Array:
    """The ground's fictitious spatial acceleration (0; -g) that puts gravity into a recursion."""
    return jnp.concatenate([jnp.zeros(3, model.gravity.dtype), -model.gravity])
