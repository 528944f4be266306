"""The one entry point of trajectory optimisation: `solve(problem, solver, us0)`."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array
from jax.sharding import Mesh, PartitionSpec

from mbjax._src.runtime import contact_jit
from mbjax._src.system.status import raise_on_failure

from mbjax._src.trajopt.ilqr import ILQR
from mbjax._src.trajopt.problem import Problem
from mbjax._src.trajopt.batch import working_set
from mbjax._src.trajopt.result import AbstractIterativeSolver, AbstractSolver, Result, checked
from mbjax._src.trajopt.sweep import padded


def solve(problem: Problem, solver: AbstractSolver = ILQR(), us0: Array | None = None,
          states0: Array | None = None, throw: bool = False, width: int | None = None) -> Result:
    """Optimise a problem's controls with a solver strategy, or a batch of problems.

    One compiled program runs the solver's iterations and returns the optimised trajectory as a
    `Result`, whose status says whether the solver converged and whether the trajectory's steps
    resolve its motion, and where not, what to try (`print(result)`). A batch of problems is
    solved in one program too.

    The program is compiled once for what is not an array in the problem and the solver (the
    cost functions, sizes, the solver's settings): a problem that differs only in arrays reuses
    it. So pass the data a cost reads (a target, a weight) as arrays, bound to a module-level
    function by `eqx.Partial(terminal, target=target)` or held by a residual module
    (`frame_residual(model, frame, target)`); a closure over a target is a new function each
    time it is defined, and compiles anew (docs/solving.md).

    Args:
        problem: the trajectory-optimisation problem, or a batch of problems (see Batches in
            docs/details.md).
        solver: the method, an `AbstractSolver` instance (`ILQR()`, `MultipleShooting()`,
            `Shooting()`).
        us0: the first guess, shape (horizon, nu), clipped to the bounds; None for zeros.
        states0: a state trajectory as first guess, shape (horizon + 1, nq + nv), for `ILQR`
            (FDDP's infeasible start) and `MultipleShooting`: the knots need not follow the
            dynamics; None for the rollout of us0.
        throw: raise an error naming the failure (not converged, non-finite) instead of
            returning the result with its status.
        width: a batch's working set per device (static); None for 1 on a CPU, where a
            vmapped iteration costs more than its members one by one (benchmarks/README.md),
            and 64 on an accelerator (a guess: not yet measured on one).

    Returns:
        The `Result`, with a leading batch axis on every field for a batch.

    Raises:
        TypeError: problem is not a `Problem` or solver not a solver instance.
        ValueError: us0 or states0 has the wrong shape, states0 was given to a solver that
            starts from a rollout (`Shooting`), or width is not a positive int.
        equinox.EquinoxRuntimeError: with throw=True, the solve failed.

    More on compilation, batches, accuracy: the documentation site's Details page
    (docs/details.md).
    """
    if not isinstance(problem, Problem):
        raise TypeError(f"problem must be a mbjax.trajopt.Problem, got {type(problem).__name__}")
    if not isinstance(solver, AbstractSolver):
        raise TypeError(f"solver must be a solver instance such as ILQR(), got {solver!r}")
    # strongly typed float arrays: a weakly typed guess (jnp.full(shape, 1.0)) would compile anew
    us0, states0 = (None if x is None else jnp.asarray(x, dtype=float) for x in (us0, states0))
    if problem.q0.ndim == 2:
        if width is None:
            width = 1 if jax.default_backend() == "cpu" else 64
        if not (isinstance(width, int | np.integer) and width >= 1):
            raise ValueError(f"width must be a positive int (a batch's working set), got {width!r}")
        args = (problem, solver, us0, states0)
        return _solve_batch(not problem.vectorized, *args)(*args, throw, width)
    args = (problem, solver, us0, states0)
    return _solve(not problem.vectorized, *args)(*args, throw)


def _solve_one(problem: Problem, solver: AbstractSolver, us0: Array | None,
               states0: Array | None, throw: bool) -> Result:
    result = solver.solve(problem, problem.initial_controls(us0), states0)
    return raise_on_failure(checked(result, problem.jumps()), throw, "mbjax.trajopt.solve")


def _solve_many(problems: Problem, solver: AbstractSolver, us0: Array | None,
                states0: Array | None, throw: bool, width: int) -> Result:
    params, static = eqx.partition(problems, eqx.is_array)
    size = problems.q0.shape[0]
    if us0 is not None and us0.shape[:1] != (size,):
        raise ValueError(f"us0 must be (batch, horizon, nu) for a batch of {size} problems, got "
                         f"shape {us0.shape}")
    us = jax.vmap(lambda p, u: eqx.combine(p, static).initial_controls(u),
                  in_axes=(0, None if us0 is None else 0))(params, us0)
    if isinstance(solver, AbstractIterativeSolver) and states0 is None:
        result = _split(lambda p, u: working_set(solver, eqx.combine(p, static), u, width),
                        params, us)
    else:
        result = jax.vmap(lambda p, u, x: solver.solve(eqx.combine(p, static), u, x),
                          in_axes=(0, 0, None if states0 is None else 0))(params, us, states0)
    jumps = problems.jumps()
    return raise_on_failure(jax.vmap(lambda r: checked(r, jumps))(result), throw,
                            "mbjax.trajopt.solve")


# jitted, and compiled without XLA's loop-invariant code motion where the knots solve contacts
# (`mbjax._src.runtime`, item 5)
_solve, _solve_batch = contact_jit(_solve_one), contact_jit(_solve_many)


def _split(fn, params, us: Array):
    """fn(params, us) of a batch, the batch split over `jax.devices()` (padded with copies of
    its last member to a multiple of their number) where there are several."""
    devices = jax.devices()
    if len(devices) == 1:
        return fn(params, us)
    size = us.shape[0]
    (params, us), _ = padded((params, us), len(devices))
    mesh = Mesh(np.asarray(devices), ("batch",))
    out = jax.shard_map(fn, mesh=mesh, in_specs=PartitionSpec("batch"),
                        out_specs=PartitionSpec("batch"), check_vma=False)(params, us)
    return jax.tree.map(lambda x: x[:size], out)
