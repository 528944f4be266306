"""The vertical spinning top of Borri 1990 §7-8 (Tables 1-2).

A symmetric top on a fixed suspension point, spinning steadily about the upward vertical e_3 at
the rate Omega, is linearized about that steady motion. Its transverse motion has the exact
exponents s = i [Omega J_a +- sqrt((Omega J_a)^2 - (2 J_t omega)^2)] / (2 J_t), omega = sqrt(m g d /
J_t) (eq 7.11): stable above the critical spin Omega_c = 2 J_t omega / J_a, where the two merge at
s = i omega. The tables use omega = 5/3 ("exact eigenvalues +- i 5/3"); only omega matters, so
J_t = 1, J_a = 0.4 and m g d = 25/9 here.
"""

import jax.numpy as jnp

from mbjax._src.lie.coordinates import AbstractRotation, Quaternion
from mbjax._src.rigid import RigidBody
from mbjax._src.tfe import Body

GRAVITY = 9.81
MASS = 1.0
J_TRANSVERSE = 1.0
J_AXIAL = 0.4
OMEGA = 5.0 / 3.0                                 # sqrt(m g d / J_t), eq 7.11
D = OMEGA**2 * J_TRANSVERSE / (MASS * GRAVITY)   # suspension point to centre of mass
CRITICAL_SPIN = 2.0 * J_TRANSVERSE * OMEGA / J_AXIAL


def rigid_body(rotation: AbstractRotation = Quaternion()) -> RigidBody:
    """The top as a `RigidBody` about its suspension point, centre of mass D above it.

    Args:
        rotation: how the attitude is written in q, `mbjax.lie.Quaternion()` or
            `mbjax.lie.RotationVector()`.

    Returns:
        The `mbjax.rigid.RigidBody`.
    """
    return RigidBody(MASS, jnp.diag(jnp.array([J_TRANSVERSE, J_TRANSVERSE, J_AXIAL])),
                     com=(0.0, 0.0, D), gravity=(0.0, 0.0, -GRAVITY), fixed_point=True,
                     rotation=rotation)


def build() -> Body:
    """The scene: the top as a `mbjax.tfe.Body` about its suspension point.

    Returns:
        The `Body` (fixed point, 3 dof).
    """
    return Body.from_rigid(rigid_body())


def exact_boundaries(dt):
    """The stability boundaries of the two-node primal element (Borri 1990 eq 7.10).

    The spin rates at which the discriminant D of eq 7.10 vanishes.

    Args:
        dt: the node spacing [s].

    Returns:
        exact: the boundary with exact integration [rad/s].
        reduced: with reduced integration (the physical one) [rad/s].
        physical: the critical spin CRITICAL_SPIN [rad/s].
    """
    exact = CRITICAL_SPIN * jnp.sqrt(1.0 + (OMEGA * jnp.asarray(dt)) ** 2 / 12.0)
    return exact, jnp.full_like(exact, CRITICAL_SPIN), CRITICAL_SPIN
