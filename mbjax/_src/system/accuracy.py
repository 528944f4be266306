"""What every driver asks of its accuracy arguments (dt, rtol, atol) and how it checks its accuracy:
concrete numbers checked once; by default, the step against the motion's rate at every step
(`step_ratio`); with a tolerance, step doubling on a few sampled states."""

import functools
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


# The default check (no tolerance asked): `simulate`, `solve_tfe` and `mbjax.trajopt.solve` flag
# INACCURATE past these loose limits (benchmarks/README.md, section "accuracy", measures
# their false alarms over every scene and reproduction, none, and their cost).
# The step times the motion's fastest rate, estimated from consecutive increments of the state:
# 1 is about six steps per period of an oscillation, where a fourth-order method already errs by
# about 1 % a step; runs past their stability limit read 1.2 to 3.5 (benchmarks/README.md).
RESOLUTION_LIMIT = 1.0
# steps in a row the estimate must exceed the limit (a kick, a control switch, a wrap is one)
SUSTAINED = 3
# steps a part must have been in motion before its ratio counts (`step_ratio`)
ONSET = 8
# the invariants' drift relative to the motion's scale (`mbjax._src.system.invariants`), the
# bound `solve_tfe` holds by default
DRIFT_LIMIT = 0.1
# the bound `simulate` holds the drift to without a tolerance (tests/tools/drift_cost.py measures
# it over the tour's scenes): their resolved runs drift by 7.2e-5 at most, and the 7-link chain
# that RK4 leaves 1.5 rad from the converged run at dt = 0.04 s drifts by 4.7e-2 (issue 60);
# 1e-2 is a loss or gain of 1 % of the motion's scale
DEFAULT_DRIFT_LIMIT = 1e-2


def step_ratio(previous, increment, state, moved):
    """The step times the motion's rate from consecutive increments d of a state sequence:
    |d_k - d_(k-1)| / |d_(k-1)|, which for a smooth motion sampled every h is h |y''| / |y'|
    (h omega for an oscillation), whatever the state's units.

    Each argument is a tuple of the state's parts (the configuration, the velocity), and the
    ratio is the least of the parts': an unresolved or unstable motion shows in all of them,
    while a control switched at every step jumps only the velocity's increments and a turning
    point only the configuration's. A part counts once its increments have exceeded
    sqrt(eps) (1 + |y|) for `ONSET` steps in a row: at rest it says nothing, and a motion
    starting from rest like t^p reads about p / k at its k-th step. 0 where no part counts.
    Norms over the first axis (a batch of states, one per column, gives a ratio per column).

    Returns:
        (the ratio, the parts' updated counts of steps in motion).
    """
    squares, counts = [], []          # squared norms: one square root per step, not six
    for d0, d1, y, n in zip(previous, increment, state, moved):
        size = jnp.sum(d0 * d0, axis=0)
        eps = jnp.finfo(y.dtype).eps
        moving = size > eps * (1.0 + jnp.sqrt(jnp.sum(y * y, axis=0))) ** 2
        n = jnp.where(moving, n + 1, 0)
        squares.append(jnp.where(n > ONSET, jnp.sum((d1 - d0) ** 2, axis=0)
                                 / jnp.where(moving, size, 1.0), jnp.inf))
        counts.append(n)
    least = functools.reduce(jnp.minimum, squares)
    return jnp.sqrt(jnp.where(jnp.isinf(least), 0.0, least)), tuple(counts)


def sustained(ratios: jax.Array) -> jax.Array:
    """Each step's ratio held for `SUSTAINED` steps: the least of it and the previous ones
    (leading axis: steps); 0 for the first."""
    held = ratios
    for lag in range(1, SUSTAINED):
        held = jnp.minimum(held, jnp.concatenate([jnp.zeros(lag, ratios.dtype), ratios[:-lag]]))
    return held


def resolution(*parts: jax.Array, jumps=None) -> jax.Array:
    """The largest sustained step ratio along a state sequence given by its parts (T, n_i)
    (configurations, velocities): `step_ratio` between every three consecutive states, held
    for `SUSTAINED` steps. `jumps` (T - 1,) marks the transitions that are discontinuous by
    design (an impulse at touchdown: the velocity jumps in no time); a ratio whose three states
    span one is not a step's error and counts 0."""
    parts = tuple(jax.lax.stop_gradient(x) for x in parts)
    d = tuple(jnp.diff(x, axis=0) for x in parts)
    across = (jnp.zeros(len(parts[0]) - 2, bool) if jumps is None
              else jnp.asarray(jumps[:-1]) | jnp.asarray(jumps[1:]))

    def one(moved, k):
        ratio, moved = step_ratio(tuple(x[k] for x in d), tuple(x[k + 1] for x in d),
                                  tuple(x[k + 1] for x in parts), moved)
        return moved, jnp.where(across[k], 0.0, ratio)

    zeros = tuple(jnp.zeros((), int) for _ in parts)
    _, ratios = jax.lax.scan(one, zeros, jnp.arange(len(parts[0]) - 2))
    return jnp.max(sustained(ratios), initial=0.0)
