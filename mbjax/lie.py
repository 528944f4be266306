"""Rotations: the rotation vector, its tangent map Gamma (Borri 1990 App. A) and quaternions
(w, x, y, z). Every function is exact and differentiable, to any order, at and near zero rotation."""

from mbjax._src.lie.rotation_vector import exp as exp
from mbjax._src.lie.rotation_vector import log as log
from mbjax._src.lie.rotation_vector import hat as hat
from mbjax._src.lie.rotation_vector import vee as vee
from mbjax._src.lie.rotation_vector import gamma as gamma
from mbjax._src.lie.rotation_vector import gamma_inv as gamma_inv
from mbjax._src.lie.coordinates import AbstractRotation as AbstractRotation
from mbjax._src.lie.coordinates import Quaternion as Quaternion
from mbjax._src.lie.coordinates import RotationVector as RotationVector
from mbjax._src.lie.quaternion import quat_to_matrix as quat_to_matrix
from mbjax._src.lie.quaternion import quat_from_matrix as quat_from_matrix

__all__ = [
    "AbstractRotation", "Quaternion", "RotationVector",
    "exp", "log", "hat", "vee", "gamma", "gamma_inv", "quat_to_matrix", "quat_from_matrix"
]
