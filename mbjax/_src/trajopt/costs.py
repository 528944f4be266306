"""Cost functions as a `Problem` reads them: a scalar, or residuals meaning 1/2 |r|^2; and their
sums."""

from collections.abc import Callable

import equinox as eqx
import jax.numpy as jnp
from jax import Array


def as_cost(cost, name: str) -> Callable:
    """A cost function, or a tuple of them as their `Sum`; a TypeError naming it otherwise."""
    cost = Sum(tuple(cost)) if isinstance(cost, list | tuple) else cost
    if not callable(cost):
        raise TypeError(f"{name} must be a callable returning a scalar cost or a vector of "
                        "residuals, or a tuple of them")
    return cost


def _value(c: Array) -> Array:
    """A cost function's output as a cost: itself, or 1/2 |r|^2 for residuals r."""
    c = jnp.asarray(c)
    if c.ndim > 1:
        raise ValueError(f"a cost must return a scalar or a vector of residuals, got shape {c.shape}")
    return 0.5 * c @ c if c.ndim == 1 else c


class Sum(eqx.Module):
    """A sum of cost functions: their residuals stacked where each returns residuals, else the
    sum of their values (a residual vector r counting 1/2 |r|^2)."""

    terms: tuple

    def __call__(self, *args) -> Array:
        values = [jnp.asarray(term(*args)) for term in self.terms]
        if all(v.ndim == 1 for v in values):
            return jnp.concatenate(values)
        return sum(_value(v) for v in values)
