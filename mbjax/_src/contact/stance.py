"""A stance: a tree with some of its frames held on the ground, and the ground's reactions."""

from collections.abc import Sequence

import jax.numpy as jnp
from jax import Array

from mbjax._src.contact.contact import AbstractContact, wrenches
from mbjax._src.loops.coupled import Coupled
from mbjax._src.loops.method import AbstractLoopMethod
from mbjax._src.loops.system import ClosedSystem
from mbjax._src.model.model import Model
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


def stance(tree: AbstractTreeSystem, q: Array, contacts: Sequence[AbstractContact], *,
           method: AbstractLoopMethod | None = None, projection: bool = False) -> ClosedSystem:
    """A contact phase: `tree` with each contact's frame held where it is in configuration q.

    Each contact becomes a cut joint with the ground (`AbstractContact.closure`), and the phase
    is a `ClosedSystem` of the tree and those closures, in the order of `contacts`; its
    multipliers are the ground's reactions (`contact_wrenches`).

    Args:
        tree: the robot, a rigid tree system such as `TreeSystem(model, control)`.
        q: the configuration where the phase starts, shape (nq,).
        contacts: the frames on the ground, `PointContact`s and `SurfaceContact`s.
        method: the loop method; None for `Coupled(baumgarte=(25.0, 0.0))`, the
            stabilization of Crocoddyl's contact models, (Kp, Kd) = (0, 50). `Stabilized()` is
            Anderson 1993's O(n + m^3) route.
        projection: project (q, v) onto the contacts after each step.

    Returns:
        The phase, a `ClosedSystem`.

    Raises:
        TypeError: tree is not a rigid tree system, or contacts are not contacts.
        KeyError: a contact's frame is not in the model.
    """
    if not (isinstance(tree, AbstractTreeSystem) and isinstance(getattr(tree, "model", None), Model)):
        raise TypeError(f"tree must be a rigid tree system such as TreeSystem(model), got "
                        f"{type(tree).__name__}")
    contacts = _contacts(contacts)
    closures = tuple(c.closure(tree.model, jnp.asarray(q, float)) for c in contacts)
    method = Coupled(baumgarte=CROCODDYL_GAINS) if method is None else method
    return ClosedSystem(tree, closures, method, projection)


def contact_wrenches(system: ClosedSystem, contacts: Sequence[AbstractContact], t, q: Array,
                     u: Array) -> Array:
    """The ground's wrench on each contact's frame, (torque; force) in world components at the
    frame's origin: the contacts' multipliers (Pinocchio's `constraintDynamics` forces, in its
    LOCAL_WORLD_ALIGNED frame).

    Args:
        system: the phase, as `stance` made it from the same contacts.
        contacts: the contacts, in the order `stance` took them.
        t: time [s], a scalar.
        q: configuration, shape (nq,).
        u: the phase's velocity state (the joint velocities for `Coupled`).

    Returns:
        The wrenches, shape (len(contacts), 6); a point contact's torque is zero.

    Raises:
        ValueError: the system's first closures do not match the contacts' sizes.
    """
    contacts = _contacts(contacts)
    closures = system.closures[:len(contacts)]
    if len(closures) < len(contacts) or any(
            c.kind != j.kind for c, j in zip(contacts, closures, strict=False)):
        raise ValueError("system must be the stance of these contacts (stance(tree, q, contacts))")
    return wrenches(contacts, closures, system.multipliers(t, q, u))
