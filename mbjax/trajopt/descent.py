"""The one optimisation loop of `mbjax.trajopt`: Adam on a flat parameter vector."""

import jax
import optax
from jax import Array


def adam_descent(loss, x0: Array, *, learning_rate: float, iterations: int, final_fraction: float):
    """(x, loss per iteration): `iterations` Adam steps on loss(x), the learning rate
    cosine-decayed to `final_fraction` of itself, as one `lax.scan`. The gradient is forward mode
    (`jax.jacfwd`): for the tens to hundreds of parameters here it compiles several times faster
    than reverse mode through the simulator's third-order autodiff dynamics."""
    optimizer = optax.adam(optax.cosine_decay_schedule(learning_rate, iterations, alpha=final_fraction))

    def step(carry, _):
        x, state = carry
        value, grad = loss(x), jax.jacfwd(loss)(x)
        updates, state = optimizer.update(grad, state, x)
        return (optax.apply_updates(x, updates), state), value

    (x, _), losses = jax.lax.scan(step, (x0, optimizer.init(x0)), None, length=iterations)
    return x, losses
