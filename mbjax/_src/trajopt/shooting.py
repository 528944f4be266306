"""Single shooting: the controls are the unknowns, and the gradient is reverse mode through the
rollout, its steps taken by an optax optimizer (`Shooting`, whose docstring describes the
method)."""

import equinox as eqx
import jax
import jax.numpy as jnp
import optax
from jax import Array

from mbjax._src.trajopt.problem import Problem
from mbjax._src.trajopt.result import AbstractSolver, Result, history, no_states, rollout_result


def cosine_adam(learning_rate: float, iterations: int, final_fraction: float = 0.1):
    """optax's Adam with its learning rate cosine-decayed over a run.

    `Shooting(optimizer=cosine_adam(learning_rate, iterations), iterations=iterations)` is single
    shooting's first-order baseline.

    Args:
        learning_rate: the first learning rate.
        iterations: the steps over which it decays (the solver's iterations).
        final_fraction: the fraction of learning_rate it decays to.

    Returns:
        The optax optimizer, `optax.adam(optax.cosine_decay_schedule(learning_rate, iterations,
            alpha=final_fraction))`.
    """
    return optax.adam(optax.cosine_decay_schedule(learning_rate, iterations, alpha=final_fraction))


class Shooting(AbstractSolver):
    """Single shooting: the controls are the unknowns, the gradient is reverse mode through the rollout.

    A solver strategy for `mbjax.trajopt.solve`. It works for any system,
    quaternion coordinates included; bounds are kept by projection, sound where none is active
    at the optimum.

    Args:
        optimizer (optax.GradientTransformation): the optax optimizer that takes the steps
            (static): `optax.lbfgs()` (the default: L-BFGS with its zoom line search), or Adam
            with its learning rate cosine-decayed over the run,
            `mbjax.trajopt.cosine_adam(learning_rate, iterations)`; any other optax optimizer
            too.
        iterations (int): the most iterations (static).
        tolerance (float): stop when the (projected) gradient's norm falls below this times its
            first value.

    Raises:
        TypeError: optimizer is not an optax optimizer (the strings "lbfgs" and "adam" of old,
            say).

    More on the method and on Gauss-Newton: the documentation site's Details page
    (docs/details.md).
    """

    optimizer: optax.GradientTransformation = eqx.field(static=True, default=optax.lbfgs())
    iterations: int = eqx.field(static=True, default=500)
    tolerance: float = 1e-6

    def __check_init__(self):
        if not isinstance(self.optimizer, optax.GradientTransformation):
            hint = (" (call it: optax.lbfgs(), not optax.lbfgs)" if callable(self.optimizer)
                    else "")
            raise TypeError(f"optimizer must be an optax optimizer such as optax.lbfgs() or "
                            f"mbjax.trajopt.cosine_adam(learning_rate, iterations){hint}, got "
                            f"{self.optimizer!r}")

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

        optimizer = optax.with_extra_args_support(self.optimizer)
        lower = jnp.broadcast_to(problem.lower, shape).ravel()
        upper = jnp.broadcast_to(problem.upper, shape).ravel()

        def projected_gradient(x, grad):
            """|grad| without the components that push against an active bound."""
            held = ((x <= lower) & (grad > 0)) | ((x >= upper) & (grad < 0))
            return jnp.linalg.norm(jnp.where(held, 0.0, grad))

        x0 = us.ravel()
        state0 = optimizer.init(x0)
        # a line search leaves the value and gradient at the point it accepted in the state
        line_search = all(optax.tree.get(state0, k) is not None for k in ("value", "grad"))
        value_and_grad = optax.value_and_grad_from_state(objective)

        def evaluate(x, state, projected=False):
            """(cost, gradient) at x; a line search has them already, unless the projection
            moved x."""
            if not line_search:
                return jax.value_and_grad(objective)(x)
            return jax.lax.cond(projected, jax.value_and_grad(objective),
                                lambda x: value_and_grad(x, state=state), x)

        def iterate(s):
            x, state, value, grad, i, costs = s
            updates, state = optimizer.update(grad, state, x, value=value, grad=grad,
                                              value_fn=objective)
            stepped = optax.apply_updates(x, updates)
            x = jnp.clip(stepped, lower, upper)
            value, grad = evaluate(x, state, jnp.any(x != stepped))
            return x, state, value, grad, i + 1, costs.at[i + 1].set(value)

        value0, grad0 = evaluate(x0, state0)
        first = projected_gradient(x0, grad0)

        def converged(s):
            return projected_gradient(s[0], s[3]) <= self.tolerance * first

        def running(s):
            return (s[4] < self.iterations) & ~converged(s) & jnp.isfinite(s[2])

        s = jax.lax.while_loop(running, iterate, (x0, state0, value0, grad0, jnp.array(0),
                                                  history(self.iterations + 1, value0)))
        return rollout_result(problem, s[0].reshape(shape), s[5], s[4], converged(s),
                              "Shooting")
