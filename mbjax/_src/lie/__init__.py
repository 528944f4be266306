"""Rotations: the rotation vector, its tangent map Gamma (Borri 1990 App. A) and quaternions.

Every function is exact and differentiable (to any order) at and near zero rotation.
"""

from mbjax._src.lie.quaternion import (
    quat_conjugate as quat_conjugate,
    quat_from_matrix as quat_from_matrix,
    quat_from_rotvec as quat_from_rotvec,
    quat_multiply as quat_multiply,
    quat_normalize as quat_normalize,
    quat_to_matrix as quat_to_matrix,
    rotvec_from_quat as rotvec_from_quat,
)
from mbjax._src.lie.rotation_vector import (
    det_gamma as det_gamma,
    exp as exp,
    gamma as gamma,
    gamma_inv as gamma_inv,
    hat as hat,
    log as log,
    rescale as rescale,
    vee as vee,
)
from mbjax._src.lie.sincos import sincos as sincos
