"""The one entry point of trajectory optimisation: `solve(problem, solver, us0)`."""

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax._src.system.status import raise_on_failure

from mbjax._src.trajopt.ilqr import ILQR
from mbjax._src.trajopt.problem import Problem
from mbjax._src.trajopt.result import AbstractSolver, Result


def solve(problem: Problem, solver: AbstractSolver = ILQR(), us0: Array | None = None,
          states0: Array | None = None, throw: bool = False) -> Result:
    """Optimise a problem's controls with a solver strategy.

    One compiled program: the solver's iterations run inside it, and `jax.vmap` solves many
    problems at once. A second problem of the same shapes (another target, another model
    parameter) reuses the program where its costs hold their data as leaves (equinox modules,
    or `eqx.Partial` of module-level functions, as `mbjax.scenes.arm.reach_problem` builds
    them); a fresh closure is a new function, and compiles anew.

    Args:
        problem: the trajectory-optimisation problem.
        solver: the method, an `AbstractSolver` instance (`ILQR()`, `MultipleShooting()`,
            `Shooting()`).
        us0: the first guess, shape (horizon, nu), clipped to the bounds; None for zeros.
        states0: a state trajectory as first guess, shape (horizon + 1, nq + nv), for
            `MultipleShooting` (an infeasible start: the knots need not follow the dynamics);
            None for the rollout of us0.
        throw: raise an error naming the failure (not converged, non-finite) instead of
            returning the result with its status.

    Returns:
        The `Result`.

    Raises:
        TypeError: problem is not a `Problem` or solver not a solver instance.
        ValueError: us0 or states0 has the wrong shape, or states0 was given to a solver that
            starts from a rollout (`ILQR`, `Shooting`).
        equinox.EquinoxRuntimeError: with throw=True, the solve failed.
    """
    if not isinstance(problem, Problem):
        raise TypeError(f"problem must be a mbjax.trajopt.Problem, got {type(problem).__name__}")
    if not isinstance(solver, AbstractSolver):
        raise TypeError(f"solver must be a solver instance such as ILQR(), got {solver!r}")
    # strongly typed float arrays: a weakly typed guess (jnp.full(shape, 1.0)) would compile anew
    us0, states0 = (None if x is None else jnp.asarray(x, dtype=float) for x in (us0, states0))
    return _solve(problem, solver, us0, states0, throw)


@eqx.filter_jit
def _solve(problem: Problem, solver: AbstractSolver, us0: Array | None, states0: Array | None,
           throw: bool) -> Result:
    return raise_on_failure(solver.solve(problem, problem.initial_controls(us0), states0), throw,
                            "mbjax._src.trajopt.solve")
