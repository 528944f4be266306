"""Symbolic-zero tangents in the custom derivative rules (`adjoint`, `kinematics`): which
arguments carry a tangent, so that a rule spends nothing on the others."""

import jax
import jax.numpy as jnp
from jax.custom_derivatives import SymbolicZero


def is_zero(tangent) -> bool:
    """Whether a tangent (a pytree, for a model) is JAX's symbolic zero in every leaf."""
    return all(isinstance(t, SymbolicZero)
               for t in jax.tree.leaves(tangent, is_leaf=lambda t: isinstance(t, SymbolicZero)))


def instantiate(tangent, primal):
    """Symbolic zeros in a tangent pytree made concrete."""
    return jax.tree.map(lambda t, p: jnp.zeros_like(p) if isinstance(t, SymbolicZero) else t,
                        tangent, primal, is_leaf=lambda t: isinstance(t, SymbolicZero))
