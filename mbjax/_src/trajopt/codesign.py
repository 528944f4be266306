"""Co-design: the gradient of a problem's optimal cost with respect to the design (a link's
length or mass, a cost weight, the initial state).

J*(theta) = min_u J(u; theta) over controls within bounds that do not depend on theta. At the
optimum u*(theta) the cost is stationary in u (on the free controls; the ones held at a bound
stay there), so by the implicit function theorem the controls' own change drops out of
dJ*/dtheta (the envelope theorem):

    dJ*/dtheta = dJ/dtheta (u*, theta),

one reverse-mode pass through the rollout at the solved controls, however the solver got there
(its iterations are never differentiated). This holds to the accuracy of the solve: the error is
of the order of the remaining gradient in u times du*/dtheta.
"""

from collections.abc import Callable

import jax
from jax import Array

from mbjax._src.trajopt.ilqr import ILQR
from mbjax._src.trajopt.problem import Problem
from mbjax._src.trajopt.result import AbstractSolver
from mbjax._src.trajopt.solve import solve


def optimal_cost(build: Callable[..., Problem], theta, solver: AbstractSolver = ILQR(),
                 us0: Array | None = None, throw: bool = True) -> Array:
    """The optimal cost `J*(theta)` of a design, differentiable by the envelope theorem.

    `jax.grad` of it with respect to theta is dJ/dtheta at the solved controls (see The
    envelope theorem, below), one reverse pass through the rollout; the solver's iterations are
    never differentiated. The envelope theorem needs the optimum: by default a solve that failed
    (not converged, non-finite) raises, naming the failure, instead of returning a cost and a
    gradient that are not the optimum's.

    Args:
        build: a function of the design returning its `Problem`; the control bounds must not
            depend on theta.
        theta (PyTree): the design, any pytree (a link's length or mass, a cost weight, the initial
            state).
        solver: the solver strategy.
        us0: the first guess, shape (horizon, nu); None for zeros.
        throw: raise if the solve failed (default); False returns the cost the solver reached
            whatever its status (`solve(build(theta), solver, us0).status` tells it).

    Returns:
        The cost the solver reaches, a scalar.

    Raises:
        equinox.EquinoxRuntimeError: with throw=True, the solve failed (under `jax.jit` and
            `jax.vmap` too).

    The envelope theorem:
        `J*(theta) = min_u J(u; theta)` over controls within bounds that do not depend on
        theta. At the optimum `u*(theta)` the cost is stationary in u (on the free controls; the
        ones held at a bound stay there), so by the implicit function theorem the controls' own
        change drops out of `dJ*/dtheta`:

        ```text
        dJ*/dtheta = dJ/dtheta (u*, theta),
        ```

        one reverse-mode pass through the rollout at the solved controls, however the solver got
        there (its iterations are never differentiated). This holds to the accuracy of the
        solve: the error is of the order of the remaining gradient in u times `du*/dtheta`.
    """

    @jax.custom_vjp
    def value(theta):
        return solve(build(theta), solver, us0, throw=throw).cost

    def forward(theta):
        result = solve(build(theta), solver, us0, throw=throw)
        return result.cost, (theta, result.us)

    def backward(residuals, cotangent):
        theta, us = residuals
        grad = jax.grad(lambda design: build(design).objective(us))(theta)
        return (jax.tree.map(lambda g: cotangent * g, grad),)

    value.defvjp(forward, backward)
    return value(theta)
