"""Constraint loads from a symmetric positive semi-definite system, redundancy included.

Redundant constraints (a planar loop closed by a spatial revolute joint) and singular
configurations make the loads' matrix (A nu A^t, or A Gamma) singular. The loads are then the
Tikhonov-regularized least-squares ones, (W + rho I) x = rhs with rho = 1e-12 trace / m, refined
once (iterated Tikhonov): the same answer to round-off whenever the equations are consistent,
finite always, and smooth for gradients; `numerical_rank` reports the rank so a status can say so.
A W that is all zero (every contact of a stance in the air) gives zero loads. The factorizations
are `mbjax._src.linalg`'s loops, not LAPACK calls, so that they batch safely under `jax.vmap`.
"""

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.linalg import cho_solve, cholesky

REGULARIZATION = 1e-12
RANK_TOL = 1e-9


def numerical_rank(W: Array) -> Array:
    """The pivots of the symmetric positive semi-definite W's Cholesky factorization above
    RANK_TOL times its largest diagonal entry: a column that depends on earlier ones leaves a
    pivot of round-off. (An eigenvalue decomposition would be a LAPACK call, see `cholesky`.)"""
    W = jax.lax.stop_gradient(W)
    pivots = jnp.diagonal(cholesky(W)) ** 2
    return jnp.sum(pivots > RANK_TOL * jnp.max(jnp.diagonal(W)))


def multipliers(W: Array, rhs: Array) -> tuple[Array, Array]:
    """Regularized solution of W x = rhs for a symmetric positive semi-definite W (rhs (m,) or
    (m, k)), and the numerical rank of W."""
    return solver(W)(rhs), numerical_rank(W)


def solver(W: Array):
    """The regularized solve x = W^+ rhs of `multipliers` with W factored once."""
    m = W.shape[0]
    rho = REGULARIZATION * jnp.trace(W) / m
    factor = cholesky(W + rho * jnp.eye(m, dtype=W.dtype))

    def solve(rhs):
        x = cho_solve(factor, rhs)
        # One step of iterated Tikhonov: the shift's bias on a well-posed W drops from rho / lambda
        # to (rho / lambda)^2 (round-off); a redundant W still gets a finite, smooth answer.
        return x + cho_solve(factor, rhs - W @ x)

    return solve
