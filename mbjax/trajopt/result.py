"""What every trajectory-optimisation solver returns, and the interface solvers implement."""

import abc

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax.integrate.solution import WithStatus
from mbjax.trajopt.problem import Problem


class Result(WithStatus):
    """The optimised trajectory: states `qs`, `vs` (N + 1 each), controls `us` (N), the final
    `cost`, the cost after each iteration (`costs`, `iterations + 1` entries used, NaN after),
    the `iterations` taken and a `Status`: success when the solver's convergence test passed,
    NOT_CONVERGED when it ran out of iterations or could not make progress, NONFINITE when the
    cost or the trajectory blew up. `feedback`: the time-varying gains K_k (N, nu, nx) of
    u = u_k + K_k (x - x_k) where the solver has them (DDP: from its last accepted iteration's
    backward pass, about the trajectory before that step, the same at convergence), else
    zeros."""

    qs: Array
    vs: Array
    us: Array
    cost: Array
    costs: Array
    iterations: Array
    feedback: Array
    status: Array


class AbstractSolver(eqx.Module):
    """A trajectory-optimisation method: `solve(problem, us)` from the initial controls us."""

    @abc.abstractmethod
    def solve(self, problem: Problem, us: Array) -> Result:
        """Optimise the controls of `problem` starting from `us` (inside the bounds)."""


def history(length: int, first: Array) -> Array:
    """A cost history of `length` entries: `first`, then NaN."""
    return jnp.full(length, jnp.nan, first.dtype).at[0].set(first)
