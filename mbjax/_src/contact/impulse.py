"""The impulse at touchdown: the velocity jump that brings contacts that start to rest."""

from collections.abc import Sequence

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.contact.contact import AbstractContact, on_ground, wrenches
from mbjax._src.contact.stance import _contacts
from mbjax._src.loops.constraints import Loops
from mbjax._src.loops.kkt import implicit_kkt
from mbjax._src.lie.inputs import check_unit_quaternions
from mbjax._src.model.model import Model, coordinates
from mbjax._src.rigid import rnea_derivatives
from mbjax._src.rigid.rnea import inverse_dynamics
from mbjax._src.rigid.system import TreeSystem


def impulse_map(model: Model, q: Array, v: Array, contacts: tuple) -> tuple[Array, Array]:
    """`impulse` without its checks, to trace inside other programs."""
    closures = tuple(c.closure(model, q) for c in contacts)
    loops = Loops(TreeSystem(model), closures)
    v_plus, Lambda = implicit_kkt((loops, q, v), _matrices, _residual)
    return v_plus, wrenches(closures, Lambda, *loops.tree.frames(q))


def _matrices(theta) -> tuple[Array, Array]:
    loops, q, _ = theta
    return loops.tree.mass_matrix(q), loops.jacobian(q)


def _residual(theta, v_plus: Array, Lambda: Array) -> tuple[Array, Array]:
    """The impulse map as a residual of (v+, Lambda) (`mbjax._src.loops.kkt`): (M (v+ - v) -
    A^t Lambda, A v+), the impulses that leave A v+ = 0. M (v+ - v) is the RNEA at rest
    without gravity, whose derivative in q is written out (`rnea_derivatives`, Pinocchio's
    `computeImpulseDynamicsDerivatives` likewise) rather than the mass matrix's."""
    loops, q, v = theta
    return (_momentum(loops.tree.model, q, v_plus - v) - loops.force(q, Lambda),
            loops.rate(q, v_plus))


def _momentum(model: Model, q: Array, jump: Array) -> Array:
    """M(q) jump, as the RNEA at zero velocity with no gravity."""
    still = eqx.tree_at(lambda m: m.gravity, model, jnp.zeros_like(model.gravity))
    rnea = (rnea_derivatives.inverse_dynamics if rnea_derivatives.applies(model)
            else inverse_dynamics)
    return rnea(still, q, jnp.zeros_like(jump), jump)


def impulse(model: Model, q: Array, v: Array, contacts: Sequence[AbstractContact]) -> tuple[Array, Array]:
    """The velocity just after contacts start, and the ground's impulses that make it.

    A perfectly inelastic touchdown of rigid bodies: the contacts' frames stop at once, in
    the impulse map v+ = v- + M^-1 A^t Lambda with A v+ = 0 (Crocoddyl's
    `ActionModelImpulseFwdDynamics`, Pinocchio's `impulseDynamics` with no restitution), where A
    is the contacts' constraint Jacobian and Lambda their impulses. The configuration does not
    move. Redundant contacts (more constraints than the motion has) get the least-squares
    impulses.

    Args:
        model: the robot.
        q: the configuration at touchdown, shape (nq,).
        v: the velocity just before, shape (nv,).
        contacts: every contact held after the touchdown (those already on the ground too,
            whose frames are at rest).

    Returns:
        (v_plus, impulses): the velocity after, shape (nv,); and the ground's impulse on each
        contact's frame, (angular; linear) in world components at its origin [N m s; N s],
        shape (len(contacts), 6).

    Raises:
        TypeError: contacts are not contacts.
        KeyError: a contact's frame is not in the model.
        ValueError: q or v of another shape, a quaternion in q not of unit norm, or a contact
            with a height not on its ground.
    """
    q, v = coordinates(model, q, "q"), coordinates(model, v, "v")
    check_unit_quaternions(q, model.quaternions(), "q")
    contacts = _contacts(contacts)
    on_ground(model, q, contacts)
    return _impulse(model, q, v, contacts)


_impulse = jax.jit(impulse_map)
