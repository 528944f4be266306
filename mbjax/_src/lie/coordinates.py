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
    """How an orientation is written in q; see the module."""

    size: eqx.AbstractClassVar[int]

    @abc.abstractmethod
    def to_matrix(self, rot: Array) -> Array:
        """The rotation matrix R (3, 3), body to space, of coordinates `rot` (size,)."""

    @abc.abstractmethod
    def from_matrix(self, R: Array) -> Array:
        """The coordinates (size,) of the rotation matrix R (3, 3)."""

    @abc.abstractmethod
    def rate(self, rot: Array, Omega: Array) -> Array:
        """d rot / dt (size,) for the body-frame angular velocity Omega (3,)."""

    @abc.abstractmethod
    def retract(self, rot0: Array, xi: Array) -> Array:
        """The coordinates of R0 exp(xi): a body-frame rotation vector xi (3,) applied to rot0."""

    @abc.abstractmethod
    def normalize(self, rot: Array) -> Array:
        """The canonical coordinates of the same rotation (unit length, principal angle)."""


class Quaternion(AbstractRotation):
    """Unit quaternions (w, x, y, z)."""

    size = 4

    def to_matrix(self, rot):
        return quat.quat_to_matrix(rot)

    def from_matrix(self, R):
        return quat.quat_from_matrix(R)

    def rate(self, rot, Omega):
        return 0.5 * quat.quat_multiply(rot, jnp.concatenate([jnp.zeros(1, Omega.dtype), Omega]))

    def retract(self, rot0, xi):
        return quat.quat_multiply(rot0, quat.quat_from_rotvec(xi))

    def normalize(self, rot):
        return quat.quat_normalize(rot)


class RotationVector(AbstractRotation):
    """Borri 1990's rotation vector r, R = exp(r x I) (App. A)."""

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

    def normalize(self, rot):
        return rv.rescale(rot)
