"""Crocoddyl's solvers on an example (`mbjax_harness.crocoddyl.examples.Example`): a solver
from a fixed first guess (`CrocoddylSolver`: its cost history, its timed solves), the
controls' conversions between the two engines, and the check that the two problems are one
(`agreement`).
"""

import jax.numpy as jnp
import numpy as np

from mbjax_harness.crocoddyl.examples import Example
from mbjax_harness.timing import measure

ITERATIONS = 200     # a full solve's at most (`mbjax bench trajopt`'s ITERATIONS)


class CrocoddylSolver:
    """One Crocoddyl problem's solver (FDDP, or BoxDDP for bounded controls), from a fixed first
    guess and its rollout (or the states xs0, an infeasible start), its problem set to
    `threads` threads (None: Crocoddyl's default, a thread per core)."""

    def __init__(self, problem, us0, solver: str = "SolverFDDP", threads: int | None = 1,
                 xs0=None):
        import crocoddyl

        if threads is not None:
            problem.nthreads = threads
        self.problem, self.us0 = problem, [np.asarray(u, float) for u in us0]
        self.xs0 = None if xs0 is None else [np.asarray(x, float) for x in xs0]
        self.solver = getattr(crocoddyl, solver)(problem)

    def _states(self) -> list:
        return self.problem.rollout(self.us0) if self.xs0 is None else self.xs0

    def solve(self, iterations: int) -> bool:
        return self.solver.solve(self._states(), self.us0, iterations, self.xs0 is None)

    def history(self, iterations: int = ITERATIONS) -> list[float]:
        """The cost before and after each iteration of a full solve (at most `iterations`)."""
        import crocoddyl

        costs = []

        class Record(crocoddyl.CallbackAbstract):
            def __call__(self, solver):
                costs.append(solver.cost)

        first = self.problem.calc(self._states(), self.us0)
        self.solver.setCallbacks([Record()])
        self.solve(iterations)
        self.solver.setCallbacks([])
        return [first] + costs

    def timed(self, iterations: int, repeats: int) -> float:
        """The median wall time of a solve of at most `iterations` (after one warm-up)."""
        return measure(self.solve, iterations, repeats=repeats)[1].run_s


def _controls(example: Example, croc_problem):
    """(to Crocoddyl: mbjax's (N, nu) -> Crocoddyl's list, an impulse model's empty; back:
    Crocoddyl's list -> (N, nu), zeros where a model takes none)."""
    if example.controls is None:
        return (lambda us: [np.asarray(u, float) for u in us]), np.asarray
    to = example.controls(croc_problem)
    nu = example.problem.nu
    return to, lambda us: np.stack([np.pad(np.asarray(u, float), (0, nu - len(u))) for u in us])


def agreement(example: Example, croc_problem) -> dict:
    """That the two are one problem: the first guess's one-step states (each of Crocoddyl's
    knots stepped from mbjax's state, largest difference in Crocoddyl's layout) and the guess's
    cost in both (relative)."""
    problem, us0 = example.problem, np.asarray(example.us0, float)
    to_croc, _ = _controls(example, croc_problem)
    xs = problem.rollout(jnp.asarray(us0))
    xs_croc, us_croc = example.to_crocoddyl(xs), to_croc(us0)
    step = 0.0
    for k, model in enumerate(croc_problem.runningModels):
        data = model.createData()
        model.calc(data, xs_croc[k], us_croc[k])
        step = max(step, float(np.max(np.abs(np.asarray(data.xnext) - xs_croc[k + 1]))))
    cost_mbjax = float(problem.cost(xs, jnp.asarray(us0)))
    cost_croc = croc_problem.calc(list(xs_croc), us_croc)
    return {"one_step_agreement": step,
            "cost_agreement": abs(cost_croc - cost_mbjax) / abs(cost_mbjax)}
