"""Kinetic and potential energy and the momentum of a tree.

T = 1/2 sigma^T mu sigma (Jerkovsky 1978 eq 10), summed body by body from the recursive velocities
(O(n)); V = -sum_k M_k g . c_k; the momentum is the sum of the bodies' (angular about the
ground origin; linear) momenta, ground frame.
"""

import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.system.invariants import ANGULAR, LINEAR, Invariants, along_gravity
from mbjax._src.model import Model
from mbjax._src.rigid.kinematics import body_kinematics, forward_kinematics


@jax.jit
def kinetic_energy(model: Model, q: Array, v: Array) -> Array:
    """The tree's kinetic energy, 1/2 sum_k V_k^T I_k V_k (Jerkovsky 1978 eq 10), plus the
    rotors' 1/2 armature v^2.

    Args:
        model: the tree.
        q: configuration, shape (nq,).
        v: generalized velocity, shape (nv,).

    Returns:
        T [J], a scalar.
    """
    kin = body_kinematics(model, q, v)
    return 0.5 * (jnp.einsum("ki,kij,kj->", kin.V, kin.I, kin.V) + model.armature @ (v * v))


@jax.jit
def potential_energy(model: Model, q: Array) -> Array:
    """Gravity's potential, V = -sum_k M_k g . c_k, zero with every centre of mass at the ground
    origin.

    Args:
        model: the tree (its `gravity`, shape (3,) [m/s^2]).
        q: configuration, shape (nq,).

    Returns:
        V [J], a scalar.
    """
    R, p = forward_kinematics(model, q)
    c = p + jnp.einsum("kij,kj->ki", R, model.com)
    return -jnp.sum(model.mass * (c @ model.gravity))


@jax.jit
def energy(model: Model, q: Array, v: Array) -> Array:
    """Kinetic plus gravitational energy plus the joint springs' energy,
    T + V + sum 1/2 stiffness (q - spring_reference)^2, a scalar [J]."""
    return (kinetic_energy(model, q, v) + potential_energy(model, q)
            + 0.5 * jnp.sum(model.stiffness * model.spring_stretch(q)**2))


@jax.jit
def spatial_momentum(model: Model, q: Array, v: Array) -> Array:
    """(angular momentum about the ground origin; linear momentum), ground frame."""
    kin = body_kinematics(model, q, v)
    return jnp.einsum("kij,kj->i", kin.I, kin.V)


def floating(model: Model) -> bool:
    """Every base body (parent: the ground) hangs from a free joint: no joint holds the tree to
    the ground, so only gravity changes its momentum."""
    return all(kind == "free" for kind, parent in zip(model.joint_types, model.topology.parents)
               if parent < 0)


def free_momenta(model: Model, t: Array, q: Array, v: Array) -> Invariants:
    """A floating tree's conserved momenta (`floating`): the linear momentum less the weight's
    impulse, P - M g t, and the angular momentum about the ground origin, H, of which only the
    component along gravity is conserved where there is gravity (the weight's moment
    c x M g is normal to g). Each is measured against the sum of the bodies' momentum
    magnitudes; none is held where a base's free joint is damped."""
    kin = body_kinematics(model, q, v)
    G = jnp.einsum("kij,kj->ki", kin.I, kin.V)                 # each body's (H about 0; P)
    H, P = jnp.sum(G[:, :3], 0), jnp.sum(G[:, 3:], 0)
    g = model.gravity
    H = along_gravity(H, g)
    P = P - jnp.sum(model.mass) * g * t
    scale = jnp.concatenate([jnp.full(3, jnp.sum(jnp.linalg.norm(G[:, :3], axis=-1))),
                             jnp.full(3, jnp.sum(jnp.linalg.norm(G[:, 3:], axis=-1)))])
    bases = np.flatnonzero(np.asarray(model.topology.parents) < 0)
    undamped = jnp.all(model.body_v(model.damping)[bases] == 0)
    return Invariants(values=jnp.concatenate([H, P]), scale=scale,
                      conserved=jnp.full(6, undamped), decreasing=jnp.zeros(6, bool),
                      names=ANGULAR + LINEAR)
