"""The ground's reactions along a multi-phase problem's trajectory."""

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax._src.trajopt.problem import Problem


def knot_wrenches(problem: Problem, xs: Array, us: Array) -> Array:
    """The ground's wrench on each contact's frame at every knot of a trajectory: what the
    stance of each knot (`mbjax.contact.stance`) pushes with under that knot's control, as
    `mbjax.contact.contact_wrenches` gives it (`AbstractKnot.wrenches`).

    Args:
        problem: a multi-phase problem whose stances hold the same contacts in the same order
            (those in the air with active=False), as a gait's do.
        xs: states, shape (N + 1, nx) or (N, nx) (a `Result`'s `xs`; the last is ignored).
        us: controls, shape (N, nu).

    Returns:
        The wrenches, (torque; force) in world components at each frame [N m; N], shape
            (N, number of contacts, 6): zero for a frame in the air, and at a knot that is an
            `Impulse` or whose system holds nothing on the ground (a flight).

    Raises:
        ValueError: xs or us of the wrong shape, a problem without stances, or stances of
            different numbers of contacts.
    """
    N = problem.horizon
    xs, us = jnp.asarray(xs, dtype=float), jnp.asarray(us, dtype=float)
    if xs.shape not in ((N, problem.nx), (N + 1, problem.nx)) or us.shape != (N, problem.nu):
        raise ValueError(f"xs must be ({N} or {N + 1}, {problem.nx}) and us ({N}, {problem.nu}), "
                         f"got {xs.shape} and {us.shape}")
    shapes = {s.shape for s in _shapes(problem) if s is not None}
    if len(shapes) != 1:
        raise ValueError("problem must hold stances (mbjax.contact.stance) of the same contacts, "
                         f"got {'none' if not shapes else 'stances of ' + str(sorted(shapes))}")
    return _wrenches(problem, xs[:N], us, shapes.pop())


def _shapes(problem: Problem) -> list:
    """Each phase's wrenches' shape (None for a phase without a stance)."""
    x, u = problem.x0, jnp.zeros(problem.nu)
    q, v = problem.split(x)
    return [eqx.filter_eval_shape(lambda k: k.wrenches(0.0, q, v, u), k) for k in problem._phases()]


@eqx.filter_jit
def _wrenches(problem: Problem, xs: Array, us: Array, shape: tuple) -> Array:
    def one(knot, x, u, t):
        w = knot.wrenches(t, *problem.split(x), u)
        return jnp.zeros(shape, x.dtype) if w is None else w

    return problem._map(one, xs, us, problem.times(xs.dtype))
