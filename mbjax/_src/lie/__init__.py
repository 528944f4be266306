"""Rotations: the rotation vector, its tangent map Gamma (Borri 1990 App. A) and quaternions.

Every function is exact and differentiable (to any order) at and near zero rotation.
"""

from mbjax._src.lie.quaternion import (
    quat_conjugate,
    quat_from_matrix,
    quat_from_rotvec,
    quat_multiply,
    quat_normalize,
    quat_to_matrix,
    rotvec_from_quat,
)
from mbjax._src.lie.rotation_vector import det_gamma, exp, gamma, gamma_inv, hat, log, rescale, vee
from mbjax._src.lie.sincos import sincos

__all__ = [
    "det_gamma", "exp", "gamma", "gamma_inv", "hat", "log", "rescale", "sincos", "vee",
    "quat_conjugate", "quat_from_matrix", "quat_from_rotvec", "quat_multiply", "quat_normalize",
    "quat_to_matrix", "rotvec_from_quat",
]
