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
    """(body, q0, u0) of the scene."""
    body = RigidBody(MGL / GRAVITY, jnp.diag(jnp.array(INERTIA)), com=(0.0, 0.0, 1.0),
                     gravity=(0.0, 0.0, -GRAVITY), fixed_point=True, rotation=rotation)
    q0, u0 = body.initial_state(lie.exp(jnp.array(LAMBDA0)), jnp.array(W0))
    return body, q0, u0
