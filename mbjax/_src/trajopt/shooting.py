"""Single shooting: the controls are the unknowns, and the gradient is reverse mode through the
rollout (`Shooting`, whose docstring describes the method)."""

import equinox as eqx
import jax
import jax.numpy as jnp
import optax
from jax import Array

from mbjax._src.trajopt.descent import cosine_adam
from mbjax._src.trajopt.problem import Problem
from mbjax._src.trajopt.result import AbstractSolver, Result, history, no_states, rollout_result

METHODS = ("lbfgs", "adam")


class Shooting(AbstractSolver):
    """Single shooting: the controls are the unknowns, the gradient is reverse mode through the rollout.

    A solver strategy for `mbjax.trajopt.solve` (see The method, below). It works for any system,
    quaternion coordinates included; bounds are kept by projection, sound where none is active
    at the optimum.

    Args:
        method (str): "lbfgs" (optax's L-BFGS with its zoom line search) or "adam" (static).
        iterations (int): the most iterations (static).
        tolerance (float): stop when the (projected) gradient's norm falls below this times its
            first value.
        learning_rate (float): Adam's, cosine-decayed to a tenth over `iterations`; L-BFGS takes its
            steps from the line search.

    Raises:
        ValueError: method is not one of `METHODS`.

    The method:
        Single shooting: the controls are the unknowns, the objective is the problem's cost of their
        rollout, and its gradient is reverse mode through the rollout (`mbjax/_src/rigid/adjoint.py`
        for trees: a few rollouts' cost, whatever the horizon).

        `Shooting("lbfgs")` takes optax's L-BFGS with its zoom line search (Nocedal and Wright, Alg.
        3.5 and 7.4); `Shooting("adam")`, optax's Adam with a cosine-decayed learning rate, is the
        first-order baseline. Control bounds are kept by projecting the controls onto them after
        every step (projected gradient for Adam; for L-BFGS a heuristic, sound where no bound is
        active: use `ILQR` for problems whose optimum lies on its bounds). The iterations are one
        `lax.while_loop`: success when the gradient's norm falls below `tolerance` times its first
        value (its projection on the box, for bounded controls), NOT_CONVERGED when `iterations` run
        out.

    Gauss-Newton:
        Gauss-Newton on the controls of single shooting is not offered: with the costs' residuals
        stacked into one vector r(u), a dense Levenberg-Marquardt on all N nu controls converged far
        more slowly than iLQR on the benchmark problems (see benchmarks/README.md). The stage
        structure is what Gauss-Newton needs here: `ILQR` is Gauss-Newton on the controls with the
        step solved by a Riccati recursion and applied through a closed-loop rollout, and
        `MultipleShooting` is Gauss-Newton on the knots' states and controls.
    """

    method: str = eqx.field(static=True, default="lbfgs")
    iterations: int = eqx.field(static=True, default=500)
    tolerance: float = 1e-6
    learning_rate: float = 1e-2

    def __post_init__(self):
        if self.method not in METHODS:
            raise ValueError(f"method must be one of {METHODS}, got {self.method!r}")

    def solve(self, problem: Problem, us: Array, states: Array | None = None) -> Result:
        """Optimise the controls of `problem` from `us` (normally through `mbjax.trajopt.solve`).

        Args:
            problem: the trajectory-optimisation problem.
            us: the first guess, inside the bounds, shape (horizon, nu).
            states: must be None (the unknowns are the controls alone).

        Returns:
            The `Result` (no feedback gains: `feedback` is zeros).

        Raises:
            ValueError: states were given.
        """
        no_states(states, "Shooting")
        shape = us.shape

        def objective(flat):
            return problem.objective(flat.reshape(shape))

        if self.method == "lbfgs":
            optimizer = optax.lbfgs()
            value_and_grad = optax.value_and_grad_from_state(objective)
        else:
            optimizer = cosine_adam(self.learning_rate, self.iterations, 0.1)
            value_and_grad = jax.value_and_grad(objective)
        lower = jnp.broadcast_to(problem.lower, shape).ravel()
        upper = jnp.broadcast_to(problem.upper, shape).ravel()

        def projected_gradient(x, grad):
            """|grad| without the components that push against an active bound."""
            held = ((x <= lower) & (grad > 0)) | ((x >= upper) & (grad < 0))
            return jnp.linalg.norm(jnp.where(held, 0.0, grad))

        def evaluate(x, state, projected=False):
            """(cost, gradient) at x; L-BFGS's line search has them already, unless the
            projection moved x."""
            if self.method != "lbfgs":
                return value_and_grad(x)
            return jax.lax.cond(projected, jax.value_and_grad(objective),
                                lambda x: value_and_grad(x, state=state), x)

        def iterate(s):
            x, state, value, grad, i, costs = s
            if self.method == "lbfgs":
                updates, state = optimizer.update(grad, state, x, value=value, grad=grad,
                                                  value_fn=objective)
            else:
                updates, state = optimizer.update(grad, state, x)
            stepped = optax.apply_updates(x, updates)
            x = jnp.clip(stepped, lower, upper)
            value, grad = evaluate(x, state, jnp.any(x != stepped))
            return x, state, value, grad, i + 1, costs.at[i + 1].set(value)

        x0 = us.ravel()
        state0 = optimizer.init(x0)
        value0, grad0 = evaluate(x0, state0)
        first = projected_gradient(x0, grad0)

        def converged(s):
            return projected_gradient(s[0], s[3]) <= self.tolerance * first

        def running(s):
            return (s[4] < self.iterations) & ~converged(s) & jnp.isfinite(s[2])

        s = jax.lax.while_loop(running, iterate, (x0, state0, value0, grad0, jnp.array(0),
                                                  history(self.iterations + 1, value0)))
        return rollout_result(problem, s[0].reshape(shape), s[5], s[4], converged(s))
