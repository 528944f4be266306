"""A stance: a tree with some of its frames held on the ground, and the ground's reactions."""

from collections.abc import Sequence

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax._src.contact.contact import AbstractContact, on_ground, wrenches
from mbjax._src.contact.friction import cone_flags, friction
from mbjax._src.loops.coupled import Coupled
from mbjax._src.loops.method import AbstractLoopMethod
from mbjax._src.loops.system import ClosedSystem
from mbjax._src.lie.inputs import check_unit_quaternions
from mbjax._src.model.model import Model, coordinates
from mbjax._src.system.tree_system import AbstractTreeSystem

# Crocoddyl's contact models stabilize with Baumgarte gains (Kp, Kd) = (0, 50): the contact's
# acceleration error obeys e_ddot + Kd e_dot + Kp e = 0, which is `Coupled`'s
# e_ddot + 2 alpha e_dot + beta^2 e = 0 with alpha = Kd / 2 and beta = sqrt(Kp)
CROCODDYL_GAINS = (25.0, 0.0)


def _contacts(contacts) -> tuple[AbstractContact, ...]:
    contacts = tuple(contacts)
    if not contacts or not all(isinstance(c, AbstractContact) for c in contacts):
        raise TypeError("contacts must be one or more PointContact(...) or SurfaceContact(...), "
                        f"got {contacts!r}")
    return contacts


class Grip(eqx.Module):
    """A stance's watch (`ClosedSystem`'s `watch`), which holds its contacts: with a friction
    coefficient mu, `Status.PULLING` where a contact's normal force is negative,
    `Status.SLIPPING` where its tangential force exceeds mu times the normal one (the exact
    cone), each beyond round-off (1e-9 of the force); no flags without mu."""

    contacts: tuple
    mu: Array | None

    def __call__(self, loops, q: Array, multipliers: Array) -> Array:
        if self.mu is None:
            return jnp.zeros((), jnp.int32)
        w = wrenches(loops.closures[:len(self.contacts)], multipliers, *loops.tree.frames(q))
        return cone_flags(w[:, 3:], jnp.stack([c.normal for c in self.contacts]), self.mu)


def stance(tree: AbstractTreeSystem, q: Array, contacts: Sequence[AbstractContact], *,
           method: AbstractLoopMethod | None = None, projection: bool = False,
           mu=None) -> ClosedSystem:
    """A contact phase: `tree` with each contact's frame held where it is in configuration q.

    Each contact becomes a cut joint with the ground (`AbstractContact.closure`), and the phase
    is a `ClosedSystem` of the tree and those closures, in the order of `contacts`, which holds
    the contacts (`stance_contacts`): its multipliers are the ground's reactions on them
    (`contact_wrenches`), which the contact residuals of `mbjax.trajopt` read.

    Args:
        tree: the robot, a rigid tree system such as `TreeSystem(model, control)`.
        q: the configuration where the phase starts, shape (nq,).
        contacts: the frames on the ground, `PointContact`s and `SurfaceContact`s.
        method: the loop method; None for `Coupled(baumgarte=(25.0, 0.0))`, the
            stabilization of Crocoddyl's contact models, (Kp, Kd) = (0, 50). `Stabilized()` is
            Anderson 1993's O(n + m^3) route.
        projection: project (q, v) onto the contacts after each step.
        mu (float | None): the friction coefficient: `mbjax.simulate` then flags a saved state
            where a contact pulls on the ground (`Status.PULLING`) or its force leaves the
            friction cone (`Status.SLIPPING`), failures both, the contact model's assumptions
            broken; None for no watch.

    Returns:
        The phase, a `ClosedSystem`.

    Raises:
        TypeError: tree is not a rigid tree system, or contacts are not contacts.
        KeyError: a contact's frame is not in the model.
        ValueError: mu is not positive, q is not of shape (nq,), a quaternion in q is not of
            unit norm, or a contact with a height is not on its ground.
    """
    if not (isinstance(tree, AbstractTreeSystem) and isinstance(getattr(tree, "model", None), Model)):
        raise TypeError(f"tree must be a rigid tree system such as TreeSystem(model), got "
                        f"{type(tree).__name__}")
    contacts = _contacts(contacts)
    q = coordinates(tree.model, q, "q")
    check_unit_quaternions(q, tree.model.quaternions(), "q")
    on_ground(tree.model, q, contacts)
    closures = tuple(c.closure(tree.model, q) for c in contacts)
    method = Coupled(baumgarte=CROCODDYL_GAINS) if method is None else method
    watch = Grip(contacts, None if mu is None else friction(mu))
    return ClosedSystem(tree, closures, method, projection, watch=watch)


def contact_wrenches(phase: ClosedSystem, t, q: Array, v: Array) -> Array:
    """The ground's wrench on each of a stance's contacts, (torque; force) in world components
    at the frame's origin: the contacts' multipliers (Pinocchio's `constraintDynamics` forces,
    in its LOCAL_WORLD_ALIGNED frame).

    Args:
        phase: the stance, as `stance` made it.
        t: time [s], a scalar.
        q: configuration, shape (nq,).
        v: the phase's velocity state (the joint velocities for `Coupled`).

    Returns:
        The wrenches, shape (len(contacts), 6), in the order `stance` took the contacts; a point
            contact's torque is zero.

    Raises:
        ValueError: the phase is not a stance.
    """
    return stance_wrenches(phase, q, phase.multipliers(t, q, v))


def stance_wrenches(phase: ClosedSystem, q: Array, multipliers: Array) -> Array:
    """The ground's wrench on each of a stance's contacts at configuration q from the phase's
    multipliers, as `contact_wrenches` gives them, shape (len(contacts), 6)."""
    n = len(stance_contacts(phase))
    return wrenches(phase.closures[:n], multipliers, *phase.tree.frames(q))


def is_stance(system) -> bool:
    """Whether a system is a stance, as `stance` makes it."""
    return isinstance(getattr(system, "watch", None), Grip)          # only a stance has one


def stance_contacts(phase, name: str = "phase") -> tuple[AbstractContact, ...]:
    """The contacts a stance holds, in order.

    Args:
        phase: a stance, as `stance` made it.
        name: the argument's name, for the error.

    Returns:
        The contacts, a tuple.

    Raises:
        ValueError: naming `name`, where phase is not a stance (`stance(tree, q, contacts)`).
    """
    if not is_stance(phase):
        raise ValueError(f"{name} must be a stance (mbjax.contact.stance(tree, q, contacts)), got "
                         f"{type(phase).__name__}")
    return phase.watch.contacts
