"""The public dynamics of a tree: `forward_dynamics`, `inverse_dynamics`, `mass_matrix`.

`forward_dynamics(..., method=...)` runs Anderson 1993's O(n) recursion (`Recursive()`) or
Jerkovsky 1978's transformation operator with a Cholesky solve (`Dense()`, O(n^3)); `Auto()` picks
one for the model's size (`mbjax._src.system.dynamics`).
"""

from functools import partial

import jax
from jax import Array

from mbjax._src.model import Model
from mbjax._src.model.model import coordinates
from mbjax._src.rigid.aba import aba
from mbjax._src.rigid.adjoint import with_adjoint
from mbjax._src.rigid.batching import aba_vmappable
from mbjax._src.rigid.dense import dense_forward_dynamics
from mbjax._src.rigid.crba import composite_mass_matrix
from mbjax._src.rigid.rnea import inverse_dynamics as _rnea
from mbjax._src.system.dynamics import AbstractForwardDynamics, Auto, Recursive, as_dynamics


def _check(model: Model, **arrays) -> None:
    """Each array's shape for this model (`coordinates` in mbjax/_src/model/model.py), f_ext
    (n, 6) or None."""
    for name, value in arrays.items():
        if name != "f_ext":
            coordinates(model, value, name)
        elif value is not None and getattr(value, "shape", None) != (model.n, 6):
            raise ValueError(f"f_ext must have shape ({model.n}, 6) for this model (n = "
                             f"{model.n} bodies), got shape {getattr(value, 'shape', None)}; use "
                             "jax.vmap for batches")


@partial(jax.jit, static_argnames="method")
def forward_dynamics(model: Model, q: Array, v: Array, tau: Array,
                     method: AbstractForwardDynamics = Auto(), f_ext: Array | None = None) -> Array:
    """Joint accelerations under joint forces, gravity and external wrenches.

    Args:
        model: the tree.
        q: configuration, shape (nq,).
        v: generalized velocity, shape (nv,): the joint rates of revolute, prismatic and universal
            joints, the body angular velocity (and origin velocity) of spherical and free ones.
        tau: generalized forces, shape (nv,) (N m or N).
        method: `Recursive()` (Anderson 1993 §2.3, O(n)), `Dense()` (Jerkovsky 1978 eq 74 and a
            Cholesky solve, O(n^3)) or `Auto()` (one of them by the model's size).
        f_ext: external wrenches, shape (n, 6), one per body, world-frame components (torque
            about the body's origin; force), acting on the body at its origin; or None.

    Returns:
        The accelerations v_dot, shape (nv,).

    Raises:
        ValueError: an array of the wrong shape (named), or TypeError: `method` not a strategy.
    """
    method = as_dynamics(method)
    _check(model, q=q, v=v, tau=tau, f_ext=f_ext)
    if isinstance(method.resolve(model.nv), Recursive):
        return recursive_forward_dynamics(model, q, v, tau, f_ext)
    return dense_forward_dynamics(model, q, v, tau, f_ext)


def _primal(model: Model, q: Array, v: Array, tau: Array, f_ext: Array | None) -> Array:
    if f_ext is None:                          # jax.vmap's fast routes (mbjax._src.rigid.batching)
        return aba_vmappable(model, q, v, tau)
    return aba(model, q, v, tau, f_ext)


# Anderson 1993's recursion, differentiated through the equations of motion (mbjax._src.rigid.adjoint):
# reverse mode through the adjoint rule costs about 3x the forward pass, half of what
# differentiating the recursion costs; see benchmarks/README.md
recursive_forward_dynamics = with_adjoint(_primal)


@jax.jit
def inverse_dynamics(model: Model, q: Array, v: Array, v_dot: Array,
                     f_ext: Array | None = None) -> Array:
    """Joint forces that produce the accelerations v_dot: the RNEA, O(n).

    Args:
        model: the tree.
        q: configuration, shape (nq,).
        v: generalized velocity, shape (nv,).
        v_dot: generalized acceleration, shape (nv,).
        f_ext: external wrenches, shape (n, 6), as in `forward_dynamics`; or None.

    Returns:
        The generalized forces tau, shape (nv,), under gravity and f_ext.

    Raises:
        ValueError: an array of the wrong shape, named.
    """
    _check(model, q=q, v=v, v_dot=v_dot, f_ext=f_ext)
    return _rnea(model, q, v, v_dot, f_ext)


@jax.jit
def mass_matrix(model: Model, q: Array) -> Array:
    """The generalized mass matrix mu_hat_ff (Jerkovsky 1978 eq 55), by the composite-rigid-body
    algorithm (Featherstone's RBDA §6.2).

    Args:
        model: the tree.
        q: configuration, shape (nq,).

    Returns:
        M(q), symmetric positive-definite, shape (nv, nv) (kg m^2, kg or kg m by coordinate
            pair), the joints' armature included.

    Raises:
        ValueError: q of the wrong shape.
    """
    _check(model, q=q)
    return composite_mass_matrix(model, q)
