"""What every trajectory-optimisation solver returns, and the interface solvers implement."""

import abc
from functools import partial

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.system.accuracy import RESOLUTION_LIMIT
from mbjax._src.system.accuracy import resolution as accuracy_resolution
from mbjax._src.system.status import (Flags, flags, RESOLVED, Status, WithStatus, accuracy_notes,
                                      run_member)
from mbjax._src.trajopt.problem import Problem


# the regularization past which `ILQR` and `MultipleShooting` give up (no step lowers the cost)
MU_CEILING = 1e10
# the median step length of an iteration's last fifth below which `messages()` calls them short
SHORT_STEP = 0.1


class Result(WithStatus):
    """The optimised trajectory that `mbjax.trajopt.solve` returns.

    Its states, controls, costs and feedback gains, and a status that says whether the solver
    converged (`ok`, `messages()`). N is the problem's horizon, nx = nq + nv.

    Args:
        qs: configurations, shape (N + 1, nq).
        vs: velocities, shape (N + 1, nv).
        us: controls, shape (N, nu).
        cost: the final cost, a scalar.
        costs: the cost after each iteration, shape (iterations + 1,) of the solver's
            maximum; the entries past the iterations taken are NaN.
        iterations: the iterations taken.
        feedback: the time-varying gains K_k of u = u_k + K_k dx on the deviation
            dx = `Problem.difference`(x_k, x), shape (N, nu, ndx), where the solver has them (DDP: from its last accepted iteration's backward pass,
            about the trajectory before that step, the same at convergence), else zeros.
        status: the `Status` flags; `mbjax.trajopt.solve` adds INACCURATE where the
            trajectory's steps do not resolve its motion (`resolution` above 1).
        resolution: the step times the trajectory's fastest rate, from consecutive increments
            of its states, held over 3 steps (`mbjax.integrate.Solution`'s default check; the
            increments across an `Impulse` knot, a jump by design, left out):
            above 1 the discrete dynamics the solver optimised are far from the continuous
            ones (an optimum that exploits the integrator's error); NaN before the check.
        inaccurate_by: 1 where the resolution made it INACCURATE, else 0.
        regularization: the regularization mu at the end (`ILQR`, `MultipleShooting`); NaN
            for a solver without one.
        step_lengths: the step length each iteration accepted, 0 where it accepted none,
            shape (iterations,) of the solver's maximum, NaN past the iterations taken
            (`ILQR`); all NaN for a solver that does not record them.
        solver: the solver's class name (static), which `messages()` names in its advice.
        hint: the solver's advice where its steps stay short (static; `messages()`).

    Status:
        The status is success when the solver's convergence test passed, NOT_CONVERGED when it
        ran out of iterations or could not make progress, NONFINITE when the cost or the
        trajectory blew up (for `ILQR` also when it stopped unconverged after an iteration that a
        non-finite cost kept from progressing). `messages()` names the likely remedy of each
        failure from what the result records (see docs/solving.md).
    """

    qs: Array
    vs: Array
    us: Array
    cost: Array
    costs: Array
    iterations: Array
    feedback: Array
    status: Flags = eqx.field(converter=flags)
    resolution: Array = float("nan")
    inaccurate_by: Array = 0
    regularization: Array = float("nan")
    step_lengths: Array = float("nan")
    solver: str = eqx.field(static=True, default="")
    hint: str = eqx.field(static=True, default="", repr=False)

    @property
    def xs(self) -> Array:
        """The states (N + 1, nq + nv), qs and vs side by side, as `Problem`'s functions and
        `knot_wrenches` take them."""
        return jnp.concatenate([self.qs, self.vs], axis=-1)

    def notes(self, i: int) -> dict:
        """What tripped each flag of the i-th result, and what to change (`WithStatus.messages`)."""
        notes = accuracy_notes(self, i)
        code = int(run_member(self, self.status, i))
        if code & Status.NOT_CONVERGED:
            notes[Status.NOT_CONVERGED] = self._not_converged(i)
        if code & Status.NONFINITE:
            notes[Status.NONFINITE] = ("the cost or the trajectory became inf or NaN: try a finer "
                                       "Problem(dt=...), bounds Problem(lower=..., upper=...) "
                                       "on the controls, or a first guess us0 nearer a solution")
        if code & Status.INACCURATE and Status.INACCURATE in notes:
            notes[Status.INACCURATE] += ("; try a finer Problem(dt=...), with horizon= raised "
                                         "to keep the duration")
        return notes

    def _not_converged(self, i: int) -> str:
        """Why the i-th run stopped unconverged, and the likely remedy."""
        taken = int(run_member(self, self.iterations, i))
        costs = np.asarray(run_member(self, self.costs, i), dtype=float)
        limit = costs.shape[-1] - 1
        mu = float(run_member(self, self.regularization, i))
        if taken < limit and mu >= MU_CEILING:
            return (f"no step lowered the cost: the regularization reached {mu:.0e} after "
                    f"{taken} iterations; try a first guess nearer a solution (us0=, states0=), "
                    "MultipleShooting() from states, or cost weights of similar scales")
        if taken < limit:
            return f"stopped after {taken} of {limit} iterations"
        k = max(1, taken // 5)
        steps = np.asarray(run_member(self, self.step_lengths, i), dtype=float)
        recent = steps[taken - k:taken] if steps.ndim else np.full(k, np.nan)
        if self.hint and np.all(np.isfinite(recent)) and np.median(recent) < SHORT_STEP:
            return (f"iterations={limit} ran out on short steps (median step length "
                    f"{np.median(recent):.2g} over the last {k}): try {self.hint}")
        before, after = costs[taken - k], costs[taken]
        if before > 2 * after > 0:
            ratio = before / after
            change = f"the cost fell {ratio:.2g}-fold" if ratio < 10 else (
                f"the cost fell {ratio:,.0f}-fold")
        elif before > after != 0:
            change = f"the cost fell {100 * (before - after) / abs(after):.2g}%"
        else:
            change = "the cost did not fall"
        raise_ = f"{self.solver}(iterations=...)" if self.solver else "the solver's iterations"
        return (f"iterations={limit} ran out, {change} over the last {k}: raise {raise_}, or "
                "go on from this result: solve(problem, solver, result.us)")


def cost_floor(dtype) -> float:
    """The cost below which a solver counts it as an exact optimum's zero: (1e3 eps)^2, the
    square of residuals at round-off of quantities of order one (the stopping tests are
    relative to the cost, which never holds at a cost of 0)."""
    return float((1e3 * jnp.finfo(dtype).eps) ** 2)


def checked(result: Result, jumps=None) -> Result:
    """The result with the default accuracy check: INACCURATE where its steps do not resolve
    its motion (`mbjax._src.system.accuracy.resolution` over the states; `jumps`, one per
    step, marks an impulse's knot, whose jump is the model's, not a step's error)."""
    resolution = accuracy_resolution(result.qs, result.vs, jumps=jumps)
    over = resolution > RESOLUTION_LIMIT
    return eqx.tree_at(lambda r: (r.status, r.resolution, r.inaccurate_by), result,
                       (result.status | jnp.where(over, int(Status.INACCURATE), 0).astype(
                           result.status.dtype), resolution, jnp.where(over, RESOLVED, 0)))


class AbstractSolver(eqx.Module):
    """A trajectory-optimisation method, a strategy passed to `mbjax.trajopt.solve`.

    Subclasses implement `solve(problem, us, states)`.
    """

    @abc.abstractmethod
    def solve(self, problem: Problem, us: Array, states: Array | None = None) -> Result:
        """Optimise the controls of `problem` starting from `us`.

        Args:
            problem: the trajectory-optimisation problem.
            us: the first guess, inside the bounds, shape (horizon, nu).
            states: a state trajectory as first guess, shape (horizon + 1, nx), for a solver
                that can use one; None for the rollout of us.

        Returns:
            The `Result`.
        """


class AbstractIterativeSolver(AbstractSolver):
    """A solver written as an iteration: `init` a state from the first guess, `step` it while
    `running`, read the `result`. Its `solve` is that loop; a batch of problems runs the same
    steps through a working set (`mbjax._src.trajopt.batch`), so converged members leave."""

    @abc.abstractmethod
    def init(self, problem: Problem, us: Array, states: Array | None = None):
        """The iteration's state (a pytree of arrays) before the first iteration, from the
        controls us and a state trajectory (None for us's rollout; a solver that cannot start
        from one raises a ValueError naming states0, `no_states`)."""

    @abc.abstractmethod
    def running(self, state) -> Array:
        """Whether the iteration goes on from `state`."""

    @abc.abstractmethod
    def step(self, problem: Problem, state):
        """One iteration from `state`."""

    @abc.abstractmethod
    def result(self, problem: Problem, state) -> Result:
        """The `Result` of `state`."""

    def solve(self, problem: Problem, us: Array, states: Array | None = None) -> Result:
        """Optimise the controls of `problem` from `us` (see `AbstractSolver.solve`)."""
        state = jax.lax.while_loop(self.running, partial(self.step, problem),
                                   self.init(problem, us, states))
        return self.result(problem, state)


def history(length: int, first: Array) -> Array:
    """A cost history of `length` entries: `first`, then NaN."""
    return jnp.full(length, jnp.nan, first.dtype).at[0].set(first)


def no_states(states, solver: str) -> None:
    """Refuse a state trajectory as first guess for a solver that starts from a rollout."""
    if states is not None:
        raise ValueError(f"states0: {solver} starts from the rollout of us0 and takes no state "
                         "trajectory; ILQR and MultipleShooting take one (an infeasible start)")


def rollout_result(problem: Problem, us: Array, costs: Array, iterations: Array,
                   converged: Array, solver: str = "", regularization=jnp.nan) -> Result:
    """The Result of controls us found without feedback gains by `solver` (its class name): their
    rollout and its cost, with success where `converged` and NONFINITE where the rollout blew
    up, and the solver's final `regularization` (NaN for none)."""
    xs = problem.rollout(us)
    cost = problem.cost(xs, us)
    finite = jnp.isfinite(cost) & jnp.all(jnp.isfinite(xs))
    status = (jnp.where(converged, 0, int(Status.NOT_CONVERGED))
              | jnp.where(finite, 0, int(Status.NONFINITE)))
    q, v = problem.split(xs)
    return Result(qs=q, vs=v, us=us, cost=cost, costs=costs, iterations=iterations,
                  feedback=jnp.zeros((problem.horizon, problem.nu, problem.ndx), us.dtype),
                  status=status, regularization=jnp.asarray(regularization, cost.dtype),
                  step_lengths=jnp.full(costs.shape[0] - 1, jnp.nan, cost.dtype), solver=solver)
