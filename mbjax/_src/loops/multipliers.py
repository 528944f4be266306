"""Constraint loads from a symmetric positive semi-definite system, redundancy included.

Redundant constraints (a planar loop closed by a spatial revolute joint) and singular
configurations make the loads' matrix (A nu A^t, or A Gamma) singular. The loads are then the
Tikhonov-regularized least-squares ones, (W + rho I) x = rhs with rho = 1e-12 trace / m, refined
once (iterated Tikhonov): the same answer to round-off whenever the equations are consistent,
finite always, and smooth for gradients; `numerical_rank` reports the rank so a status can say so.
"""

import jax
import jax.numpy as jnp
from jax import Array

REGULARIZATION = 1e-12
RANK_TOL = 1e-9


def numerical_rank(W: Array) -> Array:
    """Eigenvalues of the symmetric positive semi-definite W above RANK_TOL times the largest."""
    s = jnp.linalg.eigvalsh(jax.lax.stop_gradient(W))
    return jnp.sum(s > RANK_TOL * s[-1])


def multipliers(W: Array, rhs: Array) -> tuple[Array, Array]:
    """Regularized solution of W x = rhs for a symmetric positive semi-definite W (rhs (m,) or
    (m, k)), and the numerical rank of W."""
    return solver(W)(rhs), numerical_rank(W)


def solver(W: Array):
    """The regularized solve x = W^+ rhs of `multipliers` with W factored once."""
    m = W.shape[0]
    rho = REGULARIZATION * jnp.trace(W) / m
    factor = jax.scipy.linalg.cho_factor(W + rho * jnp.eye(m, dtype=W.dtype))

    def solve(rhs):
        x = jax.scipy.linalg.cho_solve(factor, rhs)
        # One step of iterated Tikhonov: the shift's bias on a well-posed W drops from rho / lambda
        # to (rho / lambda)^2 (round-off); a redundant W still gets a finite, smooth answer.
        return x + jax.scipy.linalg.cho_solve(factor, rhs - W @ x)

    return solve
