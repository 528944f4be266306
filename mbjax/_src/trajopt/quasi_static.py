"""A first guess that holds each knot's state still: Crocoddyl's `quasiStatic`."""

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax._src.trajopt.problem import Problem


def quasi_static(problem: Problem, xs: Array | None = None) -> Array:
    """The controls that hold each knot's configuration at rest: a first guess for `solve`.

    At knot k, with q its configuration and v = 0, the controls u_k and the contact forces f
    (the multipliers of the knot's closures: a stance's feet) are the least-norm solution of
    B u + A^T f = g(q), the actuation B, the closures' Jacobian A and the generalized gravity
    force g: the balance of forces with no motion (Crocoddyl's `quasiStatic`, pseudo-inverse and
    all). An impulse's knot, and a step where no control can hold the state, get the least-squares
    answer (zero for an impulse, which moves nothing).

    Args:
        problem: the problem, one phase or many (`Knot`s, `Impulse`s).
        xs: the states to hold, shape (N, nx) or (N + 1, nx) (the last ignored); None for x0 at
            every knot (Crocoddyl's examples' guess).

    Returns:
        The controls, shape (N, nu), clipped to the problem's bounds.

    Raises:
        ValueError: xs of the wrong shape.
    """
    N = problem.horizon
    xs = (jnp.broadcast_to(problem.x0, (N, problem.nx)) if xs is None
          else jnp.asarray(xs, dtype=float))
    if xs.shape not in ((N, problem.nx), (N + 1, problem.nx)):
        raise ValueError(f"xs must be (horizon, nx) = ({N}, {problem.nx}) or one longer, got "
                         f"shape {xs.shape}")
    return _quasi_static(problem, xs[:N])


@eqx.filter_jit
def _quasi_static(problem: Problem, xs: Array) -> Array:
    us = problem._map(lambda knot, x: knot.quasi_static_control(problem.split(x)[0], problem.nu),
                      xs)
    return jnp.clip(us, problem.lower, problem.upper)
