"""Projection of a state onto the constraint manifold: Phi(q, t) = 0 and A v + B = 0.

Positions: Gauss-Newton with minimum-norm steps in the velocity coordinates, q <- retract(q,
-A^+ Phi), a `lax.while_loop` that stops at |Phi| <= tol or after max_iter steps; velocities: the
minimum-norm correction v <- v - A^+ (A v + B), the mass-weighted one when `mass` is given
(v - M^-1 A^t (A M^-1 A^t)^+ (A v + B), kinetic-energy-optimal). The pseudo-inverses are the
regularized solves of `mbjax.loops.coupled.multipliers`, so redundant constraints are fine.
Used for consistent initial conditions (`consistent_state`, which projects or rejects with a
clear message) and, after every step, to stop drift.
"""

import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax.loops.constraints import Loops
from mbjax.loops.coupled import multipliers
from mbjax.rigid.dynamics import mass_matrix


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


def consistent_state(loops: Loops, q, v, t=0.0, *, project: bool = True, tol: float = 1e-10):
    """Initial conditions on the constraints, checked (concrete values, outside jit).

    project=True: (q, v) projected onto Phi = 0 and A v + B = 0 (kinetic-energy-optimal velocity
    correction); a ValueError says so when the positions cannot be brought within tol (the loop
    cannot close near q: an unreachable closure or a wrong branch). project=False: (q, v) returned
    unchanged if they meet the constraints to tol, else a ValueError with the residuals."""
    q, v = jnp.asarray(q, float), jnp.asarray(v, float)
    model = loops.model
    if q.shape != (model.nq,) or v.shape != (model.nv,):
        raise ValueError(f"q and v must have shapes ({model.nq},) and ({model.nv},), "
                         f"got {q.shape} and {v.shape}")
    if not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))):
        raise ValueError("the initial state has non-finite entries")
    if project:
        q, norm, iterations = project_configuration(loops, model.normalize(q), t, tol=tol)
        if not float(norm) <= tol:
            raise ValueError(f"the initial configuration cannot be projected onto the loop "
                             f"closures: |Phi| = {float(norm):.3g} after {int(iterations)} "
                             f"Gauss-Newton steps (is the mechanism able to close near q?)")
        v = project_velocity(loops, q, v, t, mass=mass_matrix(model, q))
        return q, v
    position = float(jnp.linalg.norm(loops.phi(q, t)))
    velocity = float(jnp.linalg.norm(loops.rate(q, v, t)))
    if position > tol or velocity > tol:
        raise ValueError(f"the initial state violates the loop closures: |Phi| = {position:.3g}, "
                         f"|A v + B| = {velocity:.3g} (tolerance {tol:g}); project it with "
                         f"consistent_state(..., project=True)")
    return q, v
