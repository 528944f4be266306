"""The heavy symmetric top of Simo and Wong (1991), a standard test of rotation integrators.

Inertia about the fixed point J = diag(5, 5, 1), m g l = 20 (here m = 20/9.81 kg, l = 1 m,
g = 9.81 m/s^2), initial attitude Lambda0 = exp([0.05, 0, 0]), body angular velocity
W0 = [0, 0, 50] rad/s, 10 s.
"""

import jax.numpy as jnp

from mbjax._src import lie
from mbjax._src.lie.coordinates import AbstractRotation, Quaternion
from mbjax._src.rigid import RigidBody

GRAVITY = 9.81
MGL = 20.0
INERTIA = (5.0, 5.0, 1.0)
LAMBDA0 = (0.05, 0.0, 0.0)
W0 = (0.0, 0.0, 50.0)
DURATION = 10.0


def build(rotation: AbstractRotation = Quaternion()):
    """The scene: the heavy top about its fixed point, spinning at W0 from the attitude exp(LAMBDA0).

    Args:
        rotation: how the attitude is written in q, `mbjax.lie.Quaternion()` or
            `mbjax.lie.RotationVector()`.

    Returns:
        body: the `mbjax.rigid.RigidBody`.
        q0: the initial attitude coordinates, shape (4,) or (3,).
        v0: the initial body angular velocity [rad/s], shape (3,).

    Raises:
        TypeError: rotation is not a rotation strategy instance.
    """
    body = RigidBody(MGL / GRAVITY, jnp.diag(jnp.array(INERTIA)), com=(0.0, 0.0, 1.0),
                     gravity=(0.0, 0.0, -GRAVITY), fixed_point=True, rotation=rotation)
    q0, v0 = body.initial_state(lie.exp(jnp.array(LAMBDA0)), jnp.array(W0))
    return body, q0, v0
