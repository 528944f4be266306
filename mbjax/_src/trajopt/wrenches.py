"""The ground's reactions along a multi-phase problem's trajectory."""

from collections.abc import Sequence

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax._src.contact.contact import AbstractContact
from mbjax._src.contact.stance import _contacts, contact_wrenches
from mbjax._src.control import Constant
from mbjax._src.trajopt.knots import Knot
from mbjax._src.trajopt.problem import Problem


def knot_wrenches(problem: Problem, xs: Array, us: Array,
                  contacts: Sequence[AbstractContact]) -> Array:
    """The ground's wrench on each contact's frame at every knot of a trajectory: what the
    stance of each knot (`mbjax.contact.stance`) pushes with under that knot's control, as
    `mbjax.contact.contact_wrenches` gives it.

    Args:
        problem: a multi-phase problem whose every stance was made from `contacts` (the same
            frames in the same order, those in the air with active=False).
        xs: states, shape (N + 1, nx) or (N, nx) (a `Result`'s `xs`; the last is ignored).
        us: controls, shape (N, nu).
        contacts: the contacts, in the order the stances took them.

    Returns:
        The wrenches, (torque; force) in world components at each frame [N m; N], shape
            (N, len(contacts), 6): zero for a frame in the air, and at a knot that is an
            `Impulse` or whose system holds nothing on the ground (a flight).

    Raises:
        ValueError: xs or us of the wrong shape, or a stance not made from `contacts`.
    """
    contacts = _contacts(contacts)
    N = problem.horizon
    xs, us = jnp.asarray(xs, dtype=float), jnp.asarray(us, dtype=float)
    if xs.shape not in ((N, problem.nx), (N + 1, problem.nx)) or us.shape != (N, problem.nu):
        raise ValueError(f"xs must be ({N} or {N + 1}, {problem.nx}) and us ({N}, {problem.nu}), "
                         f"got {xs.shape} and {us.shape}")
    return _wrenches(problem, xs[:N], us, contacts)


@eqx.filter_jit
def _wrenches(problem: Problem, xs: Array, us: Array, contacts: tuple) -> Array:
    def one(knot, x, u, t):
        system = getattr(knot, "system", None)
        if not isinstance(knot, Knot) or not hasattr(system, "closures"):
            return jnp.zeros((len(contacts), 6), x.dtype)
        q, v = problem.split(x)
        system = system.with_control(Constant(u)).hold(t, q, v)
        return contact_wrenches(system, contacts, t, q, system.initial_state(q, v, t))

    return problem._map(one, xs, us, problem.times(xs.dtype))
