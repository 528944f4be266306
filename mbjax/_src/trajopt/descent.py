"""Adam on a flat parameter vector, the Carpal Wrist synthesis' and controller's loop, and the
cosine-decayed Adam it and `Shooting("adam")` share."""

import jax
import optax
from jax import Array


def cosine_adam(learning_rate: float, iterations: int, final_fraction: float):
    """optax's Adam with its learning rate cosine-decayed over a run.

    Args:
        learning_rate: the first learning rate.
        iterations: the steps over which it decays.
        final_fraction: the fraction of learning_rate it decays to.

    Returns:
        The optax optimizer.
    """
    return optax.adam(optax.cosine_decay_schedule(learning_rate, iterations, alpha=final_fraction))


def adam_descent(loss, x0: Array, *, learning_rate: float, iterations: int, final_fraction: float,
                 gradient: str = "forward"):
    """Adam steps on loss(x), the learning rate cosine-decayed, as one `lax.scan`.

    Args:
        loss: the scalar loss, a function of x.
        x0: the starting parameters, shape (n,).
        learning_rate: the first learning rate.
        iterations: the number of steps.
        final_fraction: the fraction of learning_rate it decays to.
        gradient: "forward" (`jax.jacfwd`), which compiles faster than reverse mode through
            the simulator's third-order autodiff dynamics and wins for tens of parameters (the
            torque splines); or "reverse" (`jax.value_and_grad`), which costs a few forward
            passes whatever the parameter count, so it wins for a network's hundred-odd weights
            once compiled.

    Returns:
        x: the final parameters, shape (n,).
        losses: the loss at each iteration, shape (iterations,).

    Raises:
        ValueError: gradient is neither "forward" nor "reverse".
    """
    if gradient not in ("forward", "reverse"):
        raise ValueError(f"gradient must be 'forward' or 'reverse', got {gradient!r}")
    optimizer = cosine_adam(learning_rate, iterations, final_fraction)

    def step(carry, _):
        x, state = carry
        if gradient == "forward":
            value, grad = loss(x), jax.jacfwd(loss)(x)
        else:
            value, grad = jax.value_and_grad(loss)(x)
        updates, state = optimizer.update(grad, state, x)
        return (optax.apply_updates(x, updates), state), value

    (x, _), losses = jax.lax.scan(step, (x0, optimizer.init(x0)), None, length=iterations)
    return x, losses
