"""Outward kinematics of a tree (seed 002 §2.3 step (i), eqs 20-31 for rigid bodies).

Everything is in body coordinates with 6-D spatial vectors (angular; linear): X[k] is the Plucker
transform from body parents[k] to body k, V[k] = X[k] V[parent] + S[k] v[k] (eqs 21, 23) and the
velocity-product ("remainder") acceleration c[k] = S_dot[k] v[k] + V[k] x S[k] v[k] (eqs 29, 31).
"""

from typing import NamedTuple

import jax.numpy as jnp
from jax import Array

from mbjax.model import Model
from mbjax.spatial import cross_motion, plucker
from mbjax.tree import forward_pass


class Kinematics(NamedTuple):
    X: Array      # (n, 6, 6) parent-to-body transforms
    S: Array      # (n, 6, width) motion subspaces
    V: Array      # (n, 6) spatial velocities
    c: Array      # (n, 6) velocity-product accelerations
    v: Array      # (n, width) joint velocities, zero-padded


def body_kinematics(model: Model, q: Array, v: Array) -> Kinematics:
    """Transforms, motion subspaces, velocities and remainder accelerations of every body."""
    R, p, S, S_dot = model.joints(q, v)
    X = plucker(jnp.swapaxes(R, -1, -2), p)
    vb = model.body_v(v)
    joint_velocity = jnp.einsum("kij,kj->ki", S, vb)
    V = forward_pass(model.topology, lambda V_parent, inp: inp[0] @ V_parent + inp[1],
                     jnp.zeros(6, q.dtype), (X, joint_velocity))
    c = jnp.einsum("kij,kj->ki", S_dot, vb) + cross_motion(V, joint_velocity)
    return Kinematics(X, S, V, c, vb)


def forward_kinematics(model: Model, q: Array) -> tuple[Array, Array]:
    """World orientation (n, 3, 3) and origin (n, 3) of every body frame."""
    R, p, _, _ = model.joints(q, jnp.zeros(model.nv, q.dtype))

    def compose(parent, local):
        (R_parent, p_parent), (R_local, p_local) = parent, local
        return R_parent @ R_local, p_parent + R_parent @ p_local

    return forward_pass(model.topology, compose, (jnp.eye(3, dtype=q.dtype), jnp.zeros(3, q.dtype)),
                        (R, p))


def gravity_acceleration(model: Model) -> Array:
    """The ground's fictitious spatial acceleration (0; -g) that puts gravity into a recursion."""
    return jnp.concatenate([jnp.zeros(3, model.gravity.dtype), -model.gravity])
