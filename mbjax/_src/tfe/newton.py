"""Newton's method for one element's equations, differentiable by the implicit function theorem
(Borri 1990 §5: "in order to take advantage of the quadratic convergence property of the Newton
method, consistent linearized expressions ... are required" - here the tangent is jacfwd of the
residual, so it is consistent by construction).
"""

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array


class NewtonInfo(eqx.Module):
    """How a Newton solve went.

    Args:
        iterations: iterations taken.
        step: the last step's size |dx|.
        residual: the residual norm at the returned point.
        history: the residual norm before each iteration, shape (max_iter + 1,), NaN past
            the end.
        converged: whether the step met the tolerance with everything finite.
    """

    iterations: Array
    step: Array
    residual: Array
    history: Array
    converged: Array


def newton(F, x0: Array, *, tol, max_iter: int) -> tuple[Array, NewtonInfo]:
    """A root of F by Newton's method, stopping when |dx| <= tol (1 + |x|) or after max_iter steps.

    The loop is a `lax.while_loop`; derivatives of the root with respect to anything F closes
    over come from the implicit function theorem (`lax.custom_root`: dx/dtheta =
    -F_x^-1 F_theta), so neither forward nor reverse mode traverses the iterations.

    Args:
        F: the residual, a function of x with as many outputs as x has entries.
        x0: the starting point, shape (n,).
        tol: the tolerance on the step, relative to 1 + |x|.
        max_iter: the most iterations.

    Returns:
        x: the root found, shape (n,).
        info: the `NewtonInfo` of the solve.
    """

    def solve(f, x_init):
        def cond(carry):
            x, k, step, _ = carry
            return (k < max_iter) & ~(step <= tol * (1.0 + jnp.linalg.norm(x)))

        def body(carry):
            x, k, _, history = carry
            r = f(x)
            dx = -jnp.linalg.solve(jax.jacfwd(f)(x), r)
            return x + dx, k + 1, jnp.linalg.norm(dx), history.at[k].set(jnp.linalg.norm(r))

        history = jnp.full(max_iter + 1, jnp.nan, x_init.dtype)
        x, k, step, history = jax.lax.while_loop(
            cond, body, (x_init, jnp.array(0), jnp.array(jnp.inf, x_init.dtype), history))
        return x, (k.astype(x.dtype), step, history)  # float aux: custom_root needs float tangents

    def tangent_solve(g, y):
        return jnp.linalg.solve(jax.jacfwd(g)(y), y)

    x, (k, step, history) = jax.lax.custom_root(F, x0, solve, tangent_solve, has_aux=True)
    k = k.astype(int)
    x_stop = jax.lax.stop_gradient(x)
    residual = jnp.linalg.norm(F(x_stop))
    history = history.at[k].set(residual)
    converged = (step <= tol * (1.0 + jnp.linalg.norm(x_stop))) & jnp.isfinite(residual)
    return x, NewtonInfo(k, step, residual, history, converged)
