"""Projection of a state onto the constraint manifold: Phi(q, t) = 0 and A v + B = 0.

Positions, after every step (`project_configuration`): along the constraint normals at q,
q* = retract(q, xi) with xi = A(q)^T y in the row space of A and Phi(q*) = 0. A fixed number of
chord (Gauss-Newton with the Jacobian frozen at q, factored once) iterations,

    xi <- A^+ (A xi - Phi(retract(q, xi))),

converge linearly at a rate of about |xi| times the constraints' curvature, so a step's drift is
gone to round-off in a few. Gradients come from the implicit function theorem (`lax.custom_root`),
not from the iterations: xi is the root of F(xi) = A^+ Phi(retract(q, xi)) + (I - A^+ A) xi, whose
Jacobian is the identity plus O(|xi|), so its tangent systems are solved by three Neumann
iterations. Both `jax.grad` and `jax.jacfwd` pass; no `while_loop` is on the path.

Velocities: the minimum-norm correction v <- v - A^+ (A v + B), the mass-weighted one when
`mass` is given (v - M^-1 A^t (A M^-1 A^t)^+ (A v + B), kinetic-energy-optimal); linear in v.

A^+ is the regularized pseudo-inverse of `mbjax._src.loops.multipliers`, so redundant constraints are
fine. Initial conditions far from the constraints (`consistent_state`) first take full
Gauss-Newton steps (the Jacobian updated each time).
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.linalg import cho_solve, cholesky
from mbjax._src.loops.constraints import Loops
from mbjax._src.loops.multipliers import multipliers, solver

ITERATIONS = 4          # chord iterations after a step: drift of 1e-4 rad is gone to round-off
NEUMANN = 3             # tangent solves with the Jacobian I + O(|xi|)


def project_configuration(loops: Loops, q: Array, t=0.0, *,
                          iterations: int = ITERATIONS) -> tuple[Array, Array]:
    """Project a configuration onto Phi(q, t) = 0 along the constraint normals at q.

    A fixed number of chord iterations; gradients by the implicit function theorem (the method
    below). Meant for the small drift of one step, after every step; far from the constraints
    use `consistent_state`.

    Args:
        loops: the tree and its closures (`ClosedSystem.loops`).
        q: configuration, shape (nq,).
        t (float): time [s], a scalar.
        iterations: number of chord iterations; static.

    Returns:
        (q on the constraints, shape (nq,), with its quaternions normalized; |Phi| there, a
            scalar).

    The method:
        q* = retract(q, xi) with xi = A(q)^T y in the row space of A and Phi(q*) = 0. A fixed
        number of chord (Gauss-Newton with the Jacobian frozen at q, factored once) iterations,

            xi <- A^+ (A xi - Phi(retract(q, xi))),

        converge linearly at a rate of about |xi| times the constraints' curvature, so a step's
        drift is gone to round-off in a few. Gradients come from the implicit function theorem
        (`lax.custom_root`), not from the iterations: xi is the root of
        F(xi) = A^+ Phi(retract(q, xi)) + (I - A^+ A) xi, whose Jacobian is the identity plus
        O(|xi|), so its tangent systems are solved by three Neumann iterations. Both `jax.grad`
        and `jax.jacfwd` pass; no `while_loop` is on the path. A^+ is a regularized
        pseudo-inverse, so redundant constraints are fine.
    """
    tree = loops.tree
    A = loops.jacobian(q, t)
    solve_W = solver(A @ A.T)

    def pinv(r):
        return A.T @ solve_W(r)

    def F(xi):
        return pinv(loops.phi(tree.retract(q, xi), t) - A @ xi) + xi

    def chord(F, xi):
        return jax.lax.scan(lambda x, _: (x - F(x), None), xi, None, length=iterations)[0]

    def tangent_solve(g, b):
        return jax.lax.scan(lambda x, _: (b - g(x) + x, None), b, None, length=NEUMANN)[0]

    xi = jax.lax.custom_root(F, jnp.zeros(tree.nv, q.dtype), chord, tangent_solve)
    q = tree.normalize(tree.retract(q, xi))
    return q, jnp.linalg.norm(loops.phi(q, t))


def gauss_newton(loops: Loops, q: Array, t=0.0, *, iterations: int = 30) -> Array:
    """q after `iterations` full Gauss-Newton steps with minimum-norm corrections,
    q <- retract(q, -A^+ Phi), the Jacobian updated every step (for starts far from Phi = 0)."""
    tree = loops.tree

    def step(q, _):
        A = loops.jacobian(q, t)
        y, _ = multipliers(A @ A.T, loops.phi(q, t))
        return tree.normalize(tree.retract(q, -A.T @ y)), None

    return jax.lax.scan(step, q, None, length=iterations)[0]


@eqx.filter_jit
def project_velocity(loops: Loops, q: Array, v: Array, t=0.0, mass=None) -> Array:
    """Project a velocity onto the velocity constraints A v + B = 0 by the smallest correction.

    Redundant constraints are fine (a regularized pseudo-inverse).

    Args:
        loops: the tree and its closures (`ClosedSystem.loops`).
        q: configuration, shape (nq,).
        v: joint velocities, shape (nv,).
        t: time [s], a scalar.
        mass: a symmetric positive-definite metric, shape (nv, nv) (the mass matrix: the
            kinetic-energy-optimal correction); None: the Euclidean one.

    Returns:
        The corrected v, shape (nv,).
    """
    A = loops.jacobian(q, t)
    if mass is None:
        y, _ = multipliers(A @ A.T, loops.rate(q, v, t))
        return v - A.T @ y
    factor = cholesky(mass)
    nu_At = cho_solve(factor, A.T)
    y, _ = multipliers(A @ nu_At, loops.rate(q, v, t))
    return v - nu_At @ y


@eqx.filter_jit
def _project(loops, q, v, t, iterations):
    q = gauss_newton(loops, loops.tree.normalize(q), t, iterations=iterations)
    q, norm = project_configuration(loops, q, t)
    return q, norm, project_velocity(loops, q, v, t, mass=loops.tree.mass_matrix(q))


def consistent_state(system, q, v, t=0.0, *, project: bool = True, tol: float = 1e-10,
                     iterations: int = 30):
    """Initial conditions (q, v) on the loop closures of `system`, checked.

    Needs concrete values (call it outside jit). Make the method's state from the result with
    `ClosedSystem.initial_state(q, v)`.

    Args:
        system (ClosedSystem | Loops): a `ClosedSystem` or `Loops`.
        q (Array): configuration, shape (nq,).
        v (Array): joint velocities, shape (nv,).
        t (float): time [s], a scalar.
        project: True: project q onto Phi = 0 (`iterations` full Gauss-Newton steps, then the
            chord projection) and v onto A v + B = 0 (the kinetic-energy-optimal correction);
            False: only check that (q, v) meet the constraints.
        tol: the largest |Phi| (and, with project=False, |A v + B|) accepted.
        iterations: Gauss-Newton steps of the projection.

    Returns:
        (q, v): projected, or unchanged with project=False.

    Raises:
        TypeError: `system` is neither a `ClosedSystem` nor `Loops`.
        ValueError: q or v of the wrong shape or non-finite, or tol not positive; with
            project=True, positions that
            cannot be brought within tol (the loop cannot close near q: an unreachable closure
            or a wrong branch); with project=False, a state that violates the constraints (the
            message gives the residuals).
    """
    loops = getattr(system, "loops", system)
    if not isinstance(loops, Loops):
        raise TypeError(f"system must be a ClosedSystem or Loops, got {type(system).__name__}")
    if not (isinstance(tol, int | float | np.number) and tol > 0 and np.isfinite(tol)):
        raise ValueError(f"tol must be a positive finite number, got {tol!r}")
    q, v = jnp.asarray(q, float), jnp.asarray(v, float)
    tree = loops.tree
    if q.shape != (tree.nq,) or v.shape != (tree.nv,):
        raise ValueError(f"q and v must have shapes ({tree.nq},) and ({tree.nv},), "
                         f"got {q.shape} and {v.shape}")
    if not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))):
        raise ValueError("the initial state has non-finite entries")
    if project:
        q, norm, v = _project(loops, q, v, jnp.asarray(t, float), iterations)
        if not float(norm) <= tol:
            raise ValueError(f"the initial configuration cannot be projected onto the loop "
                             f"closures: |Phi| = {float(norm):.3g} after {iterations} "
                             f"Gauss-Newton steps (is the mechanism able to close near q?)")
        return q, v
    position = float(jnp.linalg.norm(loops.phi(q, t)))
    velocity = float(jnp.linalg.norm(loops.rate(q, v, t)))
    if position > tol or velocity > tol:
        raise ValueError(f"the initial state violates the loop closures: |Phi| = {position:.3g}, "
                         f"|A v + B| = {velocity:.3g} (tolerance {tol:g}); project it with "
                         f"consistent_state(..., project=True)")
    return q, v
