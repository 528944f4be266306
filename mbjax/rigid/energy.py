"""Kinetic and potential energy and the momentum of a tree.

T = 1/2 sigma^T mu sigma (seed 001 eq 10), summed body by body from the recursive velocities
(O(n)); V = -sum_k M_k g . c_k; the momentum is the sum of the bodies' (angular about the
ground origin; linear) momenta, ground frame.
"""

import jax
import jax.numpy as jnp
from jax import Array

from mbjax.model import Model
from mbjax.rigid.kinematics import body_kinematics, forward_kinematics


@jax.jit
def kinetic_energy(model: Model, q: Array, v: Array) -> Array:
    """1/2 sum_k V_k^T I_k V_k (eq 10), plus the rotors' 1/2 armature v^2."""
    kin = body_kinematics(model, q, v)
    return 0.5 * (jnp.einsum("ki,kij,kj->", kin.V, kin.I, kin.V) + model.armature @ (v * v))


@jax.jit
def potential_energy(model: Model, q: Array) -> Array:
    """Gravity's potential, zero at the ground origin."""
    R, p = forward_kinematics(model, q)
    c = p + jnp.einsum("kij,kj->ki", R, model.com)
    return -jnp.sum(model.mass * (c @ model.gravity))


@jax.jit
def energy(model: Model, q: Array, v: Array) -> Array:
    return kinetic_energy(model, q, v) + potential_energy(model, q)


@jax.jit
def spatial_momentum(model: Model, q: Array, v: Array) -> Array:
    """(angular momentum about the ground origin; linear momentum), ground frame."""
    kin = body_kinematics(model, q, v)
    return jnp.einsum("kij,kj->i", kin.I, kin.V)
