"""Kinetic and potential energy and the momentum of a tree.

T = 1/2 sigma^T mu sigma (Jerkovsky 1978 eq 10), summed body by body from the recursive velocities
(O(n)); V = -sum_k M_k g . c_k; the momentum is the sum of the bodies' (angular about the
ground origin; linear) momenta, ground frame. `energies` gives T and the total from one
outward sweep, which the energies and the invariants a simulation checks read.
"""

import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.linalg import unrolled_dot
from mbjax._src.system.invariants import ANGULAR, LINEAR, Invariants, along_gravity
from mbjax._src.model import Model
from mbjax._src.rigid.kinematics import body_kinematics, forward_kinematics
from mbjax._src.tree import forward_pass


@jax.jit
def kinetic_energy(model: Model, q: Array, v: Array) -> Array:
    """The tree's kinetic energy, 1/2 sum_k V_k^T I_k V_k (Jerkovsky 1978 eq 10), plus the
    rotors' 1/2 armature v^2, from one outward sweep (`energies`).

    Args:
        model: the tree.
        q: configuration, shape (nq,).
        v: generalized velocity, shape (nv,).

    Returns:
        T [J], a scalar.
    """
    return energies(model, q, v)[0]


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
    T + V + sum 1/2 stiffness (q - spring_reference)^2, a scalar [J] (`energies`)."""
    return energies(model, q, v)[1]


def _sweep(model: Model, q: Array, v: Array) -> tuple[Array, Array, Array, Array]:
    """Step (i) of the recursion (Anderson 1993 eqs 20-23) reduced to what the energy and the
    momentum need: each body's pose and its spatial velocity V_k = V_parent + S_k v_k (ground
    frame at the ground origin) in one tree pass, without the motion subspaces' rates, the
    remainder accelerations or the 6 x 6 inertias of `body_kinematics`, and without the second
    pass of `forward_kinematics`. Products are broadcast sums (`unrolled_dot`), not batched
    matrix products.

    Returns:
        (R, c, w, v_c): the bodies' rotations (n, 3, 3), centres of mass (n, 3), angular
            velocities (n, 3) and centre-of-mass velocities v_k + w_k x c_k (n, 3), ground frame.
    """
    R_local, p_local, S_local, _ = model.joints(q, v)
    twist = unrolled_dot(S_local, model.body_v(v))            # S v in body axes, (n, 6)

    def outward(parent, local):
        (R_parent, p_parent, V_parent), (R_joint, p_joint, s) = parent, local
        R = unrolled_dot(R_parent, R_joint)
        p = p_parent + unrolled_dot(R_parent, p_joint)
        w = unrolled_dot(R, s[:3])
        return R, p, V_parent + jnp.concatenate([w, jnp.cross(p, w) + unrolled_dot(R, s[3:])])

    ground = (jnp.eye(3, dtype=q.dtype), jnp.zeros(3, q.dtype), jnp.zeros(6, q.dtype))
    R, p, V = forward_pass(model.topology, outward, ground, (R_local, p_local, twist))
    c = p + unrolled_dot(R, model.com)
    w = V[:, :3]
    return R, c, w, V[:, 3:] + jnp.cross(w, c)


def energies(model: Model, q: Array, v: Array) -> tuple[Array, Array]:
    """(T, E): the kinetic and the total energy from one outward sweep, what `kinetic_energy`,
    `energy` and the invariants `simulate` checks along a run read (a small program to compile
    and run).

    From the sweep's poses and velocities (`_sweep`), vectorized over the bodies:
    T = 1/2 sum_k (M_k |v_c,k|^2 + w_k^T J_k w_k), J_k the inertia about the centre of mass c_k
    and w_k in body axes, plus the rotors' 1/2 armature v^2 (the same sum as Jerkovsky 1978
    eq 10); V = -sum_k M_k g . c_k plus the springs' 1/2 stiffness stretch^2.

    Args:
        model: the tree.
        q: configuration, shape (nq,).
        v: generalized velocity, shape (nv,).

    Returns:
        (T, E) [J], scalars: the kinetic energy and kinetic plus gravitational plus spring
            energy.
    """
    R, c, w, v_c = _sweep(model, q, v)
    w_body = unrolled_dot(jnp.swapaxes(R, -1, -2), w)
    T = 0.5 * (jnp.sum(model.mass * jnp.sum(v_c * v_c, -1))
               + jnp.sum(w_body * unrolled_dot(model.inertia, w_body))
               + jnp.sum(model.armature * v * v))
    V = -jnp.sum(model.mass * jnp.sum(c * model.gravity, -1))
    return T, T + V + 0.5 * jnp.sum(model.stiffness * model.spring_stretch(q)**2)


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
    magnitudes; none is held where a base's free joint is damped. From the outward sweep of
    `energies`: each body's momenta are P_k = M_k v_c,k and, about the ground origin,
    H_k = c_k x P_k + R_k J_k R_k^T w_k."""
    R, c, w, v_c = _sweep(model, q, v)
    P_k = model.mass[:, None] * v_c
    H_k = jnp.cross(c, P_k) + unrolled_dot(R, unrolled_dot(model.inertia, unrolled_dot(
        jnp.swapaxes(R, -1, -2), w)))
    G = jnp.concatenate([H_k, P_k], -1)                       # each body's (H about 0; P)
    H, P = jnp.sum(H_k, 0), jnp.sum(P_k, 0)
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
