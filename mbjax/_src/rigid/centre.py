"""The centre of mass of a tree."""

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.model import Model
from mbjax._src.rigid.kinematics import forward_kinematics


@jax.jit
def center_of_mass(model: Model, q: Array) -> Array:
    """The tree's centre of mass in the world, sum_k M_k c_k / sum_k M_k (Pinocchio's
    `centerOfMass`).

    Args:
        model: the tree.
        q: configuration, shape (nq,).

    Returns:
        Its position [m], shape (3,).
    """
    R, p = forward_kinematics(model, q)
    c = p + jnp.einsum("kij,kj->ki", R, model.com)
    return model.mass @ c / jnp.sum(model.mass)
