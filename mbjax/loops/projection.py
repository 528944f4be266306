"""Projection of a state onto the constraint manifold: Phi(q, t) = 0 and A v + B = 0.

Positions: Gauss-Newton with minimum-norm steps in the velocity coordinates, q <- retract(q,
-A^+ Phi), a `lax.while_loop` that stops at |Phi| <= tol or after max_iter steps; velocities: the
minimum-norm correction v <- v - A^+ (A v + B), the mass-weighted one when `mass` is given
(v - M^-1 A^t (A M^-1 A^t)^+ (A v + B), kinetic-energy-optimal). The pseudo-inverses are the
regularized solves of `mbjax.loops.coupled.multipliers`, so redundant constraints are fine.
Used for consistent initial conditions and, after every step, to stop drift.
"""

import jax
import jax.numpy as jnp
from jax import Array

from mbjax.loops.constraints import Loops
from mbjax.loops.coupled import multipliers


def project_configuration(loops: Loops, q: Array, t=0.0, *, tol=1e-12, max_iter: int = 20):
    """(q on Phi = 0, residual norm, iterations)."""
    model = loops.model

    def step(carry):
        q, _, k = carry
        A = loops.jacobian(q, t)
        r = loops.phi(q, t)
        y, _ = multipliers(A @ A.T, r)
        q = model.normalize(model.retract(q, -A.T @ y))
        return q, jnp.linalg.norm(loops.phi(q, t)), k + 1

    def cond(carry):
        _, norm, k = carry
        return (norm > tol) & (k < max_iter)

    q, norm, k = jax.lax.while_loop(cond, step, (q, jnp.linalg.norm(loops.phi(q, t)), 0))
    return q, norm, k


def project_velocity(loops: Loops, q: Array, v: Array, t=0.0, mass=None) -> Array:
    """v with A v + B = 0, the smallest correction (in the metric of `mass` when given)."""
    A = loops.jacobian(q, t)
    W = A @ A.T if mass is None else A @ jnp.linalg.solve(mass, A.T)
    y, _ = multipliers(W, loops.rate(q, v, t))
    return v - (A.T @ y if mass is None else jnp.linalg.solve(mass, A.T @ y))
