"""The constrained dynamics' KKT system, solved once and differentiated through its own factors.

Held by constraints A x + g = 0, a tree's accelerations (or an impulse's velocity jump) and the
constraint loads K solve

```text
[M  -A^T] [x]   [-f]
[A    0 ] [K] = [-g],      that is  r(theta, x, K) = (M x - A^T K + f, A x + g) = 0,
```

with M the mass matrix, f the tree's forces (the RNEA's, Jerkovsky 1978 eq 55) and g the
constraints' drift (Jerkovsky 1978 eqs 89-93). `implicit_kkt` solves it by the Schur complement
W = A M^-1 A^T, and gives its derivatives by the implicit function theorem: along a tangent
dtheta of everything the system depends on (the model's parameters, q, v, the control, the
anchors), (dx, dK) solves the same factored system with the right-hand side -dr/dtheta . dtheta,
one forward-mode pass through the residual at the solved (x, K): the RNEA with the constraint
loads as external forces and the constraints' second derivative. No factorization is
differentiated (Carpentier and Mansard 2018, "Analytical derivatives of rigid body dynamics
algorithms"; Pinocchio's `computeConstraintDynamicsDerivatives` and
`computeImpulseDynamicsDerivatives`, Crocoddyl's `calcDiff`). Under `jax.jacfwd` the factors are
computed once and every direction is a pass and two substitutions. Reverse mode transposes the
tangent, so `jax.grad` gets the adjoint route.

The factorizations are `mbjax._src.linalg`'s loops, not LAPACK calls: vmapped over states they
batch into elementwise operations (a batched LAPACK call deadlocks jaxlib 0.10.2's CPU runtime).
"""

from collections.abc import Callable

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.linalg import cho_solve, cholesky
from mbjax._src.loops.multipliers import solver


def _factored(theta, matrices: Callable, residual: Callable):
    """((x, K), solve): the solution at theta and the factored solve of the KKT system,
    solve(rF, rG) -> (x, K) for M x - A^T K = rF, A x = rG (right-hand sides (n, ...), (m, ...))."""
    M, A = matrices(theta)
    L = cholesky(M)
    Y = cho_solve(L, A.T)                                  # M^-1 A^T
    loads = solver(A @ Y)                                  # W^-1, regularized (`multipliers`)

    def solve(rF, rG):
        x = cho_solve(L, rF)
        K = loads(rG - A @ x)
        return x + Y @ K, K

    F0, G0 = residual(theta, jnp.zeros(M.shape[0], M.dtype), None)
    return solve(-F0, -G0), solve


@eqx.filter_custom_jvp
def implicit_kkt(theta, matrices: Callable, residual: Callable) -> tuple[Array, Array]:
    """(x, K) with residual(theta, x, K) = 0 (see the module).

    Args:
        theta: a pytree of everything the system depends on; its inexact arrays are
            differentiated.
        matrices: theta -> (M (n, n), A (m, n)), M symmetric positive definite.
        residual: (theta, x, K) -> (M x - A^T K + f, A x + g), affine in (x, K); K None for
            zero loads (no A^T K to form).

    Returns:
        (x, K), shapes (n,) and (m,).
    """
    return _factored(theta, matrices, residual)[0]


@implicit_kkt.def_jvp
def _implicit_kkt_jvp(primals, tangents):
    theta, matrices, residual = primals
    (x, K), solve = _factored(theta, matrices, residual)
    # only the arrays that carry a tangent move: the rest (a model's parameters, when only the
    # state is differentiated) stay out of the pass
    live = jax.tree.map(lambda t: t is not None, tangents[0], is_leaf=lambda z: z is None)
    moving, fixed = eqx.partition(theta, live)
    dmoving = eqx.filter(tangents[0], live)
    _, (dF, dG) = jax.jvp(lambda m: residual(eqx.combine(m, fixed), x, K), (moving,), (dmoving,))
    return (x, K), solve(-dF, -dG)
