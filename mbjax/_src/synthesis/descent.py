"""Adam on a flat parameter vector, the Carpal Wrist synthesis' and controller's loop, with the
gradient taken by a strategy (`ForwardMode`, `ReverseMode`) and the learning rate cosine-decayed
(`mbjax.trajopt.cosine_adam`, which single shooting's Adam shares)."""

import abc

import equinox as eqx
import jax
import optax
from jax import Array

from mbjax._src.trajopt.shooting import cosine_adam


class AbstractGradient(eqx.Module):
    """How a descent takes the gradient of its loss: `ForwardMode()` or `ReverseMode()`, passed as
    `gradient=` (`mbjax.wrist.train_controller`).

    A subclass implements `value_and_grad`; both modes give the same gradient up to rounding,
    and differ in what they cost (see each).
    """

    @abc.abstractmethod
    def value_and_grad(self, loss, x: Array) -> tuple[Array, Array]:
        """The loss and its gradient at x.

        Args:
            loss: the scalar loss, a function of x.
            x: the parameters, shape (n,).

        Returns:
            value: loss(x), a scalar.
            grad: its gradient, shape (n,).
        """


class ForwardMode(AbstractGradient):
    """The gradient by forward mode (`jax.jacfwd`): one tangent per parameter.

    It compiles faster than reverse mode through the simulator's third-order autodiff dynamics
    and wins for tens of parameters (the Carpal Wrist's torque splines).
    """

    def value_and_grad(self, loss, x: Array) -> tuple[Array, Array]:
        """The loss and its gradient at x.

        Args:
            loss: the scalar loss, a function of x.
            x: the parameters, shape (n,).

        Returns:
            (loss(x), jax.jacfwd(loss)(x)).
        """
        return loss(x), jax.jacfwd(loss)(x)


class ReverseMode(AbstractGradient):
    """The gradient by reverse mode (`jax.value_and_grad`): a few forward passes whatever the
    parameter count, so it wins for a network's hundred-odd weights once compiled."""

    def value_and_grad(self, loss, x: Array) -> tuple[Array, Array]:
        """The loss and its gradient at x.

        Args:
            loss: the scalar loss, a function of x.
            x: the parameters, shape (n,).

        Returns:
            jax.value_and_grad(loss)(x).
        """
        return jax.value_and_grad(loss)(x)


def check_gradient(gradient) -> None:
    """Refuse what is not a gradient strategy (the strings "forward" and "reverse" of old).

    Args:
        gradient: what was passed as `gradient=`.

    Raises:
        TypeError: gradient is not an `AbstractGradient` instance.
    """
    if not isinstance(gradient, AbstractGradient):
        hint = " (an instance: ReverseMode(), not ReverseMode)" if isinstance(gradient, type) else ""
        raise TypeError(f"gradient must be a gradient strategy, ForwardMode() or ReverseMode()"
                        f"{hint}, got {gradient!r}")


def adam_descent(loss, x0: Array, *, learning_rate: float, iterations: int, final_fraction: float,
                 gradient: AbstractGradient = ForwardMode()):
    """Adam steps on loss(x), the learning rate cosine-decayed, as one `lax.scan`.

    Args:
        loss: the scalar loss, a function of x.
        x0: the starting parameters, shape (n,).
        learning_rate: the first learning rate.
        iterations: the number of steps.
        final_fraction: the fraction of learning_rate it decays to.
        gradient: how the gradient is taken, `ForwardMode()` (`jax.jacfwd`), which compiles
            faster than reverse mode through the simulator's third-order autodiff dynamics and
            wins for tens of parameters (the torque splines); or `ReverseMode()`
            (`jax.value_and_grad`), which costs a few forward passes whatever the parameter
            count, so it wins for a network's hundred-odd weights once compiled.

    Returns:
        x: the final parameters, shape (n,).
        losses: the loss at each iteration, shape (iterations,).

    Raises:
        TypeError: gradient is not a gradient strategy (a string, say).
    """
    check_gradient(gradient)
    optimizer = cosine_adam(learning_rate, iterations, final_fraction)

    def step(carry, _):
        x, state = carry
        value, grad = gradient.value_and_grad(loss, x)
        updates, state = optimizer.update(grad, state, x)
        return (optax.apply_updates(x, updates), state), value

    (x, _), losses = jax.lax.scan(step, (x0, optimizer.init(x0)), None, length=iterations)
    return x, losses
