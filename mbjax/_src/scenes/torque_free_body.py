"""The torque-free symmetric body of Borri 1990 §8.1.

Transverse to axial inertia 1.875, 15 rad/s about the symmetry axis and 10 rad/s about a
transverse axis, 6 s (about 100 rad of total rotation). Only the rotation is modelled: with the
reference point at the centre of mass, translation decouples (Borri 1990 §8.1).
"""

import jax
import jax.numpy as jnp
import numpy as np

from mbjax._src import lie
from mbjax._src.lie.coordinates import AbstractRotation, Quaternion
from mbjax._src.rigid import RigidBody, torque_free_motion

J_AXIAL = 1.0
J_TRANSVERSE = 1.875
OMEGA0 = (10.0, 0.0, 15.0)  # body frame; the symmetry axis is body z
DURATION = 6.0


def build(rotation: AbstractRotation = Quaternion()):
    """The scene: the torque-free symmetric body, starting at R0 = I with the angular velocity OMEGA0.

    Args:
        rotation: how the attitude is written in q, `mbjax.lie.Quaternion()` or
            `mbjax.lie.RotationVector()`.

    Returns:
        body: the `mbjax.rigid.RigidBody` (rotation only, about its centre of mass).
        q0: the initial attitude coordinates, shape (4,) or (3,).
        v0: the initial body angular velocity [rad/s], shape (3,).

    Raises:
        TypeError: rotation is not a rotation strategy instance.
    """
    body = RigidBody(1.0, np.diag([J_TRANSVERSE, J_TRANSVERSE, J_AXIAL]),
                     gravity=(0.0, 0.0, 0.0), fixed_point=True, rotation=rotation)
    q0, v0 = body.initial_state(np.eye(3), np.array(OMEGA0))
    return body, q0, v0


def exact_rotation(t):
    """The exact rotation R(t) in closed form (Borri 1990 eqs 8.7-8.8).

    Args:
        t: time [s], a scalar.

    Returns:
        R(t), body to space, shape (3, 3).
    """
    return torque_free_motion(J_AXIAL, J_TRANSVERSE, jnp.eye(3), jnp.array(OMEGA0), t)[0]


def rotation_error_matrix(R, t):
    """The angle between a computed rotation and the exact one (Borri 1990 Fig. 1's error).

    Args:
        R: the computed rotation, shape (3, 3).
        t: its time [s], a scalar.

    Returns:
        The angle [rad], a scalar.
    """
    return jnp.linalg.norm(lie.log(R @ exact_rotation(t).T, check=False))


def rotation_error(body: RigidBody, q, t):
    """The rotation error (`rotation_error_matrix`) of a state of the scene's body.

    Args:
        body: the body from `build`.
        q: its configuration, shape (4,) or (3,).
        t: the state's time [s], a scalar.

    Returns:
        The angle [rad], a scalar.
    """
    return rotation_error_matrix(body.rotation_matrix(q), t)


@jax.jit
def rotation_errors(body: RigidBody, qs, ts):
    """The rotation error along a trajectory.

    Args:
        body: the body from `build`.
        qs: configurations, shape (T, 4) or (T, 3).
        ts: their times [s], shape (T,).

    Returns:
        The angles [rad], shape (T,).
    """
    return jax.vmap(lambda q, t: rotation_error(body, q, t))(qs, ts)
