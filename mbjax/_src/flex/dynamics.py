"""The public forward dynamics of a flexible tree, with the same strategies as a rigid tree's:
Anderson 1993's O(n) recursion (`Recursive()`, `mbjax._src.flex.aba`) or Lagrange's equations
solved densely (`Dense()`, `mbjax._src.flex.lagrange`)."""

from functools import partial

import jax
from jax import Array

from mbjax._src.flex.aba import flexible_aba
from mbjax._src.flex.lagrange import lagrangian_forward_dynamics
from mbjax._src.flex.model import FlexibleModel
from mbjax._src.system.dynamics import AbstractForwardDynamics, Auto, Recursive, as_dynamics


@partial(jax.jit, static_argnames="method")
def forward_dynamics(model: FlexibleModel, q: Array, v: Array, tau: Array,
                     method: AbstractForwardDynamics = Auto(), f_ext: Array | None = None) -> Array:
    """Accelerations of a flexible tree under generalized forces, gravity, elasticity (with
    geometric stiffening) and external wrenches (Anderson 1993 §2.3, eqs 48-86).

    Args:
        model: the flexible tree.
        q: configuration (joint, then modal coordinates), shape (nq,).
        v: generalized velocity (joint rates, then modal rates), shape (nv,).
        tau: generalized forces (joint forces [N m or N], then modal forces), shape (nv,).
        method: `Recursive()` (the O(n) recursion), `Dense()` (Lagrange's equations, the
            residual's Jacobian in v_dot solved densely) or `Auto()`.
        f_ext: external wrenches, one per body, world frame (torque about the body's frame
            origin; force), shape (n, 6), acting on the body's joint grid; or None.

    Returns:
        The accelerations v_dot, shape (nv,).

    Raises:
        TypeError: `model` is not a `FlexibleModel` or `method` not a strategy.
    """
    if not isinstance(model, FlexibleModel):
        raise TypeError(f"model must be a FlexibleModel, got {type(model).__name__}")
    if isinstance(as_dynamics(method).resolve(model.nv), Recursive):
        return flexible_aba(model, q, v, tau, f_ext)
    return lagrangian_forward_dynamics(model, q, v, tau, f_ext)
