"""What every driver asks of its accuracy arguments (dt, rtol, atol) and how it estimates its error:
concrete numbers checked once, and step doubling on a few sampled states."""

import math

import jax
import jax.numpy as jnp
import numpy as np


# the most states a step-doubling error estimate samples along a run (`simulate`, `solve_tfe`)
ERROR_SAMPLES = 8


def sample_indices(n: int) -> np.ndarray:
    """Up to `ERROR_SAMPLES` indices spread evenly over range(n)."""
    if n < 1:
        return np.zeros(0, int)
    return np.unique(np.linspace(0, n - 1, min(ERROR_SAMPLES, n)).round().astype(int))


def number(value, name: str) -> float:
    """A concrete, finite real number (dt, t0, t1, rtol, atol: they fix the shape of the
    computation or its checks), or an error naming it."""
    if isinstance(value, jax.core.Tracer):
        raise TypeError(f"{name} must be a concrete number, not a traced value (differentiate or "
                        "vmap the state and the parameters)")
    try:
        if isinstance(value, str | bytes):
            raise TypeError
        x = float(value)
    except (TypeError, ValueError) as error:
        raise TypeError(f"{name} must be a real number, got {value!r:.60}") from error
    if not math.isfinite(x):
        raise ValueError(f"{name} must be finite, got {x}")
    return x


def tolerances(rtol, atol) -> tuple[float, float]:
    """(rtol, atol) as floats, None as 0; an error unless both are finite, non-negative and not
    both zero."""
    rtol, atol = (0.0 if x is None else number(x, name) for x, name in ((rtol, "rtol"),
                                                                        (atol, "atol")))
    if not (rtol >= 0 and atol >= 0 and rtol + atol > 0):
        raise ValueError(f"rtol and atol must be finite, non-negative and not both zero, got "
                         f"{rtol}, {atol}")
    return rtol, atol


def doubled(step, state, t, h, span):
    """(one step of h, the first of two of h / 2, the second) from `state` at t, for step
    doubling: step(state, t, h) -> state, whose end time is t + span (span = h for a time
    step; a time element of node spacing h spans a multiple of it). The three steps run as one
    scan, so `step` is traced (and compiled) once, not three times."""
    def one(previous, k):
        start = jax.tree.map(lambda a, b: jnp.where(k == 2, a, b), previous, state)
        new = step(start, jnp.where(k == 2, t + span / 2, t), jnp.where(k == 0, h, h / 2))
        return new, new

    _, ends = jax.lax.scan(one, state, jnp.arange(3))
    return tuple(jax.tree.map(lambda x, i=i: x[i], ends) for i in range(3))
