"""What every trajectory-optimisation solver returns, and the interface solvers implement."""

import abc

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax._src.system.status import Status, WithStatus
from mbjax._src.trajopt.problem import Problem


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


def require_vector_state(problem: Problem, solver: str) -> None:
    """Refuse a problem whose configuration has more coordinates than velocities: `solver`
    steps in the coordinates (q, v)."""
    if problem.nq != problem.nv:
        raise ValueError(f"{solver} steps in the coordinates (q, v), which needs as many "
                         f"configuration coordinates as velocities; this system has "
                         f"nq = {problem.nq}, nv = {problem.nv} (quaternions): use Shooting")


def rollout_result(problem: Problem, us: Array, costs: Array, iterations: Array,
                   converged: Array) -> Result:
    """The Result of controls us found without feedback gains: their rollout and its cost, with
    success where `converged` and NONFINITE where the rollout blew up."""
    xs = problem.rollout(us)
    cost = problem.cost(xs, us)
    finite = jnp.isfinite(cost) & jnp.all(jnp.isfinite(xs))
    status = (jnp.where(converged, 0, int(Status.NOT_CONVERGED))
              | jnp.where(finite, 0, int(Status.NONFINITE)))
    q, v = problem.split(xs)
    return Result(qs=q, vs=v, us=us, cost=cost, costs=costs, iterations=iterations,
                  feedback=jnp.zeros((problem.horizon, problem.nu, problem.nx), us.dtype),
                  status=status)
