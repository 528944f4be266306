"""Coupled free and constrained motion by Lagrange multipliers (seed 001 §VI: eqs 85-93, the
velocity form, and eqs 95-98, the momentum form), with optional Baumgarte stabilization.

With nu = mu^-1 the inverse mass matrix, the unconstrained acceleration a_free = nu (K^a - Y) and
the constraint rows A v_dot + b = 0 (mbjax.loops.constraints), eqs 89-92 give the multipliers
K_c from (A nu A^t) K_c = -(A a_free + b) and eq 93 the motion v_dot = a_free + nu A^t K_c.
Baumgarte's stabilization adds 2 alpha (A v + B) + beta^2 Phi to b, so the constraint errors obey
e_ddot + 2 alpha e_dot + beta^2 e = 0 instead of drifting.

The momentum form integrates G = mu v instead of v: G_dot = K^a - X + A^t K_c (eq 87), with
X = Y - mu_dot v (eq 99) and the multipliers of eq 98,
(A nu A^t) K_c = -(A nu (K^a - X) + b + A nu_dot G), nu_dot G = -nu mu_dot v; eq 99 makes them
equal to eq 92's, which the tests check.

Redundant constraints (a planar loop closed by a spatial revolute joint) and singular
configurations make A nu A^t singular. The multipliers are then the Tikhonov-regularized
least-squares ones, (A nu A^t + rho I) K_c = rhs with rho = 1e-12 trace / m, refined once
(iterated Tikhonov): the same accelerations to round-off whenever the equations are consistent,
finite always, and smooth for gradients; `rank` reports the numerical rank so a status can say so. The mass matrix
is dense here (O(n^3)); `mbjax.loops.stabilized` is seed 002's O(n + m^3) route.
"""

import jax
import jax.numpy as jnp
from jax import Array

from mbjax.loops.constraints import Loops
from mbjax.rigid.dynamics import mass_matrix
from mbjax.rigid.rnea import inverse_dynamics

REGULARIZATION = 1e-12
RANK_TOL = 1e-9


def numerical_rank(W: Array) -> Array:
    """Eigenvalues of the symmetric positive semi-definite W above RANK_TOL times the largest."""
    s = jnp.linalg.eigvalsh(jax.lax.stop_gradient(W))
    return jnp.sum(s > RANK_TOL * s[-1])


def multipliers(W: Array, rhs: Array) -> tuple[Array, Array]:
    """Regularized solution of W x = rhs for a symmetric positive semi-definite W, and the
    numerical rank of W."""
    m = W.shape[0]
    rho = REGULARIZATION * jnp.trace(W) / m
    factor = jax.scipy.linalg.cho_factor(W + rho * jnp.eye(m, dtype=W.dtype))
    x = jax.scipy.linalg.cho_solve(factor, rhs)
    # One step of iterated Tikhonov: the shift's bias on a well-posed W drops from rho / lambda
    # to (rho / lambda)^2 (round-off); a redundant W still gets a finite, smooth answer.
    x = x + jax.scipy.linalg.cho_solve(factor, rhs - W @ x)
    return x, numerical_rank(W)


def coupled_acceleration(loops: Loops, q: Array, v: Array, tau: Array, t=0.0,
                         baumgarte=(0.0, 0.0)) -> tuple[Array, Array, Array]:
    """(v_dot, K_c, rank) of seed 001 eqs 89-93; K_c are the multipliers of the rows of A, so
    A^t K_c is the generalized constraint force. The Baumgarte gains are Python floats."""
    model = loops.model
    mu = mass_matrix(model, q)
    bias = inverse_dynamics(model, q, v, jnp.zeros_like(v))        # Y: gravity, velocity terms
    factor = jax.scipy.linalg.cho_factor(mu)
    a_free = jax.scipy.linalg.cho_solve(factor, tau - bias)
    A = loops.jacobian(q, t)
    b = loops.acceleration_bias(q, v, t)
    if tuple(baumgarte) != (0.0, 0.0):        # Python floats: no extra passes when unused
        alpha, beta = baumgarte
        b = b + 2.0 * alpha * loops.rate(q, v, t) + beta**2 * loops.phi(q, t)
    nu_At = jax.scipy.linalg.cho_solve(factor, A.T)
    K_c, rank = multipliers(A @ nu_At, -(A @ a_free + b))
    return a_free + nu_At @ K_c, K_c, rank


def momentum_rate(loops: Loops, q: Array, G: Array, tau: Array, t=0.0) -> tuple[Array, Array, Array]:
    """(G_dot, K_c, rank) of the momentum formulation, seed 001 eqs 95-98, for momenta G = mu v."""
    model = loops.model
    mu = mass_matrix(model, q)
    factor = jax.scipy.linalg.cho_factor(mu)
    v = jax.scipy.linalg.cho_solve(factor, G)
    mu_dot_v = jax.jvp(lambda q_: mass_matrix(model, q_), (q,), (model.q_dot(q, v),))[1] @ v
    X = inverse_dynamics(model, q, v, jnp.zeros_like(v)) - mu_dot_v      # eq 99
    A = loops.jacobian(q, t)
    nu_At = jax.scipy.linalg.cho_solve(factor, A.T)
    nu_dot_G = -jax.scipy.linalg.cho_solve(factor, mu_dot_v)
    rhs = -(nu_At.T @ (tau - X) + loops.acceleration_bias(q, v, t) + A @ nu_dot_G)  # eq 98
    K_c, rank = multipliers(A @ nu_At, rhs)
    return tau - X + A.T @ K_c, K_c, rank
