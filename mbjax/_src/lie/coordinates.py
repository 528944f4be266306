"""Rotation coordinates as strategies: how a body's orientation is stored in its configuration q.

`Quaternion()`: unit quaternions (w, x, y, z), rot_dot = rot * (0, Omega) / 2, normalized after a
step. `RotationVector()`: Borri 1990's rotation vector r, r_dot = Gamma(r)^-T Omega (eqs 2.8, A.21,
A.24), rescaled to |r| <= pi after a step (eq A.29). Both give the chart about a configuration that
implicit integrators use: R = R0 exp(xi), a body-frame increment.
"""

import abc

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax._src.lie import quaternion as quat
from mbjax._src.lie import rotation_vector as rv


class AbstractRotation(eqx.Module):
    """How a body's orientation is written in its configuration q (a strategy).

    Passed as `rotation=` to the systems that carry an orientation (`mbjax.rigid.RigidBody`,
    the scenes' `build`); the concrete strategies `Quaternion()` and `RotationVector()` take
    no arguments. The class attribute `size` is the number of coordinates.

    The strategies:
        `Quaternion()`: unit quaternions (w, x, y, z), rot_dot = rot * (0, Omega) / 2,
        normalized after a step. `RotationVector()`: Borri 1990's rotation vector r,
        r_dot = Gamma(r)^-T Omega (eqs 2.8, A.21, A.24), rescaled to |r| <= pi after a step
        (eq A.29). Both give the chart about a configuration that implicit integrators use:
        R = R0 exp(xi), a body-frame increment (`retract`, and `difference` its inverse).
    """

    size: eqx.AbstractClassVar[int]

    @abc.abstractmethod
    def to_matrix(self, rot: Array) -> Array:
        """The rotation matrix of the coordinates.

        Args:
            rot: the orientation's coordinates, shape (size,).

        Returns:
            R, body to space, shape (3, 3).
        """

    @abc.abstractmethod
    def from_matrix(self, R: Array) -> Array:
        """The coordinates of a rotation matrix.

        Args:
            R: rotation matrix, body to space, shape (3, 3).

        Returns:
            The coordinates, shape (size,).
        """

    @abc.abstractmethod
    def rate(self, rot: Array, Omega: Array) -> Array:
        """The coordinates' rate for a body-frame angular velocity.

        Args:
            rot: the coordinates, shape (size,).
            Omega: body-frame angular velocity, shape (3,) [rad/s].

        Returns:
            d rot / dt, shape (size,).
        """

    @abc.abstractmethod
    def retract(self, rot0: Array, xi: Array) -> Array:
        """The coordinates of R0 exp(xi): a body-frame rotation increment applied to rot0.

        Args:
            rot0: the coordinates of R0, shape (size,).
            xi: body-frame rotation vector, shape (3,).

        Returns:
            The coordinates of R0 exp(xi), shape (size,).
        """

    @abc.abstractmethod
    def difference(self, rot0: Array, rot1: Array) -> Array:
        """The body-frame rotation vector xi with R1 = R0 exp(xi), |xi| <= pi (`retract`'s inverse).

        Args:
            rot0: the coordinates of R0, shape (size,).
            rot1: the coordinates of R1, shape (size,).

        Returns:
            xi, shape (3,).
        """

    @abc.abstractmethod
    def normalize(self, rot: Array) -> Array:
        """The canonical coordinates of the same rotation (unit length, principal angle).

        Args:
            rot: the coordinates, shape (size,).

        Returns:
            The normalized coordinates, shape (size,).
        """


class Quaternion(AbstractRotation):
    """Orientations as unit quaternions (w, x, y, z), normalized after a step (4 coordinates).

    rot_dot = rot * (0, Omega) / 2. Takes no arguments.
    """

    size = 4

    def to_matrix(self, rot):
        return quat.quat_to_matrix(rot)

    def from_matrix(self, R):
        return quat.quat_from_matrix(R)

    def rate(self, rot, Omega):
        return 0.5 * quat.quat_multiply(rot, jnp.concatenate([jnp.zeros(1, Omega.dtype), Omega]))

    def retract(self, rot0, xi):
        return quat.quat_multiply(rot0, quat.quat_from_rotvec(xi))

    def difference(self, rot0, rot1):
        return quat.rotvec_from_quat(quat.quat_multiply(quat.quat_conjugate(quat.quat_normalize(rot0)),
                                                        quat.quat_normalize(rot1)))

    def normalize(self, rot):
        return quat.quat_normalize(rot)


class RotationVector(AbstractRotation):
    """Orientations as Borri 1990's rotation vector r, R = exp(r x I) (App. A; 3 coordinates).

    r_dot = Gamma(r)^-T Omega (eqs 2.8, A.21, A.24), rescaled to |r| <= pi after a step
    (eq A.29). Takes no arguments.
    """

    size = 3

    def to_matrix(self, rot):
        return rv.exp(rot)

    def from_matrix(self, R):
        return rv.log(R)

    def rate(self, rot, Omega):
        return rv.gamma_inv(rot).T @ Omega

    def retract(self, rot0, xi):
        return quat.rotvec_from_quat(quat.quat_multiply(quat.quat_from_rotvec(rot0),
                                                        quat.quat_from_rotvec(xi)))

    def difference(self, rot0, rot1):
        return quat.rotvec_from_quat(quat.quat_multiply(
            quat.quat_conjugate(quat.quat_from_rotvec(rot0)), quat.quat_from_rotvec(rot1)))

    def normalize(self, rot):
        return rv.rescale(rot)
